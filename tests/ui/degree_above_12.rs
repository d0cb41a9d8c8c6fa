chain::machine! {
    pub M {
        bodies {
            bed {},
            slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dz: { name: EZX, basis: chebyshev, degree: 13, range: [0, 1000] } },
            },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
