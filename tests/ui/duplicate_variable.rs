chain::machine! {
    pub M {
        bodies {
            bed {},
            a { parent: bed, joint: { type: prismatic, axis: +x, variable: x } },
            b { parent: a, joint: { type: prismatic, axis: +y, variable: x } },
        },
        workpiece: bed,
        tool: b,
    }
}
fn main() {}
