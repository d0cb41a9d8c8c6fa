//! Criterion benchmark of FORM + SORM on the 375 cases of the gantry grinder
//! (`examples/machines/gantry_grinder.yaml`) with non-normal inputs and one
//! correlation: `dxx` lognormal (mean 0.002, std 0.05/6, shift −0.03), `dyy`
//! truncated normal on [−0.01, 0.012], and `dxx`–`dyx` correlated 0.5 (Nataf).
//!
//! Run with `cargo bench -p reliability --bench sorm`; the figure is recorded
//! in `docs/performance.md` ("FORM + SORM with non-normal, correlated
//! inputs").
//!
//! With `CHAIN_SORM_CASES=path.json` set, the benchmark first writes the 375
//! cases (inputs, each case's sensitivity row, tolerance and chain's FORM and
//! SORM indices) to that file for `openturns_sorm375.py`, the side-by-side
//! run through OpenTURNS.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use reliability::machine;
use reliability::sorm::Sorm;

fn gantry() -> (chain_core::Machine, chain_core::CompiledModel) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/machines/gantry_grinder.yaml");
    let text = std::fs::read_to_string(&path)
        .expect("gantry_grinder.yaml")
        .replace(
            "  dxx: {dist: normal, mean: 0, std: 0.05/6}",
            "  dxx: {dist: lognormal, mean: 0.002, std: 0.05/6, shift: -0.03}",
        )
        .replace(
            "  dyy: {dist: normal, mean: 0, std: 0.05/6}",
            "  dyy: {dist: truncated_normal, mean: 0, std: 0.05/6, min: -0.01, max: 0.012}",
        );
    let text = format!("{text}\ncorrelation:\n  - [dxx, dyx, 0.5]\n");
    let machine = chain_core::load_str(&text, "gantry_nonnormal.yaml").expect("machine");
    let model = chain_core::compile(&machine);
    (machine, model)
}

fn benches(c: &mut Criterion) {
    let (machine, model) = gantry();
    let study = machine::study(&machine, &model, &[], None).expect("study");
    let events = study.events().expect("events");
    assert_eq!(events.len(), 375);
    let sorm = Sorm::default();
    if let Ok(path) = std::env::var("CHAIN_SORM_CASES") {
        write_cases(&path, study.inputs(), &events, &sorm);
    }
    let mut g = c.benchmark_group("sorm");
    g.throughput(Throughput::Elements(375));
    g.bench_function("375_cases_nonnormal", |b| {
        b.iter(|| {
            for e in &events {
                let r = sorm.run(e).expect("sorm");
                assert!(r.converged);
                black_box(r);
            }
        })
    });
    g.finish();
}

/// The cases and chain's answers as JSON, for the OpenTURNS script.
fn write_cases(
    path: &str,
    inputs: &reliability::Inputs,
    events: &[reliability::Event<'_>],
    sorm: &Sorm,
) {
    let cases: Vec<serde_json::Value> = events
        .iter()
        .map(|e| {
            let r = sorm.run(e).expect("sorm");
            serde_json::json!({
                "row": e.limit_state.row(0),
                "tolerance": e.limit_state.tolerances()[0],
                "beta_form": r.form.beta,
                "beta_breitung": r.beta_breitung,
                "beta_hohenbichler_rackwitz": r.beta_hohenbichler_rackwitz,
                "beta_tvedt": r.beta_tvedt,
            })
        })
        .collect();
    let doc = serde_json::json!({"inputs": inputs, "cases": cases});
    std::fs::write(path, serde_json::to_string(&doc).expect("json")).expect("write the cases");
}

criterion_group! {
    name = group;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(group);
