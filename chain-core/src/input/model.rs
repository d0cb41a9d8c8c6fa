//! The validated machine model.
//!
//! A [`Machine`] is what the loader (YAML, [`crate::load`]) and the `machine!`
//! macro both produce, and what the derivation ([`crate::derive()`]) consumes. By
//! the time a `Machine` exists every rule of the machine-file contract has been
//! checked: names resolve, the body graph is a tree with one root, every
//! variable drives exactly one joint, every parameter an expression uses is
//! declared. Every node keeps an [`Origin`] pointing back at the user's text so
//! that later stages can still report located errors.

use serde::Serialize;

/// Where a node of the model came from: a byte span in the source text plus the
/// key path (`bodies.x_slide.joint.axis`) that reaches it.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Origin {
    /// Byte offset of the first byte in the source text.
    pub offset: usize,
    /// Length in bytes (0 for a point location).
    pub len: usize,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (in characters).
    pub column: usize,
    /// Dotted key path, e.g. `bodies.x_slide.joint.axis`.
    pub key: String,
}

/// A coordinate axis of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// The x axis.
    X,
    /// The y axis.
    Y,
    /// The z axis.
    Z,
}

impl Axis {
    /// 0 for x, 1 for y, 2 for z.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }
}

/// A signed coordinate axis, as in `+x` or `-z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SignedAxis {
    /// Which axis.
    pub axis: Axis,
    /// `false` for `+`, `true` for `-`.
    pub negative: bool,
}

impl SignedAxis {
    /// `+1.0` or `-1.0`.
    pub fn sign(self) -> f64 {
        if self.negative {
            -1.0
        } else {
            1.0
        }
    }
}

impl std::fmt::Display for SignedAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{}",
            if self.negative { "-" } else { "+" },
            self.axis.name()
        )
    }
}

/// An arithmetic expression over numbers and parameters, as written in an
/// offset, a tool point or a statistics entry.
///
/// Names are resolved at load time: [`Expr::Param`] holds the index into
/// [`Machine::parameters`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Expr {
    /// A literal number.
    Num(f64),
    /// A parameter, by index into [`Machine::parameters`].
    Param(usize),
    /// Unary minus.
    Neg(Box<Expr>),
    /// Sum.
    Add(Box<Expr>, Box<Expr>),
    /// Difference.
    Sub(Box<Expr>, Box<Expr>),
    /// Product.
    Mul(Box<Expr>, Box<Expr>),
    /// Quotient. The divisor must not contain parameters (checked at load).
    Div(Box<Expr>, Box<Expr>),
    /// Integer power.
    Pow(Box<Expr>, i32),
}

impl Expr {
    /// Evaluates with the given parameter values (indexed like
    /// [`Machine::parameters`]).
    pub fn eval(&self, params: &[f64]) -> f64 {
        match self {
            Expr::Num(v) => *v,
            Expr::Param(i) => params[*i],
            Expr::Neg(a) => -a.eval(params),
            Expr::Add(a, b) => a.eval(params) + b.eval(params),
            Expr::Sub(a, b) => a.eval(params) - b.eval(params),
            Expr::Mul(a, b) => a.eval(params) * b.eval(params),
            Expr::Div(a, b) => a.eval(params) / b.eval(params),
            Expr::Pow(a, n) => a.eval(params).powi(*n),
        }
    }

    /// True if the expression is the literal zero.
    pub fn is_zero(&self) -> bool {
        matches!(self, Expr::Num(v) if *v == 0.0)
    }
}

/// A named parameter of the machine (a structural length, say).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Parameter {
    /// The name used in expressions.
    pub name: String,
    /// Its value, or `None` when it is symbolic and supplied at run time.
    pub value: Option<f64>,
    /// Where it was declared.
    pub origin: Origin,
}

/// The kind of joint that moves a body relative to its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Translation by `±q` along the axis.
    Prismatic,
    /// Rotation by `±q` (right-hand rule) about the axis.
    Rotary,
}

/// An axis variable (the command of one joint).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Variable {
    /// The variable's name (`x`, `A`, ...).
    pub name: String,
    /// The kind of the joint it drives.
    pub kind: JointKind,
    /// Index of the body whose joint it drives.
    pub body: usize,
    /// Where it was declared.
    pub origin: Origin,
}

