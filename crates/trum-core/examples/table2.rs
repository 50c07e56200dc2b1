//! Diagnosis of Sun et al. 2021 Table 2 (no-load speed and feedback voltage at four preloads)
//! with the trum60-qut preset; prints what docs/DIAGNOSIS.md reports.
#![allow(clippy::unwrap_used)] // examples: developer tools, a panic is the error report
use trum_core::*;
fn main() {
    let text = include_bytes!("../../../tests/data/good/measurements/sun2021_table2.csv");
    let meas = measurements::parse_measurements(text, "sun2021_table2.csv").unwrap();
    let motor = presets::preset("trum60-qut").unwrap();
    let data = bench::observations(&meas, &motor);
    let t0 = std::time::Instant::now();
    let d = diagnose::diagnose(&motor, &data.rows, &data.groups, &diagnose::DiagnoseOptions::default()).unwrap();
    println!(
        "verdict {} confounded {:?} base {:.3} noise {:.3} z2 {:.2} folds {} t={:.1}s",
        d.verdict,
        d.confounded_with,
        d.baseline_heldout_nrmse,
        d.noise_nrmse,
        d.baseline_heldout_chi2_per_reading,
        d.folds,
        t0.elapsed().as_secs_f64()
    );
    for r in &d.ranking {
        println!(
            "  {:40} ev={:7.2} after={:.3} shrink={:.2} [{:.2},{:.2}] {:?}",
            r.effect, r.evidence, r.heldout_nrmse_after, r.shrink, r.shrink_interval.0, r.shrink_interval.1, r.params
        );
    }
    for g in &d.gap_where {
        println!("  where {} {} {:.2} z={:.1}", g.quantity, g.region, g.mean_residual, g.z);
    }
    for n in &d.notes {
        println!("  note: {n}");
    }
    for (k, v) in &d.baseline_params {
        println!("  {k} = {v:.4e}");
    }
}
