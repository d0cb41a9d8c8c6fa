//! The differential-motion-matrix route of seed 000 (its Eq. 3 and Eq. 5), run
//! over the same ring as the matrix route, as an independent cross-check.
//!
//! `T_wt` is a product of nominal factors and small-error factors
//! `E_k = I + Δ_k`. To first order `T_wt = T0·(I + Σ_k B_k⁻¹ Δ_k B_k)`, where
//! `B_k` is the nominal product of the factors after `E_k`; the twist of
//! `B_k⁻¹ Δ_k B_k` is `DJ[B_k]·ΔE_k` with the 6×6 differential motion matrix
//!
//! ```text
//! DJ[T] = [ Rᵀ   −Rᵀ(P×) ]
//!         [ 0      Rᵀ    ]      (seed 000, Eq. 3)
//! ```
//!
//! Errors on the workpiece branch enter inverted (`E⁻¹ = I − Δ` to first
//! order), which is the sign flip of the paper's Eq. 15. Summing the tool-frame
//! twists (Eq. 5, then Eq. 18) gives `d` and `δ`; the tool point adds `δ × tp`.

use crate::algebra::{expr_to_poly, Dual, Poly, Transform};
use crate::derive::{body_factors, branches, slot_dual, transpose_apply, Factor};
use crate::model::{ErrorSlots, Frame, Machine};

/// The six components, as [`crate::SymbolicModel::components`], derived by the
/// differential-motion-matrix route.
pub fn derive_dmm(machine: &Machine, frame: Frame) -> [Vec<(usize, Poly)>; 6] {
    // Flatten T_wt into signed factors.
    enum Signed {
        Nominal(Box<Transform>),
        Error(ErrorSlots, f64),
    }
    let (wp_path, tool_path) = branches(machine);
    let mut factors = Vec::new();
    for &b in wp_path.iter().rev() {
        for f in body_factors(machine, b).into_iter().rev() {
            factors.push(match f {
                Factor::Nominal(t) => Signed::Nominal(Box::new(t.inverse())),
                Factor::Error(s) => Signed::Error(s, -1.0),
            });
        }
    }
    for &b in &tool_path {
        for f in body_factors(machine, b) {
            factors.push(match f {
                Factor::Nominal(t) => Signed::Nominal(t),
                Factor::Error(s) => Signed::Error(s, 1.0),
            });
        }
    }

    // Walk backwards accumulating B_k and the tool-frame twist.
    let mut after = Transform::identity();
    let mut twist: [Dual; 6] = Default::default();
    for f in factors.iter().rev() {
        match f {
            Signed::Nominal(t) => after = t.mul(&after),
            Signed::Error(slots, sign) => {
                let local: [Dual; 6] =
                    std::array::from_fn(|i| slot_dual(machine, &slots.slots[i], *sign));
                let dj = differential_motion_matrix(&after);
                for (i, row) in dj.iter().enumerate() {
                    for (k, entry) in row.iter().enumerate() {
                        if !entry.is_zero() && !local[k].is_zero() {
                            twist[i] = twist[i].add(&Dual::nominal(entry.clone()).mul(&local[k]));
                        }
                    }
                }
            }
        }
    }
    let total = factors
        .iter()
        .fold(Transform::identity(), |acc, f| match f {
            Signed::Nominal(t) => acc.mul(t),
            Signed::Error(..) => acc,
        });
    let r0: [[Poly; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| total.r[i][j].value.clone()));
    let tp: [Poly; 3] = std::array::from_fn(|i| expr_to_poly(&machine.tool_point[i]));

    let mut components: [Vec<(usize, Poly)>; 6] = Default::default();
    for j in 0..machine.errors.len() {
        let d: [Poly; 3] = std::array::from_fn(|i| twist[i].slope(j));
        let delta: [Poly; 3] = std::array::from_fn(|i| twist[i + 3].slope(j));
        // Tool frame: p = d + δ × tp, o = δ.
        let cross = [
            delta[1].mul(&tp[2]).sub(&delta[2].mul(&tp[1])),
            delta[2].mul(&tp[0]).sub(&delta[0].mul(&tp[2])),
            delta[0].mul(&tp[1]).sub(&delta[1].mul(&tp[0])),
        ];
        let p: [Poly; 3] = std::array::from_fn(|i| d[i].add(&cross[i]));
        let (p, o) = match frame {
            Frame::Tool => (p, delta),
            Frame::Workpiece => (apply(&r0, &p), apply(&r0, &delta)),
        };
        for (c, value) in p.into_iter().chain(o).enumerate() {
            if !value.is_zero() {
                components[c].push((j, value));
            }
        }
    }
    components
}

/// `DJ[T]` of seed 000 Eq. 3 for a nominal transform `T = [R P; 0 1]`.
pub fn differential_motion_matrix(t: &Transform) -> [[Poly; 6]; 6] {
    let r: [[Poly; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| t.r[i][j].value.clone()));
    let p: [Poly; 3] = std::array::from_fn(|i| t.t[i].value.clone());
    let mut dj: [[Poly; 6]; 6] = Default::default();
    // Columns n, o, a of R; row i of the upper blocks uses column i.
    for i in 0..3 {
        let col: [Poly; 3] = std::array::from_fn(|k| r[k][i].clone());
        // (p × col)
        let pc = [
            p[1].mul(&col[2]).sub(&p[2].mul(&col[1])),
            p[2].mul(&col[0]).sub(&p[0].mul(&col[2])),
            p[0].mul(&col[1]).sub(&p[1].mul(&col[0])),
        ];
        dj[i][..3].clone_from_slice(&col);
        dj[i][3..].clone_from_slice(&pc);
        dj[i + 3][3..].clone_from_slice(&col);
    }
    dj
}

fn apply(r: &[[Poly; 3]; 3], v: &[Poly; 3]) -> [Poly; 3] {
    let rt: [[Poly; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| r[j][i].clone()));
    transpose_apply(&rt, v)
}