/// A joint: kind, signed axis and the variable that drives it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Joint {
    /// Prismatic or rotary.
    pub kind: JointKind,
    /// Signed axis in the body frame.
    pub axis: SignedAxis,
    /// Index into [`Machine::variables`].
    pub variable: usize,
    /// Where it was declared.
    pub origin: Origin,
}

/// A fixed elementary rotation of a body frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FixedRotation {
    /// About which axis.
    pub about: Axis,
    /// Angle in radians.
    pub angle: f64,
    /// Where it was declared.
    pub origin: Origin,
}

/// The six slots of a small-error transform `E(dx, dy, dz, ex, ey, ez)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Slot {
    /// Translation error along x.
    Dx,
    /// Translation error along y.
    Dy,
    /// Translation error along z.
    Dz,
    /// Rotation error about x.
    Ex,
    /// Rotation error about y.
    Ey,
    /// Rotation error about z.
    Ez,
}

impl Slot {
    /// All six slots in `dx, dy, dz, ex, ey, ez` order.
    pub const ALL: [Slot; 6] = [Slot::Dx, Slot::Dy, Slot::Dz, Slot::Ex, Slot::Ey, Slot::Ez];

    /// Position in `dx, dy, dz, ex, ey, ez` order.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The slot's key in a machine file.
    pub fn name(self) -> &'static str {
        ["dx", "dy", "dz", "ex", "ey", "ez"][self.index()]
    }

    /// True for `dx, dy, dz`.
    pub fn is_linear(self) -> bool {
        self.index() < 3
    }
}

/// The error parameters assigned to the six slots of one small-error transform.
/// A slot may hold several names (a motion error plus a squareness term); the
/// slot's value is their sum.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ErrorSlots {
    /// Error indices (into [`Machine::errors`]) per slot, in `dx..ez` order.
    pub slots: [Vec<usize>; 6],
}

impl ErrorSlots {
    /// True if no slot holds an error.
    pub fn is_empty(&self) -> bool {
        self.slots.iter().all(Vec::is_empty)
    }
}

/// What kind of quantity an error parameter is; sets its units (mm or rad) and
/// how tolerances convert to standard deviations in allocation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorKind {
    /// A translation (`dx, dy, dz` slots): a length.
    Linear,
    /// A rotation (`ex, ey, ez` slots of `errors` or `location_errors`): an angle.
    Angular,
    /// A squareness term (`squareness` map): an angle.
    Squareness,
}

/// One error parameter (one random variable), however many places use it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorParam {
    /// Its name.
    pub name: String,
    /// Linear, angular or squareness.
    pub kind: ErrorKind,
    /// Where it was first used.
    pub origin: Origin,
    /// A thermal coefficient's sensor (index into [`Machine::sensors`]):
    /// the parameter is per kelvin of that sensor's deviation from its
    /// reference, its effect multiplied by `ΔT = T − reference`
    /// (`docs/thermal.md`, "Temperature in the machine model"). `None` for
    /// every geometric error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor: Option<usize>,
}

/// A named condition of the machine (`sensors:` in the machine file): a
/// temperature, in °C, whose deviation from its reference drives the
/// thermal coefficients (`docs/thermal.md`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensor {
    /// Its name (`T_spindle`).
    pub name: String,
    /// The temperature at which the geometric errors hold and every
    /// thermal term is zero (°C; 20 °C, ISO 1, unless declared).
    pub reference: f64,
    /// Where it was declared.
    pub origin: Origin,
}

/// The reference temperature of a sensor declared without one: 20 °C, the
/// standard reference temperature of geometrical product specification
/// (ISO 1).
pub const REFERENCE_TEMPERATURE: f64 = 20.0;

