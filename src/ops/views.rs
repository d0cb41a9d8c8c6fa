//! What the CLI's tables and the charts of [`crate::plot`] both show of a
//! document, formed once: a target's reliabilities as maps over the grid
//! (the paper's Tables 2-4), the words saying where sensitivities hold, a
//! quantity's label.

use chain_core::geometric::Where;
use reliability::{Quantity, Study, StudyResult};

/// One target's reliabilities as maps over the two grid axes it varies along
/// (further varying axes give one map per value), like Tables 2-4.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetMap {
    /// Row axis (name, values), if the target varies along it.
    pub rows: Option<(String, Vec<f64>)>,
    /// Column axis (name, values), if the target varies along a second axis.
    pub cols: Option<(String, Vec<f64>)>,
    /// One map per combination of the other varying axes: (label, values[row][col]).
    pub maps: Vec<(String, Vec<Vec<f64>>)>,
    /// Parallel to `maps`: true where FORM did not converge.
    pub unconverged: Vec<Vec<Vec<bool>>>,
}

/// Builds the maps of target `t` from a study result.
pub fn target_map(study: &Study, r: &StudyResult, t: usize) -> TargetMap {
    let grid = &study.spec().grid;
    let np = study.points().len();
    let cases = r.target_cases(t);
    let dims: Vec<usize> = grid.axes.iter().map(|(_, v)| v.len()).collect();
    // Axes along which the limit state changes (decided on the model, not on
    // sampled values, which are noisy).
    let target = study.targets()[t];
    let varying: Vec<usize> = (0..dims.len())
        .filter(|&a| {
            (0..np).any(|p| {
                let mut idx = grid.index(p);
                if idx[a] == 0 {
                    return false;
                }
                idx[a] = 0;
                let q = flat(&idx, &dims);
                match (study.limit_state(target, p), study.limit_state(target, q)) {
                    (Ok(g1), Ok(g2)) => g1 != g2,
                    _ => true,
                }
            })
        })
        .collect();
    let row_axis = varying.first().copied();
    let col_axis = varying.get(1).copied();
    let others: Vec<usize> = varying.iter().skip(2).copied().collect();
    let len = |a: Option<usize>| a.map_or(1, |a| dims[a]);
    let other_count: usize = others.iter().map(|&a| dims[a]).product();
    let mut maps = Vec::new();
    let mut unconverged = Vec::new();
    for o in 0..other_count.max(1) {
        let mut idx = vec![0; dims.len()];
        let mut rest = o;
        let mut label = Vec::new();
        for &a in others.iter().rev() {
            idx[a] = rest % dims[a];
            rest /= dims[a];
        }
        for &a in &others {
            label.push(format!("{} = {}", grid.axes[a].0, grid.axes[a].1[idx[a]]));
        }
        let mut m = vec![vec![0.0; len(col_axis)]; len(row_axis)];
        let mut u = vec![vec![false; len(col_axis)]; len(row_axis)];
        for (i, (row, urow)) in m.iter_mut().zip(&mut u).enumerate() {
            for (j, (cell, ucell)) in row.iter_mut().zip(urow.iter_mut()).enumerate() {
                if let Some(a) = row_axis {
                    idx[a] = i;
                }
                if let Some(a) = col_axis {
                    idx[a] = j;
                }
                let case = &cases[flat(&idx, &dims)];
                *cell = case.reliability;
                *ucell = !case.converged();
            }
        }
        maps.push((label.join(", "), m));
        unconverged.push(u);
    }
    TargetMap {
        rows: row_axis.map(|a| grid.axes[a].clone()),
        cols: col_axis.map(|a| grid.axes[a].clone()),
        maps,
        unconverged,
    }
}

fn flat(idx: &[usize], dims: &[usize]) -> usize {
    idx.iter().zip(dims).fold(0, |acc, (i, d)| acc * d + i)
}

/// `at x = 0, y = 1500, z = 600`.
pub fn at_text(a: &[(String, f64)]) -> String {
    format!(
        "at {}",
        a.iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// Where geometric coefficients hold: `at x = 0, …` or `mean over N grid
/// points`.
pub fn where_text(w: &Where) -> String {
    match w {
        Where::At(a) => at_text(a),
        Where::Grid(g) => format!(
            "mean over {} grid points",
            g.iter().map(|(_, v)| v.len()).product::<usize>()
        ),
    }
}

/// `|p|` for the volumetric quantity, the component's name otherwise.
pub fn quantity_label(q: Quantity) -> &'static str {
    match q {
        Quantity::Volumetric => "|p|",
        Quantity::Component(c) => c.name(),
    }
}

/// The decimals that show an uncertainty `u` to two significant digits,
/// and its value to the same place (3 without one; at most 6): how the
/// circular test's diagnosis is printed in the table and on the report's
/// page.
pub fn places(u: Option<f64>) -> usize {
    u.filter(|u| *u > 0.0 && u.is_finite())
        .map_or(3, |u| (1 - u.log10().floor() as i32).clamp(0, 6) as usize)
}
