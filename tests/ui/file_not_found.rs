chain::machine!(pub M = "tests/ui/no_such_machine.yaml");
fn main() {}
