chain::machine! {
    pub M {
        parameters: { L: 100 },
        bodies {
            bed {},
            slide { parent: bed, offset: [0, 0, L * / 2], joint: { type: prismatic, axis: +x, variable: x } },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
