//! Transient (step) response of a TRUM with a discretised stick-slip contact (the bar-type transient paper).
//!
//! Degrees of freedom (Chen et al. 2020 Appendix A, eq. A1-A4 with ε = 0; the bar-type transient paper eq. 3-5):
//!
//! ```text
//! stator modes  m·q̈_A + c·q̇_A + k_s·q_A = Θ·V·cos ωt        + Q_A
//!               m·q̈_B + c·q̇_B + k_s·q_B = Θ·V·cos(ωt − Δφ) + Q_B
//! rotor, axial  m_r·z̈ + d_z·ż + k_sp·(z − z₀) = F_c − F_N      (the bar-type transient paper eq. 5)
//! rotor, turn   J_r·Ω̇ + d_r·Ω = T_c − T_load·sign Ω            (the bar-type transient paper eq. 4)
//! ```
//!
//! The load is a Coulomb brake of magnitude T_load ≥ 0 (a brake, a dynamometer, bearing
//! friction): it opposes the rotation in either direction, and at rest (Ω = 0) it holds
//! the rotor against any contact torque |T_c| ≤ T_load. The rotor equation is therefore
//! odd in Ω, so a reversed wave (Δφ = −90°) under a load is the mirror image of the
//! forward one. While the rotor turns forwards it is the constant load of eq. 4.
//!
//! The surface displacement is w(x, t) = q_A·cos kx + q_B·sin kx (k = N/R0); Δφ = +90°
//! gives a wave travelling towards +x. One wavelength is cut into `nodes_per_wavelength`
//! nodes (256 in the bar-type transient paper); all N waves are identical, so every sum is multiplied by N.
//! Node j carries a Winkler spring (Chen et al. 2020 eq. 3, Sun et al. 2021 eq. 5)
//! p_j = k_f·Δx·max(0, w(x_j) − z) with k_f = E_f·b_f/h_f, and a tangential spring of
//! stiffness k_t·Δx (the rotor-side springs of the bar-type transient paper, Fig. 7) whose deflection δ_j
//! follows the relative surface displacement u_s − u_r. The stator surface moves
//! tangentially by u_s = h0·∂w/∂x, i.e. with speed h0·∂²w/∂x∂t, counted positive in the
//! rotor's positive sense (the surface at a crest moves against the wave, so the
//! rotor turns opposite to the wave; for Δφ = +90° its speed is positive).
//!
//! **Coulomb stick-slip per node (the bar-type transient paper eq. 1-2), by return mapping.** Each step the
//! trial force f* = k_t·Δx·(δ_j + Δu_s − Δu_r) is the tangential force that keeps the node
//! from slipping over the step. If |f*| ≤ μ·p_j the node sticks (f = f*, eq. 2 not
//! satisfied); otherwise it slips with f = μ·p_j·sign(f*) (eq. 1; the sign of f* is the
//! sign of the slip v_s − v_r once the node slips) and δ_j is reset to f/(k_t·Δx). This
//! is Coulomb's law exactly, for a friction layer with tangential compliance 1/k_t; no
//! velocity threshold or smoothing is involved. As k_t → ∞ the stick zones shrink to
//! the two stick points of the rigid steady model ([`crate::contact`]) and the result
//! converges to [`crate::solve`]; the bar-type transient paper's wide stick zones appear for a soft layer
//! (k_t ≈ G·b_f/h_f ≈ k_f/2.6). See [`TransientConfig::tangential_stiffness_ratio`].
//!
//! Generalised contact forces (virtual work, mode shapes cos kx and sin kx at the
//! surface, so the same modal mass as [`crate::stator`]):
//! Q_A = N·Σ f_j·h0·k·sin kx_j, Q_B = −N·Σ f_j·h0·k·cos kx_j, torque T_c = N·R0·Σ f_j,
//! axial force F_c = N·Σ p_j. The normal forces' modal projection −N·Σ p_j·(cos, sin) is
//! left out by default, as in the steady model (it is a contact stiffening, the
//! `preload_stiffening` effect with `modal_fraction = 1`); [`TransientConfig::normal_modal_coupling`] adds it.
//!
//! Integrator: see [`sim`](self) (kick-drift-kick Verlet with implicit linear damping and
//! exact kinematic slip increments). Effects in `Motor::effects` are not modelled here.

