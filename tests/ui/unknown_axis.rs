chain::machine! {
    pub M {
        bodies { bed {}, slide { parent: bed, joint: { type: prismatic, axis: +w, variable: x } } },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