/// The basis of a function slot (measured-machines spec, section 1): how an
/// error motion `F(q)` of a jointed body varies along its own joint variable
/// `q` (the variable's value, before the axis sign).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "basis", rename_all = "lowercase")]
pub enum Basis {
    /// `F(q) = Σ_{k ∈ powers} F_k · q^k`.
    Powers {
        /// The exponents, as written (distinct, non-negative).
        powers: Vec<u32>,
    },
    /// `F(q) = Σ_{k=from..degree} F_k · P_k(t)`, `t = (2q − lo − hi)/(hi − lo)`.
    Legendre {
        /// Highest degree.
        degree: u32,
        /// `[lo, hi]`, `lo < hi`.
        range: [f64; 2],
        /// Lowest degree (default 0).
        from: u32,
    },
    /// `F(q) = Σ_{k=from..degree} F_k · T_k(t)`, `t` as for Legendre.
    Chebyshev {
        /// Highest degree.
        degree: u32,
        /// `[lo, hi]`, `lo < hi`.
        range: [f64; 2],
        /// Lowest degree (default 0).
        from: u32,
    },
    /// `F(q) = F_0 + Σ_{k=1..harmonics} (F_c<k>·cos kq + F_s<k>·sin kq)`
    /// (rotary joints only).
    Fourier {
        /// Number of harmonics.
        harmonics: u32,
    },
}

impl Basis {
    /// The basis functions in coefficient order: powers in the order
    /// written; `from..=degree`; Fourier `1, cos q, sin q, cos 2q, ...`.
    pub fn terms(&self) -> Vec<BasisFn> {
        match self {
            Basis::Powers { powers } => powers.iter().map(|&k| BasisFn::Power(k)).collect(),
            Basis::Legendre {
                degree,
                range,
                from,
            } => (*from..=*degree)
                .map(|k| BasisFn::Legendre { k, range: *range })
                .collect(),
            Basis::Chebyshev {
                degree,
                range,
                from,
            } => (*from..=*degree)
                .map(|k| BasisFn::Chebyshev { k, range: *range })
                .collect(),
            Basis::Fourier { harmonics } => std::iter::once(BasisFn::Cos(0))
                .chain((1..=*harmonics).flat_map(|k| [BasisFn::Cos(k), BasisFn::Sin(k)]))
                .collect(),
        }
    }

    /// `powers`, `legendre`, `chebyshev` or `fourier`.
    pub fn name(&self) -> &'static str {
        match self {
            Basis::Powers { .. } => "powers",
            Basis::Legendre { .. } => "legendre",
            Basis::Chebyshev { .. } => "chebyshev",
            Basis::Fourier { .. } => "fourier",
        }
    }
}

/// One basis function `b_k(q)` of a function slot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum BasisFn {
    /// `q^k`.
    Power(u32),
    /// The Legendre polynomial `P_k(t)`, `t = (2q − lo − hi)/(hi − lo)`.
    Legendre {
        /// Degree.
        k: u32,
        /// `[lo, hi]`.
        range: [f64; 2],
    },
    /// The Chebyshev polynomial of the first kind `T_k(t)`, `t` as above.
    Chebyshev {
        /// Degree.
        k: u32,
        /// `[lo, hi]`.
        range: [f64; 2],
    },
    /// `cos kq` (`k = 0`: the constant 1).
    Cos(u32),
    /// `sin kq`, `k ≥ 1`.
    Sin(u32),
}

impl BasisFn {
    /// `b(q)`. Legendre by Bonnet's recurrence `(n+1)P_{n+1} = (2n+1)tP_n − nP_{n−1}`,
    /// Chebyshev by `T_{n+1} = 2tT_n − T_{n−1}`, Fourier by `cos`/`sin` of `kq`.
    pub fn value(&self, q: f64) -> f64 {
        match *self {
            BasisFn::Power(k) => q.powi(i32::try_from(k).unwrap_or(i32::MAX)),
            BasisFn::Legendre { k, range } => {
                let t = Self::scaled(q, range);
                let (mut p0, mut p1) = (1.0, t);
                if k == 0 {
                    return 1.0;
                }
                for n in 1..k {
                    let n = f64::from(n);
                    let p2 = ((2.0 * n + 1.0) * t * p1 - n * p0) / (n + 1.0);
                    p0 = p1;
                    p1 = p2;
                }
                p1
            }
            BasisFn::Chebyshev { k, range } => {
                let t = Self::scaled(q, range);
                let (mut t0, mut t1) = (1.0, t);
                if k == 0 {
                    return 1.0;
                }
                for _ in 1..k {
                    let t2 = 2.0 * t * t1 - t0;
                    t0 = t1;
                    t1 = t2;
                }
                t1
            }
            BasisFn::Cos(k) => (f64::from(k) * q).cos(),
            BasisFn::Sin(k) => (f64::from(k) * q).sin(),
        }
    }

