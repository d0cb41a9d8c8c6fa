//! Generated code vs hand-written Rust vs the runtime tape (issue 7 targets;
//! figures in docs/performance.md). Run with
//! `cargo bench -p chain-macro --bench generated`.

use std::hint::black_box;

use chain::core::ErrorModel;
use criterion::{criterion_group, Criterion};

chain::machine!(GantryGrinder = "../examples/machines/gantry_grinder.yaml");
chain::machine!(Cnc5Bevel = "../examples/machines/cnc5_bevel.yaml");
chain::machine!(AcTrunnion = "../examples/machines/ac_trunnion.yaml");
chain::machine!(BcHeadTable = "benches/machines/bc_head_table.yaml");

/// The v1 emission of the same machine (`chain derive --format rust`, the
/// bodies before issue 17), committed for `tests/generated_into.rs`.
#[allow(dead_code)]
mod v1 {
    include!("../../tests/generated_v1/bc_head_table.rs");
}

/// SymPy's `cse` + `rust_code` of the same 6×33 Jacobian
/// (`benches/sympy/generate.py`).
mod sympy {
    include!("sympy/bc_head_table_sympy.rs");
}

/// Seed 000's corrected Eq. 18 sensitivity written by hand, in the generated
/// type's error order (docs/errata.md for the two corrections).
#[inline]
fn hand_written(q: &[f64; 3]) -> [[f64; 21]; 6] {
    let (x, z, y) = (q[0], q[1], q[2]);
    use GantryGrinder as G;
    let mut s = [[0.0; 21]; 6];
    s[0][G::ERR_DXX] = -1.0;
    s[0][G::ERR_EYX] = -z;
    s[0][G::ERR_EZX] = y;
    s[0][G::ERR_SXY] = y;
    s[0][G::ERR_DXZ] = 1.0;
    s[0][G::ERR_EZZ] = -y;
    s[0][G::ERR_DXY] = 1.0;
    s[1][G::ERR_DYX] = -1.0;
    s[1][G::ERR_EXX] = z;
    s[1][G::ERR_EZX] = x;
    s[1][G::ERR_SXY] = x;
    s[1][G::ERR_DYZ] = 1.0;
    s[1][G::ERR_DYY] = 1.0;
    s[2][G::ERR_DZX] = -1.0;
    s[2][G::ERR_EXX] = -y;
    s[2][G::ERR_EYX] = -x;
    s[2][G::ERR_DZZ] = 1.0;
    s[2][G::ERR_EXZ] = y;
    s[2][G::ERR_SYZ] = y;
    s[2][G::ERR_DZY] = 1.0;
    s[3][G::ERR_EXX] = -1.0;
    s[3][G::ERR_EXZ] = 1.0;
    s[3][G::ERR_SYZ] = 1.0;
    s[3][G::ERR_EXY] = 1.0;
    s[4][G::ERR_EYX] = -1.0;
    s[4][G::ERR_EYZ] = 1.0;
    s[4][G::ERR_SXZ] = 1.0;
    s[4][G::ERR_EYY] = 1.0;
    s[5][G::ERR_EZX] = -1.0;
    s[5][G::ERR_SXY] = -1.0;
    s[5][G::ERR_EZZ] = 1.0;
    s[5][G::ERR_EZY] = 1.0;
    s
}

fn gantry(c: &mut Criterion) {
    let q = [500.0, 1000.0, 750.0];
    assert_eq!(hand_written(&q), GantryGrinder::sensitivity(&q, &[]));
    c.bench_function("gantry_sensitivity/generated", |b| {
        b.iter(|| black_box(GantryGrinder::sensitivity(black_box(&q), &[])))
    });
    c.bench_function("gantry_sensitivity/hand_written", |b| {
        b.iter(|| black_box(hand_written(black_box(&q))))
    });
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/machines/gantry_grinder.yaml"
    );
    let machine = chain::core::load_file(std::path::Path::new(path)).expect("valid machine");
    let runtime = chain::core::compile(&machine);
    let mut out = vec![0.0; 6 * 21];
    c.bench_function("gantry_sensitivity/runtime_tape", |b| {
        b.iter(|| {
            runtime.sensitivity(black_box(&q), &[], &mut out);
            black_box(&out);
        })
    });
}

fn five_axis(c: &mut Criterion) {
    let p: Vec<f64> = Cnc5Bevel::PARAMETER_VALUES
        .iter()
        .map(|v| v.unwrap_or(100.0))
        .collect();
    let p: [f64; 1] = [p[0]];
    let q = [120.0, -40.0, 0.3, 250.0, 0.5, -0.2];
    c.bench_function("cnc5_bevel_sensitivity/generated", |b| {
        b.iter(|| black_box(Cnc5Bevel::sensitivity(black_box(&q), black_box(&p))))
    });
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/machines/cnc5_bevel.yaml"
    );
    let machine = chain::core::load_file(std::path::Path::new(path)).expect("valid machine");
    let runtime = chain::core::compile(&machine);
    let mut out = vec![0.0; 6 * runtime.errors().len()];
    c.bench_function("cnc5_bevel_sensitivity/runtime_tape", |b| {
        b.iter(|| {
            runtime.sensitivity(black_box(&q), black_box(&p), &mut out);
            black_box(&out);
        })
    });
}

