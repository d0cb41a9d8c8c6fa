//! The batched kernels of the `machine!` types:
//! `sensitivity_batch_into`, `sensitivity_nonzeros_batch_into`,
//! `error_batch_into`, `error_batch_each_into` and the `ErrorModel` batch
//! methods over them, on every example machine (a test below fails when a
//! machine file is added without its type here).
//!
//! The reference is the per-point functions of the same type. The batched
//! kernels evaluate four points at once with the vectorised `sin`/`cos` of
//! `chain_core::lanes` (≤ 2 ulp from the standard library's), so values agree
//! to rounding, not bit for bit: each entry within 4 ulp of the per-point
//! value or 1e-15 of the row's largest magnitude (an entry that is a small
//! difference of large terms inherits the terms' rounding, not its own).

use crate::common::Points;
use chain::core::ErrorModel;

chain::machine!(pub AcTrunnion = "examples/machines/ac_trunnion.yaml");
chain::machine!(pub AcTrunnionRotary = "examples/machines/ac_trunnion_rotary.yaml");
chain::machine!(pub BcTableRotary = "examples/machines/bc_table_rotary.yaml");
chain::machine!(pub Cnc5Bevel = "examples/machines/cnc5_bevel.yaml");
chain::machine!(pub CradleGenerator = "examples/machines/cradle_generator.yaml");
chain::machine!(pub GantryGrinder = "examples/machines/gantry_grinder.yaml");
chain::machine!(pub HeadHeadBc = "examples/machines/head_head_bc.yaml");
chain::machine!(pub InternalGrinder = "examples/machines/internal_grinder.yaml");
chain::machine!(pub Legendre5 = "examples/machines/legendre5.yaml");
chain::machine!(pub SpreadAlongAxis = "examples/machines/spread_along_axis.yaml");
chain::machine!(pub Vmc3 = "examples/machines/vmc3.yaml");
chain::machine!(pub Arm6 = "examples/robots/arm6_offsets.yaml");
chain::machine!(pub Puma560 = "examples/robots/puma560_dh.yaml");
chain::machine!(pub Panda = "examples/robots/panda_mdh.yaml");
chain::machine!(pub BcHeadTable = "chain-macro/benches/machines/bc_head_table.yaml");

/// The machine files with a type above.
const DECLARED: [&str; 14] = [
    "machines/ac_trunnion.yaml",
    "machines/ac_trunnion_rotary.yaml",
    "machines/bc_table_rotary.yaml",
    "machines/cnc5_bevel.yaml",
    "machines/cradle_generator.yaml",
    "machines/gantry_grinder.yaml",
    "machines/head_head_bc.yaml",
    "machines/internal_grinder.yaml",
    "machines/legendre5.yaml",
    "machines/spread_along_axis.yaml",
    "machines/vmc3.yaml",
    "robots/arm6_offsets.yaml",
    "robots/panda_mdh.yaml",
    "robots/puma560_dh.yaml",
];

/// Every machine file of `examples/machines/` and `examples/robots/` has a
/// type in this test (values, truth and settings files are not machines:
/// they have no `bodies:`).
#[test]
fn every_example_machine_is_declared() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut found = Vec::new();
    for dir in ["machines", "robots"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            if path.extension().is_some_and(|e| e == "yaml") && text.contains("\nbodies:") {
                found.push(format!(
                    "{dir}/{}",
                    path.file_name().unwrap().to_string_lossy()
                ));
            }
        }
    }
    found.sort();
    assert_eq!(found, DECLARED);
}