use crate::params::Motor;
use crate::solve::{solve, OperatingPoint, Status};
use thiserror::Error;

mod metrics;
pub(crate) mod sim;
#[cfg(test)]
mod tests;

pub use metrics::step_metrics;

/// Default axial damping of the rotor d_z [N·s/m] (Chen et al. 2020 Table A1).
pub const DEFAULT_AXIAL_DAMPING_NS_PER_M: f64 = 1.5e4;

/// Default tangential penalty stiffness of a node, as a multiple of the Winkler stiffness k_f.
pub const DEFAULT_TANGENTIAL_STIFFNESS_RATIO: f64 = 300.0;

/// Settings of one step-response run. All fields SI. The drive (both phases, amplitude
/// `voltage_v`) is switched on at t = 0 with the stator at rest and the rotor at rest on
/// its preloaded equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub struct TransientConfig {
    /// Simulated time [s], > 0.
    pub duration_s: f64,
    /// Time steps per drive period (≥ 16; 64-128 recommended).
    pub steps_per_period: usize,
    /// Contact nodes over one wavelength (≥ 8; 256 in the bar-type transient paper).
    pub nodes_per_wavelength: usize,
    /// Phase of phase B behind phase A [rad]; π/2 = travelling wave, 0 = standing wave.
    pub phase_difference_rad: f64,
    /// Load torque on the rotor T_load [N·m], ≥ 0: a Coulomb brake, T_load·sign Ω against
    /// the rotation in either direction, holding the rotor at rest while |T_c| ≤ T_load
    /// (the bar-type transient paper eq. 4, see the module doc).
    pub load_torque_nm: f64,
    /// Drive voltage amplitude per phase, zero-to-peak [V], > 0.
    pub voltage_v: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
    /// Axial preload F_N [N], > 0.
    pub preload_n: f64,
    /// Record the time series every this many steps (≥ 1).
    pub record_every: usize,
    /// Times [s] at which to return the contact state per node (each in [0, duration]).
    pub snapshot_times_s: Vec<f64>,
    /// Axial damping of the rotor d_z [N·s/m], > 0 (default 1.5e4, Chen et al. 2020 Table A1).
    pub axial_damping_ns_per_m: f64,
    /// Tangential stiffness of the contact layer per unit length as a multiple of
    /// k_f = E_f·b_f/h_f, > 0. The default 300 is a penalty stiffness: the settled speed
    /// then lies ≈ 100/√300 ≈ 6 % above the rigid-Coulomb steady model (error ∝ ratio^(-1/2)); ≈ 0.38 (G = E/2.6) is the
    /// physical shear stiffness of a solid layer.
    pub tangential_stiffness_ratio: f64,
    /// Project the normal contact forces on the stator modes (contact stiffening,
    /// Chen et al. 2020 eq. A4 F_dn). Off by default, like the steady model.
    pub normal_modal_coupling: bool,
}

impl Default for TransientConfig {
    /// 10 ms at 200 V, 43 kHz, 260 N, no load, 90°, 64 steps/period, 256 nodes.
    fn default() -> Self {
        TransientConfig {
            duration_s: 10e-3,
            steps_per_period: 64,
            nodes_per_wavelength: 256,
            phase_difference_rad: 0.5 * std::f64::consts::PI,
            load_torque_nm: 0.0,
            voltage_v: 200.0,
            frequency_hz: 43e3,
            preload_n: 260.0,
            record_every: 16,
            snapshot_times_s: Vec::new(),
            axial_damping_ns_per_m: DEFAULT_AXIAL_DAMPING_NS_PER_M,
            tangential_stiffness_ratio: DEFAULT_TANGENTIAL_STIFFNESS_RATIO,
            normal_modal_coupling: false,
        }
    }
}

