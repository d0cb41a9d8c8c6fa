// A crate outside the workspace that depends on `chain` alone: the generated
// code must name only paths reachable through `chain`.
use chain::core::ErrorModel;

chain::machine! {
    pub Slide {
        parameters: { L: 250 },
        bodies {
            bed {},
            x_slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dx: dxx, ey: eyx, ez: ezx },
            },
            spindle { parent: x_slide, offset: [0, 0, -L] },
        },
        workpiece: bed,
        tool: spindle,
    }
}

chain::machine!(pub(crate) Gantry = "examples/machines/gantry_grinder.yaml");

fn main() {
    let s = Slide::sensitivity(&[10.0], &[250.0]);
    // px = dxx - L*eyx (the tool sits L below the slide)
    assert_eq!(s[0][Slide::ERR_DXX], 1.0);
    assert_eq!(s[0][Slide::ERR_EYX], -250.0);
    let model: &dyn ErrorModel = &Gantry;
    assert_eq!(model.errors().len(), 21);
}
