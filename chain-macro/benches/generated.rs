//! Generated code vs hand-written Rust vs the runtime tape (targets and
//! figures in docs/performance.md). Run with
//! `cargo bench -p chain-macro --bench generated`.

use std::hint::black_box;

use chain::core::ErrorModel;
use criterion::{criterion_group, Criterion};

chain::machine!(GantryGrinder = "../examples/machines/gantry_grinder.yaml");
chain::machine!(Cnc5Bevel = "../examples/machines/cnc5_bevel.yaml");
chain::machine!(AcTrunnion = "../examples/machines/ac_trunnion.yaml");
chain::machine!(BcHeadTable = "benches/machines/bc_head_table.yaml");
chain::machine!(CradleGenerator = "../examples/machines/cradle_generator.yaml");
chain::machine!(HeadHeadBc = "../examples/machines/head_head_bc.yaml");
chain::machine!(InternalGrinder = "../examples/machines/internal_grinder.yaml");
chain::machine!(Legendre5 = "../examples/machines/legendre5.yaml");
chain::machine!(SpreadAlongAxis = "../examples/machines/spread_along_axis.yaml");
chain::machine!(Vmc3 = "../examples/machines/vmc3.yaml");

/// The v1 emission of the same machine (`chain derive --format rust`: the
/// plain bodies, without the shared sums of what `machine!` emits),
/// committed for `tests/it/commands/generated_into.rs`.
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
    let runtime = runtime_tape("../examples/machines/gantry_grinder.yaml");
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
    let runtime = runtime_tape("../examples/machines/cnc5_bevel.yaml");
    let mut out = vec![0.0; 6 * runtime.errors().len()];
    c.bench_function("cnc5_bevel_sensitivity/runtime_tape", |b| {
        b.iter(|| {
            runtime.sensitivity(black_box(&q), black_box(&p), &mut out);
            black_box(&out);
        })
    });
}

/// The "two rotary axes, 40+ errors" target machine: an A/C trunnion
/// with 41 errors (`examples/machines/ac_trunnion.yaml`).
fn two_rotary_axes(c: &mut Criterion) {
    let p = [150.0, 200.0];
    let q = [-40.0, 0.5, -1.2, 120.0, 250.0];
    c.bench_function("ac_trunnion_sensitivity/generated", |b| {
        b.iter(|| black_box(AcTrunnion::sensitivity(black_box(&q), black_box(&p))))
    });
}

/// The B-head/C-table machine with 33 errors
/// (`benches/machines/bc_head_table.yaml`): the v1 body, the functions
/// `machine!` emits and SymPy's output of the same Jacobian, in one binary.
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

/// Points per iteration of the `every_machine` group (criterion's
/// throughput is per point).
const POINTS: usize = 1024;

/// Points per call of the batched routes in the `every_machine` group.
const CHUNK: usize = 64;

/// Deterministic points of `nv` coordinates: ±500 on even coordinates,
/// a few radians on odd ones (every value is valid for both kinds).
fn bench_points(nv: usize) -> Vec<f64> {
    (0..POINTS * nv)
        .map(|i| {
            let x = (i as f64 * 0.618_033_988_749_895).fract() - 0.5;
            if i % 2 == 0 {
                1000.0 * x
            } else {
                6.0 * x
            }
        })
        .collect()
}

