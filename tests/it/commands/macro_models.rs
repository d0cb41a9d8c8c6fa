//! `chain::machine!`: the file and inline forms of the gantry grinder, the
//! generated code of every example machine against the runtime evaluator, and
//! seed 000's Eq. 18 (errata applied, see docs/errata.md) against the
//! generated functions.

use crate::common;

use chain::core::ErrorModel;
use common::cli::ok_stdout;
use common::root;

chain::machine!(pub GantryFile = "examples/machines/gantry_grinder.yaml");
chain::machine!(pub InternalGrinder = "examples/machines/internal_grinder.yaml");
chain::machine!(pub Cnc5Bevel = "examples/machines/cnc5_bevel.yaml");
chain::machine!(pub AcTrunnion = "examples/machines/ac_trunnion.yaml");
chain::machine!(pub Puma560Dh = "examples/robots/puma560_dh.yaml");
chain::machine!(pub PandaMdh = "examples/robots/panda_mdh.yaml");

// A `dh` and an `mdh` row in the inline form (docs/yaml.md,
// "Denavit–Hartenberg bodies").
chain::machine! {
    pub DhInline {
        machine: two_link,
        bodies {
            base {},
            l1 {
                parent: base,
                dh: { theta: 90deg, d: 100, a: 25, alpha: -90deg, joint: rotary, variable: q1,
                      errors: { theta: T1, d: D1, a: A1, alpha: AL1, beta: B1 } },
                errors: { ez: EC1 },
            },
            l2 {
                parent: l1,
                mdh: { theta: 0, d: 50, a: 300, alpha: 0, joint: prismatic, variable: q2,
                       errors: { a: A2, d: D2 } },
            },
        },
        workpiece: base,
        tool: l2,
    }
}

chain::machine! {
    pub GantryInline {
        machine: gantry_grinder,
        bodies {
            bed {},
            x_slide {
                parent: bed,
                joint: { type: prismatic, axis: +x, variable: x },
                errors: { dx: dxx, dy: dyx, dz: dzx, ex: exx, ey: eyx, ez: ezx },
                squareness: { ez: Sxy },
            },
            table { parent: x_slide },
            z_slide {
                parent: bed,
                joint: { type: prismatic, axis: +z, variable: z },
                errors: { dx: dxz, dy: dyz, dz: dzz, ex: exz, ey: eyz, ez: ezz },
                squareness: { ex: Syz, ey: Sxz },
            },
            y_slide {
                parent: z_slide,
                joint: { type: prismatic, axis: +y, variable: y },
                errors: { dx: dxy, dy: dyy, dz: dzy, ex: exy, ey: eyy, ez: ezy },
            },
            tool { parent: y_slide },
        },
        workpiece: table,
        tool: tool,
        tool_point: [0, 0, 0],
        frame: tool,
    }
}

/// A small deterministic generator (xorshift64*), so the test needs no crate.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn inline_and_file_forms_generate_identical_functions() {
    assert_eq!(GantryFile::ERRORS, GantryInline::ERRORS);
    assert_eq!(GantryFile::VARIABLES, GantryInline::VARIABLES);
    let mut rng = Rng(7);
    for _ in 0..1000 {
        let q = [
            rng.uniform(0.0, 1000.0),
            rng.uniform(600.0, 1400.0),
            rng.uniform(-1500.0, 1500.0),
        ];
        let e: [f64; 21] = std::array::from_fn(|_| rng.uniform(-1e-3, 1e-3));
        assert_eq!(
            GantryFile::sensitivity(&q, &[]),
            GantryInline::sensitivity(&q, &[])
        );
        assert_eq!(
            GantryFile::error(&q, &[], &e),
            GantryInline::error(&q, &[], &e)
        );
    }
}

/// Seed 000 Eq. 18 with its two errata applied (docs/errata.md): px gains the
/// −y·ε_zz of Eq. 17, and oz gains the −S_xy of Eq. 15.
fn eq18_corrected(x: f64, y: f64, z: f64, e: &dyn Fn(&str) -> f64) -> [f64; 6] {
    let _ = x;
    [
        -e("dxx") - z * e("eyx") + y * e("ezx") + e("dxz") + e("dxy") + y * e("Sxy") - y * e("ezz"),
        -e("dyx") + z * e("exx") + x * e("ezx") + e("dyz") + e("dyy") + x * e("Sxy"),
        -e("dzx") - y * e("exx") - x * e("eyx") + e("dzz") + y * e("exz") + e("dzy") + y * e("Syz"),
        -e("exx") + e("exz") + e("Syz") + e("exy"),
        -e("eyx") + e("eyz") + e("Sxz") + e("eyy"),
        -e("ezx") + e("ezz") + e("ezy") - e("Sxy"),
    ]
}

