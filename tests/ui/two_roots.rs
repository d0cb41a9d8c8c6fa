chain::machine! {
    pub M {
        bodies { bed {}, base {}, slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x } } },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
