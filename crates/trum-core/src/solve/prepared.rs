//! The motor constants the solver needs, computed once per motor.

use super::{iterated, OperatingPoint, Solution};
use crate::contact;
use crate::effects::{Effect, ALL, N_EFFECTS};
use crate::params::Motor;
use crate::stator;

/// Motor constants the solver needs, computed once per motor.
#[derive(Clone, Debug, PartialEq)]
pub struct Prepared {
    /// Wave number N, wavelengths around the ring [-].
    pub(crate) n: f64,
    /// Mean contact radius R0 [m].
    pub(crate) r0: f64,
    /// Wave number per unit length k = N/R0 [1/m].
    pub(crate) k: f64,
    /// Winkler stiffness of the friction layer k_f = E_f·b_f/h_f [N/m²].
    pub(crate) kf: f64,
    /// Distance h0 of the stator surface from the neutral plane [m].
    pub(crate) h0: f64,
    /// Friction coefficient μ of the layer [-].
    pub(crate) mu: f64,
    /// Modal mass m [kg].
    pub(crate) m: f64,
    /// Modal stiffness k_s = m·(2π·f_r)² [N/m].
    pub(crate) ks: f64,
    /// Modal damping c [N·s/m].
    pub(crate) c: f64,
    /// Force factor Θ of the piezoceramic [N/V].
    pub(crate) theta: f64,
    /// Clamped capacitance C0 per phase [F].
    pub(crate) c0: f64,
    /// Dielectric loss tangent tan δ [-].
    pub(crate) tan_d: f64,
    /// Feedback-electrode gain [V/m].
    pub(crate) kfb: f64,
    /// Rotor viscous damping d_r [N·m·s].
    pub(crate) dr: f64,
    /// Heat transfer coefficient times surface, α·S [W/K].
    pub(crate) alpha_s: f64,
    /// Heat capacity of the motor [J/K].
    pub(crate) heat_cap: f64,
    /// `preload_stiffening`: scale s of the contact stiffness added to the mode [-] (0: off).
    pub(crate) stiffening: f64,
    /// `preload_stiffening`'s modal fraction: 0 Sun et al. 2021 eq. 8, 1 the
    /// radial-friction paper's modal projection.
    pub(crate) modal_fraction: f64,
    /// `hertz_softening`: cubic coefficient β at zero preload [N/m³] (0: off).
    pub(crate) beta: f64,
    /// `hertz_softening`: relative growth of β per newton of preload [1/N].
    pub(crate) beta_gain: f64,
    /// Friction law of the generalised interface: the `radial_friction` ratio (the slip
    /// scale of `tangential_compliance` is set per contact by
    /// [`crate::interface::interface_law`]).
    pub(crate) law: crate::interface::Law,
    /// `tangential_compliance`: shear compliance κ of the layer relative to its normal
    /// compliance [-] (0: off).
    pub(crate) compliance: f64,
    /// `thermal_drift`: relative change per kelvin of (stiffness, friction, damping) [1/K].
    pub(crate) thermal: [f64; 3],
    /// `voltage_sag`: source resistance of the driver per phase [Ω] (0: off).
    pub(crate) sag_ohm: f64,
    /// `eccentricity`: axial runout δ of the rotor [m] (0: off).
    pub(crate) runout_m: f64,
    /// `radial_friction`'s preload exponent q: ρ·(F_N/100 N)^q [-] (0: ρ as given).
    pub(crate) radial_exponent: f64,
    /// `hertz_softening`'s preload exponent n: β·(1 + g·F_N)^n [-] (1: linear growth).
    pub(crate) beta_exponent: f64,
    /// `thermal_drift`: share of the rise on a fast interface node [-] (0: one capacity).
    pub(crate) thermal_interface: f64,
    /// `voltage_sag`: current amplitude per phase the driver holds its voltage up to [A]
    /// (0: a plain resistive source).
    pub(crate) sag_knee_a: f64,
    /// `eccentricity`: twice- and three-times-per-revolution ripple relative to the
    /// once-per-revolution one [-].
    pub(crate) runout_harmonics: [f64; 2],
    /// Per effect (registry order): its truth form (synthetic bench data) instead of its
    /// candidate form ([`Prepared::truth`]).
    pub(crate) truth_of: [bool; N_EFFECTS],
    /// Per effect: the second family of truth forms (docs/EFFECTS.md).
    pub(crate) truth_b_of: [bool; N_EFFECTS],
    /// Whether solutions report the stall torque. For the generalised interface it costs a
    /// numerical integral per solve (the rotor at rest) that the speed solve itself rarely
    /// needs; calibration reads only the observables and leaves it out
    /// ([`Prepared::without_stall_torque`]).
    pub(crate) stall_torque: bool,
    /// Work bound of each solve [units of [`super::WORK_BOUND`]].
    pub(crate) work_bound: u64,
}

