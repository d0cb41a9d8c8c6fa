chain::machine! {
    pub M {
        bodies { bed {}, slide { parnt: bed, joint: { type: prismatic, axis: +x, variable: x } } },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
