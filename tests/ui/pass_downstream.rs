// A crate outside the workspace that depends on `chain` alone: the generated
// code must name only paths reachable through `chain`. tests/it/commands/downstream.rs
// builds this same file as a crate of its own on `chain` without default
// features (the library without the CLI).
use chain::core::ErrorModel;
use chain::reliability::{Event, Form, Inputs, Marginal, ToleranceLimitState};

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

pub fn main() {
    let s = Slide::sensitivity(&[10.0], &[250.0]);
    // px = dxx - L*eyx (the tool sits L below the slide)
    assert_eq!(s[0][Slide::ERR_DXX], 1.0);
    assert_eq!(s[0][Slide::ERR_EYX], -250.0);
    let model: &dyn ErrorModel = &Gantry;
    assert_eq!(model.errors().len(), 21);
    // A FORM reliability on the generated model: px = dxx - L*eyx against a
    // 0.03 mm tolerance.
    let inputs = Inputs::new(
        vec!["dxx".into(), "eyx".into()],
        vec![
            Marginal::normal(0.0, 0.01).unwrap(),
            Marginal::normal(0.0, 0.00001).unwrap(),
        ],
    )
    .unwrap();
    let g = ToleranceLimitState::component(
        vec![s[0][Slide::ERR_DXX], s[0][Slide::ERR_EYX]],
        0.03,
        chain::core::model::Sided::Upper,
    )
    .unwrap();
    let form = Form::default()
        .run(&Event::new(&inputs, g).unwrap())
        .unwrap();
    assert!(form.reliability > 0.99);
}
