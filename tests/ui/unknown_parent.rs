chain::machine! {
    pub M {
        bodies { bed {}, slide { parent: bde, joint: { type: prismatic, axis: +x, variable: x } } },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
