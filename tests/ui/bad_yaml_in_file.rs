chain::machine!(pub M = "tests/ui/bad_yaml.yaml");
fn main() {}
