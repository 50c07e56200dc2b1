//! What a bench measures and the model predicts: the observable quantities (one per
//! measurement-file column the model can predict, with their default noise levels) and an
//! observed row (an operating point and the readings taken there). Shared by synthesis,
//! noise estimation, calibration and diagnosis.

use crate::operating_point::OperatingPoint;

/// A measured quantity the model predicts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Observable {
    /// Mean rotor speed [rev/min].
    SpeedRpm,
    /// Electrical input power, both phases [W].
    InputPowerW,
    /// Drive current amplitude per phase [A].
    CurrentA,
    /// Efficiency [-].
    Efficiency,
    /// Feedback electrode voltage amplitude [V].
    FeedbackV,
    /// Stator temperature [°C].
    TemperatureC,
    /// Speed standard deviation over a revolution [rev/min].
    SpeedStdRpm,
}

impl Observable {
    /// All observables, in column order.
    pub const ALL: [Observable; 7] = [
        Observable::SpeedRpm,
        Observable::InputPowerW,
        Observable::CurrentA,
        Observable::Efficiency,
        Observable::FeedbackV,
        Observable::TemperatureC,
        Observable::SpeedStdRpm,
    ];

    /// The measurement-file column name.
    pub fn column(self) -> &'static str {
        match self {
            Observable::SpeedRpm => "speed_rpm",
            Observable::InputPowerW => "input_power_w",
            Observable::CurrentA => "current_a",
            Observable::Efficiency => "efficiency",
            Observable::FeedbackV => "feedback_v",
            Observable::TemperatureC => "temperature_c",
            Observable::SpeedStdRpm => "speed_std_rpm",
        }
    }

    /// The expected reading of this quantity in row `row` when the model gives `model` and
    /// the reading's noise has standard deviation `sigma`. Where the bench clips the speed
    /// standard deviation at zero (`ObservedRow::speed_std_clipped`), its readings of a
    /// smoothly running motor (true value near 0) are the non-negative part of the noise,
    /// whose mean, σ/√(2π) at a true value of zero, a model predicting 0 misses in every
    /// reading alike (eccentricity, which adds a speed ripple, then fits that bias: 1000-row
    /// null data, evidence 9.6). The expected reading of max(0, m + ε), ε ~ N(0, σ²), is
    /// m·Φ(m/σ) + σ·φ(m/σ), which is m to within 1e-9·σ once m > 6σ. Otherwise, and for
    /// every other quantity: `model`.
    pub fn expected_reading(self, row: &ObservedRow, model: f64, sigma: f64) -> f64 {
        match self {
            Observable::SpeedStdRpm if row.speed_std_clipped && sigma > 0.0 && model < 8.0 * sigma => {
                let x = model / sigma;
                model * crate::normal::normal_cdf(x) + sigma * crate::normal::normal_pdf(x)
            }
            _ => model,
        }
    }

    /// Default noise level of one reading when the data do not say (documented in
    /// docs/DIAGNOSIS.md): an absolute floor plus a relative part.
    pub fn default_sigma(self, value: f64) -> f64 {
        let v = value.abs();
        match self {
            Observable::SpeedRpm => 0.5 + 0.01 * v,
            Observable::InputPowerW => 0.05 + 0.02 * v,
            Observable::CurrentA => 0.002 + 0.015 * v,
            Observable::Efficiency => 0.005 + 0.03 * v,
            Observable::FeedbackV => 0.2 + 0.01 * v,
            Observable::TemperatureC => 0.2,
            Observable::SpeedStdRpm => 0.05 + 0.1 * v,
        }
    }
}

/// One measured row: the operating point and the readings taken there.
#[derive(Clone, Debug, PartialEq)]
pub struct ObservedRow {
    /// Operating point (elapsed time included for time series).
    pub op: OperatingPoint,
    /// Readings: (what, value, noise level σ).
    pub readings: Vec<(Observable, f64, f64)>,
    /// Ambient temperature for temperature readings [°C].
    pub ambient_c: f64,
    /// The bench reports this row's speed standard deviation clipped at zero, and its σ is
    /// the readings' own noise level: the reading is compared with the expected reading of
    /// clipped noise ([`Observable::expected_reading`]). Set by the diagnosis where the
    /// data show both (docs/DIAGNOSIS.md, "Calibration").
    pub speed_std_clipped: bool,
}
