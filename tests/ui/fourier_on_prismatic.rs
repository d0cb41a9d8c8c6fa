chain::machine! {
    pub M {
        bodies {
            bed {},
            slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dy: { name: EYX, basis: fourier, harmonics: 2 } },
            },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