    /// `t = (2q − lo − hi)/(hi − lo)`, the spec's map of `[lo, hi]` onto `[−1, 1]`.
    pub fn scaled(q: f64, range: [f64; 2]) -> f64 {
        let [lo, hi] = range;
        (2.0 * q - lo - hi) / (hi - lo)
    }

    /// The coefficient's name suffix: `k` (powers, Legendre, Chebyshev),
    /// `0`, `c<k>`, `s<k>` (Fourier).
    pub fn suffix(&self) -> String {
        match *self {
            BasisFn::Power(k) | BasisFn::Legendre { k, .. } | BasisFn::Chebyshev { k, .. } => {
                k.to_string()
            }
            BasisFn::Cos(0) => "0".to_string(),
            BasisFn::Cos(k) => format!("c{k}"),
            BasisFn::Sin(k) => format!("s{k}"),
        }
    }

    /// True if `b(q) ≡ 1` (`q^0`, `P_0`, `T_0`, the Fourier constant).
    pub fn is_constant(&self) -> bool {
        matches!(
            *self,
            BasisFn::Power(0)
                | BasisFn::Legendre { k: 0, .. }
                | BasisFn::Chebyshev { k: 0, .. }
                | BasisFn::Cos(0)
        )
    }
}

/// A function slot: an error motion `F(q) = Σ_k F_k b_k(q)` of a jointed
/// body, whose coefficients `F_k` are ordinary error parameters named
/// `<name>_<suffix>` (measured-machines spec, section 1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorFunction {
    /// The function's name (`EYX`); not itself an error parameter.
    pub name: String,
    /// Its basis.
    pub basis: Basis,
    /// Index into [`Machine::variables`] of the joint variable `q`.
    pub variable: usize,
    /// `(error index, basis function)` per coefficient, in [`Basis::terms`]
    /// order; a thermal function (`per:`) repeats the terms once per sensor,
    /// sensor by sensor (each coefficient's [`ErrorParam::sensor`]).
    pub coefficients: Vec<(usize, BasisFn)>,
    /// A thermal function's sensors (indices into [`Machine::sensors`]),
    /// in the order of its `per:`; empty for a geometric function.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<usize>,
    /// Where it was first declared.
    pub origin: Origin,
}

/// A body of the machine: a rigid frame placed in its parent's frame by
/// `Trans(offset) * Rot(rotation) * E(location_errors) * J(q) * E(errors + squareness)`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Body {
    /// The body's name.
    pub name: String,
    /// Index of the parent body; `None` for the root.
    pub parent: Option<usize>,
    /// Offset of the body frame in the parent frame.
    pub offset: [Expr; 3],
    /// Fixed rotations, applied in order.
    pub rotation: Vec<FixedRotation>,
    /// Position-independent (location) errors, applied before the joint.
    pub location_errors: ErrorSlots,
    /// The joint, if the body moves.
    pub joint: Option<Joint>,
    /// Motion errors and squareness terms, applied after the joint.
    pub errors: ErrorSlots,
    /// Where the body was declared.
    pub origin: Origin,
}

/// Which frame the derived `p` and `o` are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Frame {
    /// The workpiece frame (the default).
    #[default]
    Workpiece,
    /// The tool frame: `R_wt(q,0)^T p`, `R_wt(q,0)^T o`.
    Tool,
}

impl Frame {
    /// `workpiece` or `tool`.
    pub fn name(self) -> &'static str {
        match self {
            Frame::Workpiece => "workpiece",
            Frame::Tool => "tool",
        }
    }
}

