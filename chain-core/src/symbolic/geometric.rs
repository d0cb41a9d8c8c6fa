//! Geometric error sensitivity coefficients (seed 004, Fan et al. 2020,
//! Eq. 4-6), for any error model.
//!
//! For each error component `u` (`px, py, pz, ox, oy, oz`) and error parameter
//! `v`:
//!
//! - the sensitivity `S_uv = |∂E_u/∂e_v|` (Eq. 5), exact, from
//!   [`ErrorModel::sensitivity`];
//! - the normalised coefficient `C_uv = S_uv·e_v / Σ_w S_uw·e_w` (Eq. 6 with
//!   each sensitivity weighted by the nominal size `e_v` of its error), so
//!   that `C_uv` is the share of error `v` in the worst-case first-order sum
//!   of direction `u`, and `Σ_v C_uv = 1` whenever the direction has any
//!   error at all (otherwise every `C_uv = 0`).
//!
//! `e_v` is chosen by the error's kind ([`ErrorKind`]): a length for linear
//! errors, an angle (radians) for angular and squareness errors
//! ([`NominalSizes`]). With equal numbers for both (e.g. 0.001 mm and
//! 0.001 rad) the weighting cancels and `C = S/ΣS`, Eq. 6 as printed; this is
//! the normalisation the paper's Figures 3-5 imply (see
//! `docs/geometric_sensitivity.md`).
//!
//! ```
//! use chain_core::{geometric, load_str};
//! let yaml = "machine: m\nbodies:\n  bed: {}\n  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: dxx, ez: ezx}}\nworkpiece: bed\ntool: x_slide\ntool_point: [0, 100, 0]\n";
//! let machine = load_str(yaml, "m.yaml").unwrap();
//! let model = chain_core::compile(&machine);
//! let sizes = geometric::NominalSizes::default().of(&machine);
//! let r = geometric::at_point(&model, &[0.0], &[], &sizes);
//! // px = dxx - 100·ezx: S = (1, 100), S·e = (0.001, 100·0.001°).
//! let px = &r.components[0];
//! assert_eq!(px.ranked[0].error, "ezx");
//! assert!((px.ranked[0].s - 100.0).abs() < 1e-12);
//! assert!((px.ranked[0].c + px.ranked[1].c - 1.0).abs() < 1e-12);
//! ```

use serde::Serialize;

use crate::model::{BasisFn, Component, ErrorKind, Machine};
use crate::named::NameMap;
use crate::ErrorModel;

/// One degree in radians.
const DEG: f64 = std::f64::consts::PI / 180.0;

/// The nominal size `e_v` of each kind of error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NominalSizes {
    /// Linear errors, in the model's length unit (mm).
    pub linear: f64,
    /// Angular errors, in radians.
    pub angular: f64,
    /// Squareness errors, in radians.
    pub squareness: f64,
}

impl Default for NominalSizes {
    /// The paper's values: 0.001 mm and 0.001° (Section 5.2).
    fn default() -> NominalSizes {
        NominalSizes {
            linear: 0.001,
            angular: 0.001 * DEG,
            squareness: 0.001 * DEG,
        }
    }
}

/// The largest nominal angular (or squareness) error size: π rad.
pub const MAX_NOMINAL_ANGLE: f64 = std::f64::consts::PI;
/// The largest nominal linear error size: 1e6 in the model's length unit.
pub const MAX_NOMINAL_LENGTH: f64 = 1e6;

impl NominalSizes {
    /// The size of one kind of error.
    pub fn of_kind(&self, kind: ErrorKind) -> f64 {
        match kind {
            ErrorKind::Linear => self.linear,
            ErrorKind::Angular => self.angular,
            ErrorKind::Squareness => self.squareness,
        }
    }

    /// `e_v` for every error of the machine, in `machine.errors` order (the
    /// order of the compiled model's [`ErrorModel::errors`]).
    ///
    /// The coefficient `F_k` of a function slot (measured-machines spec,
    /// section 1) moves its slot by `F_k·b_k(q)`, so its size is the kind's
    /// size over the largest `|b_k|` along the axis ([`coefficient_extent`]):
    /// the coefficient value that moves the slot by the nominal size at the
    /// far end of the travel.
    pub fn of(&self, machine: &Machine) -> Vec<f64> {
        machine
            .errors
            .iter()
            .enumerate()
            .map(|(j, e)| self.of_kind(e.kind) / coefficient_extent(machine, j))
            .collect()
    }

