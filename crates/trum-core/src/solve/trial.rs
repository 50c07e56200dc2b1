//! One trial amplitude: the drive it is evaluated under (the set voltage and frequency
//! after `thermal_drift` and `voltage_sag` act on them) and everything that follows from
//! the amplitude: contact zone, stick angle, interface factors, modal impedance and the
//! amplitude G(W) = Θ·V/|Z(W)| it implies.

use super::{OperatingPoint, Prepared, Solution};
use crate::contact::{self, Contact};
use crate::effects::Effect;
use crate::interface::{coulomb_interface, general_interface, interface_law, AngleCarry};
use crate::stator::{self, modal_stiffness};

/// Everything that follows from one trial amplitude.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Trial {
    /// Trial amplitude W [m].
    pub(super) w: f64,
    /// The contact zone at W.
    pub(super) contact: Contact,
    /// χ(φ0) = sin φ0 − φ0·c.
    pub(super) chi0: f64,
    /// Stick half-angle θs [rad].
    pub(super) ts: f64,
    /// Rotor surface speed [m/s]: v0·cos θs, or below it when the whole contact drives.
    pub(super) vr: f64,
    /// True when the rotor is at rest (the load torque is at or above the drive).
    pub(super) stalled: bool,
    /// Force scale A = 2·N·k_f·W/k [N]: the axial force is A·χ(φ0).
    pub(super) a: f64,
    /// Crest surface speed v0 = k·h0·ω·W [m/s].
    pub(super) v0: f64,
    /// Torque factor 2χ(θs) − χ(φ0) or its generalisation ([`crate::interface::factors`]):
    /// the drive torque is R0·μ·A·tf [-].
    pub(super) tf: f64,
    /// Friction power taken from the wave per v0, in units of 2Nμk_f·W/k [-].
    pub(super) pf: f64,
    /// Radial slip power per v0, same units as `pf` [-] (zero for the Coulomb interface).
    pub(super) rf: f64,
    /// Torque factor with the rotor at rest (stall torque = R0·μ·A·tf0); NaN when the
    /// generalised interface did not need it (computed in `finish`).
    pub(super) tf0: f64,
    /// Modal impedance Z = (Re, Im) = (k_eff − m·ω², ω·(c + c_t)) [N/m].
    pub(super) z: (f64, f64),
    /// Effective modal stiffness k_eff (with preload stiffening and Hertz softening) [N/m].
    pub(super) k_eff: f64,
    /// Θ·V/|Z|: the amplitude this trial implies.
    pub(super) w_next: f64,
    /// d(W − w_next)/dW, exact: the baseline Coulomb interface only (NaN elsewhere).
    pub(super) slope: f64,
    /// Contact and stick angles for the next trial's start (baseline Coulomb interface).
    pub(super) carry: [Option<AngleCarry>; 2],
}

impl Trial {
    /// The Newton step on this trial's exact slope of r(W) = W − G(W), where it has a
    /// positive one (callers keep it only inside their bracket).
    pub(super) fn newton(&self) -> Option<f64> {
        (self.slope > 0.0).then(|| self.w - (self.w - self.w_next) / self.slope)
    }
}

/// Per-point inputs after effects that act on the drive (voltage sag, thermal state).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Drive {
    /// Axial preload F [N].
    pub(crate) f_n: f64,
    /// Load torque T [N·m].
    pub(crate) t_load: f64,
    /// Electrode voltage amplitude V [V] (below the set voltage under `voltage_sag`).
    pub(crate) v: f64,
    /// Drive angular frequency ω [rad/s].
    pub(crate) omega: f64,
    /// Friction coefficient μ [-] (temperature dependent under `thermal_drift`).
    pub(crate) mu: f64,
    /// Modal stiffness k_s [N/m] (temperature dependent under `thermal_drift`).
    pub(crate) ks: f64,
    /// Modal damping [N·s/m] (temperature dependent under `thermal_drift`).
    pub(crate) c: f64,
}

/// Quality factor k/(ω·c) above which the material damping no longer sets the amplitude
/// scale of [`Drive::clamp_floor`]: no stator reaches it (bronze and steel stators with
/// bonded piezoceramics: Q of 50 to a few thousand), and there the friction at the contact
/// limits the amplitude instead.
const FLOOR_Q_MAX: f64 = 1e5;

