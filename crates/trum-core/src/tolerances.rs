//! How well each uncertain baseline parameter of a motor is known before calibration:
//! the default priors and fit bounds that calibration starts from and that a motor file's
//! `[tolerances]` table overrides.

/// How well a baseline parameter is known before the data are seen: the standard
/// deviation of its logarithm (a relative tolerance) and the bounds of its fit, as
/// factors on the nominal value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Dotted motor key.
    pub key: &'static str,
    /// Prior standard deviation of ln(value / nominal) [-].
    pub rel_sd: f64,
    /// Lower bound of the fit as a factor on the nominal value.
    pub lo: f64,
    /// Upper bound of the fit as a factor on the nominal value.
    pub hi: f64,
    /// The readings that must be present for the data to see it.
    pub needs: Needs,
}

/// Which readings a baseline parameter needs before it is fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Needs {
    /// Any data (it moves the speed).
    Always,
    /// Feedback-electrode voltages.
    Feedback,
    /// Electrical readings (input power or current).
    Electrical,
    /// A temperature time series.
    ThermalSeries,
}

/// Default tolerances of the baseline parameters, by class (docs/DIAGNOSIS.md,
/// "Calibration"). Material and contact constants are known to a factor of a few (broad
/// priors, bounds at about ±2σ); machined geometry to a few percent; the modal mass and
/// the electrical constants in between. A real motor differs from its nominal file in all
/// of them at once, so all are fitted: a parameter the data cannot determine stays at its
/// prior instead of leaving a structured residual for an effect to fill.
pub const TOLERANCES: &[Tolerance] = &[
    Tolerance { key: "friction_layer.friction_coefficient", rel_sd: 0.6, lo: 0.3, hi: 3.0, needs: Needs::Always },
    Tolerance { key: "friction_layer.youngs_modulus_pa", rel_sd: 1.15, lo: 0.1, hi: 10.0, needs: Needs::Always },
    Tolerance { key: "stator.modal_damping_ns_per_m", rel_sd: 0.8, lo: 0.2, hi: 5.0, needs: Needs::Always },
    Tolerance { key: "stator.force_factor_n_per_v", rel_sd: 0.6, lo: 0.3, hi: 3.0, needs: Needs::Always },
    Tolerance { key: "stator.resonance_frequency_hz", rel_sd: 0.015, lo: 0.97, hi: 1.03, needs: Needs::Always },
    Tolerance { key: "geometry.neutral_plane_distance_m", rel_sd: 0.05, lo: 0.8, hi: 1.25, needs: Needs::Always },
    Tolerance { key: "geometry.mean_radius_m", rel_sd: 0.02, lo: 0.93, hi: 1.07, needs: Needs::Always },
    Tolerance { key: "stator.modal_mass_kg", rel_sd: 0.1, lo: 0.7, hi: 1.4, needs: Needs::Always },
    Tolerance { key: "electrical.feedback_gain_v_per_m", rel_sd: 0.6, lo: 0.3, hi: 3.0, needs: Needs::Feedback },
    Tolerance { key: "electrical.clamped_capacitance_f", rel_sd: 0.35, lo: 0.5, hi: 2.0, needs: Needs::Electrical },
    Tolerance { key: "electrical.dielectric_loss_tangent", rel_sd: 0.4, lo: 0.3, hi: 3.0, needs: Needs::Electrical },
    Tolerance { key: "thermal.heat_capacity_j_per_k", rel_sd: 0.6, lo: 0.3, hi: 3.0, needs: Needs::ThermalSeries },
    Tolerance {
        key: "thermal.heat_transfer_coefficient_w_per_m2k",
        rel_sd: 0.6,
        lo: 0.3,
        hi: 3.0,
        needs: Needs::ThermalSeries,
    },
];
