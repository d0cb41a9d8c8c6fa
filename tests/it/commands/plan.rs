//! `chain plan` and the planning library (measured-machines spec, section 5)
//! against an independent computation: the design rows are the finite
//! differences of the exact numeric 4×4 product of `tests/it/common` (not
//! chain's derivation), the determinants on the identifiable subspace are
//! products of the test's own singular values (nalgebra's SVD of the chosen
//! rows), the expected std the diagonal of their pseudo-inverse. Shown: the
//! D-optimal choice beats the even spread and 100 seeded random subsets on
//! the gantry grinder and on the 5-axis bevel-gear machine; no single swap
//! improves it; the reported std equals the independent one; bad input is
//! refused with its location and nothing on stdout.

// Matrix loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use chain::core::measured::{Measurement, Observed};
use chain::core::plan::{self, Plan, PlanError, Rows};
use chain::core::{ErrorModel, Machine};
use common::{load_example, Exact, Rng};
use nalgebra::DMatrix;

/// The test's own design rows of machine-ordered poses `qs` (errors in the
/// model's order): finite differences of the exact product.
fn exact_rows(
    m: &Machine,
    model: &dyn ErrorModel,
    qs: &[Vec<f64>],
    p: &[f64],
    dirs: Option<&[[f64; 3]]>,
) -> DMatrix<f64> {
    let ex = Exact::new(m);
    let n_e = model.errors().len();
    let order: Vec<usize> = (model.errors().iter())
        .map(|e| m.error_index(e).unwrap())
        .collect();
    let rows = if dirs.is_some() { 1 } else { 3 };
    let mut a = DMatrix::zeros(qs.len() * rows, n_e);
    for (i, q) in qs.iter().enumerate() {
        let s = ex.fd_sensitivity(q, p, 1e-4);
        for (k, &j) in order.iter().enumerate() {
            let col: [f64; 3] = std::array::from_fn(|c| s[c * m.errors.len() + j]);
            match dirs {
                None => {
                    for c in 0..3 {
                        a[(3 * i + c, k)] = col[c];
                    }
                }
                Some(u) => a[(i, k)] = (0..3).map(|c| u[i][c] * col[c]).sum(),
            }
        }
    }
    a
}

/// The candidate records of machine-ordered poses (as
/// `Measurements::read` gives them from a candidate CSV).
fn candidates(qs: &[Vec<f64>], p: &[f64], dirs: Option<&[[f64; 3]]>) -> Vec<Measurement> {
    (qs.iter().enumerate())
        .map(|(i, q)| Measurement {
            line: i + 2,
            q: q.clone(),
            p: p.to_vec(),
            observed: match dirs {
                None => Observed::Point,
                Some(d) => Observed::Direction { u: d[i] },
            },
            values: vec![],
            std: None,
            setup: None,
            temperatures: Vec::new(),
        })
        .collect()
}

/// The rows of candidates `s` of a design with `rows` rows per candidate.
fn pick(a: &DMatrix<f64>, rows: usize, s: &[usize]) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(s.len() * rows, a.ncols());
    for (k, &i) in s.iter().enumerate() {
        for r in 0..rows {
            out.set_row(k * rows + r, &a.row(i * rows + r));
        }
    }
    out
}

/// The rank of `a` after equilibrating its columns (singular values above
/// 1e-6 of the largest).
fn rank(a: &DMatrix<f64>) -> usize {
    let mut b = a.clone();
    for j in 0..b.ncols() {
        let n = b.column(j).norm();
        if n > 0.0 {
            b.column_mut(j).scale_mut(1.0 / n);
        }
    }
    let s = b.singular_values();
    let max = s.max();
    s.iter().filter(|&&x| x > 1e-6 * max).count()
}

/// `ln` of the product of the `r` largest squared singular values of `a`
/// (the determinant of `AᵀA` on an `r`-dimensional row space); −∞ when the
/// `r`-th is negligible.
fn log_pdet(a: &DMatrix<f64>, r: usize) -> f64 {
    let mut s: Vec<f64> = a.singular_values().iter().copied().collect();
    s.sort_by(|x, y| y.total_cmp(x));
    if s.len() < r || s[r - 1] <= 1e-9 * s[0] {
        return f64::NEG_INFINITY;
    }
    s[..r].iter().map(|x| 2.0 * x.ln()).sum()
}

