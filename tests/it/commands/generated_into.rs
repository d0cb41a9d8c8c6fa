//! The `machine!` functions that write into the caller's storage:
//! `sensitivity_into`, `sensitivity_flat_into`, `sensitivity_nonzeros` with
//! `NONZEROS`, `error_into` and the `ErrorModel` impl over them, on every
//! example machine the macro declares and on the B-head/C-table benchmark
//! machine (`chain-macro/benches/machines/bc_head_table.yaml`).
//!
//! The reference is the v1 emission of the same machines (`chain derive
//! --format rust`, `chain_core::emit::Emission::Derive`: each function a
//! self-contained body) committed under `tests/generated_v1/` and compiled
//! here: `v1_files_are_current` checks that they are the emitter's v1
//! output, so this test compares the `machine!` bodies (`Emission::Macro`)
//! against the v1 ones. Values are equal as `f64` (`==`) and bit for bit
//! when non-zero: the `machine!` bodies share a sum and its negation, exact
//! in IEEE 754 but for the sign of a zero.

use crate::common::Points;
use chain::core::ErrorModel;

mod v1 {
    #![allow(dead_code, clippy::all)]
    pub mod gantry {
        include!("../../generated_v1/gantry_grinder.rs");
    }
    pub mod internal {
        include!("../../generated_v1/internal_grinder.rs");
    }
    pub mod cnc5 {
        include!("../../generated_v1/cnc5_bevel.rs");
    }
    pub mod ac {
        include!("../../generated_v1/ac_trunnion.rs");
    }
    pub mod hh {
        include!("../../generated_v1/head_head_bc.rs");
    }
    pub mod bc {
        include!("../../generated_v1/bc_head_table.rs");
    }
}

chain::machine!(pub Gantry = "examples/machines/gantry_grinder.yaml");
chain::machine!(pub Internal = "examples/machines/internal_grinder.yaml");
chain::machine!(pub Cnc5 = "examples/machines/cnc5_bevel.yaml");
chain::machine!(pub Ac = "examples/machines/ac_trunnion.yaml");
chain::machine!(pub Hh = "examples/machines/head_head_bc.yaml");
chain::machine!(pub Bc = "chain-macro/benches/machines/bc_head_table.yaml");

const FILES: [(&str, &str); 6] = [
    ("examples/machines/gantry_grinder.yaml", "gantry_grinder"),
    (
        "examples/machines/internal_grinder.yaml",
        "internal_grinder",
    ),
    ("examples/machines/cnc5_bevel.yaml", "cnc5_bevel"),
    ("examples/machines/ac_trunnion.yaml", "ac_trunnion"),
    ("examples/machines/head_head_bc.yaml", "head_head_bc"),
    (
        "chain-macro/benches/machines/bc_head_table.yaml",
        "bc_head_table",
    ),
];

fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn v1_files_are_current() {
    for (file, name) in FILES {
        let machine = chain::core::load_file(&root().join(file)).unwrap_or_else(|d| panic!("{d}"));
        let model = chain::core::derive(&machine);
        let options = chain::core::emit::EmitOptions::for_model(&model);
        assert_eq!(options.emission, chain::core::emit::Emission::Derive);
        let code = chain::core::emit::emit_pretty(&model, &options);
        let recorded =
            std::fs::read_to_string(root().join(format!("tests/generated_v1/{name}.rs"))).unwrap();
        assert!(
            code == recorded,
            "tests/generated_v1/{name}.rs is not the v1 emission of {file}: \
             rerun `chain derive {file} --format rust > tests/generated_v1/{name}.rs`"
        );
    }
}

/// `a == b` as numbers and bit for bit when non-zero.
fn same(a: f64, b: f64) -> bool {
    a == b && (a == 0.0 || a.to_bits() == b.to_bits())
}

