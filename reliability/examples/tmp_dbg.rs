use chain_core::model::{Component, Sided};
use reliability::{machine, sensitivity, Event, Form, Inputs, ToleranceLimitState};
use std::path::Path;
fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).unwrap();
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None).unwrap();
    let p = 24;
    let row = study.row(p, Component::Px).to_vec();
    println!("point {:?} row {:?}", study.points()[p], row);
    let base = study
        .inputs()
        .with_moments(0, 0.002, study.inputs().stds()[0])
        .and_then(|i| i.with_moments(4, 2e-6, i.stds()[4]))
        .unwrap();
    println!("means {:?}\nstds {:?}", base.means(), base.stds());
    let r = |inp: &Inputs| {
        1.0 - Event::new(
            inp,
            ToleranceLimitState::component(row.clone(), 0.03, Sided::Upper).unwrap(),
        )
        .unwrap()
        .exact_pf()
        .unwrap()
    };
    let e = Event::new(
        &base,
        ToleranceLimitState::component(row.clone(), 0.03, Sided::Upper).unwrap(),
    )
    .unwrap();
    let s = sensitivity(&e, &Form::default().run(&e).unwrap()).unwrap();
    let (mu, sd) = (base.means()[0], base.stds()[0]);
    let h = 1e-4 * sd;
    let fd = (r(&base.with_moments(0, mu, sd + h).unwrap())
        - r(&base.with_moments(0, mu, sd - h).unwrap()))
        / (2.0 * h);
    println!("dstd analytic {} fd {}", s.inputs[0].dr_dstd, fd);
    println!("R {} {}", s.reliability, r(&base));
}
