chain::machine!(pub M = "tests/ui/bad_key.yaml");
fn main() {}
