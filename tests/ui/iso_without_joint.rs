chain::machine! {
    pub M {
        bodies {
            bed { errors: iso },
            slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x }, errors: iso },
        },
        workpiece: bed,
        tool: slide,
    }
}
fn main() {}
