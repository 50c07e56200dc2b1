//! Calibration on small data (4-8 rows, `common/rows.rs`) of the generic motor.
//! Properties: no panic; a calibration's parameters are finite and its χ² finite or +∞.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::bench::observations;
use trum_core::calibrate::{Calibration, FitOptions};
use trum_core::presets;

#[path = "../common/rows.rs"]
mod rows;

fuzz_target!(|data: &[u8]| {
    let motor = presets::find("generic60").expect("preset").motor();
    let Some(m) = rows::small_rows(&motor, data) else { return };
    let bench = observations(&m, &motor);
    // as `trum calibrate` runs it: the baseline parameters, refitted from a bound
    let cal = Calibration::builder(&motor, &bench.rows).options(&FitOptions::default()).refit_bounds(true).run();
    if let Ok(cal) = cal {
        assert!(cal.chi2.is_finite() || cal.chi2 == f64::INFINITY, "{}", cal.chi2);
        for p in &cal.params {
            assert!(p.value.is_finite(), "{} = {}", p.name, p.value);
        }
    }
});