/// One group for every example machine and the B-head/C-table
/// five-axis machine, `POINTS` points per iteration: generated
/// `sensitivity_into`, the runtime tape point by point, the batched tape on
/// the calling thread (`sensitivity_points`) and `sensitivity_batch` in a
/// rayon pool of 1 and of 2 threads.
macro_rules! every_machine {
    ($g:expr, $pools:expr, $ty:ident, $name:literal, $path:literal) => {{
        const NV: usize = $ty::VARIABLES.len();
        const NP: usize = $ty::PARAMETERS.len();
        const NE: usize = $ty::ERRORS.len();
        let runtime = runtime_tape($path);
        let qs = bench_points(NV);
        let p: [f64; NP] = std::array::from_fn(|k| $ty::PARAMETER_VALUES[k].unwrap_or(100.0));
        // The runtime model's orders, by name.
        let var_of: Vec<usize> = (runtime.variables().iter())
            .map(|v| {
                $ty::VARIABLES
                    .iter()
                    .position(|w| w == v)
                    .expect("same variables")
            })
            .collect();
        let err_of: Vec<usize> = (runtime.errors().iter())
            .map(|e| {
                $ty::ERRORS
                    .iter()
                    .position(|f| f == e)
                    .expect("same errors")
            })
            .collect();
        let rp: Vec<f64> = (runtime.parameters().iter())
            .map(|n| {
                p[$ty::PARAMETERS
                    .iter()
                    .position(|m| m == n)
                    .expect("same parameters")]
            })
            .collect();
        let rqs: Vec<f64> = (0..POINTS)
            .flat_map(|k| var_of.iter().map(move |&v| (k, v)))
            .map(|(k, v)| qs[k * NV + v])
            .collect();
        // The four routes agree before they are timed.
        let mut batch = vec![0.0; POINTS * 6 * NE];
        runtime
            .sensitivity_batch(&rqs, &rp, &mut batch)
            .expect("sizes fit");
        for k in 0..POINTS {
            let q: [f64; NV] = std::array::from_fn(|v| qs[k * NV + v]);
            let mut out = [[0.0; NE]; 6];
            $ty::sensitivity_into(&q, &p, &mut out);
            for c in 0..6 {
                for (j, &g) in err_of.iter().enumerate() {
                    let (a, b) = (out[c][g], batch[k * 6 * NE + c * NE + j]);
                    assert!(
                        (a - b).abs() <= 1e-10 * a.abs().max(1.0),
                        "{}: point {k}, ({c}, {j}): generated {a} vs batch {b}",
                        $name
                    );
                }
            }
        }
        let mut out = [[0.0; NE]; 6];
        $g.bench_function(concat!($name, "/generated_into"), |b| {
            b.iter(|| {
                for q in qs.chunks_exact(NV) {
                    let q: &[f64; NV] = q.try_into().expect("NV values");
                    $ty::sensitivity_into(black_box(q), black_box(&p), &mut out);
                    black_box(&mut out);
                }
            })
        });
        let mut one = vec![0.0; 6 * NE];
        $g.bench_function(concat!($name, "/runtime_per_point"), |b| {
            b.iter(|| {
                for q in rqs.chunks_exact(NV) {
                    runtime.sensitivity(black_box(q), black_box(&rp), &mut one);
                    black_box(&mut one);
                }
            })
        });
        // The batched routes write `CHUNK` points' matrices into one reused
        // buffer at a time (as `BuiltMachine::map` consumes its runs), so
        // the output stays in cache as the generated code's one matrix does.
        let (cv, cw) = (CHUNK * NV, CHUNK * 6 * NE);
        let mut chunk = vec![0.0; cw];
        $g.bench_function(concat!($name, "/batch_calling_thread"), |b| {
            b.iter(|| {
                for qc in rqs.chunks_exact(cv) {
                    runtime
                        .sensitivity_points(black_box(qc), black_box(&rp), &mut chunk)
                        .expect("sizes fit");
                    black_box(&mut chunk);
                }
            })
        });
        $g.bench_function(concat!($name, "/batch_1_thread"), |b| {
            b.iter(|| {
                $pools[0].1.install(|| {
                    for qc in rqs.chunks_exact(cv) {
                        runtime
                            .sensitivity_batch(black_box(qc), black_box(&rp), &mut chunk)
                            .expect("sizes fit");
                        black_box(&mut chunk);
                    }
                })
            })
        });
        // Two threads: each takes half the points, its own reused buffer.
        let mut halves = vec![vec![0.0; cw]; 2];
        $g.bench_function(concat!($name, "/batch_2_thread"), |b| {
            b.iter(|| {
                $pools[1].1.install(|| {
                    use rayon::prelude::*;
                    (rqs.par_chunks(rqs.len() / 2))
                        .zip(halves.par_iter_mut())
                        .for_each(|(half, buf)| {
                            for qc in half.chunks_exact(cv) {
                                runtime
                                    .sensitivity_points(black_box(qc), black_box(&rp), buf)
                                    .expect("sizes fit");
                                black_box(&mut *buf);
                            }
                        })
                })
            })
        });
        // The whole `POINTS` matrices in one parallel call (2 threads).
        $g.bench_function(concat!($name, "/batch_all_points_2_thread"), |b| {
            b.iter(|| {
                $pools[1]
                    .1
                    .install(|| {
                        runtime.sensitivity_batch(black_box(&rqs), black_box(&rp), &mut batch)
                    })
                    .expect("sizes fit");
                black_box(&mut batch);
            })
        });
    }};
}