/// Errors of [`step_response`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TransientError {
    /// A configuration value is out of range or not finite.
    #[error("invalid `{name}` = {value}: {reason}")]
    InvalidConfig {
        /// Field name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// The motor parameters do not validate.
    #[error("invalid motor: {0}")]
    InvalidMotor(String),
    /// The explicit scheme would be unstable: ω_max·h exceeds the limit.
    #[error("time step too large: ω_max·h = {omega_h:.3} > {limit} (stiffest mode {what}); raise steps_per_period")]
    StepTooLarge {
        /// Estimated ω_max·h of the stiffest contact mode.
        omega_h: f64,
        /// Accepted limit.
        limit: f64,
        /// Which mode.
        what: &'static str,
    },
    /// The run would take more steps than the limit.
    #[error("too many steps: {steps} > {limit}")]
    TooManySteps {
        /// Requested steps.
        steps: u64,
        /// Limit.
        limit: u64,
    },
    /// The state became non-finite.
    #[error("the simulation diverged at t = {time_s} s")]
    Diverged {
        /// Time of the first non-finite state [s].
        time_s: f64,
    },
}

/// Recorded time series (every `record_every` steps, starting at t = 0).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimeSeries {
    /// Time [s].
    pub time_s: Vec<f64>,
    /// Instantaneous rotor speed [rpm].
    pub speed_rpm: Vec<f64>,
    /// Rotor speed averaged over the last drive period [rpm] (zero before t = 0).
    pub speed_period_mean_rpm: Vec<f64>,
    /// Wave amplitude √(q_A² + q_B²) [m].
    pub amplitude_m: Vec<f64>,
    /// Rotor axial position z relative to its rest position before the drive starts [m].
    pub axial_position_m: Vec<f64>,
    /// Contact (friction) torque on the rotor T_c [N·m].
    pub torque_nm: Vec<f64>,
    /// Axial contact force F_c [N].
    pub axial_force_n: Vec<f64>,
}

/// Contact state of one node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeState {
    /// The stator surface is below the rotor: no force.
    NoContact,
    /// In contact and not slipping: |f| ≤ μ·p (the bar-type transient paper eq. 2 not satisfied).
    Stick,
    /// In contact and slipping: f = μ·p·sign(slip) (the bar-type transient paper eq. 1).
    Slip,
}

impl NodeState {
    /// The word written in `state` columns: `no_contact`, `stick`, `slip`.
    pub fn as_str(self) -> &'static str {
        match self {
            NodeState::NoContact => "no_contact",
            NodeState::Stick => "stick",
            NodeState::Slip => "slip",
        }
    }
}

/// One contact node at a snapshot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeSample {
    /// Position along the wavelength x_j ∈ [0, λ) [m].
    pub position_m: f64,
    /// Contact pressure per unit circumferential length [N/m].
    pub pressure_n_per_m: f64,
    /// Tangential friction force on the rotor per unit length, positive driving [N/m].
    pub tangential_force_n_per_m: f64,
    /// Slip speed v_s − v_r of the stator surface over the rotor [m/s].
    pub slip_speed_m_s: f64,
    /// Stick, slip or no contact.
    pub state: NodeState,
}

/// Distribution of the contact forces over one wavelength at one instant (the bar-type transient paper Fig. 10).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Requested time [s].
    pub requested_time_s: f64,
    /// Time of the step the snapshot was taken at (the step nearest the request) [s].
    pub time_s: f64,
    /// Rotor speed at that instant [rpm].
    pub speed_rpm: f64,
    /// The nodes, in order of position.
    pub nodes: Vec<NodeSample>,
}

impl Snapshot {
    /// Number of nodes in each state: (no contact, stick, slip).
    pub fn counts(&self) -> (usize, usize, usize) {
        let c = |s| self.nodes.iter().filter(|n| n.state == s).count();
        (c(NodeState::NoContact), c(NodeState::Stick), c(NodeState::Slip))
    }
}