    /// Parses `linear=0.001,angular=0.001deg[,squareness=…]`: lengths as
    /// plain numbers, angles in radians or with a `deg` (or `rad`) suffix.
    /// Keys not given keep their value in `self`; `squareness` follows
    /// `angular` unless given. Every value must be finite and positive.
    pub fn parse(&self, text: &str) -> Result<NominalSizes, String> {
        let mut out = *self;
        let mut squareness = None;
        let mut any = false;
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            any = true;
            let (key, value) = item.split_once('=').ok_or_else(|| {
                format!("expected KIND=VALUE (linear=0.001,angular=0.001deg), found `{item}`")
            })?;
            let key = key.trim();
            let value = value.trim();
            let number = |v: &str, angle: bool| -> Result<f64, String> {
                let (digits, scale) = match (angle, v.strip_suffix("deg"), v.strip_suffix("rad")) {
                    (true, Some(d), _) => (d, DEG),
                    (true, None, Some(r)) => (r, 1.0),
                    _ => (v, 1.0),
                };
                let x: f64 = digits.trim().parse().map_err(|_| {
                    if angle {
                        format!(
                            "`{v}` is not an angle (a number in radians, or with a `deg` suffix)"
                        )
                    } else {
                        format!("`{v}` is not a length (a number, in the model's unit)")
                    }
                })?;
                let x = x * scale;
                if !x.is_finite() || x <= 0.0 {
                    return Err(format!(
                        "`{key}={v}`: the nominal error size must be positive and finite"
                    ));
                }
                // A size is a small error: bounded so that `S·e` and its sum
                // stay finite.
                let (max, unit) = if angle {
                    (MAX_NOMINAL_ANGLE, "π rad (180°)")
                } else {
                    (MAX_NOMINAL_LENGTH, "1e6 (model units)")
                };
                if x > max {
                    return Err(format!(
                        "`{key}={v}`: the nominal error size must be at most {unit}"
                    ));
                }
                Ok(x)
            };
            match key {
                "linear" => out.linear = number(value, false)?,
                "angular" => out.angular = number(value, true)?,
                "squareness" => squareness = Some(number(value, true)?),
                other => {
                    return Err(format!(
                        "unknown error kind `{other}` (expected linear, angular or squareness)"
                    ))
                }
            }
        }
        if !any {
            return Err("no value given (expected e.g. linear=0.001,angular=0.001deg)".into());
        }
        out.squareness = squareness.unwrap_or(out.angular);
        Ok(out)
    }
}

/// The largest `|b_k(q)|` of error `j`'s basis function along its axis; 1
/// for a constant error parameter.
///
/// Legendre and Chebyshev polynomials are bounded by 1 on their `range`, and
/// `cos kq`, `sin kq` by 1 everywhere. A power `q^k` (`k ≥ 1`) is bounded by
/// the largest `|q|^k` over the machine's reliability grid of that variable;
/// without such a grid the extent is taken as 1 (the size is then per unit
/// of `q^k`).
pub fn coefficient_extent(machine: &Machine, j: usize) -> f64 {
    let Some((f, b)) = machine.coefficient_of(j) else {
        return 1.0;
    };
    if !matches!(b, BasisFn::Power(_)) {
        return 1.0;
    }
    let grid = machine
        .reliability
        .as_ref()
        .and_then(|r| r.grid.iter().find(|(v, _)| *v == f.variable));
    let extent = grid.map_or(0.0, |(_, values)| {
        values
            .iter()
            .map(|q| b.value(q.abs()).abs())
            .fold(0.0, f64::max)
    });
    if extent > 0.0 && extent.is_finite() {
        extent
    } else {
        1.0
    }
}

/// One error's sensitivity in one direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coefficient {
    /// Error parameter name.
    pub error: String,
    /// Index in the model's error order.
    pub index: usize,
    /// `S_uv = |∂E_u/∂e_v|` (at a point) or its mean over the points.
    pub s: f64,
    /// The nominal size `e_v`.
    pub e: f64,
    /// `C_uv = S_uv·e_v / Σ_w S_uw·e_w` (at a point) or its mean over the points.
    pub c: f64,
    /// Smallest `C_uv` over the points (equal to `c` at one point).
    pub c_min: f64,
    /// Largest `C_uv` over the points (equal to `c` at one point).
    pub c_max: f64,
}

/// The ranked coefficients of one direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentSensitivity {
    /// The direction.
    pub component: Component,
    /// `Σ_v S_uv·e_v`: the worst-case first-order error of this direction
    /// with every error at its nominal size (mean over the points).
    pub total: f64,
    /// Every error of the model, sorted by `c`, largest first (ties in the
    /// model's error order).
    pub ranked: Vec<Coefficient>,
}

