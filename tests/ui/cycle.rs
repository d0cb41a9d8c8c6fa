chain::machine! {
    pub M {
        bodies {
            bed {},
            a { parent: b, joint: { type: prismatic, axis: +x, variable: x } },
            b { parent: a, joint: { type: prismatic, axis: +y, variable: y } },
        },
        workpiece: bed,
        tool: a,
    }
}
fn main() {}