/// Every check of one planning problem: returns the plan.
fn check_plan(a_exact: &DMatrix<f64>, design: &Rows, count: usize, seed: u64) -> Plan {
    let rows = design.per_candidate();
    let n = design.len();
    let result = plan::plan(design, count).expect("plan");
    // The rank is the test's own.
    let r = rank(a_exact);
    assert_eq!(result.rank, r, "rank of the whole candidate set");
    assert_eq!(result.optimal.candidates.len(), count);
    // The reported log det is the test's.
    let opt = log_pdet(&pick(a_exact, rows, &result.optimal.candidates), r);
    let reported = result.optimal.log_det.expect("optimal is regular");
    assert!(
        (opt - reported).abs() < 1e-5 * opt.abs().max(1.0),
        "log det: reported {reported}, independent {opt}"
    );
    // Larger than the even spread (reported and independent).
    let even = log_pdet(&pick(a_exact, rows, &plan::even(n, count)), r);
    assert!(opt > even, "optimal {opt} vs even {even}");
    if let Some(e) = result.even.log_det {
        assert!(
            (e - even).abs() < 1e-5 * even.abs().max(1.0),
            "{e} vs {even}"
        );
    } else {
        assert_eq!(even, f64::NEG_INFINITY);
    }
    // Larger than each of 100 random subsets.
    let mut rng = Rng::new(seed);
    for _ in 0..100 {
        let mut all: Vec<usize> = (0..n).collect();
        for k in 0..count {
            let j = k + (rng.next_u64() % (n - k) as u64) as usize;
            all.swap(k, j);
        }
        let ld = log_pdet(&pick(a_exact, rows, &all[..count]), r);
        assert!(opt > ld, "optimal {opt} vs random {ld}");
    }
    // A local optimum: no single swap improves it (beyond 1e-7 relative).
    let s = &result.optimal.candidates;
    for slot in 0..count {
        for j in (0..n).filter(|j| !s.contains(j)) {
            let mut t = s.clone();
            t[slot] = j;
            let ld = log_pdet(&pick(a_exact, rows, &t), r);
            assert!(
                ld <= opt + 1e-7,
                "swapping candidate {} for {j} improves ln det by {}",
                s[slot],
                ld - opt
            );
        }
    }
    // The expected std: sqrt of the diagonal of the pseudo-inverse of the
    // chosen rows' information.
    let a_s = pick(a_exact, rows, s);
    let info = a_s.tr_mul(&a_s);
    let pinv = pinv_rows(&a_s, r);
    let largest = (0..info.ncols())
        .map(|j| pinv[(j, j)].sqrt())
        .fold(0.0, f64::max);
    for j in 0..info.ncols() {
        let want = pinv[(j, j)].sqrt();
        let got = result.optimal.std[j].expect("std");
        // A parameter entirely in the null space has std 0 (its column is
        // zero up to the finite differences' rounding).
        assert!(
            (got - want).abs() <= 1e-5 * want + 1e-7 * largest,
            "std of {}: reported {got}, independent {want}",
            result.errors[j]
        );
    }
    result
}

/// The pseudo-inverse of `AᵀA` from the SVD of `A` (its `r` largest
/// singular values kept): `V_r Σ_r⁻² V_rᵀ`.
fn pinv_rows(a: &DMatrix<f64>, r: usize) -> DMatrix<f64> {
    let svd = a.clone().svd(false, true);
    let vt = svd.v_t.expect("V");
    let mut idx: Vec<usize> = (0..svd.singular_values.len()).collect();
    idx.sort_by(|&x, &y| svd.singular_values[y].total_cmp(&svd.singular_values[x]));
    let mut out = DMatrix::zeros(a.ncols(), a.ncols());
    for &k in &idx[..r] {
        let v = vt.row(k).transpose();
        out += (&v * v.transpose()) / svd.singular_values[k].powi(2);
    }
    out
}