/// The `every_machine` group (see [`every_machine!`]).
fn every_machine(c: &mut Criterion) {
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, 2]
        .into_iter()
        .map(|t| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .expect("a pool");
            (t, pool)
        })
        .collect();
    let mut g = c.benchmark_group("every_machine");
    g.throughput(criterion::Throughput::Elements(POINTS as u64));
    g.sample_size(20)
        .warm_up_time(std::time::Duration::from_millis(700))
        .measurement_time(std::time::Duration::from_millis(2000));
    every_machine!(
        g,
        &pools,
        AcTrunnion,
        "ac_trunnion",
        "../examples/machines/ac_trunnion.yaml"
    );
    every_machine!(
        g,
        &pools,
        Cnc5Bevel,
        "cnc5_bevel",
        "../examples/machines/cnc5_bevel.yaml"
    );
    every_machine!(
        g,
        &pools,
        CradleGenerator,
        "cradle_generator",
        "../examples/machines/cradle_generator.yaml"
    );
    every_machine!(
        g,
        &pools,
        GantryGrinder,
        "gantry_grinder",
        "../examples/machines/gantry_grinder.yaml"
    );
    every_machine!(
        g,
        &pools,
        HeadHeadBc,
        "head_head_bc",
        "../examples/machines/head_head_bc.yaml"
    );
    every_machine!(
        g,
        &pools,
        InternalGrinder,
        "internal_grinder",
        "../examples/machines/internal_grinder.yaml"
    );
    every_machine!(
        g,
        &pools,
        Legendre5,
        "legendre5",
        "../examples/machines/legendre5.yaml"
    );
    every_machine!(
        g,
        &pools,
        SpreadAlongAxis,
        "spread_along_axis",
        "../examples/machines/spread_along_axis.yaml"
    );
    every_machine!(g, &pools, Vmc3, "vmc3", "../examples/machines/vmc3.yaml");
    every_machine!(
        g,
        &pools,
        BcHeadTable,
        "bc_head_table",
        "benches/machines/bc_head_table.yaml"
    );
    g.finish();
}

