//! The compiled model against the independent numeric product of
//! `tests/it/common` (spec section 1, exact rigid transforms, no linearisation):
//!
//! - `sensitivity()` equals a 5-point central difference of the exact error in
//!   every error parameter (1e-6 relative, with an absolute floor of 1e-9 ×
//!   the machine's length scale, far above the difference's rounding noise of
//!   ~1e-13 × scale / h);
//! - `error(q, p, e)` equals `sensitivity(q, p) · e`;
//! - `nominal()` equals `R_wt(q, 0)` and `T_wt(q, 0) · tool_point` of the
//!   exact product;
//!
//! for the three example machines at random points of their workspaces, and
//! for random tree machines (proptest) written as YAML and loaded with
//! `load_str`.

// Matrix and component loops read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use crate::common;

use chain_core::model::Machine;
use common::{load_example, Exact, Rng};
use proptest::prelude::*;

/// Random axis values in `machine.variables` order, from per-variable ranges.
fn random_q(machine: &Machine, rng: &mut Rng, range: impl Fn(&str) -> (f64, f64)) -> Vec<f64> {
    machine
        .variables
        .iter()
        .map(|v| {
            let (lo, hi) = range(&v.name);
            rng.range(lo, hi)
        })
        .collect()
}

/// Random error values: ±0.01 for linear errors, ±1e-4 for angular ones.
fn random_e(machine: &Machine, rng: &mut Rng) -> Vec<f64> {
    machine
        .errors
        .iter()
        .map(|e| match e.kind {
            chain_core::model::ErrorKind::Linear => rng.range(-0.01, 0.01),
            _ => rng.range(-1e-4, 1e-4),
        })
        .collect()
}

fn check_example(file: &str, points: usize, range: impl Fn(&str) -> (f64, f64)) {
    let m = load_example(file);
    let model = chain_core::compile(&m);
    let ex = Exact::new(&m);
    let p = ex.file_parameters();
    assert!(
        p.iter().all(|v| v.is_finite()),
        "{file}: every parameter has a value"
    );
    let mut rng = Rng::new(0x5eed ^ file.len() as u64);
    for _ in 0..points {
        let q = random_q(&m, &mut rng, &range);
        if let Err(msg) = ex.check_sensitivity(&model, &q, &p, 1e-6, 1e-9) {
            panic!("{file}: {msg}");
        }
        let e = random_e(&m, &mut rng);
        if let Err(msg) = ex.check_error_and_nominal(&model, &q, &p, &e, 1e-10) {
            panic!("{file}: {msg}");
        }
    }
}

#[test]
fn gantry_grinder_matches_the_exact_product() {
    // Section 3.3 of seed 000: x in [0, 1000], y in [-1500, 1500], z in [600, 1400].
    check_example("gantry_grinder.yaml", 100, |v| match v {
        "x" => (0.0, 1000.0),
        "y" => (-1500.0, 1500.0),
        _ => (600.0, 1400.0),
    });
}

#[test]
fn internal_grinder_matches_the_exact_product() {
    check_example("internal_grinder.yaml", 100, |v| match v {
        "x1" => (-300.0, 100.0),
        "x2" => (-100.0, 100.0),
        _ => (-50.0, 150.0),
    });
}

#[test]
fn cnc5_bevel_matches_the_exact_product() {
    check_example("cnc5_bevel.yaml", 100, |v| match v {
        "x" | "y" | "z" => (-400.0, 400.0),
        _ => (-std::f64::consts::PI, std::f64::consts::PI),
    });
}

#[test]
fn ac_trunnion_matches_the_exact_product() {
    check_example("ac_trunnion.yaml", 100, |v| match v {
        "x" | "y" | "z" => (-400.0, 400.0),
        _ => (-std::f64::consts::PI, std::f64::consts::PI),
    });
}

