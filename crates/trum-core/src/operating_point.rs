//! An operating point of the motor: the preload, load torque and drive it runs at, and
//! the time since the drive was switched on. Shared by the solver, the grids of a map and
//! the observed rows of measurement data.

/// One operating point. All fields SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatingPoint {
    /// Axial preload pressing the rotor on the stator [N], > 0.
    pub preload_n: f64,
    /// Load torque on the rotor [N·m], ≥ 0.
    pub torque_nm: f64,
    /// Drive voltage amplitude per phase, zero-to-peak [V], > 0.
    pub voltage_v: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
    /// Time since the drive was switched on [s], ≥ 0 (only `thermal_drift` uses it).
    pub elapsed_s: f64,
}

impl OperatingPoint {
    /// A steady operating point (elapsed time 0).
    pub fn new(preload_n: f64, torque_nm: f64, voltage_v: f64, frequency_hz: f64) -> Self {
        OperatingPoint { preload_n, torque_nm, voltage_v, frequency_hz, elapsed_s: 0.0 }
    }

    /// Why the point is invalid, if it is.
    pub fn invalid_reason(&self) -> Option<String> {
        let checks = [
            ("preload_n", self.preload_n, true),
            ("voltage_v", self.voltage_v, true),
            ("frequency_hz", self.frequency_hz, true),
            ("torque_nm", self.torque_nm, false),
            ("elapsed_s", self.elapsed_s, false),
        ];
        for (name, v, strict) in checks {
            if !v.is_finite() {
                return Some(format!("{name} = {v} is not a finite number"));
            }
            if strict && v <= 0.0 {
                return Some(format!("{name} = {v} must be > 0"));
            }
            if !strict && v < 0.0 {
                return Some(format!("{name} = {v} must be >= 0"));
            }
        }
        None
    }
}