/// The runtime tape has no sparsity: the trait's defaults.
#[test]
fn runtime_model_has_no_sparsity() {
    let machine =
        chain::core::load_file(&root().join(FILES[0].0)).unwrap_or_else(|d| panic!("{d}"));
    let runtime = chain::core::compile(&machine);
    assert_eq!(runtime.sparsity(), None);
    let mut out = [5.0; 32];
    assert!(!runtime.sensitivity_nonzeros(&[1.0, 2.0, 3.0], &[], &mut out));
    assert_eq!(out, [5.0; 32]);
}

/// The whole comparison for one machine: `machine!` type `$new`, v1 type
/// `$old`.
macro_rules! compare {
    ($new:ty, $old:ty, $file:expr) => {{
        const V: usize = <$new>::VARIABLES.len();
        const P: usize = <$new>::PARAMETERS.len();
        const N: usize = <$new>::ERRORS.len();
        const K: usize = <$new>::NONZEROS.len();
        let machine = chain::core::load_file(&root().join($file)).unwrap_or_else(|d| panic!("{d}"));
        let model = chain::core::derive(&machine);
        // NONZEROS is exactly the symbolic derivation's non-zero entries, row-major.
        let symbolic: Vec<(usize, usize)> = model
            .components
            .iter()
            .enumerate()
            .flat_map(|(c, row)| {
                row.iter()
                    .filter(|(_, poly)| !poly.is_zero())
                    .map(move |(j, _)| (c, *j))
            })
            .collect();
        assert_eq!(<$new>::NONZEROS.to_vec(), symbolic, "{}", $file);
        let mut sorted = symbolic.clone();
        sorted.sort();
        assert_eq!(sorted, symbolic, "NONZEROS row-major");
        let mut points = Points(0x9e37_79b9_7f4a_7c15);
        let mut zeros_seen = 0usize;
        for _ in 0..200 {
            let mut q = [0.0; V];
            let mut p = [0.0; P];
            let mut e = [0.0; N];
            points.fill(&mut q, 3.0);
            q.iter_mut().for_each(|x| *x *= 100.0);
            // Rotary variables see angles of several turns, prismatic ones ±300 mm.
            points.fill(&mut p, 200.0);
            points.fill(&mut e, 1e-3);
            let old = <$old>::sensitivity(&q, &p);
            let new = <$new>::sensitivity(&q, &p);
            // Garbage in the output: every entry must be written.
            let mut into = [[f64::NAN; N]; 6];
            <$new>::sensitivity_into(&q, &p, &mut into);
            let mut flat = [f64::NAN; 6 * N];
            <$new>::sensitivity_flat_into(&q, &p, &mut flat);
            let mut nz = [f64::NAN; K];
            <$new>::sensitivity_nonzeros(&q, &p, &mut nz);
            let mut via_trait = vec![f64::NAN; 6 * N];
            ErrorModel::sensitivity(&<$new>::default(), &q, &p, &mut via_trait);
            for c in 0..6 {
                for j in 0..N {
                    let o = old[c][j];
                    assert!(
                        same(o, new[c][j]),
                        "sensitivity [{c}][{j}]: {o} vs {}",
                        new[c][j]
                    );
                    assert!(
                        same(o, into[c][j]),
                        "into [{c}][{j}]: {o} vs {}",
                        into[c][j]
                    );
                    assert!(same(o, flat[c * N + j]), "flat [{c}][{j}]");
                    assert!(same(o, via_trait[c * N + j]), "ErrorModel [{c}][{j}]");
                }
            }
            let mut nz_trait = vec![f64::NAN; K];
            let model = <$new>::default();
            assert!(ErrorModel::sensitivity_nonzeros(
                &model,
                &q,
                &p,
                &mut nz_trait
            ));
            assert_eq!(ErrorModel::sparsity(&model), Some(&<$new>::NONZEROS[..]));
            for (k, &(c, j)) in <$new>::NONZEROS.iter().enumerate() {
                assert!(same(old[c][j], nz[k]), "nonzeros[{k}] = ({c}, {j})");
                assert!(same(old[c][j], nz_trait[k]), "ErrorModel nonzeros[{k}]");
            }
            // Every entry outside NONZEROS is exactly zero at this point.
            for c in 0..6 {
                for j in 0..N {
                    if !<$new>::NONZEROS.contains(&(c, j)) {
                        assert_eq!(old[c][j], 0.0, "[{c}][{j}] outside NONZEROS");
                        zeros_seen += 1;
                    }
                }
            }
            let old_e = <$old>::error(&q, &p, &e);
            let mut into_e = [f64::NAN; 6];
            <$new>::error_into(&q, &p, &e, &mut into_e);
            let new_e = <$new>::error(&q, &p, &e);
            let mut trait_e = [f64::NAN; 6];
            ErrorModel::error(&<$new>::default(), &q, &p, &e, &mut trait_e);
            for c in 0..6 {
                assert!(
                    same(old_e[c], new_e[c]),
                    "error[{c}]: {} vs {}",
                    old_e[c],
                    new_e[c]
                );
                assert!(same(old_e[c], into_e[c]), "error_into[{c}]");
                assert!(same(old_e[c], trait_e[c]), "ErrorModel::error[{c}]");
            }
        }
        assert_eq!(zeros_seen, 200 * (6 * N - K));
        // Slices of the wrong length: NaN (q) or the entries that fit (out), no panic.
        let mut short = vec![7.0; 5];
        ErrorModel::sensitivity(&<$new>::default(), &[0.0; V], &[1.0; P], &mut short);
        let full = <$new>::sensitivity(&[0.0; V], &[1.0; P]);
        assert!(short
            .iter()
            .zip(full.iter().flatten())
            .all(|(a, b)| same(*a, *b)));
        let mut out = vec![0.0; 6 * N];
        ErrorModel::sensitivity(&<$new>::default(), &[0.0; 0], &[1.0; P], &mut out);
        assert!(out.iter().all(|x| x.is_nan()));
        // The sparse path refuses wrong lengths and leaves `out` alone.
        let mut wrong = vec![3.0; K + 1];
        let model = <$new>::default();
        assert!(!ErrorModel::sensitivity_nonzeros(
            &model, &[0.0; V], &[1.0; P], &mut wrong
        ));
        assert!(wrong.iter().all(|x| *x == 3.0));
        K
    }};
}