/// The gantry's 5 × 5 × 5 grid, machine-ordered.
fn gantry_grid() -> Vec<Vec<f64>> {
    let mut qs = Vec::new();
    for x in [0.0, 250.0, 500.0, 750.0, 1000.0] {
        for y in [-1500.0, -750.0, 0.0, 750.0, 1500.0] {
            for z in [600.0, 800.0, 1000.0, 1200.0, 1400.0] {
                qs.push(vec![x, y, z]);
            }
        }
    }
    qs
}

#[test]
fn gantry_point_plan_beats_even_and_random_and_is_a_local_optimum() {
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let qs = gantry_grid();
    let p: Vec<f64> = vec![];
    let a = exact_rows(&m, &model, &qs, &p, None);
    let design = Rows::of(&model, &m, &candidates(&qs, &p, None)).unwrap();
    let r = check_plan(&a, &design, 8, 1);
    // Position-only data cannot see every angular error of a machine with
    // one tool point: the rank is below the 21 errors.
    assert!(r.rank < 21, "rank {}", r.rank);
    assert!(r.aliased.iter().any(|&x| x));
}

#[test]
fn gantry_direction_plan_along_the_body_diagonals() {
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let grid = gantry_grid();
    let s = 1.0 / 3f64.sqrt();
    let diagonals = [[s, s, s], [-s, s, s], [s, -s, s], [s, s, -s]];
    let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut qs = Vec::new();
    let mut dirs = Vec::new();
    for (k, q) in grid.iter().enumerate() {
        for (d, u) in diagonals.iter().chain(&axes).enumerate() {
            if (k + d) % 3 == 0 {
                qs.push(q.clone());
                dirs.push(*u);
            }
        }
    }
    let a = exact_rows(&m, &model, &qs, &[], Some(&dirs));
    let design = Rows::of(&model, &m, &candidates(&qs, &[], Some(&dirs))).unwrap();
    check_plan(&a, &design, 30, 2);
}

#[test]
fn five_axis_point_plan_beats_even_and_random_and_is_a_local_optimum() {
    let m = load_example("cnc5_bevel.yaml");
    let model = chain::core::compile(&m);
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    let mut rng = Rng::new(7);
    let qs: Vec<Vec<f64>> = (0..150)
        .map(|_| {
            m.variables
                .iter()
                .map(|v| match v.name.as_str() {
                    "x" | "y" | "z" => rng.range(-300.0, 300.0),
                    _ => rng.range(-1.0, 1.0),
                })
                .collect()
        })
        .collect();
    let a = exact_rows(&m, &model, &qs, &p, None);
    let design = Rows::of(&model, &m, &candidates(&qs, &p, None)).unwrap();
    check_plan(&a, &design, 20, 3);
}

#[test]
fn weighted_candidates_plan_on_the_rows_divided_by_their_std() {
    // A `std` per candidate (two instruments): the information is AᵀWA,
    // W = diag(1/std²); the test's rows are the exact ones divided by the
    // std, and every check of `check_plan` (rank, log det, even, random,
    // local optimum, std) holds on them; the std are absolute.
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let qs = gantry_grid();
    let std: Vec<f64> = (0..qs.len())
        .map(|i| if i % 3 == 0 { 0.001 } else { 0.004 })
        .collect();
    let mut a = exact_rows(&m, &model, &qs, &[], None);
    for i in 0..qs.len() {
        for c in 0..3 {
            a.row_mut(3 * i + c).scale_mut(1.0 / std[i]);
        }
    }
    let mut recs = candidates(&qs, &[], None);
    for (r, s) in recs.iter_mut().zip(&std) {
        r.std = Some(*s);
    }
    let design = Rows::of(&model, &m, &recs).unwrap();
    assert!(design.weighted());
    let r = check_plan(&a, &design, 10, 5);
    assert!(r.weighted);
    // Weighting changes the choice: the precise instrument's candidates
    // (every third) are preferred.
    let precise = (r.optimal.candidates.iter())
        .filter(|&&i| i % 3 == 0)
        .count();
    assert!(precise > 10 / 3 + 1, "{:?}", r.optimal.candidates);
}

