//! Criterion benchmarks of reliability with a posterior (`docs/posterior.md`)
//! on the gantry grinder of seed 000: the cost of the correlated normal block
//! against the independent inputs of the `statistics` section.
//!
//! Run with `cargo bench -p reliability --bench posterior`; figures in
//! `docs/performance.md`.
//!
//! - `posterior/form_375_cases/{independent,correlated}`: FORM on every case of
//!   the 5×5×5 grid (closed form on the standard-space rows);
//! - `posterior/mc_px/{independent,correlated}`: crude Monte Carlo on px at the
//!   worst corner through the general route (`x = T(u)` per sample, the limit
//!   state's affine view hidden), 2¹⁸ samples, one thread.

use std::hint::black_box;
use std::path::Path;

use chain_core::model::{Component, Sided};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use reliability::{
    machine, Algorithm, Event, Form, Inputs, LimitState, MonteCarlo, Posterior, Sampler, Study,
    ToleranceLimitState,
};

const POSTERIOR: &str = "machine: gantry_grinder
values:
  dxx: {value: 0.004, std: 0.003}
  dxz: {value: -0.002, std: 0.0025}
  eyx: {value: 2.0e-6, std: 4.0e-6}
  dxy: {value: 0.001, std: 0.004}
correlation:
  - [dxx, dxz, -0.45]
  - [eyx, dxx, 0.3]
  - [dxy, dxz, 0.2]
";

/// The limit state without its affine view: the general sampling route.
struct Hidden(ToleranceLimitState);

impl LimitState for Hidden {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn branch(&self, b: usize, x: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        self.0.branch(b, x, gradient)
    }
}

fn benches(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).expect("gantry_grinder.yaml");
    let model = chain_core::compile(&m);
    let posterior =
        Posterior::parse(POSTERIOR, "posterior.yaml", Path::new("."), &m).expect("posterior");
    let correlated = posterior.inputs(&m).expect("inputs");
    let independent = machine::inputs(&m).expect("inputs");
    let spec = machine::spec(&m, None).expect("spec");
    let study =
        |inputs: &Inputs| Study::new(&model, &[], inputs.clone(), spec.clone()).expect("study");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let studies = [
        ("independent", study(&independent)),
        ("correlated", study(&correlated)),
    ];

    let mut g = c.benchmark_group("posterior/form_375_cases");
    g.throughput(Throughput::Elements(375));
    for (name, s) in &studies {
        g.bench_function(*name, |b| {
            pool.install(|| {
                b.iter(|| black_box(s.run(&Algorithm::Form(Form::default()), &()).expect("form")))
            })
        });
    }
    g.finish();

    const SAMPLES: u64 = 1 << 18;
    let mut g = c.benchmark_group("posterior/mc_px");
    g.throughput(Throughput::Elements(SAMPLES));
    g.sample_size(10);
    for (name, s) in &studies {
        let p = s.points().len() - 1;
        let ls = ToleranceLimitState::component(
            s.row(p, Component::Px).unwrap().to_vec(),
            0.03,
            Sided::Upper,
        )
        .expect("limit state");
        let event = Event::new(s.inputs(), Hidden(ls)).expect("event");
        let mc = MonteCarlo {
            samples: SAMPLES,
            seed: 1,
            cov: None,
        };
        g.bench_function(*name, |b| {
            pool.install(|| b.iter(|| black_box(mc.run(&event).expect("mc"))))
        });
    }
    g.finish();
}

criterion_group!(posterior_benches, benches);
criterion_main!(posterior_benches);
