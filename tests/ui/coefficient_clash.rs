chain::machine! {
    pub M {
        bodies {
            bed {},
            slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dx: EYX_2, dy: { name: EYX, powers: [1, 2] } },
            },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