impl Drive {
    /// The amplitude [m] below which a descent towards zero is taken as the clamped
    /// stator (W = 0), and at which a clamped state is probed for starting: 1e-9 of the
    /// amplitude scale Θ·V/(ω·c), the undamped bound, but never of more than
    /// [`FLOOR_Q_MAX`] times the static deflection Θ·V/k. Relative to the bound alone
    /// the floor grew without limit as the damping fell (c = 1e-7 N·s/m at generic60
    /// put it at 4 µm, above the running amplitude of 1 µm, and every point clamped),
    /// though the friction keeps the amplitude finite at any damping.
    pub(crate) fn clamp_floor(&self, theta: f64) -> f64 {
        let bound = theta * self.v / (self.omega * self.c);
        let static_deflection = theta * self.v / self.ks.abs();
        1e-9 * bound.min(FLOOR_Q_MAX * static_deflection)
    }

    /// The drive as set at `op`, before any effect acts on it.
    pub(crate) fn at(p: &Prepared, op: &OperatingPoint) -> Drive {
        Drive {
            f_n: op.preload_n,
            t_load: op.torque_nm,
            v: op.voltage_v,
            omega: stator::angular_frequency(op.frequency_hz),
            mu: p.mu,
            ks: p.ks,
            c: p.c,
        }
    }

    /// `thermal_drift`: the stiffness, friction and damping at a temperature rise [K]. Each
    /// relative coefficient scales its nominal value: exponential laws in the truth form,
    /// linear ones (floored at 5 % of nominal so a large drift cannot make a stiffness,
    /// damping or friction coefficient non-physical) in the candidate.
    pub(crate) fn warm(&mut self, p: &Prepared, rise_k: f64) {
        // (the second truth family: a sensitivity that saturates over about 25 K)
        let law = |x: f64| {
            if p.truth_b(Effect::ThermalDrift) {
                (1.0 + x * 25.0 * (rise_k / 25.0).tanh()).max(0.05)
            } else if p.truth(Effect::ThermalDrift) {
                (x * rise_k).exp()
            } else {
                (1.0 + x * rise_k).max(0.05)
            }
        };
        let [a, b, g] = p.thermal;
        (self.ks, self.mu, self.c) = (p.ks * law(a), p.mu * law(b), p.c * law(g));
    }
}

/// `voltage_sag`: the set voltage over |1 + Z_src·Y| with Y = I/V_e the phase admittance
/// of solution `s` (V_set = V_e·(1 + Z_src·Y)); the truth form's source is partly reactive.
pub(super) fn sagged_voltage_v(p: &Prepared, op: &OperatingPoint, s: &Solution) -> f64 {
    let ve = s.electrode_voltage_v;
    sagged_voltage_at(p, op, (s.current_in_phase_a / ve, s.current_quadrature_a / ve))
}

/// [`sagged_voltage_v`] for the phase admittance (in phase, quadrature) [S].
pub(super) fn sagged_voltage_at(p: &Prepared, op: &OperatingPoint, (yr, yi): (f64, f64)) -> f64 {
    // (the second truth family: an output resistance that grows with the load current, as
    // a driver's saturating magnetics give)
    let (zr, zi) = if p.truth_b(Effect::VoltageSag) {
        (p.sag_ohm * (0.4 + 4.5 * p.sag_ohm * yr.hypot(yi)), 0.0)
    } else if p.truth(Effect::VoltageSag) {
        (p.sag_ohm, 0.5 * p.sag_ohm)
    } else if p.sag_knee_a > 0.0 {
        return knee_sagged_voltage_v(op.voltage_v, p.sag_ohm, p.sag_knee_a, (yr, yi));
    } else {
        (p.sag_ohm, 0.0)
    };
    let (re, im) = (1.0 + zr * yr - zi * yi, zr * yi + zi * yr);
    op.voltage_v / re.hypot(im)
}

/// `voltage_sag`'s current-limited driver: it holds the set voltage `v_set` [V] while the
/// phase current amplitude |I| = |Y|·V_e stays at or below the knee `knee_a` [A], and above
/// it its output resistance `r_ohm` [Ω] drops the voltage by R·(|I| − I_k), in phase with the
/// current: V_set = |V_e + R·(|Y|·V_e − I_k)·Y/|Y||. A driver whose output stage limits its
/// current (Sun et al. 2021 §3.1 for the resistive drop; the knee is the limit), and with a
/// large R a constant-current source above the knee. Continuous in the current: at
/// |Y|·V_set = I_k both branches give V_set. The balance is a quadratic in V_e,
/// (A² + B²)·V² − 2(A·C + B·D)·V + C² + D² − V_set² = 0 with A + iB = 1 + R·Y and
/// C + iD = R·I_k·Y/|Y|; V_e is its larger root (the one that meets V_set at the knee).
pub(crate) fn knee_sagged_voltage_v(v_set: f64, r_ohm: f64, knee_a: f64, (yr, yi): (f64, f64)) -> f64 {
    let y = yr.hypot(yi);
    if y * v_set <= knee_a || y == 0.0 {
        return v_set;
    }
    let (a, b) = (1.0 + r_ohm * yr, r_ohm * yi);
    let (c, d) = (r_ohm * knee_a * yr / y, r_ohm * knee_a * yi / y);
    let qa = a * a + b * b;
    let qb = a * c + b * d;
    let qc = c * c + d * d - v_set * v_set;
    let disc = (qb * qb - qa * qc).max(0.0);
    (qb + disc.sqrt()) / qa
}