#[test]
fn the_checks_can_fail() {
    // Guard against a comparison that cannot fail: the gantry's exact product
    // with ezz moved from the Z slide to the Y slide gives a different
    // sensitivity (px loses -y·ezz), and check_sensitivity must see it.
    let m = load_example("gantry_grinder.yaml");
    let model = chain_core::compile(&m);
    let mut moved = m.clone();
    let ezz = m.error_index("ezz").unwrap();
    let z = m.body_index("z_slide").unwrap();
    let y = m.body_index("y_slide").unwrap();
    moved.bodies[z].errors.slots[5].retain(|&j| j != ezz);
    moved.bodies[y].errors.slots[5].push(ezz);
    let ex = Exact::new(&moved);
    let q = moved
        .variables
        .iter()
        .map(|v| if v.name == "y" { 700.0 } else { 100.0 })
        .collect::<Vec<_>>();
    let err = ex
        .check_sensitivity(&model, &q, &[], 1e-6, 1e-9)
        .expect_err("a moved error must be detected");
    assert!(err.contains("dpx/dezz"), "{err}");
}

// ---------------------------------------------------------------------------
// Random tree machines
// ---------------------------------------------------------------------------

/// Parameter names of the random machines; `ld` is declared `null` (symbolic)
/// and supplied at run time.
const PARAMS: [&str; 4] = ["la", "lb", "lc", "ld"];

/// An offset or tool-point expression.
#[derive(Debug, Clone)]
enum GenExpr {
    Num(f64),
    Param(usize),
    Scaled(i32, usize),
    Sum(usize, usize),
    Diff(usize, usize),
    Prod(usize, usize),
    Neg(usize),
    Div(usize, i32),
}

impl GenExpr {
    fn render(&self) -> String {
        match *self {
            GenExpr::Num(v) => format!("{v}"),
            GenExpr::Param(a) => PARAMS[a].to_string(),
            GenExpr::Scaled(c, a) => format!("{c}*{}", PARAMS[a]),
            GenExpr::Sum(a, b) => format!("{} + {}", PARAMS[a], PARAMS[b]),
            GenExpr::Diff(a, b) => format!("{} - {}", PARAMS[a], PARAMS[b]),
            GenExpr::Prod(a, b) => format!("{}*{}/100", PARAMS[a], PARAMS[b]),
            GenExpr::Neg(a) => format!("-{}", PARAMS[a]),
            GenExpr::Div(a, d) => format!("{}/{d}", PARAMS[a]),
        }
    }
}

/// One generated body (the root ignores everything but its name).
#[derive(Debug, Clone)]
struct GenBody {
    /// Parent selector, taken modulo the body's index.
    parent: usize,
    offset: [GenExpr; 3],
    /// Fixed rotations: (axis, radians, written in degrees).
    rotation: Vec<(usize, f64, bool)>,
    /// Joint: (rotary, axis, negative).
    joint: Option<(bool, usize, bool)>,
    errors: [bool; 6],
    location: [bool; 6],
    squareness: [bool; 3],
}

/// Where a shared error name goes: (body selector, in location_errors, slot 0..3).
type Place = (usize, bool, usize);

#[derive(Debug, Clone)]
struct GenMachine {
    bodies: Vec<GenBody>,
    workpiece: usize,
    tool: usize,
    tool_point: [GenExpr; 3],
    /// 0: frame omitted (workpiece), 1: workpiece, 2: tool.
    frame: u8,
    /// Values of la, lb, lc (ld is null).
    params: [f64; 3],
    /// A linear error name used in two places.
    shared_linear: (Place, Place),
    /// An angular error name used in two places.
    shared_angular: (Place, Place),
}

const SLOTS: [&str; 6] = ["dx", "dy", "dz", "ex", "ey", "ez"];
const AXES: [&str; 3] = ["x", "y", "z"];

impl GenMachine {
    fn n(&self) -> usize {
        self.bodies.len()
    }

    fn workpiece(&self) -> usize {
        self.workpiece % self.n()
    }

    fn tool(&self) -> usize {
        let t = self.tool % self.n();
        if t == self.workpiece() {
            (t + 1) % self.n()
        } else {
            t
        }
    }