/// The "two rotary axes, 40+ errors" machine of the issue: an A/C trunnion
/// with 41 errors (`examples/machines/ac_trunnion.yaml`).
fn two_rotary_axes(c: &mut Criterion) {
    let p = [150.0, 200.0];
    let q = [-40.0, 0.5, -1.2, 120.0, 250.0];
    c.bench_function("ac_trunnion_sensitivity/generated", |b| {
        b.iter(|| black_box(AcTrunnion::sensitivity(black_box(&q), black_box(&p))))
    });
}

/// Issue 17: the B-head/C-table machine with 33 errors
/// (`benches/machines/bc_head_table.yaml`): the v1 body, the new functions
/// and SymPy's output of the same Jacobian, in one binary.
fn bc_head_table(c: &mut Criterion) {
    let p = [150.0];
    let q = [120.0, 0.7, -40.0, 250.0, -0.4];
    let reference = BcHeadTable::sensitivity(&q, &p);
    let mut sym = [[0.0; 33]; 6];
    sympy::sensitivity_sympy(&q, &p, &mut sym);
    for (a, b) in reference.iter().flatten().zip(sym.iter().flatten()) {
        assert!(
            (a - b).abs() <= 1e-12 * a.abs().max(1.0),
            "SymPy {b} vs {a}"
        );
    }
    assert_eq!(v1::BcHeadTable::sensitivity(&q, &p), reference);
    let mut g = c.benchmark_group("bc_head_table");
    g.bench_function("v1_sensitivity", |b| {
        b.iter(|| black_box(v1::BcHeadTable::sensitivity(black_box(&q), black_box(&p))))
    });
    g.bench_function("sensitivity", |b| {
        b.iter(|| black_box(BcHeadTable::sensitivity(black_box(&q), black_box(&p))))
    });
    let mut out = [[0.0; 33]; 6];
    g.bench_function("sensitivity_into", |b| {
        b.iter(|| {
            BcHeadTable::sensitivity_into(black_box(&q), black_box(&p), &mut out);
            black_box(&mut out);
        })
    });
    let mut nz = [0.0; BcHeadTable::NONZEROS.len()];
    g.bench_function("sensitivity_nonzeros", |b| {
        b.iter(|| {
            BcHeadTable::sensitivity_nonzeros(black_box(&q), black_box(&p), &mut nz);
            black_box(&mut nz);
        })
    });
    g.bench_function("sympy_cse_rust_code", |b| {
        b.iter(|| {
            sympy::sensitivity_sympy(black_box(&q), black_box(&p), &mut out);
            black_box(&mut out);
        })
    });
    g.finish();
}

criterion_group!(benches, gantry, five_axis, two_rotary_axes, bc_head_table);
/// `CHAIN_CALLGRIND=NAME:COUNT` runs one function of the `bc_head_table`
/// group COUNT times and exits (no criterion): instruction counts under
/// `valgrind --tool=callgrind` that do not depend on the machine's load
/// (docs/performance.md, "Generated code at the limit").
fn callgrind(spec: &str) {
    let (name, count) = spec.split_once(':').unwrap_or((spec, "100000"));
    let count: usize = count.parse().expect("CHAIN_CALLGRIND=NAME:COUNT");
    let p = [150.0];
    let q = [120.0, 0.7, -40.0, 250.0, -0.4];
    let mut out = [[0.0; 33]; 6];
    let mut nz = [0.0; BcHeadTable::NONZEROS.len()];
    for _ in 0..count {
        match name {
            "v1_sensitivity" => {
                black_box(v1::BcHeadTable::sensitivity(black_box(&q), black_box(&p)));
            }
            "sensitivity" => {
                black_box(BcHeadTable::sensitivity(black_box(&q), black_box(&p)));
            }
            "sensitivity_into" => {
                BcHeadTable::sensitivity_into(black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            }
            "sensitivity_nonzeros" => {
                BcHeadTable::sensitivity_nonzeros(black_box(&q), black_box(&p), &mut nz);
                black_box(&mut nz);
            }
            "sympy" => {
                sympy::sensitivity_sympy(black_box(&q), black_box(&p), &mut out);
                black_box(&mut out);
            }
            "sin_cos" => {
                let (s, c) = black_box(q[1]).sin_cos();
                let (t, d) = black_box(q[4]).sin_cos();
                black_box((s, c, t, d));
            }
            other => panic!("unknown function {other}"),
        }
    }
}

fn main() {
    if let Ok(spec) = std::env::var("CHAIN_CALLGRIND") {
        callgrind(&spec);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