impl ComponentSensitivity {
    /// The entry of one error, if the model has it.
    pub fn get(&self, error: &str) -> Option<&Coefficient> {
        self.ranked.iter().find(|c| c.error == error)
    }
}

/// The coefficients of all six directions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GeometricSensitivity {
    /// Number of points averaged (1 for a single point).
    pub points: usize,
    /// `px, py, pz, ox, oy, oz`.
    pub components: Vec<ComponentSensitivity>,
}

impl GeometricSensitivity {
    /// The entry of one direction.
    pub fn component(&self, c: Component) -> &ComponentSensitivity {
        &self.components[c.index()]
    }
}

/// Accumulates `S` and `C` over points.
struct Accumulator {
    n_errors: usize,
    points: usize,
    s: Vec<f64>,
    c: Vec<f64>,
    c_min: Vec<f64>,
    c_max: Vec<f64>,
    total: [f64; 6],
    buf: Vec<f64>,
}

impl Accumulator {
    fn new(n_errors: usize) -> Accumulator {
        Accumulator {
            n_errors,
            points: 0,
            s: vec![0.0; 6 * n_errors],
            c: vec![0.0; 6 * n_errors],
            c_min: vec![f64::INFINITY; 6 * n_errors],
            c_max: vec![f64::NEG_INFINITY; 6 * n_errors],
            total: [0.0; 6],
            buf: vec![0.0; 6 * n_errors],
        }
    }

    fn add<M: ErrorModel + ?Sized>(&mut self, model: &M, q: &[f64], p: &[f64], sizes: &[f64]) {
        let n = self.n_errors;
        model.sensitivity(q, p, &mut self.buf);
        for u in 0..6 {
            let row = &self.buf[u * n..(u + 1) * n];
            let total: f64 = row.iter().zip(sizes).map(|(s, e)| s.abs() * e).sum();
            self.total[u] += total;
            for (v, (s, e)) in row.iter().zip(sizes).enumerate() {
                let k = u * n + v;
                let s = s.abs();
                let c = if total > 0.0 { s * e / total } else { 0.0 };
                self.s[k] += s;
                self.c[k] += c;
                self.c_min[k] = self.c_min[k].min(c);
                self.c_max[k] = self.c_max[k].max(c);
            }
        }
        self.points += 1;
    }

    fn finish<M: ErrorModel + ?Sized>(self, model: &M, sizes: &[f64]) -> GeometricSensitivity {
        let n = self.n_errors;
        let count = self.points.max(1) as f64;
        let names = model.errors();
        let components = Component::ALL
            .iter()
            .map(|&component| {
                let u = component.index();
                let mut ranked: Vec<Coefficient> = (0..n)
                    .map(|v| {
                        let k = u * n + v;
                        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
                        Coefficient {
                            error: names[v].to_string(),
                            index: v,
                            s: self.s[k] / count,
                            e: sizes[v],
                            c: self.c[k] / count,
                            c_min: finite(self.c_min[k]),
                            c_max: finite(self.c_max[k]),
                        }
                    })
                    .collect();
                ranked.sort_by(|a, b| b.c.total_cmp(&a.c).then(a.index.cmp(&b.index)));
                ComponentSensitivity {
                    component,
                    total: self.total[u] / count,
                    ranked,
                }
            })
            .collect();
        GeometricSensitivity {
            points: self.points,
            components,
        }
    }
}

/// `S` and `C` of every direction at axis values `q` and parameter values
/// `p`, with nominal error sizes `sizes` (in the model's error order, e.g.
/// [`NominalSizes::of`]).
///
/// # Panics
///
/// If `sizes` does not have one entry per error of the model.
pub fn at_point<M: ErrorModel + ?Sized>(
    model: &M,
    q: &[f64],
    p: &[f64],
    sizes: &[f64],
) -> GeometricSensitivity {
    mean_over(model, std::iter::once(q.to_vec()), p, sizes)
}

/// The mean of `S` and of `C` over a set of points (each `C` is normalised
/// at its own point, then averaged), with the range of `C` over them.
///
/// # Panics
///
/// If `sizes` does not have one entry per error of the model.
pub fn mean_over<M: ErrorModel + ?Sized>(
    model: &M,
    points: impl IntoIterator<Item = Vec<f64>>,
    p: &[f64],
    sizes: &[f64],
) -> GeometricSensitivity {
    let n = model.errors().len();
    assert_eq!(sizes.len(), n, "one nominal size per error");
    let mut acc = Accumulator::new(n);
    for q in points {
        acc.add(model, &q, p, sizes);
    }
    acc.finish(model, sizes)
}