/// The input distribution of one error parameter (`machine-format.md`
/// v1 and `reliability-v2.md` §1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "dist", rename_all = "snake_case")]
pub enum Distribution {
    /// Normal with mean and standard deviation (`std > 0`).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
    },
    /// Uniform on `[min, max]` (`min < max`).
    Uniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Lognormal: `ln(x − shift)` is normal; `mean > shift` and `std > 0`
    /// are the moments of `x` itself.
    Lognormal {
        /// Mean of the variable.
        mean: f64,
        /// Standard deviation of the variable.
        std: f64,
        /// The lower end of the support (0 unless given).
        shift: f64,
    },
    /// A normal with mean `mean` and standard deviation `std` (of the parent)
    /// truncated to `[min, max]` (either bound may be absent, not both).
    TruncatedNormal {
        /// Mean of the parent normal.
        mean: f64,
        /// Standard deviation of the parent normal.
        std: f64,
        /// Lower bound, if any.
        min: Option<f64>,
        /// Upper bound, if any.
        max: Option<f64>,
    },
    /// Weibull: `F(x) = 1 − exp(−((x − shift)/scale)^shape)`.
    Weibull {
        /// Scale `λ > 0`.
        scale: f64,
        /// Shape `k > 0`.
        shape: f64,
        /// The lower end of the support (0 unless given).
        shift: f64,
    },
    /// Gumbel (maximum type): `F(x) = exp(−exp(−(x − mode)/scale))`.
    Gumbel {
        /// The mode (location).
        mode: f64,
        /// Scale `> 0`.
        scale: f64,
    },
    /// Triangular on `[min, max]` with its mode in `[min, max]`.
    Triangular {
        /// Lower bound.
        min: f64,
        /// The mode.
        mode: f64,
        /// Upper bound.
        max: f64,
    },
    /// Rayleigh: `F(x) = 1 − exp(−(x − shift)²/(2·scale²))`, the size of a
    /// radial error.
    Rayleigh {
        /// Scale `σ > 0`.
        scale: f64,
        /// The lower end of the support (0 unless given).
        shift: f64,
    },
}

/// Euler–Mascheroni constant `γ`.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

impl Distribution {
    /// The family's name as written in the file (`normal`, `truncated_normal`, …).
    pub fn name(&self) -> &'static str {
        match self {
            Distribution::Normal { .. } => "normal",
            Distribution::Uniform { .. } => "uniform",
            Distribution::Lognormal { .. } => "lognormal",
            Distribution::TruncatedNormal { .. } => "truncated_normal",
            Distribution::Weibull { .. } => "weibull",
            Distribution::Gumbel { .. } => "gumbel",
            Distribution::Triangular { .. } => "triangular",
            Distribution::Rayleigh { .. } => "rayleigh",
        }
    }

    /// The mean of the variable.
    pub fn mean(&self) -> f64 {
        match *self {
            Distribution::Normal { mean, .. } => mean,
            Distribution::Uniform { min, max } => 0.5 * (min + max),
            Distribution::Lognormal { mean, .. } => mean,
            Distribution::TruncatedNormal {
                mean,
                std,
                min,
                max,
            } => {
                let (m1, _) = truncated_moments(mean, std, min, max);
                mean + std * m1
            }
            Distribution::Weibull {
                scale,
                shape,
                shift,
            } => shift + scale * libm::tgamma(1.0 + 1.0 / shape),
            Distribution::Gumbel { mode, scale } => mode + EULER_GAMMA * scale,
            Distribution::Triangular { min, mode, max } => (min + mode + max) / 3.0,
            Distribution::Rayleigh { scale, shift } => {
                shift + scale * (0.5 * std::f64::consts::PI).sqrt()
            }
        }
    }

    /// The standard deviation of the variable.
    pub fn std(&self) -> f64 {
        match *self {
            Distribution::Normal { std, .. } => std,
            Distribution::Uniform { min, max } => (max - min) / 12f64.sqrt(),
            Distribution::Lognormal { std, .. } => std,
            Distribution::TruncatedNormal {
                mean,
                std,
                min,
                max,
            } => {
                let (m1, m2) = truncated_moments(mean, std, min, max);
                std * (m2 - m1 * m1).max(0.0).sqrt()
            }
            Distribution::Weibull { scale, shape, .. } => {
                let g1 = libm::tgamma(1.0 + 1.0 / shape);
                let g2 = libm::tgamma(1.0 + 2.0 / shape);
                scale * (g2 - g1 * g1).max(0.0).sqrt()
            }
            Distribution::Gumbel { scale, .. } => scale * std::f64::consts::PI / 6f64.sqrt(),
            Distribution::Triangular { min, mode, max } => {
                let (a, c, b) = (min, mode, max);
                ((a * a + b * b + c * c - a * b - a * c - b * c) / 18.0).sqrt()
            }
            Distribution::Rayleigh { scale, .. } => {
                scale * (0.5 * (4.0 - std::f64::consts::PI)).sqrt()
            }
        }
    }
}