#[test]
fn full_rank_std_is_the_inverse_of_the_information() {
    // A design of full column rank: the std is sqrt(diag((AᵀA)⁻¹)) by
    // nalgebra's plain inverse, and the log det that of AᵀA itself.
    let mut rng = Rng::new(11);
    let (n, p) = (60, 7);
    let a = DMatrix::from_fn(n, p, |_, j| rng.range(-1.0, 1.0) * 10f64.powi(j as i32 - 3));
    let names: Vec<String> = (0..p).map(|j| format!("e{j}")).collect();
    let design = Rows::new(1, names, a.clone(), false).unwrap();
    let r = plan::plan(&design, 12).unwrap();
    assert_eq!(r.rank, p);
    assert!(r.aliased.iter().all(|&x| !x));
    let a_s = pick(&a, 1, &r.optimal.candidates);
    let info = a_s.tr_mul(&a_s);
    let inv = info.clone().try_inverse().unwrap();
    for j in 0..p {
        let want = inv[(j, j)].sqrt();
        let got = r.optimal.std[j].unwrap();
        assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
    }
    let det = info.determinant().ln();
    let got = r.optimal.log_det.unwrap();
    assert!(
        (got - det).abs() < 1e-8 * det.abs().max(1.0),
        "{got} vs {det}"
    );
}

#[test]
fn library_refusals() {
    let a = DMatrix::from_fn(6, 2, |i, j| (i + j) as f64 + 1.0);
    let d = Rows::new(3, vec!["a".into(), "b".into()], a, false).unwrap();
    assert_eq!(
        plan::plan(&d, 0),
        Err(PlanError::Count {
            count: 0,
            candidates: 2
        })
    );
    assert!(matches!(plan::plan(&d, 3), Err(PlanError::Count { .. })));
    let zero = Rows::new(1, vec!["a".into()], DMatrix::zeros(4, 1), false).unwrap();
    assert_eq!(plan::plan(&zero, 2), Err(PlanError::Uninformative));
    // Rows that are not whole candidates, or not one column per name, or
    // not finite; candidates of two kinds.
    let names = vec!["a".to_string(), "b".to_string()];
    assert!(matches!(
        Rows::new(3, names.clone(), DMatrix::zeros(4, 2), false),
        Err(PlanError::RowsPerCandidate { rows: 4, per: 3 })
    ));
    assert!(matches!(
        Rows::new(4, names.clone(), DMatrix::zeros(4, 2), false),
        Err(PlanError::RowsPerCandidate { .. })
    ));
    assert!(matches!(
        Rows::new(1, names.clone(), DMatrix::zeros(4, 3), false),
        Err(PlanError::Columns {
            columns: 3,
            errors: 2
        })
    ));
    let mut nan = DMatrix::zeros(6, 2);
    nan[(4, 1)] = f64::NAN;
    assert_eq!(
        Rows::new(1, names, nan, false),
        Err(PlanError::NonFinite { index: 4 })
    );
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let mut mixed = candidates(&gantry_grid()[..3], &[], None);
    mixed[2].observed = Observed::Direction { u: [1.0, 0.0, 0.0] };
    assert_eq!(
        Rows::of(&model, &m, &mixed),
        Err(PlanError::MixedRows {
            index: 2,
            found: 1,
            expected: 3
        })
    );
    assert_eq!(Rows::of(&model, &m, &[]), Err(PlanError::NoCandidates));
    let full = Rows::new(
        1,
        vec!["a".into(), "b".into(), "c".into()],
        DMatrix::from_fn(5, 3, |i, j| ((i + 1) as f64).powi(j as i32)),
        false,
    )
    .unwrap();
    assert!(matches!(
        plan::plan(&full, 2),
        Err(PlanError::TooFew {
            rank: 3,
            minimum: 3,
            ..
        })
    ));
}

// ---------------------------------------------------------------------------
// The command line.

const GANTRY: &str = "examples/machines/gantry_grinder.yaml";

fn grid_csv() -> String {
    let mut s = String::from("x,y,z\n");
    for q in gantry_grid() {
        s.push_str(&format!("{},{},{}\n", q[0], q[1], q[2]));
    }
    s
}

