//! The Nataf model (`reliability-v2.md` §2): the physical correlation of
//! transformed samples is the one requested, and the transform's Jacobian
//! and second derivatives match finite differences.

use reliability::inputs::Correlation;
use reliability::rng::CaseRng;
use reliability::{Inputs, Marginal};

/// The Pearson correlation of 10⁶ samples of `x = T(u)` equals the
/// requested one within 3 standard errors (`(1 − ρ²)/√n` for the sample
/// correlation, the normal-theory value; the marginals here are light-tailed
/// enough that it is the right order) for normal–lognormal (closed form),
/// uniform–uniform (closed form) and Weibull–Gumbel (quadrature) pairs.
#[test]
fn transformed_samples_have_the_requested_correlation() {
    let cases = [
        (
            Marginal::normal(1.0, 0.5).unwrap(),
            Marginal::lognormal(2.0, 0.6, 0.0).unwrap(),
            0.6,
        ),
        (
            Marginal::uniform(-1.0, 1.0).unwrap(),
            Marginal::uniform(0.0, 3.0).unwrap(),
            -0.45,
        ),
        (
            Marginal::weibull(1.5, 2.2, 0.0).unwrap(),
            Marginal::gumbel(0.0, 0.7).unwrap(),
            0.5,
        ),
    ];
    for (a, b, rho) in cases {
        let inputs = Inputs::correlated(
            vec!["a".into(), "b".into()],
            vec![a, b],
            &[Correlation { a: 0, b: 1, rho }],
        )
        .unwrap();
        let n = 1_000_000;
        let mut rng = CaseRng::new(11, 0, 0);
        let mut x = [0.0; 2];
        let (mut s, mut ss, mut sab) = ([0.0; 2], [0.0; 2], 0.0);
        for _ in 0..n {
            inputs.sample(&mut rng, &mut x);
            for j in 0..2 {
                s[j] += x[j];
                ss[j] += x[j] * x[j];
            }
            sab += x[0] * x[1];
        }
        let nf = n as f64;
        let m = [s[0] / nf, s[1] / nf];
        let v = [ss[0] / nf - m[0] * m[0], ss[1] / nf - m[1] * m[1]];
        let r = (sab / nf - m[0] * m[1]) / (v[0] * v[1]).sqrt();
        let se = (1.0 - rho * rho) / nf.sqrt();
        assert!(
            (r - rho).abs() < 3.0 * se,
            "{:?}-{:?}: sample ρ {r} vs {rho} (3 se = {})",
            a.family(),
            b.family(),
            3.0 * se
        );
        // The samples keep their marginal moments (5 standard errors).
        for (j, mg) in [a, b].iter().enumerate() {
            assert!(
                (m[j] - mg.mean()).abs() < 5.0 * mg.std() / nf.sqrt(),
                "mean {j}"
            );
        }
    }
}

/// `x = T(u)` with a non-normal correlated block: `T⁻¹(T(u)) = u`, the
/// Jacobian matrix and `Σ w_j ∇²x_j` against central differences (steps
/// 1e-6 and 1e-4; 1e-6 relative).
#[test]
fn the_block_transform_and_its_derivatives() {
    let names = ["a", "b", "c", "d"].map(String::from).to_vec();
    let marginals = vec![
        Marginal::lognormal(2.0, 0.6, 0.0).unwrap(),
        Marginal::normal(0.0, 1.0).unwrap(),
        Marginal::weibull(1.5, 2.2, 0.0).unwrap(),
        Marginal::triangular(0.0, 0.4, 1.0).unwrap(),
    ];
    let pairs = [
        Correlation {
            a: 0,
            b: 2,
            rho: 0.5,
        },
        Correlation {
            a: 2,
            b: 3,
            rho: -0.3,
        },
        Correlation {
            a: 0,
            b: 3,
            rho: 0.2,
        },
    ];
    let inputs = Inputs::correlated(names, marginals, &pairs).unwrap();
    let n = 4;
    let u = [0.4, -0.3, 1.1, -0.8];
    let mut x = [0.0; 4];
    let mut back = [0.0; 4];
    inputs.to_physical(&u, &mut x);
    inputs.to_standard(&x, &mut back);
    for k in 0..n {
        assert!((back[k] - u[k]).abs() < 1e-10, "{back:?}");
    }
    let mut jac = vec![0.0; n * n];
    inputs.jacobian_matrix(&u, &mut jac);
    let w = [0.7, -1.2, 0.5, 2.0];
    let mut hess = vec![0.0; n * n];
    inputs.add_second_derivatives(&u, &w, &mut hess);
    let phys = |u: &[f64]| {
        let mut x = [0.0; 4];
        inputs.to_physical(u, &mut x);
        x
    };
    let wx = |u: &[f64]| phys(u).iter().zip(&w).map(|(x, w)| x * w).sum::<f64>();
    for c in 0..n {
        let h = 1e-6;
        let (mut up, mut um) = (u, u);
        up[c] += h;
        um[c] -= h;
        let (xp, xm) = (phys(&up), phys(&um));
        for j in 0..n {
            let fd = (xp[j] - xm[j]) / (2.0 * h);
            assert!(
                (jac[j * n + c] - fd).abs() < 1e-6 * fd.abs().max(1e-3),
                "J[{j},{c}]"
            );
        }
        // The gradient through the Jacobian.
        let mut gu = [0.0; 4];
        inputs.gradient_u(&u, &w, &mut gu);
        let fd = (wx(&up) - wx(&um)) / (2.0 * h);
        assert!((gu[c] - fd).abs() < 1e-6 * fd.abs().max(1e-3), "∇u[{c}]");
        for d in 0..n {
            let h = 1e-4;
            let at = |sc: f64, sd: f64| {
                let mut v = u;
                v[c] += sc * h;
                v[d] += sd * h;
                wx(&v)
            };
            let fd =
                (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0)) / (4.0 * h * h);
            assert!(
                (hess[c * n + d] - fd).abs() < 1e-5 * fd.abs().max(1e-2),
                "H[{c},{d}] {} vs {fd}",
                hess[c * n + d]
            );
        }
    }
}