/// Distance in ulp of two doubles (0 when equal; `u64::MAX` across signs).
fn ulps(a: f64, b: f64) -> u64 {
    if a == b {
        return 0;
    }
    if a.is_sign_negative() != b.is_sign_negative() {
        return u64::MAX;
    }
    (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
}

/// `got` agrees with `want` within 4 ulp or 1e-15 of `scale`.
fn agrees(got: f64, want: f64, scale: f64) -> bool {
    ulps(got, want) <= 4 || (got - want).abs() <= 1e-15 * scale
}

/// The whole comparison for one machine type.
macro_rules! compare {
    ($ty:ty) => {{
        const V: usize = <$ty>::VARIABLES.len();
        const P: usize = <$ty>::PARAMETERS.len();
        const N: usize = <$ty>::ERRORS.len();
        const K: usize = <$ty>::NONZEROS.len();
        let name = stringify!($ty);
        let mut rng = Points(0x2545_f491_4f6c_dd1d);
        let p: [f64; P] =
            std::array::from_fn(|i| <$ty>::PARAMETER_VALUES[i].unwrap_or(50.0 + 10.0 * i as f64));
        // 0..=13 points: empty, partial groups of four and whole ones.
        for count in 0..=13usize {
            // Rotary variables of up to three turns, prismatic ±300 mm.
            let qs: Vec<[f64; V]> = (0..count)
                .map(|_| std::array::from_fn(|_| rng.next(3.0) * 100.0))
                .collect();
            let es: Vec<[f64; N]> = (0..count)
                .map(|_| std::array::from_fn(|_| rng.next(1e-3)))
                .collect();
            // Garbage in the outputs: every entry must be written.
            let mut sens = vec![[[f64::NAN; N]; 6]; count];
            <$ty>::sensitivity_batch_into(&qs, &p, &mut sens);
            let mut nz = vec![[f64::NAN; K]; count];
            <$ty>::sensitivity_nonzeros_batch_into(&qs, &p, &mut nz);
            let e0 = es.first().copied().unwrap_or([1e-4; N]);
            let mut err = vec![[f64::NAN; 6]; count];
            <$ty>::error_batch_into(&qs, &p, &e0, &mut err);
            let mut each = vec![[f64::NAN; 6]; count];
            <$ty>::error_batch_each_into(&qs, &p, &es, &mut each);
            // The trait's batch methods (flat slices).
            let model = <$ty>::default();
            let flat_q: Vec<f64> = qs.iter().flatten().copied().collect();
            let mut flat_s = vec![f64::NAN; count * 6 * N];
            ErrorModel::sensitivity_points(&model, &flat_q, &p, &mut flat_s).unwrap();
            let flat_e: Vec<f64> = es.iter().flatten().copied().collect();
            let mut flat_err = vec![f64::NAN; count * 6];
            ErrorModel::error_points(&model, &flat_q, &p, &flat_e, &mut flat_err).unwrap();
            let mut flat_err0 = vec![f64::NAN; count * 6];
            ErrorModel::error_points(&model, &flat_q, &p, &e0, &mut flat_err0).unwrap();
            for (i, q) in qs.iter().enumerate() {
                let s = <$ty>::sensitivity(q, &p);
                for c in 0..6 {
                    let scale = s[c].iter().fold(1.0f64, |m, x| m.max(x.abs()));
                    for j in 0..N {
                        let (got, want) = (sens[i][c][j], s[c][j]);
                        assert!(
                            agrees(got, want, scale),
                            "{name} point {i} of {count}: s[{c}][{j}] {got:e} vs {want:e}"
                        );
                        let flat = flat_s[i * 6 * N + c * N + j];
                        assert!(
                            agrees(flat, want, scale),
                            "{name} sensitivity_points [{c}][{j}]"
                        );
                        if want == 0.0 {
                            assert_eq!(got, 0.0, "{name}: a structural zero");
                        }
                    }
                }
                for (k, &(c, j)) in <$ty>::NONZEROS.iter().enumerate() {
                    let scale = s[c].iter().fold(1.0f64, |m, x| m.max(x.abs()));
                    assert!(agrees(nz[i][k], s[c][j], scale), "{name} nonzeros[{k}]");
                }
                let (want, want_each) = (<$ty>::error(q, &p, &e0), <$ty>::error(q, &p, &es[i]));
                // E = S·e: its scale is that of the terms, |S|·|e|.
                let term_scale = |e: &[f64; N]| {
                    (0..6)
                        .map(|c| (0..N).map(|j| (s[c][j] * e[j]).abs()).sum::<f64>())
                        .fold(0.0f64, f64::max)
                };
                let (sc, sc_each) = (term_scale(&e0), term_scale(&es[i]));
                for c in 0..6 {
                    assert!(
                        agrees(err[i][c], want[c], sc),
                        "{name} error_batch_into [{c}]: {:e} vs {:e}",
                        err[i][c],
                        want[c]
                    );
                    assert!(
                        agrees(flat_err0[i * 6 + c], want[c], sc),
                        "{name} error_points broadcast [{c}]"
                    );
                    assert!(
                        agrees(each[i][c], want_each[c], sc_each),
                        "{name} error_batch_each_into [{c}]"
                    );
                    assert!(
                        agrees(flat_err[i * 6 + c], want_each[c], sc_each),
                        "{name} error_points [{c}]"
                    );
                }
            }
        }
        // Refusals of the trait methods: nothing written.
        let mut out = vec![7.0; 6 * N + 1];
        let q = vec![0.0; V];
        if V > 0 {
            assert!(ErrorModel::sensitivity_points(&<$ty>::default(), &q, &p, &mut out).is_err());
            assert!(out.iter().all(|&x| x == 7.0));
        }
    }};
}

#[test]
fn batched_kernels_equal_the_per_point_functions_on_every_example() {
    compare!(AcTrunnion);
    compare!(AcTrunnionRotary);
    compare!(BcTableRotary);
    compare!(Cnc5Bevel);
    compare!(CradleGenerator);
    compare!(GantryGrinder);
    compare!(HeadHeadBc);
    compare!(InternalGrinder);
    compare!(Legendre5);
    compare!(SpreadAlongAxis);
    compare!(Vmc3);
    compare!(Arm6);
    compare!(Puma560);
    compare!(Panda);
    compare!(BcHeadTable);
}

#[test]
#[should_panic(expected = "sensitivity_batch_into: 2 points but 1 output matrices")]
fn a_batch_of_the_wrong_length_panics_with_its_lengths() {
    let qs = [[0.0; 3]; 2];
    let mut out = [[[0.0; 21]; 6]; 1];
    GantryGrinder::sensitivity_batch_into(&qs, &[], &mut out);
}
