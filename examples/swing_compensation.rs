//! Seed 003 end to end: the HTM50200 swing-head measurements (Table 1) →
//! swing-angle errors (Eq. 5, Table 2) → polynomial fits of order 2-6 →
//! the selected compensation law → a compensation table.
//!
//! Run with `cargo run --example swing_compensation`; the table goes to
//! `target/swing_compensation/`. The library takes the file's records (here
//! read with the `csv` crate); the figures are drawn by the command line,
//! `chain compensate examples/data/swing_htm50200.csv --length 577.11 --plot DIR`.

use std::path::Path;

use chain::compensate::{self, Grid, Measurements, Options, RawRecord, SelectionRule};

/// Rotation centre to cutter centre (the seed: 577.11 mm).
const LENGTH_MM: f64 = 577.11;

/// The seed's R² for orders 2-6.
const PAPER_R2: [f64; 5] = [0.0953, 0.1458, 0.1822, 0.1835, 0.1844];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("examples/data/swing_htm50200.csv");
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(&path)?;
    let records = reader
        .records()
        .map(|r| r.map(|r| RawRecord::new(r.position().map_or(0, |p| p.line()), r.iter())))
        .collect::<Result<Vec<_>, _>>()?;
    let measurements = Measurements::from_records(&path.display().to_string(), records)?;
    let analysis = compensate::analyze(&measurements, &Options::new(LENGTH_MM))?;

    println!("θ (°)   Z1−Z3 (mm)  ΔZ (mm)     Δθ (°)");
    for p in analysis.points.iter().step_by(5) {
        println!(
            "{:>5} {:>11.6} {:>9.6} {:>10.6}",
            p.theta_deg, p.z1_minus_z3, p.delta_z_mm, p.delta_theta_deg
        );
    }

    println!("\norder   R²      paper   adj. R²  LOOCV RMS (°)");
    for (fit, paper) in analysis.fits.iter().zip(PAPER_R2) {
        println!(
            "{:>5} {:>7.4} {:>7.4} {:>8.4} {:>10.5}",
            fit.order, fit.r2, paper, fit.adjusted_r2, fit.loocv_rmse
        );
    }
    for rule in SelectionRule::ALL {
        println!(
            "rule {:<12} picks order {}",
            rule.name(),
            rule.select(&analysis.fits).unwrap_or(0)
        );
    }

    let law = &analysis.compensation;
    println!(
        "\nselected order {} ({}):\n  {}",
        analysis.selected_order, analysis.selection.description, law.law
    );
    if let Some(paper_order) = analysis.fit(4) {
        println!(
            "order-4 law (the paper's choice): {}",
            compensate::polynomial_text(&paper_order.coefficients, "theta")
        );
    }
    println!(
        "error before: {:+.4}..{:+.4}°, predicted after: {:+.4}..{:+.4}° (RMS {:.4} → {:.4}°, leave-one-out {:.4}°)",
        law.residual.before.min_deg,
        law.residual.before.max_deg,
        law.residual.after.min_deg,
        law.residual.after.max_deg,
        law.residual.before.rms_deg,
        law.residual.after.rms_deg,
        law.residual.loocv_rms_deg
    );

    let out = root.join("target/swing_compensation");
    std::fs::create_dir_all(&out)?;
    let rows = law.table(&Grid::unit(1.0, 40.0).points()?, false)?;
    let table = out.join("compensation_table.csv");
    compensate::write_table_csv(&rows, std::fs::File::create(&table)?)?;
    println!(
        "\nto reach 20°, command {:.4}°",
        law.command_deg(20.0).unwrap_or(f64::NAN)
    );
    println!("wrote {}", table.display());
    Ok(())
}
