chain::machine! {
    pub M {
        bodies {
            bed {},
            slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dz: { name: EZX, basis: legendre, degree: 3 } },
            },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
