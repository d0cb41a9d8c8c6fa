chain::machine! {
    pub M {
        bodies: { bed {} },
        workpiece bed,
        tool: bed,
    }
}
fn main() {}
