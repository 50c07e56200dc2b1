//! What the solver reports for one operating point: its status and every quantity of the
//! steady state. Shared by the solver and the quantity table (`crate::quantities`).

use crate::limits::LimitWarnings;

/// Whether the model has a physical solution at the point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// Converged, rotor turning.
    Ok,
    /// The load torque is at or above the stall (blocking) torque: the rotor is at rest.
    /// All quantities are valid (speed and output power are zero).
    Stall,
    /// The friction forces clamp the stator: no vibrating steady state exists at this
    /// drive (amplitude zero), or, with `voltage_sag`, the moving stator would sag its
    /// drive below clamping and the clamped one's recovered voltage cannot start it. Valid,
    /// with zero amplitude, speed and output.
    Clamped,
    /// No steady state was found: the iteration did not converge, or, with `voltage_sag`
    /// or `thermal_drift`, the state jumps between a moving and a clamped (or stalled) one
    /// at every pass (the motor hunts, docs/EFFECTS.md). Numbers are the last iterate and
    /// must not be used. Also the status of a solve that spent its work bound
    /// ([`Solution::work_bound_reached`]).
    NoConvergence,
    /// The operating point itself is invalid (non-finite, non-positive preload, ...).
    InvalidInput,
}

impl Status {
    /// The word written in status columns.
    pub const fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Stall => "stall",
            Status::Clamped => "clamped",
            Status::NoConvergence => "no_convergence",
            Status::InvalidInput => "invalid_input",
        }
    }
    /// True when the numbers describe a physical steady state.
    pub fn is_valid(self) -> bool {
        matches!(self, Status::Ok | Status::Stall | Status::Clamped)
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Every quantity of one steady operating point (SI, unit in each name).
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Whether the numbers are a physical steady state.
    pub status: Status,
    /// True when the rotor touches the whole wave.
    pub full_contact: bool,
    /// Amplitude evaluations the solver used.
    pub iterations: u32,
    /// Wave amplitude W at the contact surface [m].
    pub amplitude_m: f64,
    /// Contact half-angle φ0 in wave phase [rad].
    pub contact_half_angle_rad: f64,
    /// Contact angle Xc, full arc in mechanical degrees (0-40° for N = 9).
    pub contact_angle_deg: f64,
    /// Contact length 2·x0 per wave [m].
    pub contact_length_m: f64,
    /// Stick (equal-speed) half-angle θs in wave phase [rad].
    pub stick_half_angle_rad: f64,
    /// Driving angle Xs, full arc in mechanical degrees.
    pub driving_angle_deg: f64,
    /// Proportion of the driving zone in the contact zone, θs/φ0 [-].
    pub driving_ratio: f64,
    /// Rotor speed [rad/s].
    pub speed_rad_s: f64,
    /// Rotor speed [rev/min].
    pub speed_rpm: f64,
    /// Peak tangential speed of the stator surface at the crest [m/s].
    pub crest_speed_m_s: f64,
    /// Load torque [N·m].
    pub torque_nm: f64,
    /// Stall (blocking) torque at this preload and drive [N·m].
    pub stall_torque_nm: f64,
    /// Axial contact force [N] (equals the preload at equilibrium).
    pub axial_force_n: f64,
    /// Electrical input power, both phases [W].
    pub input_power_w: f64,
    /// Mechanical output power T_load·Ω [W].
    pub output_power_w: f64,
    /// Dielectric loss of the piezoceramic, both phases [W].
    pub dielectric_loss_w: f64,
    /// Structural damping loss of the stator [W].
    pub damping_loss_w: f64,
    /// Friction loss in the contact interface [W].
    pub friction_loss_w: f64,
    /// Of which radial slip (nonzero only with `radial_friction`) [W].
    pub radial_friction_loss_w: f64,
    /// Rotor viscous loss d_r·Ω² [W].
    pub rotor_loss_w: f64,
    /// Output power / input power, in [0, 1].
    pub efficiency: f64,
    /// Feedback-electrode voltage amplitude [V].
    pub feedback_v: f64,
    /// Drive current amplitude per phase [A].
    pub current_a: f64,
    /// Part of the phase current in phase with the electrode voltage [A].
    pub current_in_phase_a: f64,
    /// Part of the phase current in quadrature (leading) [A].
    pub current_quadrature_a: f64,
    /// Of which the clamped capacitance's current ω·C0·V [A] (the rest is the motional
    /// branch's).
    pub capacitive_current_a: f64,
    /// Voltage at the electrodes, zero-to-peak [V] (below the set voltage with `voltage_sag`).
    pub electrode_voltage_v: f64,
    /// Phase lag ψ of the wave behind the drive [rad].
    pub phase_lag_rad: f64,
    /// Effective modal stiffness including effects [N/m].
    pub modal_stiffness_n_per_m: f64,
    /// Steady-state temperature rise of the motor over ambient [K] (Chen et al. 2020 eq.
    /// 11, t → ∞).
    pub temperature_rise_k: f64,
    /// Temperature rise at the point's elapsed time [K] (Chen et al. 2020 eq. 11).
    pub temperature_rise_at_elapsed_k: f64,
    /// Standard deviation of speed over a revolution [rev/min] (nonzero with `eccentricity`).
    pub speed_std_rpm: f64,
    /// The motor's `[limits]` this point exceeds ([`crate::limits`]); empty when it is
    /// inside all of them. Never changes the status or the numbers.
    pub warnings: LimitWarnings,
    /// True when the solve stopped because it spent its work bound
    /// ([`crate::solve::WORK_BOUND`], [`crate::solve::Prepared::with_work_bound`]) before it
    /// found a steady state; the status is then `NoConvergence` and the numbers must not be
    /// used. False for every other status and every other reason of `NoConvergence`.
    pub work_bound_reached: bool,
}

