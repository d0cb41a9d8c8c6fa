chain::machine! {
    pub M {
        bodies { bed {}, slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x }, errors: { dx: dxx } } },
        workpiece: bed,
        tool: slide,
        statistics: { dxx: { dist: normal, mean: 0, std: -0.01 } },
    }
}
fn main() {}