#[test]
fn generated_gantry_equals_corrected_eq18_at_10000_points() {
    let mut rng = Rng(11);
    let idx = |name: &str| {
        GantryFile::ERRORS
            .iter()
            .position(|n| *n == name)
            .expect(name)
    };
    let var = |name: &str| {
        GantryFile::VARIABLES
            .iter()
            .position(|n| *n == name)
            .expect(name)
    };
    for _ in 0..10_000 {
        let (x, y, z) = (
            rng.uniform(0.0, 1000.0),
            rng.uniform(-1500.0, 1500.0),
            rng.uniform(600.0, 1400.0),
        );
        let mut q = [0.0; 3];
        q[var("x")] = x;
        q[var("y")] = y;
        q[var("z")] = z;
        let e: [f64; 21] = std::array::from_fn(|_| rng.uniform(-1e-2, 1e-2));
        let expected = eq18_corrected(x, y, z, &|n| e[idx(n)]);
        let got = GantryFile::error(&q, &[], &e);
        for c in 0..6 {
            assert!(
                close(got[c], expected[c], 1e-12),
                "component {c}: {} vs {}",
                got[c],
                expected[c]
            );
        }
        // Sensitivity: the coefficient of each error is Eq. 18 at a unit error.
        let s = GantryFile::sensitivity(&q, &[]);
        for (j, name) in GantryFile::ERRORS.iter().enumerate() {
            let unit = eq18_corrected(x, y, z, &|n| if n == *name { 1.0 } else { 0.0 });
            for c in 0..6 {
                assert!(close(s[c][j], unit[c], 1e-12), "{name} component {c}");
            }
        }
    }
}

fn compare_with_runtime(generated: &dyn ErrorModel, file: &str, seed: u64) {
    let path = root().join(file);
    let machine = chain::core::load_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let runtime = chain::core::compile(&machine);
    assert_eq!(generated.errors(), runtime.errors());
    assert_eq!(generated.variables(), runtime.variables());
    assert_eq!(generated.parameters(), runtime.parameters());
    let n = runtime.errors().len();
    let p: Vec<f64> = machine
        .parameters
        .iter()
        .map(|p| p.value.unwrap_or(50.0))
        .collect();
    let mut rng = Rng(seed);
    let (mut a, mut b) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
    for _ in 0..2000 {
        let q: Vec<f64> = (0..runtime.variables().len())
            .map(|_| rng.uniform(-3.0, 3.0) * 100.0)
            .collect();
        let e: Vec<f64> = (0..n).map(|_| rng.uniform(-1e-3, 1e-3)).collect();
        generated.sensitivity(&q, &p, &mut a);
        runtime.sensitivity(&q, &p, &mut b);
        for k in 0..6 * n {
            assert!(
                close(a[k], b[k], 1e-12),
                "{file}: entry {k}: {} vs {}",
                a[k],
                b[k]
            );
        }
        let (mut ea, mut eb) = ([0.0; 6], [0.0; 6]);
        generated.error(&q, &p, &e, &mut ea);
        runtime.error(&q, &p, &e, &mut eb);
        for c in 0..6 {
            assert!(close(ea[c], eb[c], 1e-12), "{file}: error {c}");
        }
        let (na, nb) = (generated.nominal(&q, &p), runtime.nominal(&q, &p));
        for i in 0..3 {
            assert!(close(na.position[i], nb.position[i], 1e-12));
            for j in 0..3 {
                assert!(close(na.rotation[i][j], nb.rotation[i][j], 1e-12));
            }
        }
    }
}

#[test]
fn generated_code_equals_runtime_evaluator_on_every_example() {
    compare_with_runtime(&GantryFile, "examples/machines/gantry_grinder.yaml", 1);
    compare_with_runtime(
        &InternalGrinder,
        "examples/machines/internal_grinder.yaml",
        2,
    );
    compare_with_runtime(&Cnc5Bevel, "examples/machines/cnc5_bevel.yaml", 3);
    compare_with_runtime(&AcTrunnion, "examples/machines/ac_trunnion.yaml", 4);
    compare_with_runtime(&Puma560Dh, "examples/robots/puma560_dh.yaml", 5);
    compare_with_runtime(&PandaMdh, "examples/robots/panda_mdh.yaml", 6);
}

