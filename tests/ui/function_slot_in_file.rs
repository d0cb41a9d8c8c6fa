chain::machine!(pub M = "tests/ui/function_slot.yaml");
fn main() {}