/// `(E Z, E Z²)` of the standard normal truncated to `[(min − μ)/σ, (max − μ)/σ]`
/// (Johnson, Kotz & Balakrishnan, *Continuous Univariate Distributions* 1,
/// §10.1, Eq. 13.134-13.135).
fn truncated_moments(mean: f64, std: f64, min: Option<f64>, max: Option<f64>) -> (f64, f64) {
    let pdf = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let cdf = |z: f64| 0.5 * libm::erfc(-z / std::f64::consts::SQRT_2);
    let a = min.map_or(f64::NEG_INFINITY, |v| (v - mean) / std);
    let b = max.map_or(f64::INFINITY, |v| (v - mean) / std);
    // The mass, on the side of zero where it does not cancel.
    let z = if a >= 0.0 {
        cdf(-a) - cdf(-b)
    } else {
        cdf(b) - cdf(a)
    };
    let (pa, pb) = (pdf(a), pdf(b));
    let apa = if a.is_finite() { a * pa } else { 0.0 };
    let bpb = if b.is_finite() { b * pb } else { 0.0 };
    let m1 = (pa - pb) / z;
    (m1, 1.0 + (apa - bpb) / z)
}

/// The statistics entry of one error parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Statistic {
    /// Index into [`Machine::errors`].
    pub error: usize,
    /// Its distribution.
    pub distribution: Distribution,
    /// Weight in the allocation cost (default 1).
    pub cost_weight: f64,
    /// Allocation never makes the standard deviation smaller than this.
    pub min_std: Option<f64>,
    /// Where the entry was declared.
    pub origin: Origin,
}

/// One of the six error components `px, py, pz, ox, oy, oz`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Component {
    /// Position error along x.
    Px,
    /// Position error along y.
    Py,
    /// Position error along z.
    Pz,
    /// Orientation error about x.
    Ox,
    /// Orientation error about y.
    Oy,
    /// Orientation error about z.
    Oz,
}

impl Component {
    /// All six in `px, py, pz, ox, oy, oz` order.
    pub const ALL: [Component; 6] = [
        Component::Px,
        Component::Py,
        Component::Pz,
        Component::Ox,
        Component::Oy,
        Component::Oz,
    ];

    /// Position in `px..oz` order.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The names of [`Component::ALL`], in order.
    pub const NAMES: [&'static str; 6] = ["px", "py", "pz", "ox", "oy", "oz"];

    /// `px`, `py`, ...
    pub fn name(self) -> &'static str {
        Component::NAMES[self.index()]
    }

    /// Parses `px`, `py`, ...
    pub fn from_name(name: &str) -> Option<Component> {
        Component::ALL.into_iter().find(|c| c.name() == name)
    }
}

/// How a tolerance bounds a component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sided {
    /// `g = I - E` (the 2021 paper).
    #[default]
    Upper,
    /// `|E| <= I`.
    Two,
}

impl Sided {
    /// `upper` or `two` (the machine file's spelling).
    pub fn name(self) -> &'static str {
        match self {
            Sided::Upper => "upper",
            Sided::Two => "two",
        }
    }
}

/// The `reliability` section of a machine file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReliabilitySpec {
    /// Allowable error per component (only the listed components are assessed).
    pub tolerance: Vec<(Component, f64)>,
    /// One- or two-sided limit state.
    pub sided: Sided,
    /// Grid values per axis variable (index into [`Machine::variables`]).
    pub grid: Vec<(usize, Vec<f64>)>,
    /// Required minimum and mean reliability over the grid.
    pub requirement: Option<Requirement>,
    /// `acceptance: true`: also report the whole-machine acceptance
    /// probability (reliability-v2 §4).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub acceptance: bool,
    /// Where the section was declared.
    pub origin: Origin,
}

