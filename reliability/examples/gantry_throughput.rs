//! Throughput of FORM, the importance sampling and Monte Carlo on the gantry
//! grinder of seed 000, on one thread, printed as one JSON line. Used by
//! `reliability/benches/openturns_compare.py` for the side-by-side comparison
//! with OpenTURNS (docs/performance.md); the criterion benches are
//! `cargo bench -p reliability`.
//!
//! `cargo run --release -p reliability --example gantry_throughput [SAMPLES]`

use std::path::Path;
use std::time::Instant;

use chain_core::model::{Component, Sided};
use reliability::{
    machine, Algorithm, Event, Form, ImportanceSampling, MonteCarlo, Sampler, ToleranceLimitState,
};

fn main() -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let samples: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1 << 22);
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let m = chain_core::load_file(&path).map_err(|e| format!("{e}"))?;
    let model = chain_core::compile(&m);
    let study = machine::study(&m, &model, &[], None)?;
    let v = |n: &str| study.variables().iter().position(|x| x == n).unwrap_or(0);
    let (ix, iy, iz) = (v("x"), v("y"), v("z"));
    let corner = study
        .points()
        .iter()
        .position(|p| p[ix] == 1000.0 && p[iy] == 1500.0 && p[iz] == 1400.0)
        .ok_or("corner")?;
    let ls = ToleranceLimitState::component(
        study.row(corner, Component::Px).unwrap().to_vec(),
        0.03,
        Sided::Upper,
    )?;
    let event = Event::new(study.inputs(), ls)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    pool.install(|| -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        let best = |f: &mut dyn FnMut() -> Result<f64, Box<dyn std::error::Error + Send + Sync>>| {
            let mut t = f64::INFINITY;
            let mut last = 0.0;
            for _ in 0..3 {
                let s = Instant::now();
                last = f()?;
                t = t.min(s.elapsed().as_secs_f64());
            }
            Ok::<_, Box<dyn std::error::Error + Send + Sync>>((t, last))
        };
        let (t_form, r_form) = best(&mut || {
            let r = study.run(&Algorithm::Form(Form::default()), &())?;
            Ok(r.summaries[0].min)
        })?;
        let (t_form1, pf_form) = best(&mut || Ok(Form::default().run(&event)?.pf))?;
        let (t_is, pf_is) = best(&mut || {
            Ok(ImportanceSampling { samples, seed: 1, form: Form::default(), cov: None }.run(&event)?.pf)
        })?;
        let (t_mc, pf_mc) = best(&mut || Ok(MonteCarlo { samples, seed: 1, cov: None }.run(&event)?.pf))?;
        println!(
            "{{\"samples\": {samples}, \"form_375_cases_s\": {t_form:e}, \"form_px_min\": {r_form}, \
             \"form_one_case_s\": {t_form1:e}, \"form_pf\": {pf_form}, \"is_s\": {t_is:e}, \"is_pf\": {pf_is}, \
             \"mc_s\": {t_mc:e}, \"mc_pf\": {pf_mc}}}"
        );
        Ok(())
    })
}