#[test]
fn cli_json_is_the_library_plan() {
    let dir = common::cli::scratch("json");
    let c = common::cli::write(&dir, "c.csv", &grid_csv());
    let doc = common::cli::ok_json(&[
        "plan",
        GANTRY,
        "--candidates",
        c.to_str().unwrap(),
        "--count",
        "8",
        "--format",
        "json",
    ]);
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let design = Rows::of(&model, &m, &candidates(&gantry_grid(), &[], None)).unwrap();
    let want = plan::plan(&design, 8).unwrap();
    assert_eq!(doc["rank"], want.rank);
    assert_eq!(doc["kind"], "point");
    let chosen: Vec<usize> = (doc["optimal"]["candidates"].as_array().unwrap().iter())
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(chosen, want.optimal.candidates);
    // Full factorial corners: the 8 corners of the box are the D-optimal
    // choice of a model affine in q.
    for i in chosen {
        let q = &gantry_grid()[i];
        assert!(q[0] == 0.0 || q[0] == 1000.0, "{q:?}");
        assert!(q[1].abs() == 1500.0, "{q:?}");
        assert!(q[2] == 600.0 || q[2] == 1400.0, "{q:?}");
    }
    let table = common::cli::ok_stdout(&[
        "plan",
        GANTRY,
        "--candidates",
        c.to_str().unwrap(),
        "--count",
        "8",
    ]);
    assert!(table.contains("rank 8 of 21"), "{table}");
}

/// A bad candidate file or argument: located message, non-zero exit,
/// nothing on stdout (`fails` checks the last two).
#[track_caller]
fn refused(machine: &str, name: &str, text: &str, extra: &[&str], wants: &[&str]) {
    let dir = common::cli::scratch("bad");
    let c = common::cli::write(&dir, name, text);
    let mut args = vec!["plan", machine, "--candidates", c.to_str().unwrap()];
    args.extend_from_slice(extra);
    let e = common::cli::unwrapped(&common::cli::fails(&args));
    for w in wants {
        assert!(e.contains(w), "missing `{w}` in\n{e}");
    }
}

#[test]
fn cli_directions_from_stdin_and_kind() {
    // A direction file read from stdin plans the same as the library on the
    // same records; `--kind direction` agrees with the file.
    let s = 1.0 / 3f64.sqrt();
    let mut text = String::from("x,y,z,ux,uy,uz\n");
    let mut qs = Vec::new();
    let mut dirs = Vec::new();
    for (k, q) in gantry_grid().iter().enumerate() {
        let u = [[s, s, s], [-s, s, s], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]][k % 4];
        text.push_str(&format!(
            "{},{},{},{},{},{}\n",
            q[0], q[1], q[2], u[0], u[1], u[2]
        ));
        qs.push(q.clone());
        dirs.push(u);
    }
    let out = common::cli::success_json(common::cli::chain_stdin(
        &[
            "plan",
            GANTRY,
            "--candidates",
            "-",
            "--count",
            "20",
            "--kind",
            "direction",
            "--format",
            "json",
        ],
        text.as_bytes(),
    ));
    assert_eq!(out["kind"], "direction");
    assert_eq!(out["candidates_file"], "<stdin>");
    assert_eq!(out["rows_per_candidate"], 1);
    let m = load_example("gantry_grinder.yaml");
    let model = chain::core::compile(&m);
    let want = plan::plan(
        &Rows::of(&model, &m, &candidates(&qs, &[], Some(&dirs))).unwrap(),
        20,
    )
    .unwrap();
    // The grid is symmetric: many subsets tie, and a difference of 1e-16 in
    // `u` (the reader normalises it) can lead the search to another local
    // optimum; on the reader's own records the choice is the same.
    let recs = chain::core::measured::Measurements::parse(
        &text,
        "<stdin>",
        &m,
        &[],
        chain::core::measured::Layout::Candidates,
    )
    .unwrap();
    let same = plan::plan(&Rows::of(&model, &m, &recs.rows).unwrap(), 20).unwrap();
    let chosen: Vec<usize> = (out["optimal"]["candidates"].as_array().unwrap().iter())
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(chosen, same.optimal.candidates);
    assert_eq!(same.rank, want.rank);
    assert_eq!(out["rank"], want.rank);
}