/// Every point of a full-factorial grid, `axes[i]` being the values of axis
/// variable `i` (in the model's variable order), the last axis fastest.
pub fn grid_points(axes: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::with_capacity(axes.len())];
    for values in axes {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                values.iter().map(move |&x| {
                    let mut p = prefix.clone();
                    p.push(x);
                    p
                })
            })
            .collect();
    }
    out
}

// ---------------------------------------------------------------------------
// The document of `chain sensitivity --kind geometric`, shared by the CLI and
// the Python package.

/// Where geometric coefficients were evaluated.
#[derive(Debug, Clone, PartialEq)]
pub enum Where {
    /// One point, `(variable, value)` in the model's variable order.
    At(Vec<(String, f64)>),
    /// The mean over a grid, `(variable, values)` in the model's variable order.
    Grid(Vec<(String, Vec<f64>)>),
}

/// The coefficients at `where_`: at its point, or the mean over its grid.
pub fn evaluate<M: ErrorModel + ?Sized>(
    model: &M,
    where_: &Where,
    parameters: &[f64],
    sizes: &[f64],
) -> GeometricSensitivity {
    match where_ {
        Where::At(at) => {
            let point: Vec<f64> = at.iter().map(|(_, x)| *x).collect();
            at_point(model, &point, parameters, sizes)
        }
        Where::Grid(axes) => {
            let values: Vec<Vec<f64>> = axes.iter().map(|(_, x)| x.clone()).collect();
            mean_over(model, grid_points(&values), parameters, sizes)
        }
    }
}

/// The document of `chain sensitivity --kind geometric` (its JSON).
#[derive(Debug, Serialize)]
pub struct GeometricDocument<'a> {
    /// The machine's name.
    pub machine: &'a str,
    /// Always `"geometric"`.
    pub kind: &'static str,
    /// The point, or `null` for the grid mean.
    pub at: Option<NameMap<&'a str, f64>>,
    /// The grid of the mean (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<NameMap<&'a str, &'a [f64]>>,
    /// The number of grid points (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<usize>,
    /// How `c` is normalised.
    pub normalisation: &'static str,
    /// The nominal error sizes.
    pub values: &'a NominalSizes,
    /// `Σ S·e` per direction.
    pub totals: NameMap<Component, f64>,
    /// Each direction's coefficients, ranked.
    pub components: NameMap<Component, Vec<CoefficientDocument<'a>>>,
    /// Where the coefficients were evaluated (for tables).
    #[serde(skip)]
    pub where_: &'a Where,
    /// The coefficients the document was built from (for tables).
    #[serde(skip)]
    pub result: &'a GeometricSensitivity,
}

/// One coefficient of a [`GeometricDocument`]; the grid mean also has the range.
#[derive(Debug, Serialize)]
pub struct CoefficientDocument<'a> {
    /// The error parameter.
    pub error: &'a str,
    /// `S = |∂E/∂e|` (or its mean).
    pub s: f64,
    /// `C = S·e / Σ S·e` (or its mean).
    pub c: f64,
    /// The nominal size `e`.
    pub e: f64,
    /// Smallest `C` over the grid (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c_min: Option<f64>,
    /// Largest `C` over the grid (grid mean only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c_max: Option<f64>,
}

impl<'a> GeometricDocument<'a> {
    /// The document of the coefficients `r` evaluated at `where_` with the
    /// nominal sizes `nominal`.
    pub fn new(
        machine: &'a str,
        where_: &'a Where,
        nominal: &'a NominalSizes,
        r: &'a GeometricSensitivity,
    ) -> GeometricDocument<'a> {
        let grid = matches!(where_, Where::Grid(_));
        let coefficient = |e: &'a Coefficient| CoefficientDocument {
            error: &e.error,
            s: e.s,
            c: e.c,
            e: e.e,
            c_min: grid.then_some(e.c_min),
            c_max: grid.then_some(e.c_max),
        };
        GeometricDocument {
            machine,
            kind: "geometric",
            at: match where_ {
                Where::At(a) => Some(a.iter().map(|(n, v)| (n.as_str(), *v)).collect()),
                Where::Grid(_) => None,
            },
            grid: match where_ {
                Where::Grid(g) => Some(g.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect()),
                Where::At(_) => None,
            },
            points: grid.then_some(r.points),
            normalisation: "c = s*e / sum(s*e)",
            values: nominal,
            totals: r
                .components
                .iter()
                .map(|c| (c.component, c.total))
                .collect(),
            components: r
                .components
                .iter()
                .map(|c| (c.component, c.ranked.iter().map(coefficient).collect()))
                .collect(),
            where_,
            result: r,
        }
    }
}