/// A matrix that is positive definite as given but not after the Nataf
/// adjustment is refused, naming the pair where the factorisation fails;
/// normal pairs need no adjustment (the existing correlated-normal block).
#[test]
fn non_positive_definite_after_adjustment_names_the_pair() {
    let names = ["a", "b", "c"].map(String::from).to_vec();
    let n = Marginal::normal(0.0, 1.0).unwrap();
    let pairs = [
        Correlation {
            a: 0,
            b: 1,
            rho: 0.6,
        },
        Correlation {
            a: 1,
            b: 2,
            rho: 0.6,
        },
        Correlation {
            a: 0,
            b: 2,
            rho: 0.3,
        },
    ];
    let ok = Inputs::correlated(names.clone(), vec![n, n, n], &pairs).unwrap();
    assert_eq!(ok.correlation(0, 1), 0.6);
    // Three lognormals with δ = 0.8 at ρ = −0.45 each: R has eigenvalue
    // 1 − 2·0.45 = 0.1 > 0, but ρ₀ = ln(1 − 0.45·0.64)/ln(1.64) = −0.687
    // (Liu & Der Kiureghian's closed form) gives 1 − 2·0.687 < 0.
    let l = Marginal::lognormal(1.0, 0.8, 0.0).unwrap();
    let pairs = [
        Correlation {
            a: 0,
            b: 1,
            rho: -0.45,
        },
        Correlation {
            a: 1,
            b: 2,
            rho: -0.45,
        },
        Correlation {
            a: 0,
            b: 2,
            rho: -0.45,
        },
    ];
    let e = Inputs::correlated(names, vec![l, l, l], &pairs)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Nataf-adjusted correlation matrix of a, b, c is not positive definite")
            && e.contains("`b`–`c`"),
        "{e}"
    );
}

// ------------------------------------------------------------------ loading

const MACHINE: &str = "\
machine: m
bodies:
  bed: {}
  x_slide:
    parent: bed
    joint: {type: prismatic, axis: +x, variable: x}
    errors: {dx: dxx, ey: eyx, dz: dzx}
workpiece: bed
tool: x_slide
statistics:
  dxx: {dist: lognormal, mean: 1.0e-3, std: 0.8e-3}
  eyx: {dist: lognormal, mean: 1.0e-3, std: 0.8e-3}
  dzx: {dist: lognormal, mean: 1.0e-3, std: 0.8e-3}
";

fn load_err(corr: &str) -> String {
    let text = format!("{MACHINE}correlation:\n{corr}");
    match chain_core::load_str(&text, "bad.yaml") {
        Ok(_) => panic!("loaded: {corr}"),
        Err(d) => {
            assert_eq!(d.len(), 1, "{corr}: {d:#}");
            d.to_string()
        }
    }
}

/// The `correlation` list loads into the Nataf inputs; each of the spec's
/// bad cases is one located error (`bad.yaml:LINE:COL`, the key).
#[test]
fn the_correlation_list_is_loaded_and_checked() {
    let text = format!("{MACHINE}correlation:\n  - [dxx, eyx, 0.6]\n  - [eyx, dzx, '-0.1 * 2']\n");
    let m = chain_core::load_str(&text, "ok.yaml").unwrap();
    assert_eq!(m.correlations.len(), 2);
    assert_eq!(m.correlations[1].rho, -0.2);
    assert_eq!(m.correlations[0].origin.line, 15);
    let inputs = reliability::machine::inputs(&m).unwrap();
    let ix = |n: &str| inputs.index(n).unwrap();
    assert_eq!(inputs.correlation(ix("dxx"), ix("eyx")), 0.6);
    assert_eq!(inputs.correlation(ix("dzx"), ix("eyx")), -0.2);
    let cases = [
        // Not an error of the machine.
        ("  - [dxx, exy, 0.5]\n", 15, 11, "exy"),
        // Outside (−1, 1).
        ("  - [dxx, eyx, 1.0]\n", 15, 16, "strictly between"),
        // With itself.
        ("  - [dxx, dxx, 0.5]\n", 15, 11, "itself"),
        // Twice.
        ("  - [dxx, eyx, 0.5]\n  - [eyx, dxx, 0.2]\n", 16, 5, "twice"),
        // Not a triple.
        ("  - [dxx, eyx]\n", 15, 5, "3"),
    ];
    for (corr, line, col, needle) in cases {
        let msg = load_err(corr);
        let prefix = format!("bad.yaml:{line}:{col}: ");
        assert!(
            msg.starts_with(&prefix),
            "{corr}: expected {prefix}, got\n{msg}"
        );
        assert!(msg.contains("at key `correlation["), "{corr}: {msg}");
        assert!(msg.contains(needle), "{corr}: {needle}\n{msg}");
    }
    // Positive definite as given, not after the Nataf adjustment (ρ₀ =
    // ln(1 − 0.45·0.64)/ln 1.64 = −0.687): located at the failing pair.
    let text = format!(
        "{MACHINE}correlation:\n  - [dxx, eyx, -0.45]\n  - [eyx, dzx, -0.45]\n  - [dxx, dzx, -0.45]\n"
    );
    let m = chain_core::load_str(&text, "nataf.yaml").unwrap();
    let e = reliability::machine::inputs(&m).unwrap_err().to_string();
    assert!(
        e.contains("not positive definite") && e.contains(":16:5:") && e.contains("correlation[1]"),
        "{e}"
    );
}