/// The batched generated kernel (`sensitivity_batch_into`,
/// four points per lane group) against the same type's per-point
/// `sensitivity_into` and, on the B-head/C-table machine, SymPy's per-point
/// code, `POINTS` points per iteration (throughput per point); the batch
/// writes `CHUNK` matrices into one reused buffer at a time, as the per-point
/// routes write one. `batch_2_thread`: two halves on a pool of two threads.
/// The `tape_*` routes are the same machine's runtime tape (`$yaml`,
/// `CompiledModel::sensitivity_points`, blocks of `BATCH_LANES` points) on
/// the same points.
macro_rules! batched {
    ($g:expr, $pools:expr, $ty:ident, $name:literal, $yaml:literal, $p:expr, $sympy:expr) => {{
        const NV: usize = $ty::VARIABLES.len();
        const NE: usize = $ty::ERRORS.len();
        let p = $p;
        let flat = bench_points(NV);
        let qs: Vec<[f64; NV]> = flat
            .chunks_exact(NV)
            .map(|q| q.try_into().expect("NV values"))
            .collect();
        let mut chunk = vec![[[0.0; NE]; 6]; CHUNK];
        $ty::sensitivity_batch_into(&qs[..CHUNK], &p, &mut chunk);
        for (q, s) in qs.iter().zip(&chunk) {
            let one = $ty::sensitivity(q, &p);
            for (a, b) in one.iter().flatten().zip(s.iter().flatten()) {
                assert!(
                    (a - b).abs() <= 1e-13 * a.abs().max(1.0),
                    "{}: {a} vs {b}",
                    $name
                );
            }
        }
        let tape = runtime_tape($yaml);
        let tp = &p[..tape.parameters().len()];
        let mut flat_chunk = vec![0.0; CHUNK * 6 * NE];
        tape.sensitivity_points(&flat[..CHUNK * NV], tp, &mut flat_chunk)
            .expect("sizes fit");
        for (a, b) in chunk.iter().flatten().flatten().zip(&flat_chunk) {
            assert!(
                (a - b).abs() <= 1e-13 * a.abs().max(1.0),
                "{} tape: {a} vs {b}",
                $name
            );
        }
        // Every route writes `CHUNK` matrices into one reused buffer, one
        // matrix per point, as a batch consumer does.
        $g.bench_function(concat!($name, "/sensitivity_into"), |b| {
            b.iter(|| {
                for qc in qs.chunks_exact(CHUNK) {
                    for (q, o) in qc.iter().zip(chunk.iter_mut()) {
                        $ty::sensitivity_into(black_box(q), black_box(&p), o);
                    }
                    black_box(&mut chunk);
                }
            })
        });
        if let Some(per_point) = $sympy {
            $g.bench_function(concat!($name, "/sympy_per_point"), |b| {
                b.iter(|| {
                    for qc in qs.chunks_exact(CHUNK) {
                        for (q, o) in qc.iter().zip(chunk.iter_mut()) {
                            per_point(black_box(q), o);
                        }
                        black_box(&mut chunk);
                    }
                })
            });
        }
        $g.bench_function(concat!($name, "/batch_into"), |b| {
            b.iter(|| {
                for qc in qs.chunks_exact(CHUNK) {
                    $ty::sensitivity_batch_into(black_box(qc), black_box(&p), &mut chunk);
                    black_box(&mut chunk);
                }
            })
        });
        $g.bench_function(concat!($name, "/tape_batch"), |b| {
            b.iter(|| {
                for qc in flat.chunks_exact(CHUNK * NV) {
                    tape.sensitivity_points(black_box(qc), black_box(tp), &mut flat_chunk)
                        .expect("sizes fit");
                    black_box(&mut flat_chunk);
                }
            })
        });
        // Threads: `REPEAT` passes over the points per iteration, so that
        // waking the pool's threads (tens of µs on this VM) does not count.
        let mut flat_halves = vec![vec![0.0; CHUNK * 6 * NE]; 2];
        for (threads, pool) in [(1usize, &$pools[0]), (2, &$pools[1])] {
            let id = format!("{}/tape_batch_{threads}_thread_x{REPEAT}", $name);
            $g.bench_function(id, |b| {
                b.iter(|| {
                    passes(
                        pool,
                        threads,
                        &flat,
                        CHUNK * NV,
                        &mut flat_halves,
                        |qc, buf| {
                            tape.sensitivity_points(black_box(qc), black_box(tp), buf)
                                .expect("sizes fit")
                        },
                    )
                })
            });
        }
        let mut halves = vec![vec![[[0.0; NE]; 6]; CHUNK]; 2];
        for (threads, pool) in [(1usize, &$pools[0]), (2, &$pools[1])] {
            let id = format!("{}/batch_into_{threads}_thread_x{REPEAT}", $name);
            $g.bench_function(id, |b| {
                b.iter(|| {
                    passes(pool, threads, &qs, CHUNK, &mut halves, |qc, buf| {
                        $ty::sensitivity_batch_into(black_box(qc), black_box(&p), buf)
                    })
                })
            });
        }
    }};
}

/// The runtime tape of the machine file at `path` (relative to this
/// crate's directory).
fn runtime_tape(path: &str) -> chain::core::CompiledModel {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    chain::core::compile(&chain::core::load_file(&path).expect("valid machine"))
}

/// Passes over the points per iteration of the thread benchmarks of the
/// `batched` group (their time is for `REPEAT · POINTS` points).
const REPEAT: usize = 16;