/// The inline form takes `dh` / `mdh` rows: their errors in the documented
/// order (dh: Δd, Δθ, motion errors, Δa, Δα, β; mdh: Δa, Δα, β, Δd, Δθ), and
/// the tool point is the DH product's at q = 0: `l1` at Rot_z(90°) then
/// (25, 0, 100), `l2` 300 along l1's x after Rot_x(−90°), then 50 along z.
#[test]
fn inline_dh_rows_generate_the_documented_model() {
    assert_eq!(
        DhInline::ERRORS,
        ["D1", "T1", "EC1", "A1", "AL1", "B1", "A2", "D2"]
    );
    assert_eq!(DhInline::VARIABLES, ["q1", "q2"]);
    // Frame 1 = Rot_z(90°)·Trans_z(100)·Trans_x(25)·Rot_x(−90°): origin
    // (0, 25, 100), x1 = (0, 1, 0), y1 = (0, 0, −1), z1 = (−1, 0, 0). The
    // mdh row adds Trans_x(300)·Trans_z(50 + q2) in frame 1.
    for (q2, expected) in [(0.0, [-50.0, 325.0, 100.0]), (10.0, [-60.0, 325.0, 100.0])] {
        let nominal = ErrorModel::nominal(&DhInline, &[0.0, q2], &[]);
        for (got, want) in nominal.position.iter().zip(expected) {
            assert!(
                (got - want).abs() < 1e-12,
                "q2 {q2}: {:?}",
                nominal.position
            );
        }
        let r = [[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
        for (got, want) in nominal.rotation.iter().flatten().zip(r.iter().flatten()) {
            assert!((got - want).abs() < 1e-15, "{:?}", nominal.rotation);
        }
    }
}

#[test]
fn wrong_slice_lengths_give_nan_not_panic() {
    let mut out = [0.0; 6];
    GantryFile.error(&[1.0], &[], &[0.0; 21], &mut out);
    assert!(out.iter().all(|v| v.is_nan()));
}

/// `chain derive --format rust` prints the v1 emission (pinned byte for byte
/// by `tests/golden/derive_gantry.rs.txt`); the macro emits the same type with
/// the functions that write into the caller's storage
/// (`Emission::Macro`). Both are the one emitter's
/// output for the same model.
#[test]
fn derive_format_rust_prints_what_the_macro_emits() {
    let file = "examples/machines/gantry_grinder.yaml";
    // Run from the package root, where `file` is.
    let printed = ok_stdout(&["derive", file, "--format", "rust"]);
    let model = chain::core::derive(
        &chain::core::load_file(std::path::Path::new(file)).unwrap_or_else(|d| panic!("{d}")),
    );
    let options = chain::core::emit::EmitOptions::for_model(&model);
    assert_eq!(printed, chain::core::emit::emit_pretty(&model, &options));
    // The macro's expansion of the same file, formatted the same way; only the
    // `include_bytes!` that tracks the file for rebuilds differs.
    let expanded = chain::core::expand::expand_pretty(
        "pub GantryGrinder = \"examples/machines/gantry_grinder.yaml\""
            .parse()
            .expect("tokens"),
    );
    // The formatter may break the call over several lines when the absolute
    // path is long, so cut the whole statement, not one line.
    let without_tracking = remove_tracking_statement(&expanded);
    let direct = options.with_emission(chain::core::emit::Emission::Macro);
    assert_eq!(
        chain::core::emit::emit_pretty(&model, &direct),
        without_tracking
    );
    assert!(printed.contains("pub struct GantryGrinder;"));
    assert!(printed.contains("pub fn sensitivity(q: &[f64; 3], p: &[f64; 0]) -> [[f64; 21]; 6]"));
    assert!(!printed.contains("sensitivity_into"));
    assert!(without_tracking
        .contains("pub fn sensitivity_into(q: &[f64; 3], p: &[f64; 0], out: &mut [[f64; 21]; 6])"));
    assert!(without_tracking.contains("pub const NONZEROS: [(usize, usize); 32]"));
}

/// `text` without the `include_bytes!` statement (and its line) the macro adds
/// to track the machine file.
fn remove_tracking_statement(text: &str) -> String {
    let start = text
        .find("include_bytes!(")
        .expect("the expansion tracks the machine file");
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let end = start + text[start..].find(");\n").expect("statement end") + 3;
    format!("{}{}", &text[..line_start], &text[end..])
}
