//! A real motor's effect need not be small. At the top of its documented range an effect
//! pulls the calibrated baseline's parameters far from their nominal values to mimic part
//! of it, and the fit of the effect itself must still reach its own valley
//! (docs/DIAGNOSIS.md, "Fits that search").

use trum_core::diagnose::{diagnose, DiagnoseOptions};

/// `radial_friction` at the top of its range (3 × typical) on `generic60`, measured in
/// the combined campaign with read-back set points and a speed-stability floor:
/// `tests/data/diagnose/generic60_radial_friction_3_combined.csv`, written by
/// `trum synth --motor generic60 --campaign combined --noise 1 --seed 240 --motor-seed 240
/// --artefacts readback_rel=0.004,speed_std_floor_rpm=0.3 --effect radial_friction=3`.
/// The baseline is refitted from another candidate's valley; from there the lowest
/// `radial_friction` valley of the scan is a small step off the fit, and only the nominal
/// motor's valley of the same form reaches the noise. The verdict is `radial_friction` near
/// its true strength, closing most of the held-out gap.
#[test]
fn radial_friction_at_the_top_of_its_range_is_found_at_its_strength() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/diagnose/generic60_radial_friction_3_combined.csv");
    let bytes = std::fs::read(path).expect("test data");
    let m = trum_core::measurements::parse_measurements(&bytes, path).expect("measurements");
    let motor = trum_core::presets::preset("generic60").expect("preset");
    let bench = trum_core::bench::observations(&m, &motor);
    let opts = DiagnoseOptions { bootstrap: 50, ..DiagnoseOptions::default() };
    let d = diagnose(&motor, &bench.rows, &bench.groups, &opts).expect("diagnosis");
    let ranked: Vec<&str> = d.ranking.iter().map(|r| r.effect.as_str()).collect();
    assert_eq!(d.verdict, "radial_friction", "ranking {ranked:?}");
    let top = d.ranking.iter().find(|r| r.effect == "radial_friction").expect("ranked");
    let strength = top.params.iter().find(|p| p.0.ends_with("radial_velocity_ratio")).map_or(f64::NAN, |p| p.1);
    assert!(strength > 2.0, "fitted radial_velocity_ratio {strength} (truth 3)");
    assert!(top.shrink > 0.6, "held-out shrink {}", top.shrink);
    assert!(d.complete);
}
