use chain_core::model::{Component, Sided};
use reliability::{machine, Event, Form, ImportanceSampling, MonteCarlo, ToleranceLimitState};
use std::path::Path;
use std::time::Instant;
fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).unwrap();
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None).unwrap();
    let p = study.points().len() - 1;
    let ls =
        ToleranceLimitState::component(study.row(p, Component::Px).to_vec(), 0.03, Sided::Upper)
            .unwrap();
    let event = Event::new(study.inputs(), ls).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let what = std::env::args().nth(1).unwrap_or_default();
    pool.install(|| {
        for _ in 0..3 {
            let n = 1u64 << 22;
            if what != "is" {
                let t = Instant::now();
                let r = MonteCarlo {
                    samples: n,
                    seed: 1,
                }
                .run(&event)
                .unwrap();
                println!(
                    "mc {:.1} ns/sample ({})",
                    t.elapsed().as_secs_f64() * 1e9 / n as f64,
                    r.pf
                );
            }
            if what != "mc" {
                let t = Instant::now();
                let r = ImportanceSampling {
                    samples: n,
                    seed: 1,
                    form: Form::default(),
                }
                .run(&event)
                .unwrap();
                println!(
                    "is {:.1} ns/sample ({})",
                    t.elapsed().as_secs_f64() * 1e9 / n as f64,
                    r.pf
                );
            }
        }
    });
}
