//! The matrix route (`chain_core::derive`) and seed 000's differential-motion-
//! matrix route (its Eq. 3 and Eq. 5, `chain_core::dmm`) run over the same ring
//! and must give identical canonical polynomials on every example machine, in
//! both frames.

use crate::common;

use chain_core::model::{Component, Frame};
use common::{example_machines, example_path};

#[test]
fn dmm_route_equals_matrix_route_on_every_example() {
    let files = example_machines();
    assert!(
        files.len() >= 3,
        "expected the three paper machines, got {files:?}"
    );
    for path in files {
        let machine = chain_core::load_file(&path).unwrap_or_else(|e| panic!("{e}"));
        for frame in [Frame::Tool, Frame::Workpiece] {
            let model = chain_core::derive_in(&machine, frame);
            let dmm = chain_core::dmm::derive_dmm(&machine, frame);
            for c in Component::ALL {
                let a = &model.components[c.index()];
                let b = &dmm[c.index()];
                let names = |v: &Vec<(usize, chain_core::algebra::Poly)>| {
                    v.iter()
                        .map(|(j, p)| {
                            format!(
                                "{}: {}",
                                machine.errors[*j].name,
                                p.to_text(&|s| model.symbol_name(s))
                            )
                        })
                        .collect::<Vec<_>>()
                };
                assert_eq!(
                    names(a),
                    names(b),
                    "{} {:?} {}",
                    path.display(),
                    frame,
                    c.name()
                );
            }
            assert!(model.nonzero_count() > 0, "{}: empty model", path.display());
        }
    }
}

/// The spec's section 2 gantry example: its section 3 JSON excerpt gives
/// `nominal.position = ["-x", "y", "z"]` and px ∋ {dxx: -1, eyx: -z, ezx: y}.
#[test]
fn spec_example_json_excerpt() {
    let path = example_path("gantry_grinder.yaml");
    let machine = chain_core::load_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let model = chain_core::derive(&machine);
    let json = chain_core::export::to_json(&model);
    assert_eq!(json.frame, "tool");
    assert_eq!(
        json.nominal.position,
        ["-x".to_string(), "y".into(), "z".into()]
    );
    let px = json.components["px"].as_object().expect("px is an object");
    assert_eq!(px["dxx"], "-1");
    assert_eq!(px["eyx"], "-z");
    assert_eq!(px["ezx"], "y");
    // seed 000 Eq. 17: the Z axis's angular error ε_zz enters px as −y·ε_zz.
    assert_eq!(px["ezz"], "-y");
}