/// Step-response figures of the period-averaged speed (control-textbook definitions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepMetrics {
    /// Final speed: mean over the averaging window at the end of the run [rpm].
    pub final_speed_rpm: f64,
    /// Largest period-averaged speed in the direction of the final speed (the most
    /// negative one when the rotor turns backwards) [rpm].
    pub peak_speed_rpm: f64,
    /// Delay time: first time the speed reaches 50 % of the final speed [s].
    pub delay_s: Option<f64>,
    /// Rise time from 10 % to 90 % of the final speed [s].
    pub rise_time_s: Option<f64>,
    /// 0-100 % rise time: first time the speed reaches the final speed [s] (the rise
    /// time of an underdamped response in Ogata's definitions; `None` without overshoot
    /// when the speed never reaches it).
    pub rise_to_final_s: Option<f64>,
    /// Peak time: when the speed reaches its largest value [s].
    pub peak_time_s: Option<f64>,
    /// Overshoot (peak − final)/final, ≥ 0 [-].
    pub overshoot: Option<f64>,
    /// Time after which the speed stays within ±2 % of the final speed [s]
    /// (`None` if it is still outside the band at the end of the record).
    pub settling_time_s: Option<f64>,
}

impl StepMetrics {
    /// `ok` (moving, in either direction: a negative final speed is rotation the other
    /// way); `not_moving` (the rotor is at rest at the end, so no metrics, e.g. a standing
    /// wave); `not_settled` (still outside the ±2 % band at the end of the run).
    pub fn status(&self) -> &'static str {
        if self.delay_s.is_none() {
            "not_moving"
        } else if self.settling_time_s.is_none() {
            "not_settled"
        } else {
            "ok"
        }
    }
}

/// Means over the last whole drive periods of the run (at least 20 % of it), taken at
/// every step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyAverages {
    /// Length of the averaging window [s].
    pub window_s: f64,
    /// Mean rotor speed [rpm].
    pub speed_rpm: f64,
    /// Mean contact torque on the rotor [N·m].
    pub contact_torque_nm: f64,
    /// Mean wave amplitude √(q_A² + q_B²) [m].
    pub amplitude_m: f64,
    /// Mean axial contact force [N].
    pub axial_force_n: f64,
    /// Mean fraction of the wavelength in contact [-].
    pub contact_fraction: f64,
    /// Mean fraction of the wavelength sticking [-].
    pub stick_fraction: f64,
}

/// Result of [`step_response`].
#[derive(Clone, Debug, PartialEq)]
pub struct StepResponse {
    /// Recorded time series.
    pub series: TimeSeries,
    /// Step-response metrics.
    pub metrics: StepMetrics,
    /// Means at the end of the run.
    pub averages: SteadyAverages,
    /// Snapshots, in the order of `snapshot_times_s`.
    pub snapshots: Vec<Snapshot>,
    /// Time step used [s].
    pub time_step_s: f64,
    /// Steps taken.
    pub steps: u64,
}

/// Largest number of steps accepted.
pub const MAX_STEPS: u64 = 50_000_000;

fn check(name: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<(), TransientError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(TransientError::InvalidConfig { name, value, reason })
    }
}

impl TransientConfig {
    /// Checks every field; the error names the first offending one.
    pub fn validate(&self) -> Result<(), TransientError> {
        check("duration_s", self.duration_s, self.duration_s > 0.0, "must be finite and > 0")?;
        let spp = self.steps_per_period as f64;
        check("steps_per_period", spp, self.steps_per_period >= 16, "must be >= 16")?;
        let npw = self.nodes_per_wavelength as f64;
        check("nodes_per_wavelength", npw, self.nodes_per_wavelength >= 8, "must be >= 8")?;
        check("phase_difference_rad", self.phase_difference_rad, true, "must be finite")?;
        check("load_torque_nm", self.load_torque_nm, self.load_torque_nm >= 0.0, "must be finite and >= 0")?;
        check("voltage_v", self.voltage_v, self.voltage_v > 0.0, "must be finite and > 0")?;
        check("frequency_hz", self.frequency_hz, self.frequency_hz > 0.0, "must be finite and > 0")?;
        check("preload_n", self.preload_n, self.preload_n > 0.0, "must be finite and > 0")?;
        check("record_every", self.record_every as f64, self.record_every >= 1, "must be >= 1")?;
        for &t in &self.snapshot_times_s {
            check("snapshot_times_s", t, t >= 0.0 && t <= self.duration_s, "must lie in [0, duration_s]")?;
        }
        let dz = self.axial_damping_ns_per_m;
        check("axial_damping_ns_per_m", dz, dz > 0.0, "must be finite and > 0")?;
        let kt = self.tangential_stiffness_ratio;
        check("tangential_stiffness_ratio", kt, kt > 0.0, "must be finite and > 0")?;
        let steps = (self.duration_s * self.frequency_hz * spp).ceil();
        if steps > MAX_STEPS as f64 {
            return Err(TransientError::TooManySteps { steps: steps as u64, limit: MAX_STEPS });
        }
        Ok(())
    }
}