/// A reliability requirement over a grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Requirement {
    /// Minimum reliability over the grid.
    pub min: f64,
    /// Mean reliability over the grid.
    pub mean: f64,
}

/// A validated machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Machine {
    /// Identifier (`machine:` key).
    pub name: String,
    /// Free text.
    pub description: Option<String>,
    /// The file it was loaded from (for diagnostics), if any.
    pub file: Option<String>,
    /// Parameters in declaration order.
    pub parameters: Vec<Parameter>,
    /// Axis variables in body (tree pre-order) order.
    pub variables: Vec<Variable>,
    /// Error parameters in order of first use along the bodies (a function
    /// slot's coefficients among them).
    pub errors: Vec<ErrorParam>,
    /// Function slots (error motions varying along their axis), in order of
    /// first declaration.
    pub functions: Vec<ErrorFunction>,
    /// Bodies, parents before children; index 0 is the root.
    pub bodies: Vec<Body>,
    /// Index of the workpiece body.
    pub workpiece: usize,
    /// Index of the tool body.
    pub tool: usize,
    /// Tool point in the tool frame.
    pub tool_point: [Expr; 3],
    /// Frame of the derived `p`, `o`.
    pub frame: Frame,
    /// Statistics entries (at most one per error), in file order.
    pub statistics: Vec<Statistic>,
    /// The reliability section, if any.
    pub reliability: Option<ReliabilitySpec>,
    /// The top-level `correlation` list (`reliability-v2.md` §2): physical
    /// correlations between errors with statistics, in file order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub correlations: Vec<CorrelationEntry>,
    /// The named conditions (temperature sensors) the thermal coefficients
    /// read, in file order (`docs/thermal.md`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<Sensor>,
    /// The `statistics` entries of sensors: the temperatures a reliability
    /// study takes as random (`docs/thermal.md`, "Random temperatures").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sensor_statistics: Vec<SensorStatistic>,
}

/// A sensor's `statistics` entry: its temperature's distribution (°C).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorStatistic {
    /// Index into [`Machine::sensors`].
    pub sensor: usize,
    /// The temperature's distribution (°C).
    pub distribution: Distribution,
    /// Where the entry was declared.
    pub origin: Origin,
}

/// One `[name, name, rho]` entry of the `correlation` list.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrelationEntry {
    /// Index into [`Machine::errors`] of the first error.
    pub a: usize,
    /// Index of the second error.
    pub b: usize,
    /// The physical (Pearson) correlation, in `(−1, 1)`.
    pub rho: f64,
    /// Where the entry was declared (its `correlation[i]` key).
    pub origin: Origin,
}

impl Machine {
    /// Index of the body with this name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Index of the error parameter with this name.
    pub fn error_index(&self, name: &str) -> Option<usize> {
        self.errors.iter().position(|e| e.name == name)
    }

    /// Index of the variable with this name.
    pub fn variable_index(&self, name: &str) -> Option<usize> {
        self.variables.iter().position(|v| v.name == name)
    }

