//! The paper presets' baselines the model tests were written for, frozen in
//! tests/data/motors/ (shared by the test files that include this module).

use trum_core::Motor;

/// The motors these regression points were found on: frozen copies of the paper presets'
/// baseline (tests/data/motors/), so a recalibrated preset does not move them; other
/// names are the presets themselves.
pub fn preset(name: &str) -> Result<Motor, trum_core::ParamError> {
    match name {
        "trum60a" => {
            Motor::from_toml_str(include_str!("../data/motors/trum60a_baseline.toml"), "trum60a_baseline.toml")
        }
        "trum60-qut" => {
            Motor::from_toml_str(include_str!("../data/motors/trum60-qut_baseline.toml"), "trum60-qut_baseline.toml")
        }
        other => trum_core::presets::preset(other),
    }
}