/// Simulates the start-up of the motor after a voltage step and returns the time series,
/// the step metrics, the end-of-run averages and the requested contact snapshots.
/// Never panics: invalid settings, an unstable time step or divergence are errors.
pub fn step_response(motor: &Motor, cfg: &TransientConfig) -> Result<StepResponse, TransientError> {
    cfg.validate()?;
    motor.validate("motor", None).map_err(|e| TransientError::InvalidMotor(e.to_string()))?;
    let plant = sim::ring_plant(motor, cfg);
    Ok(response(sim::run(&plant)?, &plant))
}

/// [`step_response`] at `cfg.steps_per_period`, or, where the explicit scheme would be
/// unstable there ([`TransientError::StepTooLarge`]), at the smallest multiple of 16 steps
/// per period that brings the stiffest mode's ω_max·h to 95 % of its limit (h is the period
/// over the steps, so ω_max·h falls as 1/steps), up to [`MAX_STEP_REFINEMENT`] times the
/// given steps; beyond that the refusal stands, since the run would cost that many times
/// more. For front-ends whose user left the time step to the tool: a stiffer contact
/// layer needs a finer step, and the default 64 steps must not turn into an error.
/// Returns the response and the steps per period used.
pub fn step_response_stable(motor: &Motor, cfg: &TransientConfig) -> Result<(StepResponse, usize), TransientError> {
    match step_response(motor, cfg) {
        Err(TransientError::StepTooLarge { omega_h, limit, what }) if omega_h.is_finite() => {
            let need = (cfg.steps_per_period as f64 * omega_h / (0.95 * limit) / 16.0).ceil() * 16.0;
            if need > (MAX_STEP_REFINEMENT * cfg.steps_per_period) as f64 {
                return Err(TransientError::StepTooLarge { omega_h, limit, what });
            }
            let steps = (need as usize).max(cfg.steps_per_period + 16);
            let raised = TransientConfig { steps_per_period: steps, ..cfg.clone() };
            step_response(motor, &raised).map(|r| (r, steps))
        }
        r => r.map(|r| (r, cfg.steps_per_period)),
    }
}

/// How many times the given steps per period [`step_response_stable`] may take.
pub const MAX_STEP_REFINEMENT: usize = 4;

/// Fraction of the stator surface's peak tangential speed below which a settled rotor
/// counts as at rest (`not_moving`): a standing wave leaves the rotor at rounding-error
/// speeds, a travelling wave drives it at a sizeable fraction of the surface speed.
pub const REST_SPEED_FRACTION: f64 = 1e-3;

/// The metrics of a run's period-averaged speed. A final speed of either sign is motion
/// (a reversed travelling wave turns the rotor backwards); one below
/// [`REST_SPEED_FRACTION`] of the surface speed ω·h0·k·A/R0 is rest.
pub(crate) fn response(out: sim::RunOutput, plant: &sim::Plant) -> StepResponse {
    let k = plant.n_waves / plant.r0;
    let surface_rpm = crate::stator::angular_frequency(plant.frequency_hz) * plant.h0 * k * out.averages.amplitude_m
        / plant.r0
        * crate::solve::RAD_S_TO_RPM;
    let v = out.averages.speed_rpm;
    let moving = v.abs() > REST_SPEED_FRACTION * surface_rpm;
    let mut metrics = step_metrics(&out.series.time_s, &out.series.speed_period_mean_rpm, if moving { v } else { 0.0 });
    metrics.final_speed_rpm = v;
    StepResponse {
        series: out.series,
        metrics,
        averages: out.averages,
        snapshots: out.snapshots,
        time_step_s: out.time_step_s,
        steps: out.steps,
    }
}