pub(super) fn trial(
    p: &Prepared,
    d: &Drive,
    w: f64,
    ts_guess: Option<contact::AngleStart>,
    phi_guess: Option<contact::AngleStart>,
) -> Trial {
    trial_after(p, d, w, ts_guess, phi_guess, false)
}

/// [`trial`] after a trial of the same descent that stalled (`after_stall`): the
/// generalised interface then decides stall by the rotor-at-rest integral before it tries
/// the guess (`general_interface`'s `rest_first`; the same trial, fewer integrals where it
/// stalls again). The Coulomb interface ignores it.
pub(super) fn trial_after(
    p: &Prepared,
    d: &Drive,
    w: f64,
    ts_guess: Option<contact::AngleStart>,
    phi_guess: Option<contact::AngleStart>,
    after_stall: bool,
) -> Trial {
    let a = contact::force_scale_n(p.n, p.kf, w, p.k);
    let (ct, s0, c0) = contact::contact_from_ratio_near(d.f_n / a, phi_guess);
    let v0 = stator::crest_surface_speed_m_s(p.k, p.h0, d.omega, w);
    let tscale = p.r0 * d.mu * a;
    let (ts, vr, stalled, tf, pf, rf, tf0, dpf, carry);
    if p.law.radial_ratio == 0.0 && p.compliance == 0.0 {
        let cb = coulomb_interface(p, d, &ct, (s0, c0), w, tscale, v0, ts_guess);
        (ts, vr, stalled, tf, pf, tf0, dpf, carry) =
            (cb.ts, cb.vr, cb.stalled, cb.tf, cb.pf, cb.tf0, cb.pf_per_w, cb.carry);
        rf = 0.0;
    } else {
        let law = interface_law(p, d, &ct);
        // Without a neighbour's stick angle (a cold point's first trial), the Coulomb
        // law's at this amplitude (one closed-form Newton solve) starts the speed solve
        // nearer its root than the bracket [0, 1] it would search otherwise: the root is
        // unique (the torque falls with the rotor speed), so the start changes only the
        // integrals it takes.
        let guess = ts_guess.map(|g| g.0).or_else(|| {
            let visc = p.dr * v0 / p.r0;
            contact::stick_half_angle_sin_cos(&ct, (s0, c0), tscale, d.t_load, visc, None).map(|r| r.0)
        });
        let (t, v, st, fac, t0) = general_interface(p, d, &ct, tscale, v0, &law, guess, after_stall);
        (ts, vr, stalled, tf, pf, rf, tf0) = (t, v, st, fac.torque, fac.power, fac.radial, t0);
        (dpf, carry) = (f64::NAN, [None; 2]);
    }
    let ct_omega_per_pf = 2.0 * p.n * d.mu * p.kf * p.h0;
    let k_eff = modal_stiffness(p, d, w, &ct, a);
    let z = (k_eff - p.m * d.omega * d.omega, d.omega * d.c + ct_omega_per_pf * pf);
    let z2 = z.0 * z.0 + z.1 * z.1;
    let w_next = p.theta * d.v / z2.sqrt();
    // r = W − G(W), G = Θ·V/|Z|: dr/dW = 1 + G·Im Z·d(Im Z)/dW / |Z|² where the modal
    // stiffness does not depend on W (NaN where it does, or dpf is not known).
    let slope = match p.stiffening == 0.0 && p.beta == 0.0 {
        true => 1.0 + w_next * z.1 * ct_omega_per_pf * dpf / z2,
        false => f64::NAN,
    };
    // χ(φ0) with the sine the contact solve has (the axial force is A·χ(φ0))
    let chi0 = s0 - ct.half_angle_rad * ct.offset;
    Trial { w, contact: ct, chi0, ts, vr, stalled, a, v0, tf, pf, rf, tf0, z, k_eff, w_next, slope, carry }
}