#[test]
fn gantry_grinder() {
    assert_eq!(compare!(Gantry, v1::gantry::GantryGrinder, FILES[0].0), 32);
}

#[test]
fn internal_grinder() {
    compare!(Internal, v1::internal::InternalGrinder, FILES[1].0);
}

#[test]
fn cnc5_bevel() {
    compare!(Cnc5, v1::cnc5::Cnc5Bevel, FILES[2].0);
}

#[test]
fn ac_trunnion() {
    compare!(Ac, v1::ac::AcTrunnion, FILES[3].0);
}

#[test]
fn head_head_bc() {
    compare!(Hh, v1::hh::HeadHeadBc, FILES[4].0);
}

#[test]
fn bc_head_table() {
    compare!(Bc, v1::bc::BcHeadTable, FILES[5].0);
}

/// `chain-macro/benches/sympy/bc_head_table.json`, the input of the SymPy
/// benchmark code (`benches/sympy/generate.py`), is the current derivation of
/// the benchmark machine: when it is not, regenerate both files as that
/// script's header says.
#[test]
fn sympy_bench_input_is_current() {
    let machine =
        chain::core::load_file(&root().join(FILES[5].0)).unwrap_or_else(|d| panic!("{d}"));
    let model = chain::core::derive(&machine);
    let now = serde_json::to_value(chain::core::export::to_json(&model)).unwrap();
    let path = root().join("chain-macro/benches/sympy/bc_head_table.json");
    let recorded: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert!(
        now == recorded,
        "{} is not the current derivation: rerun chain-macro/benches/sympy/generate.py",
        path.display()
    );
}