impl Solution {
    /// Reactive power of both phases [var]: V·I_q, the electrode voltage amplitude times the
    /// quadrature (leading) part of the phase current amplitude, as the input power is
    /// V·I_p (two phases of ½·V·I each). Positive for the capacitive current of a
    /// piezoelectric stator.
    pub fn reactive_power_var(&self) -> f64 {
        self.electrode_voltage_v * self.current_quadrature_a
    }

    /// The clamped capacitance's part of [`Solution::reactive_power_var`] [var]:
    /// V·ω·C0·V, both phases. Used by the bench's power-meter model
    /// ([`crate::effects::Instrument::power_reading_w`]).
    pub fn capacitive_reactive_power_var(&self) -> f64 {
        self.electrode_voltage_v * self.capacitive_current_a
    }

    /// Sum of all losses [W].
    pub fn total_loss_w(&self) -> f64 {
        self.dielectric_loss_w + self.damping_loss_w + self.friction_loss_w + self.rotor_loss_w
    }

    pub(crate) fn invalid(status: Status) -> Solution {
        let n = f64::NAN;
        Solution {
            status,
            full_contact: false,
            iterations: 0,
            amplitude_m: n,
            contact_half_angle_rad: n,
            contact_angle_deg: n,
            contact_length_m: n,
            stick_half_angle_rad: n,
            driving_angle_deg: n,
            driving_ratio: n,
            speed_rad_s: n,
            speed_rpm: n,
            crest_speed_m_s: n,
            torque_nm: n,
            stall_torque_nm: n,
            axial_force_n: n,
            input_power_w: n,
            output_power_w: n,
            dielectric_loss_w: n,
            damping_loss_w: n,
            friction_loss_w: n,
            radial_friction_loss_w: n,
            rotor_loss_w: n,
            efficiency: n,
            feedback_v: n,
            current_a: n,
            current_in_phase_a: n,
            current_quadrature_a: n,
            capacitive_current_a: n,
            electrode_voltage_v: n,
            phase_lag_rad: n,
            modal_stiffness_n_per_m: n,
            temperature_rise_k: n,
            temperature_rise_at_elapsed_k: n,
            speed_std_rpm: n,
            warnings: LimitWarnings::NONE,
            work_bound_reached: false,
        }
    }
}