impl Prepared {
    /// Precomputes the constants of `motor`.
    pub fn new(motor: &Motor) -> Prepared {
        let g = &motor.geometry;
        let fl = &motor.friction_layer;
        let st = &motor.stator;
        let fx = &motor.effects;
        Prepared {
            n: g.wave_number,
            r0: g.mean_radius_m,
            k: g.wave_number / g.mean_radius_m,
            kf: contact::layer_stiffness_n_per_m2(fl.youngs_modulus_pa, g.contact_width_m, fl.thickness_m),
            h0: g.neutral_plane_distance_m,
            mu: fl.friction_coefficient,
            m: st.modal_mass_kg,
            ks: stator::modal_stiffness_n_per_m(st.modal_mass_kg, st.resonance_frequency_hz),
            c: st.modal_damping_ns_per_m,
            theta: st.force_factor_n_per_v,
            c0: motor.electrical.clamped_capacitance_f,
            tan_d: motor.electrical.dielectric_loss_tangent,
            kfb: motor.electrical.feedback_gain_v_per_m,
            dr: motor.rotor.viscous_damping_nms,
            alpha_s: motor.thermal.heat_transfer_coefficient_w_per_m2k * motor.thermal.surface_area_m2,
            heat_cap: motor.thermal.heat_capacity_j_per_k,
            stiffening: fx.value(Effect::PreloadStiffening, 0),
            modal_fraction: fx.value(Effect::PreloadStiffening, 1),
            beta: fx.value(Effect::HertzSoftening, 0),
            beta_gain: fx.value(Effect::HertzSoftening, 1),
            law: crate::interface::Law {
                radial_ratio: fx.value(Effect::RadialFriction, 0),
                slip_scale: 0.0,
                truth: fx.is_truth_form(Effect::TangentialCompliance),
                truth_radial: fx.is_truth_form(Effect::RadialFriction),
                sharpness: if fx.is_on(Effect::TangentialCompliance) {
                    fx.value(Effect::TangentialCompliance, 1)
                } else {
                    1.0
                },
            },
            compliance: fx.value(Effect::TangentialCompliance, 0),
            thermal: [0, 1, 2].map(|i| fx.value(Effect::ThermalDrift, i)),
            sag_ohm: fx.value(Effect::VoltageSag, 0),
            runout_m: fx.value(Effect::Eccentricity, 0),
            radial_exponent: fx.value(Effect::RadialFriction, 1),
            beta_exponent: if fx.is_on(Effect::HertzSoftening) { fx.value(Effect::HertzSoftening, 2) } else { 1.0 },
            thermal_interface: fx.value(Effect::ThermalDrift, 3),
            sag_knee_a: fx.value(Effect::VoltageSag, 1),
            runout_harmonics: [fx.value(Effect::Eccentricity, 1), fx.value(Effect::Eccentricity, 2)],
            truth_of: ALL.map(|e| fx.is_truth_form(e)),
            truth_b_of: ALL.map(|e| fx.is_truth_form_b(e)),
            stall_torque: true,
            work_bound: super::WORK_BOUND,
        }
    }

    /// True when effect `e` takes a truth form (either family).
    #[inline]
    pub(crate) fn truth(&self, e: Effect) -> bool {
        self.truth_of[e as usize]
    }

    /// True when effect `e` takes the second family of truth forms.
    #[inline]
    pub(crate) fn truth_b(&self, e: Effect) -> bool {
        self.truth_b_of[e as usize]
    }

    /// The same motor with `stall_torque_nm` left NaN wherever it would cost an integral
    /// the solve does not need (the generalised interface). Every other quantity, and the
    /// status, is bit for bit what [`Prepared::new`] gives; NaN there is not a failed solve.
    /// For the calibration's model passes, which read only the observables.
    pub(crate) fn without_stall_torque(mut self) -> Prepared {
        self.stall_torque = false;
        self
    }

    /// The same motor with every solve bounded at `units` of work instead of
    /// [`super::WORK_BOUND`]: interface-integrand evaluations at quadrature nodes (35-95 ns
    /// each on the reference machine) plus 10 per amplitude trial (docs/RELIABILITY.md,
    /// "The work bound of a solve"). Any value is valid: 0 computes no trial, `u64::MAX`
    /// never ends a solve. A solve that spends its bound is `no_convergence` with
    /// [`Solution::work_bound_reached`]; every other solve is bit for bit the one of
    /// [`Prepared::new`].
    pub fn with_work_bound(mut self, units: u64) -> Prepared {
        self.work_bound = units;
        self
    }

    /// True when every quantity `s` reports is a number (the stall torque excepted where
    /// it is not computed).
    pub(super) fn all_finite(&self, s: &Solution) -> bool {
        use crate::quantities::{values, STALL_TORQUE_INDEX};
        let mut v = values(s);
        if !self.stall_torque && s.stall_torque_nm.is_nan() {
            v[STALL_TORQUE_INDEX] = 0.0;
        }
        // 0·x is ±0 for a number and NaN for ±∞ and NaN: one sum without a branch per
        // quantity (this runs for every solved point)
        v.iter().map(|x| 0.0 * x).sum::<f64>() == 0.0
    }
}

impl Prepared {
    /// True when a trial amplitude (the contact, interface and amplitude map) comes out the
    /// same for `self` as for `other` at every state: they differ at most in constants that
    /// act only on the reported outputs (capacitance, dielectric loss, feedback gain, the
    /// thermal network) and neither iterates on a solution-dependent input at `op`, through
    /// which those constants would reach the drive.
    pub(crate) fn same_trials(&self, other: &Prepared, op: &OperatingPoint) -> bool {
        let outputs_only = Prepared {
            c0: other.c0,
            tan_d: other.tan_d,
            kfb: other.kfb,
            alpha_s: other.alpha_s,
            heat_cap: other.heat_cap,
            stall_torque: other.stall_torque,
            work_bound: other.work_bound,
            ..self.clone()
        };
        outputs_only == *other && iterated(self, op) == (false, false)
    }
}