/// The steady-state solver's answer at the operating point of a run, in the terms of
/// [`SteadyAverages`], signed as the run's rotation, to compare a settled transient with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyComparison {
    /// Status of the steady solution; the numbers are NaN unless it is valid.
    pub status: Status,
    /// Steady rotor speed [rpm], negative for a reversed wave (Δφ = −90°).
    pub speed_rpm: f64,
    /// Contact torque at steady state: the load plus the rotor's viscous torque,
    /// (T_load + d_r·|Ω|)·sign Ω [N·m] (negative with the speed for a reversed wave).
    pub contact_torque_nm: f64,
    /// Steady wave amplitude [m].
    pub amplitude_m: f64,
}

/// Largest |cos Δφ| at which a run's drive counts as a pure travelling wave (Δφ = ±90°
/// within about 6·10⁻⁸ degrees): the only drive the steady model describes. Degrees
/// converted to radians leave |cos| ≈ 10⁻¹⁶ at ±90°.
pub const TRAVELLING_WAVE_COS_TOLERANCE: f64 = 1e-9;

/// Why a run has no steady comparison ([`steady_comparison`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SteadyGap {
    /// The phase difference is not ±90°: the drive is a travelling wave plus a standing
    /// part, which the steady model (a pure travelling wave) does not describe.
    StandingPart {
        /// Phase of phase B behind phase A [deg].
        phase_difference_deg: f64,
    },
}

impl SteadyGap {
    /// A one-word name for status columns.
    pub const fn as_str(self) -> &'static str {
        match self {
            SteadyGap::StandingPart { .. } => "standing_wave_part",
        }
    }
}

impl std::fmt::Display for SteadyGap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            // (the phase is left out: a sweep's note lists the phases of one reason)
            SteadyGap::StandingPart { .. } => f.write_str(
                "a phase difference other than +90 or -90 deg makes the drive partly a standing wave; \
                 the steady model describes a pure travelling wave only",
            ),
        }
    }
}

/// Solves the steady model ([`crate::solve`]) at the preload, load, voltage and frequency
/// of `cfg`, for the direction of its travelling wave: at Δφ = +90° as it is; at −90°
/// mirrored, with or without load (the contact is symmetric under x → −x and the rotor
/// equation, whose brake opposes the rotation either way, is odd in Ω), so speed and
/// contact torque take the reversed wave's negative sign. Any other phase difference is
/// outside the steady model: the [`SteadyGap`] says why, and no number is given.
pub fn steady_comparison(motor: &Motor, cfg: &TransientConfig) -> Result<SteadyComparison, SteadyGap> {
    let (sin, cos) = cfg.phase_difference_rad.sin_cos();
    if cos.is_nan() || cos.abs() > TRAVELLING_WAVE_COS_TOLERANCE {
        return Err(SteadyGap::StandingPart { phase_difference_deg: cfg.phase_difference_rad.to_degrees() });
    }
    let direction = sin.signum();
    let s = solve(motor, &OperatingPoint::new(cfg.preload_n, cfg.load_torque_nm, cfg.voltage_v, cfg.frequency_hz));
    let valid = s.status.is_valid();
    let v = |x: f64| if valid { x } else { f64::NAN };
    Ok(SteadyComparison {
        status: s.status,
        speed_rpm: v(direction * s.speed_rpm),
        contact_torque_nm: v(direction * (cfg.load_torque_nm + motor.rotor.viscous_damping_nms * s.speed_rad_s)),
        amplitude_m: v(s.amplitude_m),
    })
}