    /// The machine file.
    fn yaml(&self) -> String {
        let n = self.n();
        // Error names per body: [section][slot] with section 0 = errors,
        // 1 = location_errors.
        let mut names: Vec<[[Option<String>; 6]; 2]> = (0..n)
            .map(|b| {
                let body = &self.bodies[b];
                let errors = std::array::from_fn(|s| {
                    (b > 0 && body.errors[s]).then(|| format!("e{b}{}", SLOTS[s]))
                });
                let location = std::array::from_fn(|s| {
                    (b > 0 && body.location[s]).then(|| format!("l{b}{}", SLOTS[s]))
                });
                [errors, location]
            })
            .collect();
        let mut place = |name: &str, (a, b): (Place, Place), offset: usize| {
            let first = (1 + a.0 % (n - 1), usize::from(a.1), offset + a.2 % 3);
            let mut second = (1 + b.0 % (n - 1), usize::from(b.1), offset + b.2 % 3);
            if second == first {
                second.1 = 1 - second.1;
            }
            for (body, section, slot) in [first, second] {
                names[body][section][slot] = Some(name.to_string());
            }
        };
        place("shlin", self.shared_linear, 0);
        place("shang", self.shared_angular, 3);

        let mut y = String::from("machine: random\n");
        y.push_str(&format!(
            "parameters: {{la: {}, lb: {}, lc: {}, ld: null}}\nbodies:\n  b0: {{}}\n",
            self.params[0], self.params[1], self.params[2]
        ));
        for b in 1..n {
            let body = &self.bodies[b];
            let mut parts = vec![format!("parent: b{}", body.parent % b)];
            let off: Vec<String> = body.offset.iter().map(GenExpr::render).collect();
            parts.push(format!("offset: [{}]", off.join(", ")));
            if !body.rotation.is_empty() {
                let rs: Vec<String> = body
                    .rotation
                    .iter()
                    .map(|&(axis, angle, deg)| {
                        let a = if deg {
                            format!("\"{}deg\"", angle.to_degrees().round())
                        } else {
                            format!("{angle}")
                        };
                        format!("{{about: {}, angle: {a}}}", AXES[axis])
                    })
                    .collect();
                parts.push(format!("rotation: [{}]", rs.join(", ")));
            }
            let map = |section: usize| -> Option<String> {
                let entries: Vec<String> = (0..6)
                    .filter_map(|s| {
                        names[b][section][s]
                            .as_ref()
                            .map(|nm| format!("{}: {nm}", SLOTS[s]))
                    })
                    .collect();
                (!entries.is_empty()).then(|| format!("{{{}}}", entries.join(", ")))
            };
            if let Some(l) = map(1) {
                parts.push(format!("location_errors: {l}"));
            }
            if let Some((rotary, axis, negative)) = body.joint {
                parts.push(format!(
                    "joint: {{type: {}, axis: {}{}, variable: q{b}}}",
                    if rotary { "rotary" } else { "prismatic" },
                    if negative { "-" } else { "+" },
                    AXES[axis]
                ));
            }
            if let Some(e) = map(0) {
                parts.push(format!("errors: {e}"));
            }
            let sq: Vec<String> = (0..3)
                .filter(|&s| body.squareness[s])
                .map(|s| format!("{}: s{b}{}", SLOTS[s + 3], SLOTS[s + 3]))
                .collect();
            if !sq.is_empty() {
                parts.push(format!("squareness: {{{}}}", sq.join(", ")));
            }
            y.push_str(&format!("  b{b}:\n"));
            for p in parts {
                y.push_str(&format!("    {p}\n"));
            }
        }
        y.push_str(&format!(
            "workpiece: b{}\ntool: b{}\n",
            self.workpiece(),
            self.tool()
        ));
        let tp: Vec<String> = self.tool_point.iter().map(GenExpr::render).collect();
        y.push_str(&format!("tool_point: [{}]\n", tp.join(", ")));
        match self.frame {
            1 => y.push_str("frame: workpiece\n"),
            2 => y.push_str("frame: tool\n"),
            _ => {}
        }
        y
    }
}