    /// Index of the parameter with this name.
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }

    /// Index of the sensor with this name.
    pub fn sensor_index(&self, name: &str) -> Option<usize> {
        self.sensors.iter().position(|s| s.name == name)
    }

    /// Every sensor at its reference: the state at which the thermal
    /// coefficients contribute nothing.
    pub fn reference_temperatures(&self) -> Vec<f64> {
        self.sensors.iter().map(|s| s.reference).collect()
    }

    /// The thermal factor of every error parameter at `temperatures` (°C,
    /// one per sensor in [`Machine::sensors`] order): `T_s − reference_s` for
    /// a thermal coefficient of sensor `s`, 1 for every other error. The
    /// error at a thermal state is `Σ_j c_j(q) · g_j(T) · e_j`: the model's
    /// coefficients `c_j(q)` are those of the geometry, and the state acts
    /// on the values (`docs/thermal.md`).
    pub fn thermal_factors(&self, temperatures: &[f64]) -> Vec<f64> {
        self.errors
            .iter()
            .map(|e| match e.sensor {
                Some(s) => {
                    let reference = self.sensors.get(s).map_or(0.0, |x| x.reference);
                    temperatures.get(s).map_or(0.0, |t| t - reference)
                }
                None => 1.0,
            })
            .collect()
    }

    /// True if some error parameter is a thermal coefficient.
    pub fn is_thermal(&self) -> bool {
        self.errors.iter().any(|e| e.sensor.is_some())
    }

    /// The chain of body indices from the root to `body`, root first.
    pub fn path_from_root(&self, body: usize) -> Vec<usize> {
        let mut path = vec![body];
        let mut b = body;
        while let Some(p) = self.bodies[b].parent {
            path.push(p);
            b = p;
        }
        path.reverse();
        path
    }

    /// The function and basis function an error parameter is a coefficient
    /// of, if it is one (`None` for a constant error parameter).
    pub fn coefficient_of(&self, error: usize) -> Option<(&ErrorFunction, BasisFn)> {
        self.functions.iter().find_map(|f| {
            f.coefficients
                .iter()
                .find(|(j, _)| *j == error)
                .map(|(_, b)| (f, *b))
        })
    }

    /// Index of the function slot with this name.
    pub fn function_index(&self, name: &str) -> Option<usize> {
        self.functions.iter().position(|f| f.name == name)
    }

    /// The statistics entry of an error, if any.
    pub fn statistic(&self, error: usize) -> Option<&Statistic> {
        self.statistics.iter().find(|s| s.error == error)
    }
}

/// A thermal state that does not match the machine's sensors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TemperatureError {
    /// The machine declares no sensor.
    #[error("machine `{machine}` declares no sensors, so `{name}` has no temperature to set (a machine file lists them under `sensors:`)")]
    NoSensors {
        /// The machine.
        machine: String,
        /// The name given.
        name: String,
    },
    /// Not a sensor of the machine.
    #[error("`{name}` is not a sensor of machine `{machine}`{} (its sensors: {})", suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(), sensors.join(", "))]
    Unknown {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// Its sensors.
        sensors: Vec<String>,
        /// The closest sensor, if one is close.
        suggestion: Option<String>,
    },
    /// A temperature that is not a finite number of °C, or below absolute
    /// zero.
    #[error("`{name}` = {value} °C is not a temperature (a finite value above −273.15 °C)")]
    Value {
        /// The sensor.
        name: String,
        /// The value given.
        value: f64,
    },
    /// The same sensor given twice.
    #[error("`{name}` is given twice ({first} and {second} °C)")]
    Twice {
        /// The sensor.
        name: String,
        /// The first value.
        first: f64,
        /// The second value.
        second: f64,
    },
}

impl Machine {
    /// The thermal state of `given` (sensor name, °C): every sensor not
    /// named stays at its reference. Refuses a name that is not a sensor, a
    /// sensor named twice and a value that is not a temperature.
    pub fn temperatures(&self, given: &[(String, f64)]) -> Result<Vec<f64>, TemperatureError> {
        let mut t = self.reference_temperatures();
        let mut seen: Vec<(usize, f64)> = Vec::new();
        for (name, value) in given {
            if self.sensors.is_empty() {
                return Err(TemperatureError::NoSensors {
                    machine: self.name.clone(),
                    name: name.clone(),
                });
            }
            let Some(s) = self.sensor_index(name) else {
                let names = self.sensors.iter().map(|s| s.name.as_str());
                return Err(TemperatureError::Unknown {
                    name: name.clone(),
                    machine: self.name.clone(),
                    sensors: self.sensors.iter().map(|s| s.name.clone()).collect(),
                    suggestion: crate::diagnostic::closest(name, names).map(str::to_string),
                });
            };
            if !value.is_finite() || *value <= -273.15 {
                return Err(TemperatureError::Value {
                    name: name.clone(),
                    value: *value,
                });
            }
            if let Some(&(_, first)) = seen.iter().find(|(i, _)| *i == s) {
                return Err(TemperatureError::Twice {
                    name: name.clone(),
                    first,
                    second: *value,
                });
            }
            seen.push((s, *value));
            t[s] = *value;
        }
        Ok(t)
    }
}
