chain::machine! {
    pub M {
        bodies { bed {}, slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x } } },
        workpiece: bed,
        tool: slide,
        frame: spindle,
    }
}
fn main() {}
