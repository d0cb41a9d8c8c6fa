//! Two machines declared with `chain::machine!` — the gantry grinder (seed 000)
//! inline, the internal grinder (seed 004) from its YAML file — their
//! sensitivity matrices at a point, and a small Monte Carlo of the gantry's px
//! through the `ErrorModel` trait.
//!
//! Run with `cargo run --release --example macro_models`.

use chain::core::model::Sided;
use chain::core::ErrorModel;
use chain::reliability::{Event, Form, Inputs, Marginal, MonteCarlo, Sampler, ToleranceLimitState};

chain::machine! {
    pub GantryGrinder {
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
        frame: tool,
    }
}

chain::machine!(pub InternalGrinder = "examples/machines/internal_grinder.yaml");

fn print_matrix(title: &str, names: &[&str], s: &[f64]) {
    println!("{title}");
    let n = names.len();
    for (c, row) in ["px", "py", "pz", "ox", "oy", "oz"].iter().enumerate() {
        let cells: Vec<String> = (0..n)
            .filter(|&j| s[c * n + j] != 0.0)
            .map(|j| format!("{}={:.4}", names[j], s[c * n + j]))
            .collect();
        println!("  {row}: {}", cells.join("  "));
    }
}

/// Monte Carlo of one component through the trait: any `ErrorModel` works,
/// generated or loaded at run time.
fn monte_carlo_px(model: &dyn ErrorModel, q: &[f64], stds: &[f64], tolerance: f64) {
    let n = model.errors().len();
    let mut s = vec![0.0; 6 * n];
    model.sensitivity(q, &[], &mut s);
    let names: Vec<String> = model.errors().iter().map(|e| e.to_string()).collect();
    let marginals = stds
        .iter()
        .map(|&sd| Marginal::normal(0.0, sd).expect("positive std"))
        .collect();
    let inputs = Inputs::new(names, marginals).expect("inputs");
    let g = ToleranceLimitState::component(s[..n].to_vec(), tolerance, Sided::Upper)
        .expect("limit state");
    let event = Event::new(&inputs, g).expect("event");
    let mc = MonteCarlo {
        samples: 200_000,
        seed: 42,
        cov: None,
    }
    .run(&event)
    .expect("monte carlo");
    let form = Form::default().run(&event).expect("form");
    println!(
        "  px ≤ {tolerance} mm: Monte Carlo R = {:.4} ± {:.4} (200k samples), FORM (exact here) R = {:.4}",
        1.0 - mc.pf,
        mc.std_error,
        form.reliability
    );
}

fn main() {
    // Gantry at (x, y, z) = (0, -1500, 600), in the generated type's q order.
    let mut q = [0.0; 3];
    q[GantryGrinder::VAR_X] = 0.0;
    q[GantryGrinder::VAR_Y] = -1500.0;
    q[GantryGrinder::VAR_Z] = 600.0;
    let s = GantryGrinder::sensitivity(&q, &[]);
    let flat: Vec<f64> = s.iter().flatten().copied().collect();
    print_matrix(
        "gantry grinder (inline machine!), sensitivity at x=0, y=-1500, z=600:",
        &GantryGrinder::ERRORS,
        &flat,
    );

    // Internal grinder at the paper's working position, parameters from the file.
    let p: Vec<f64> = InternalGrinder::PARAMETER_VALUES
        .iter()
        .map(|v| v.expect("the example file sets every parameter"))
        .collect();
    let mut qi = vec![0.0; InternalGrinder::VARIABLES.len()];
    for (name, value) in [("x1", -100.0), ("x2", 0.0), ("z", 40.0)] {
        if let Some(i) = InternalGrinder::VARIABLES.iter().position(|v| *v == name) {
            qi[i] = value;
        }
    }
    let mut si = vec![0.0; 6 * InternalGrinder::ERRORS.len()];
    InternalGrinder.sensitivity(&qi, &p, &mut si);
    print_matrix(
        "internal grinder (machine! from YAML), sensitivity at x1=-100, x2=0, z=40:",
        &InternalGrinder::ERRORS,
        &si,
    );

    // Table 1 of seed 000 as standard deviations, in the generated error order.
    let table1 = |name: &str| match name {
        "dxx" | "dyx" | "dzx" | "dyy" | "dzz" => 0.05 / 6.0,
        "dxy" | "dzy" => 0.04 / 6.0,
        "dxz" | "dyz" => 0.03 / 6.0,
        "exx" | "exz" | "ezz" => 0.03 / 6000.0,
        "eyx" => 0.06 / 6000.0,
        "ezx" | "exy" => 0.05 / 6000.0,
        "eyy" | "ezy" | "eyz" => 0.04 / 6000.0,
        "Sxy" | "Sxz" => 0.03 / 3000.0,
        _ => 0.02 / 3000.0, // Syz
    };
    let stds: Vec<f64> = GantryGrinder::ERRORS.iter().map(|e| table1(e)).collect();
    println!("gantry grinder, reliability of px at the same point (Table 2 prints 88.83 %):");
    monte_carlo_px(&GantryGrinder, &q, &stds, 0.03);
}
