//! Every reported quantity of a steady state from its converged trial: speed, torques,
//! losses, current, efficiency and temperature; and the clamped stator's trial.

use super::trial::{Drive, Trial};
use super::{OperatingPoint, Prepared, Solution, Status, RAD_S_TO_RPM};
use crate::contact::{self, Contact};
use crate::interface::interface_law;
use crate::stator;
use std::f64::consts::PI;

pub(super) fn clamped_trial(p: &Prepared, d: &Drive) -> Trial {
    Trial {
        w: 0.0,
        contact: Contact { half_angle_rad: PI, offset: f64::NEG_INFINITY, full: true },
        chi0: f64::INFINITY,
        ts: 0.5 * PI,
        vr: 0.0,
        stalled: true,
        a: 0.0,
        v0: 0.0,
        tf: 0.0,
        pf: 0.0,
        rf: 0.0,
        tf0: 0.0,
        z: (p.ks - p.m * d.omega * d.omega, f64::INFINITY),
        k_eff: d.ks,
        w_next: 0.0,
        slope: f64::NAN,
        carry: [None; 2],
    }
}

/// The torque factor with the rotor at rest: the generalised interface leaves this
/// integral to the converged trial (NaN until then). Taken by the rule the speed solve
/// takes at u = 0 (`factors_reusing`: the speed-free nodes where the integrand's nearest
/// singularity is far from the contact, within 1e-12 of the split rule), so it is the
/// value the speed solve finds wherever it integrates at rest itself.
pub(super) fn rest_torque_factor(p: &Prepared, d: &Drive, t: &Trial) -> f64 {
    if t.tf0.is_nan() {
        let law = interface_law(p, d, &t.contact);
        crate::interface::factors_reusing(&t.contact, 0.0, &law, &mut crate::interface::SpeedFreeRule::new()).torque
    } else {
        t.tf0
    }
}

pub(super) fn finish(p: &Prepared, d: &Drive, op: &OperatingPoint, t: &Trial, status: Status, evals: u32) -> Solution {
    let mut s = finish_unchecked(p, d, op, t, status, evals);
    // Extreme but valid inputs (1e-300 V, 1e200 Hz resonance, ...) can overflow; such a
    // point has no trustworthy solution and must say so rather than report NaN as ok.
    if s.status.is_valid() && !p.all_finite(&s) {
        s.status = Status::NoConvergence;
    }
    s
}

fn finish_unchecked(p: &Prepared, d: &Drive, op: &OperatingPoint, t: &Trial, status: Status, evals: u32) -> Solution {
    let w = t.w;
    let ct = &t.contact;
    let clamped = status == Status::Clamped;
    let speed = if t.stalled { 0.0 } else { t.vr / p.r0 };
    let vr = speed * p.r0;
    let tf0 = if clamped || !p.stall_torque { t.tf0 } else { rest_torque_factor(p, d, t) };
    let stall_torque = if clamped { 0.0 } else { p.r0 * d.mu * t.a * tf0 };
    // Friction loss = ∫ μ p |slip| dx = power taken from the wave − power given to the rotor
    // (for the baseline this is crate::losses::friction_loss_coulomb_w, tested against quadrature).
    let scale = 2.0 * p.n * d.mu * p.kf * w / p.k;
    let friction = if clamped { 0.0 } else { (scale * (t.v0 * t.pf - vr * t.tf)).max(0.0) };
    let radial = if clamped { 0.0 } else { scale * t.v0 * t.rf };
    let omega = d.omega;
    let damping = d.c * omega * omega * w * w;
    let dielectric = crate::losses::dielectric_loss_w(omega, p.c0, p.tan_d, d.v);
    let rotor = p.dr * speed * speed;
    let output = if t.stalled { 0.0 } else { op.torque_nm * speed };
    let (ire, iim) = if clamped {
        (d.v * omega * p.c0 * p.tan_d, d.v * omega * p.c0)
    } else {
        stator::phase_current_a(d.v, omega, p.c0, p.tan_d, p.theta, t.z)
    };
    let input = d.v * ire;
    let losses = dielectric + damping + friction + rotor;
    let efficiency = crate::losses::efficiency(output, input);
    let rise_ss = losses / p.alpha_s;
    let rise_t = rise_ss * (1.0 - (-p.alpha_s * op.elapsed_s / p.heat_cap).exp());
    let xc = contact::contact_angle_deg(ct.half_angle_rad, p.n);
    Solution {
        status,
        full_contact: ct.full,
        iterations: evals,
        amplitude_m: w,
        contact_half_angle_rad: ct.half_angle_rad,
        contact_angle_deg: xc,
        contact_length_m: contact::contact_length_m(ct.half_angle_rad, p.k),
        stick_half_angle_rad: t.ts,
        driving_angle_deg: contact::contact_angle_deg(t.ts, p.n),
        driving_ratio: if ct.half_angle_rad > 0.0 { t.ts / ct.half_angle_rad } else { 0.0 },
        speed_rad_s: speed,
        speed_rpm: speed * RAD_S_TO_RPM,
        crest_speed_m_s: t.v0,
        torque_nm: op.torque_nm,
        stall_torque_nm: stall_torque,
        axial_force_n: if clamped { op.preload_n } else { t.a * t.chi0 },
        input_power_w: input,
        output_power_w: output,
        dielectric_loss_w: dielectric,
        damping_loss_w: damping,
        friction_loss_w: friction,
        radial_friction_loss_w: radial,
        rotor_loss_w: rotor,
        efficiency,
        feedback_v: stator::feedback_voltage_v(p.kfb, w),
        current_a: ire.hypot(iim),
        current_in_phase_a: ire,
        current_quadrature_a: iim,
        capacitive_current_a: d.v * omega * p.c0,
        electrode_voltage_v: d.v,
        phase_lag_rad: if clamped { 0.5 * PI } else { t.z.1.atan2(t.z.0) },
        modal_stiffness_n_per_m: t.k_eff,
        temperature_rise_k: rise_ss,
        temperature_rise_at_elapsed_k: rise_t,
        speed_std_rpm: 0.0,
        warnings: crate::limits::LimitWarnings::NONE,
        work_bound_reached: false,
    }
}