#[test]
fn cli_bad_input_is_located() {
    let bad = |name: &str, text: &str, count: &str, wants: &[&str]| {
        refused(GANTRY, name, text, &["--count", count], wants)
    };
    // Bad inputs of a candidate file, the spec's among them.
    bad(
        "unknown.csv",
        "x,y,z,w\n0,0,600,1\n",
        "1",
        &["unknown.csv:1:", "column `w` is neither an axis variable"],
    );
    bad(
        "missing.csv",
        "x,y\n0,0\n",
        "1",
        &["missing.csv:1:", "no column for the axis variable `z`"],
    );
    bad(
        "nan.csv",
        "x,y,z\n0,0,600\n1,NaN,600\n",
        "1",
        &["nan.csv:3:", "column `y`: `NaN` is not finite"],
    );
    bad(
        "inf.csv",
        "x,y,z\n0,0,inf\n",
        "1",
        &["inf.csv:2:", "column `z`: `inf` is not finite"],
    );
    bad("empty.csv", "", "1", &["empty.csv:1:", "empty"]);
    bad(
        "header.csv",
        "x,y,z\n",
        "1",
        &["header.csv:1:", "no data row"],
    );
    bad(
        "wide.csv",
        "x,y,z\n0,0,600\n1,2,3,4\n",
        "1",
        &["wide.csv:3:", "has 4 fields but the header has 3 columns"],
    );
    bad(
        "narrow.csv",
        "x,y,z\n0,0,600\n1,2\n",
        "1",
        &["narrow.csv:3:", "has 2 fields but the header has 3 columns"],
    );
    // The rest of what a candidate file can get wrong.
    bad(
        "word.csv",
        "x,y,z\n0,zero,600\n",
        "1",
        &["word.csv:2:", "column `y`: `zero` is not a number"],
    );
    bad(
        "measured.csv",
        "x,y,z,dpx\n0,0,600,1\n",
        "1",
        &["measured.csv:1:", "column `dpx` is a measured value"],
    );
    bad(
        "d.csv",
        "x,y,z,ux,uy,uz,d\n0,0,600,1,0,0,1\n",
        "1",
        &["d.csv:1:", "column `d` is a measured value"],
    );
    bad(
        "dir.csv",
        "x,y,z,ux,uy,uz\n0,0,600,1,1,0\n",
        "1",
        &["dir.csv:2:", "the direction (ux, uy, uz) has length"],
    );
    bad(
        "ux.csv",
        "x,y,z,ux\n0,0,600,1\n",
        "1",
        &["ux.csv:1:", "only some of `ux,uy,uz`"],
    );
    bad(
        "std.csv",
        "x,y,z,std\n0,0,600,0.001\n1,0,600,0\n",
        "1",
        &["std.csv:3:", "standard deviation must be positive"],
    );
    // The count.
    bad(
        "big.csv",
        &grid_csv(),
        "126",
        &["big.csv: --count 126 is not a count of candidates: choose 1 to 125"],
    );
    bad("zero.csv", &grid_csv(), "0", &["--count 0"]);
    bad(
        "few.csv",
        &grid_csv(),
        "2",
        &["few.csv:", "fewer than the 8 dimensions"],
    );
    // --kind against the file.
    refused(
        GANTRY,
        "kindp.csv",
        "x,y,z,ux,uy,uz\n0,0,600,1,0,0\n",
        &["--count", "1", "--kind", "point"],
        &["kindp.csv:1:", "--kind point"],
    );
    refused(
        GANTRY,
        "kindd.csv",
        &grid_csv(),
        &["--count", "8", "--kind", "direction"],
        &[
            "kindd.csv:1:",
            "--kind direction needs the columns `ux,uy,uz`",
        ],
    );
    // Parameters: an unknown --param, a symbolic one without a column.
    refused(
        GANTRY,
        "param.csv",
        &grid_csv(),
        &["--count", "8", "--param", "tq=1"],
        &["--param tq: machine `gantry_grinder` has no parameter `tq`"],
    );
    refused(
        "examples/machines/cradle_generator.yaml",
        "symbolic.csv",
        "q,j,i,gamma_m,phi_p,S_d,E_m,X_b\n0,0,0,0,0,1,2,3\n",
        &["--count", "1"],
        &["symbolic.csv:1:", "parameter `X_1` is symbolic"],
    );
}