fn gen_expr() -> impl Strategy<Value = GenExpr> {
    prop_oneof![
        2 => Just(GenExpr::Num(0.0)),
        3 => (-600i32..600).prop_map(|v| GenExpr::Num(f64::from(v) / 2.0)),
        1 => (0usize..4).prop_map(GenExpr::Param),
        1 => (1i32..4, any::<bool>(), 0usize..4)
            .prop_map(|(c, neg, a)| GenExpr::Scaled(if neg { -c } else { c }, a)),
        1 => (0usize..4, 0usize..4).prop_map(|(a, b)| GenExpr::Sum(a, b)),
        1 => (0usize..4, 0usize..4).prop_map(|(a, b)| GenExpr::Diff(a, b)),
        1 => (0usize..4, 0usize..4).prop_map(|(a, b)| GenExpr::Prod(a, b)),
        1 => (0usize..4).prop_map(GenExpr::Neg),
        1 => (0usize..4, 2i32..6).prop_map(|(a, d)| GenExpr::Div(a, d)),
    ]
}

fn gen_body() -> impl Strategy<Value = GenBody> {
    (
        any::<usize>(),
        [gen_expr(), gen_expr(), gen_expr()],
        prop::collection::vec((0usize..3, -3.0f64..3.0, any::<bool>()), 0..3),
        prop::option::weighted(0.8, (any::<bool>(), 0usize..3, any::<bool>())),
        any::<[bool; 6]>(),
        any::<[bool; 6]>(),
        any::<[bool; 3]>(),
    )
        .prop_map(
            |(parent, offset, rotation, joint, errors, location, squareness)| GenBody {
                parent,
                offset,
                rotation,
                joint,
                errors,
                location,
                squareness,
            },
        )
}

fn gen_place() -> impl Strategy<Value = Place> {
    (0usize..7, any::<bool>(), 0usize..3)
}

fn gen_machine() -> impl Strategy<Value = GenMachine> {
    (
        prop::collection::vec(gen_body(), 2..=7),
        0usize..7,
        0usize..7,
        [gen_expr(), gen_expr(), gen_expr()],
        0u8..3,
        [-200.0f64..200.0, -200.0f64..200.0, -200.0f64..200.0],
        (gen_place(), gen_place()),
        (gen_place(), gen_place()),
    )
        .prop_map(
            |(
                bodies,
                workpiece,
                tool,
                tool_point,
                frame,
                params,
                shared_linear,
                shared_angular,
            )| {
                GenMachine {
                    bodies,
                    workpiece,
                    tool,
                    tool_point,
                    frame,
                    params,
                    shared_linear,
                    shared_angular,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn random_machines_match_the_exact_product(g in gen_machine(), seed in any::<u64>()) {
        let yaml = g.yaml();
        let m = match chain_core::load_str(&yaml, "random.yaml") {
            Ok(m) => m,
            Err(d) => panic!("generated machine does not load:\n{d}\n---\n{yaml}"),
        };
        // The generator's promises hold in the loaded machine.
        prop_assert_eq!(m.bodies.len(), g.n());
        prop_assert_eq!(m.frame == chain_core::model::Frame::Tool, g.frame == 2);
        for shared in ["shlin", "shang"] {
            let j = m.error_index(shared).expect("shared error");
            let uses: usize = m
                .bodies
                .iter()
                .map(|b| {
                    b.errors.slots.iter().chain(b.location_errors.slots.iter())
                        .map(|s| s.iter().filter(|&&k| k == j).count())
                        .sum::<usize>()
                })
                .sum();
            prop_assert_eq!(uses, 2, "{} is used in two places", shared);
        }
        let model = chain_core::compile(&m);
        let ex = Exact::new(&m);
        let mut rng = Rng::new(seed);
        let ld = rng.range(-200.0, 200.0);
        let p: Vec<f64> = m.parameters.iter().map(|p| p.value.unwrap_or(ld)).collect();
        for _ in 0..3 {
            let q: Vec<f64> = m
                .variables
                .iter()
                .map(|v| match v.kind {
                    chain_core::model::JointKind::Prismatic => rng.range(-300.0, 300.0),
                    chain_core::model::JointKind::Rotary => {
                        rng.range(-std::f64::consts::PI, std::f64::consts::PI)
                    }
                })
                .collect();
            if let Err(msg) = ex.check_sensitivity(&model, &q, &p, 1e-6, 1e-9) {
                panic!("{msg}\n---\n{yaml}");
            }
            let e = random_e(&m, &mut rng);
            if let Err(msg) = ex.check_error_and_nominal(&model, &q, &p, &e, 1e-10) {
                panic!("{msg}\n---\n{yaml}");
            }
        }
    }
}
