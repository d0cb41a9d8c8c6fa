chain::machine! {
    pub M {
        bodies { bed {}, slide { parent: bed, joint: { type: prismatic, axis: +x, variable: x } } },
        tool: slide,
    }
}
fn main() {}