/// `REPEAT` passes over `points` on `pool`: `threads` equal parts, each
/// with its own reused buffer of `bufs`, `call(chunk, buf)` for each
/// `per_call` items of a part.
fn passes<T: Sync, B: Send>(
    pool: &rayon::ThreadPool,
    threads: usize,
    points: &[T],
    per_call: usize,
    bufs: &mut [B],
    call: impl Fn(&[T], &mut B) + Sync,
) {
    use rayon::prelude::*;
    pool.install(|| {
        points
            .par_chunks(points.len() / threads)
            .zip(bufs.par_iter_mut())
            .for_each(|(part, buf)| {
                for _ in 0..REPEAT {
                    for chunk in part.chunks_exact(per_call) {
                        call(chunk, buf);
                        black_box(&mut *buf);
                    }
                }
            })
    })
}

/// The `batched` group (see [`batched!`]).
fn batched(c: &mut Criterion) {
    let pools: Vec<rayon::ThreadPool> = [1, 2]
        .into_iter()
        .map(|t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .expect("a pool")
        })
        .collect();
    let mut g = c.benchmark_group("batched");
    g.throughput(criterion::Throughput::Elements(POINTS as u64));
    g.sample_size(20)
        .warm_up_time(std::time::Duration::from_millis(700))
        .measurement_time(std::time::Duration::from_millis(2000));
    /// A per-point function of the gantry (none to compare with).
    type GantryPerPoint = fn(&[f64; 3], &mut [[f64; 21]; 6]);
    batched!(
        g,
        pools,
        GantryGrinder,
        "gantry_grinder",
        "../examples/machines/gantry_grinder.yaml",
        [0.0f64; 0],
        None::<GantryPerPoint>
    );
    let sympy = |q: &[f64; 5], out: &mut [[f64; 33]; 6]| {
        sympy::sensitivity_sympy(q, black_box(&[150.0]), out)
    };
    batched!(
        g,
        pools,
        BcHeadTable,
        "bc_head_table",
        "benches/machines/bc_head_table.yaml",
        [150.0f64],
        Some(sympy)
    );
    g.finish();
}

criterion_group!(benches, gantry, five_axis, two_rotary_axes, bc_head_table);
criterion_group!(batch, batched);
criterion_group!(machines, every_machine);
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
    let q4 = [
        q,
        [100.0, 0.3, -20.0, 200.0, 0.4],
        [90.0, -0.7, 10.0, 150.0, 1.4],
        [80.0, 1.1, 40.0, 100.0, -1.4],
    ];
    let mut out4 = [[[0.0; 33]; 6]; 4];
    // The runtime tape of the same machine and of the gantry, eight points
    // (one block) per count.
    let (bc_tape, gantry_tape) = (
        runtime_tape("benches/machines/bc_head_table.yaml"),
        runtime_tape("../examples/machines/gantry_grinder.yaml"),
    );
    let bc_q8: Vec<f64> = (0..8).flat_map(|k| q4[k % 4]).collect();
    let gantry_q8: Vec<f64> = (0..24).map(|i| 100.0 + 37.0 * i as f64).collect();
    let mut bc_out8 = vec![0.0; 8 * 6 * 33];
    let mut gantry_out8 = vec![0.0; 8 * 6 * 21];
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
            "batch_into" => {
                // One group of four points per count.
                BcHeadTable::sensitivity_batch_into(black_box(&q4), black_box(&p), &mut out4);
                black_box(&mut out4);
            }
            "tape_batch" => {
                let p = &p[..bc_tape.parameters().len()];
                bc_tape
                    .sensitivity_points(black_box(&bc_q8), black_box(p), &mut bc_out8)
                    .expect("sizes fit");
                black_box(&mut bc_out8);
            }
            "tape_batch_gantry" => {
                gantry_tape
                    .sensitivity_points(black_box(&gantry_q8), &[], &mut gantry_out8)
                    .expect("sizes fit");
                black_box(&mut gantry_out8);
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
    machines();
    batch();
    Criterion::default().configure_from_args().final_summary();
}
