//! Fixed-step integrator of the transient model.
//!
//! Kick-drift-kick (velocity) Verlet, written here rather than taken from an ODE crate:
//! the contact law is a per-node return mapping with history (the layer deflections δ_j),
//! which adaptive or multi-stage schemes would evaluate at trial states and corrupt; one
//! contact evaluation per step at the new positions keeps the stick/slip decision exact
//! and the cost at one pass over the nodes per step (10 ms with 256 nodes in ~0.1 s).
//!
//! * Kick with the old accelerations, drift the positions, evaluate the contact at the
//!   new positions, kick again with the linear damping (stator c, rotor d_r, axial d_z)
//!   taken implicitly: v₁ = (v½ + h/(2m)·F)/(1 + h·c/(2m)). The damping is then a
//!   central difference and the scheme is stable for any damping.
//! * Slip increments are exact: u_s is linear in q, so Δu_s = u_s(q₁) − u_s(q₀).
//! * Discretisation of the stator at the drive frequency ω: Verlet replaces ω² by
//!   ω̂² = (2/h·sin(ωh/2))² and the central-difference damping ω by sin(ωh)/h. The modal
//!   stiffness and damping are corrected, k_s → k_s − m·ω² + m·ω̂², c → c·ωh/sin(ωh),
//!   so the discrete forced response at the drive frequency equals the continuous one
//!   (without it the 2.25 kHz detuning of `trum60a` would be off by 0.8 % at 64
//!   steps/period). The remaining error is O(h²) in the contact forces.
//! * The load is a Coulomb brake (T_load·sign Ω while turning, holding up to T_load at
//!   rest), taken implicitly in both rotor kicks; see [`Model::rotor_kick`].
//! * Stability: ω_max·h < 1.5 for the stiffest contact mode (all nodes sticking, the
//!   tangential springs between stator modes and rotor), checked before the run.

use super::{NodeSample, NodeState, Snapshot, SteadyAverages, TimeSeries, TransientConfig, TransientError};
use crate::contact::layer_stiffness_n_per_m2;
use crate::params::Motor;
use crate::solve::RAD_S_TO_RPM;
use crate::stator::{angular_frequency, modal_stiffness_n_per_m};
use std::f64::consts::PI;

/// Accepted ω_max·h (Verlet is stable below 2).
const STABILITY_LIMIT: f64 = 1.5;

pub(crate) struct RunOutput {
    pub series: TimeSeries,
    pub averages: SteadyAverages,
    pub snapshots: Vec<Snapshot>,
    pub time_step_s: f64,
    pub steps: u64,
}

/// Torsion of the stator about the motor axis (a third rigid-body degree of freedom,
/// the bar-type transient paper eq. 3): J_s·θ̈ + c_θ·θ̇ + k_θ·θ = −T_c. It moves every
/// contact point tangentially by R0·θ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Torsion {
    /// Polar moment of inertia J_s [kg·m²].
    pub inertia_kg_m2: f64,
    /// Torsional stiffness k_θ [N·m/rad].
    pub stiffness_nm_per_rad: f64,
    /// Torsional damping c_θ [N·m·s/rad].
    pub damping_nms: f64,
}

/// Everything one run needs, in the terms of the two-mode stator model: a ring motor
/// ([`ring_plant`]) and the rigid disc of the bar-type motor (one wave around the
/// circumference, modal coordinates R·θ) map onto the same equations, so both share this
/// integrator and its contact step.
#[derive(Clone, Debug)]
pub(crate) struct Plant {
    /// Number of identical waves around the circumference N [-].
    pub n_waves: f64,
    /// Radius of the contact circle R0 [m].
    pub r0: f64,
    /// Tangential surface displacement per unit slope: u_s = h0·∂w/∂x [m].
    pub h0: f64,
    /// Normal contact stiffness per unit circumferential length k_f [N/m²].
    pub kf_n_per_m2: f64,
    /// Tangential contact stiffness per unit circumferential length [N/m²].
    pub kt_n_per_m2: f64,
    /// Static friction coefficient μ_s (stick test, the bar-type transient paper eq. 2).
    pub mu_static: f64,
    /// Dynamic friction coefficient μ_d (slip force, the bar-type transient paper eq. 1).
    pub mu_dynamic: f64,
    /// Modal mass m [kg].
    pub modal_mass_kg: f64,
    /// Modal stiffness k_s [N/m].
    pub modal_stiffness_n_per_m: f64,
    /// Modal damping c [N·s/m].
    pub modal_damping_ns_per_m: f64,
    /// Amplitude of the modal drive force per phase [N].
    pub drive_force_n: f64,
    /// Rotor inertia J_r [kg·m²], viscous damping d_r [N·m·s], mass m_r [kg].
    pub rotor_inertia_kg_m2: f64,
    pub rotor_damping_nms: f64,
    pub rotor_mass_kg: f64,
    /// Axial spring k_sp [N/m] and axial damping d_z [N·s/m] of the rotor.
    pub axial_stiffness_n_per_m: f64,
    pub axial_damping_ns_per_m: f64,
    /// Project the normal contact forces on the stator modes (1) or not (0).
    pub normal_coupling: f64,
    /// Stator torsion, if modelled.
    pub torsion: Option<Torsion>,
    /// Operating point and run settings; `load_torque_nm` is the magnitude of the Coulomb
    /// brake T_load [N·m] (see [`Model::rotor_kick`]).
    pub preload_n: f64,
    pub load_torque_nm: f64,
    pub frequency_hz: f64,
    pub phase_difference_rad: f64,
    pub duration_s: f64,
    pub steps_per_period: usize,
    pub nodes_per_wavelength: usize,
    pub record_every: usize,
    pub snapshot_times_s: Vec<f64>,
    /// Rotor speed at t = 0 [rad/s]: 0 for a step from rest; a coasting rotor otherwise.
    pub initial_rotor_speed_rad_s: f64,
}

/// The ring motor of [`crate::params::Motor`] at the settings of `cfg`.
pub(crate) fn ring_plant(motor: &Motor, cfg: &TransientConfig) -> Plant {
    let g = &motor.geometry;
    let st = &motor.stator;
    let kf = layer_stiffness_n_per_m2(
        motor.friction_layer.youngs_modulus_pa,
        g.contact_width_m,
        motor.friction_layer.thickness_m,
    );
    let mu = motor.friction_layer.friction_coefficient;
    Plant {
        n_waves: g.wave_number,
        r0: g.mean_radius_m,
        h0: g.neutral_plane_distance_m,
        kf_n_per_m2: kf,
        kt_n_per_m2: cfg.tangential_stiffness_ratio * kf,
        mu_static: mu,
        mu_dynamic: mu,
        modal_mass_kg: st.modal_mass_kg,
        modal_stiffness_n_per_m: modal_stiffness_n_per_m(st.modal_mass_kg, st.resonance_frequency_hz),
        modal_damping_ns_per_m: st.modal_damping_ns_per_m,
        drive_force_n: st.force_factor_n_per_v * cfg.voltage_v,
        rotor_inertia_kg_m2: motor.rotor.inertia_kg_m2,
        rotor_damping_nms: motor.rotor.viscous_damping_nms,
        rotor_mass_kg: motor.rotor.mass_kg,
        axial_stiffness_n_per_m: motor.assembly.axial_spring_stiffness_n_per_m,
        axial_damping_ns_per_m: cfg.axial_damping_ns_per_m,
        normal_coupling: if cfg.normal_modal_coupling { 1.0 } else { 0.0 },
        torsion: None,
        preload_n: cfg.preload_n,
        load_torque_nm: cfg.load_torque_nm,
        frequency_hz: cfg.frequency_hz,
        phase_difference_rad: cfg.phase_difference_rad,
        duration_s: cfg.duration_s,
        steps_per_period: cfg.steps_per_period,
        nodes_per_wavelength: cfg.nodes_per_wavelength,
        record_every: cfg.record_every,
        snapshot_times_s: cfg.snapshot_times_s.clone(),
        initial_rotor_speed_rad_s: 0.0,
    }
}

/// Constants of one run.
struct Model {
    n_waves: f64,
    r0: f64,
    h0k: f64,
    dx: f64,
    kf_node: f64,
    kt_node: f64,
    mu_s: f64,
    mu_d: f64,
    k_num: f64,
    c_num: f64,
    j_r: f64,
    d_r: f64,
    m_r: f64,
    k_sp: f64,
    d_z: f64,
    preload: f64,
    /// Magnitude of the Coulomb brake on the rotor T_load [N·m], ≥ 0.
    load: f64,
    coupling: f64,
    cos: Vec<f64>,
    sin: Vec<f64>,
}

/// Dynamic state.
struct State {
    qa: f64,
    qb: f64,
    va: f64,
    vb: f64,
    z: f64,
    vz: f64,
    om: f64,
    /// Stator torsion angle [rad] and rate [rad/s] (zero without torsion).
    th: f64,
    om_s: f64,
    delta: Vec<f64>,
    node: Vec<NodeState>,
}

/// Contact resultants.
#[derive(Clone, Copy, Default)]
struct Forces {
    qa: f64,
    qb: f64,
    fz: f64,
    torque: f64,
    n_contact: usize,
    n_stick: usize,
}

impl Model {
    /// Contact forces at the current positions; advances the node deflections by the
    /// surface increments (dqa, dqb) of the stator modes and dur = R0·(Δφ_r − Δθ_s) of the
    /// rotor relative to the stator's torsion.
    fn contact(&self, s: &mut State, dqa: f64, dqb: f64, dur: f64) -> Forces {
        let (mut fz, mut ft, mut ga, mut gb, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut n_contact, mut n_stick) = (0, 0);
        let iter = self.cos.iter().zip(&self.sin).zip(s.delta.iter_mut().zip(s.node.iter_mut()));
        for ((&c, &sn), (delta, state)) in iter {
            let pen = s.qa * c + s.qb * sn - s.z;
            if pen <= 0.0 {
                *delta = 0.0;
                *state = NodeState::NoContact;
                continue;
            }
            let p = self.kf_node * pen;
            // the bar-type transient paper eq. 2: trial (no-slip) force against the static limit μ_s·p
            let trial = *delta + self.h0k * (dqb * c - dqa * sn) - dur;
            let f_trial = self.kt_node * trial;
            let f = if f_trial.abs() <= self.mu_s * p {
                *delta = trial;
                *state = NodeState::Stick;
                n_stick += 1;
                f_trial
            } else {
                // the bar-type transient paper eq. 1: slip at μ_d·p in the direction of the slip
                let f = (self.mu_d * p).copysign(f_trial);
                *delta = f / self.kt_node;
                *state = NodeState::Slip;
                f
            };
            n_contact += 1;
            fz += p;
            ft += f;
            ga += f * sn;
            gb -= f * c;
            na += p * c;
            nb += p * sn;
        }
        let n = self.n_waves;
        Forces {
            qa: n * (self.h0k * ga - self.coupling * na),
            qb: n * (self.h0k * gb - self.coupling * nb),
            fz: n * fz,
            torque: n * self.r0 * ft,
            n_contact,
            n_stick,
        }
    }

    /// Rotor speed [rad/s] after a kick of length `hh` [s] from `om` [rad/s] under the
    /// contact torque `tc` [N·m], the viscous torque d_r·Ω and the brake (the bar-type
    /// transient paper eq. 4 with T_load·sign Ω). The viscous torque is taken at `om` in the
    /// first half-kick (`implicit_damping` false) and at the new speed in the second.
    ///
    /// The brake's sign(Ω) is solved for with the new speed, like the nodes' return
    /// mapping: the speed the kick would reach without the brake, `free`, is compared with
    /// the change the brake can make, h½·T_load/J_r. Within it the brake stops the rotor in
    /// this kick and the speed is exactly 0; at rest it holds as long as |T_c| ≤ T_load.
    /// Beyond it the rotor turns, and the brake acts against the way it turns at the end of
    /// the kick. Taking sign(Ω) at the old speed instead would flip ±T_load from step to
    /// step around Ω = 0 (chatter) and let a held rotor creep by h·T_load/J_r per step.
    /// While the rotor keeps turning forwards this is the constant-load kick exactly (same
    /// operations, so the same rounding).
    fn rotor_kick(&self, om: f64, tc: f64, hh: f64, implicit_damping: bool) -> f64 {
        let hold = hh * self.load / self.j_r;
        if implicit_damping {
            let free = om + hh / self.j_r * tc;
            if free.abs() <= hold {
                return 0.0;
            }
            let tq = tc - self.load.copysign(free);
            (om + hh / self.j_r * tq) / (1.0 + hh * self.d_r / self.j_r)
        } else {
            let free = om + hh * ((tc - self.d_r * om) / self.j_r);
            if free.abs() <= hold {
                return 0.0;
            }
            om + hh * ((tc - self.load.copysign(free) - self.d_r * om) / self.j_r)
        }
    }

    fn snapshot(&self, s: &State, requested: f64, t: f64) -> Snapshot {
        let vr = self.r0 * (s.om - s.om_s);
        let nodes = (0..self.cos.len())
            .map(|j| {
                let (c, sn) = (self.cos[j], self.sin[j]);
                let pen = (s.qa * c + s.qb * sn - s.z).max(0.0);
                let f = if s.node[j] == NodeState::NoContact { 0.0 } else { self.kt_node * s.delta[j] };
                NodeSample {
                    position_m: j as f64 * self.dx,
                    pressure_n_per_m: self.kf_node * pen / self.dx,
                    tangential_force_n_per_m: f / self.dx,
                    slip_speed_m_s: self.h0k * (s.vb * c - s.va * sn) - vr,
                    state: s.node[j],
                }
            })
            .collect();
        Snapshot { requested_time_s: requested, time_s: t, speed_rpm: s.om * RAD_S_TO_RPM, nodes }
    }
}

pub(crate) fn run(p: &Plant) -> Result<RunOutput, TransientError> {
    let n_nodes = p.nodes_per_wavelength;
    let k = p.n_waves / p.r0;
    let lambda = 2.0 * PI / k;
    let dx = lambda / n_nodes as f64;
    let kf = p.kf_n_per_m2;
    let omega = angular_frequency(p.frequency_hz);
    let spp = p.steps_per_period;
    let h = 1.0 / (p.frequency_hz * spp as f64);
    let wh = omega * h;
    let omega_hat = 2.0 / h * (0.5 * wh).sin();
    let m = p.modal_mass_kg;
    let ks = p.modal_stiffness_n_per_m;
    let model = Model {
        n_waves: p.n_waves,
        r0: p.r0,
        h0k: p.h0 * k,
        dx,
        kf_node: kf * dx,
        kt_node: p.kt_n_per_m2 * dx,
        mu_s: p.mu_static,
        mu_d: p.mu_dynamic,
        k_num: ks - m * omega * omega + m * omega_hat * omega_hat,
        c_num: p.modal_damping_ns_per_m * wh / wh.sin(),
        j_r: p.rotor_inertia_kg_m2,
        d_r: p.rotor_damping_nms,
        m_r: p.rotor_mass_kg,
        k_sp: p.axial_stiffness_n_per_m,
        d_z: p.axial_damping_ns_per_m,
        preload: p.preload_n,
        load: p.load_torque_nm,
        coupling: p.normal_coupling,
        cos: (0..n_nodes).map(|j| (k * j as f64 * dx).cos()).collect(),
        sin: (0..n_nodes).map(|j| (k * j as f64 * dx).sin()).collect(),
    };
    let tor = p.torsion;

    // Stability of the stiffest modes (all nodes in contact and sticking).
    let ring = 2.0 * PI * model.r0; // N·λ
    let kt_total = p.kt_n_per_m2 * ring;
    let torsion_flex = tor.map_or(0.0, |t| model.r0 * model.r0 / t.inertia_kg_m2);
    let checks = [
        (
            (kt_total * (model.r0 * model.r0 / model.j_r + model.h0k * model.h0k / m + torsion_flex)).sqrt() * h,
            "tangential stick springs",
        ),
        (((kf * ring + model.k_sp) / model.m_r).sqrt() * h, "rotor axial contact"),
        (((model.k_num + model.coupling * 0.5 * kf * ring) / m).sqrt() * h, "stator modes"),
        (tor.map_or(0.0, |t| (t.stiffness_nm_per_rad / t.inertia_kg_m2).sqrt() * h), "stator torsion"),
    ];
    for (omega_h, what) in checks {
        if omega_h.is_nan() || omega_h >= STABILITY_LIMIT {
            return Err(TransientError::StepTooLarge { omega_h, limit: STABILITY_LIMIT, what });
        }
    }

    // Rotor at rest on the preload: uniform penetration −z₀ over the ring.
    let z0 = -p.preload_n / (kf * ring);
    let mut s = State {
        qa: 0.0,
        qb: 0.0,
        va: 0.0,
        vb: 0.0,
        z: z0,
        vz: 0.0,
        om: p.initial_rotor_speed_rad_s,
        th: 0.0,
        om_s: 0.0,
        delta: vec![0.0; n_nodes],
        node: vec![NodeState::NoContact; n_nodes],
    };
    let steps = (p.duration_s / h).round().max(1.0) as u64;
    let periods = steps / spp as u64;
    let avg_steps = (spp as u64 * ((0.2 * periods as f64).round() as u64).max(1)).min(steps);
    let avg_start = steps - avg_steps;

    let f0 = p.drive_force_n;
    let drive = |i: u64| {
        let ph = 2.0 * PI * (i % spp as u64) as f64 / spp as f64;
        (f0 * ph.cos(), f0 * (ph - p.phase_difference_rad).cos())
    };
    let mut f = model.contact(&mut s, 0.0, 0.0, 0.0);
    let accel = |s: &State, f: &Forces, d: (f64, f64)| {
        (
            (d.0 + f.qa - model.k_num * s.qa - model.c_num * s.va) / m,
            (d.1 + f.qb - model.k_num * s.qb - model.c_num * s.vb) / m,
            (f.fz - model.preload - model.k_sp * (s.z - z0) - model.d_z * s.vz) / model.m_r,
            tor.map_or(0.0, |t| (-f.torque - t.stiffness_nm_per_rad * s.th - t.damping_nms * s.om_s) / t.inertia_kg_m2),
        )
    };
    let mut a = accel(&s, &f, drive(0));

    let mut series = TimeSeries::default();
    let n_rec = (steps / p.record_every as u64 + 2) as usize;
    for v in [
        &mut series.time_s,
        &mut series.speed_rpm,
        &mut series.speed_period_mean_rpm,
        &mut series.amplitude_m,
        &mut series.axial_position_m,
        &mut series.torque_nm,
        &mut series.axial_force_n,
    ] {
        v.reserve(n_rec);
    }
    let mut ring_om = vec![0.0; spp];
    let mut ring_sum = 0.0;
    let mut order: Vec<usize> = (0..p.snapshot_times_s.len()).collect();
    order.sort_by(|&x, &y| p.snapshot_times_s[x].total_cmp(&p.snapshot_times_s[y]));
    let mut snaps: Vec<Option<Snapshot>> = vec![None; order.len()];
    let mut next_snap = 0;
    let mut acc = [0.0f64; 6];

    let hh = 0.5 * h;
    for i in 0..=steps {
        let t = i as f64 * h;
        if i > 0 {
            // kick, drift
            s.va += hh * a.0;
            s.vb += hh * a.1;
            s.vz += hh * a.2;
            s.om = model.rotor_kick(s.om, f.torque, hh, false);
            s.om_s += hh * a.3;
            let (dqa, dqb) = (h * s.va, h * s.vb);
            s.qa += dqa;
            s.qb += dqb;
            s.z += h * s.vz;
            s.th += h * s.om_s;
            let dur = h * model.r0 * (s.om - s.om_s);
            f = model.contact(&mut s, dqa, dqb, dur);
            // kick with implicit linear damping
            let d = drive(i);
            let fa = d.0 + f.qa - model.k_num * s.qa;
            let fb = d.1 + f.qb - model.k_num * s.qb;
            let fzz = f.fz - model.preload - model.k_sp * (s.z - z0);
            s.va = (s.va + hh / m * fa) / (1.0 + hh * model.c_num / m);
            s.vb = (s.vb + hh / m * fb) / (1.0 + hh * model.c_num / m);
            s.vz = (s.vz + hh / model.m_r * fzz) / (1.0 + hh * model.d_z / model.m_r);
            s.om = model.rotor_kick(s.om, f.torque, hh, true);
            if let Some(t) = tor {
                let ts = -f.torque - t.stiffness_nm_per_rad * s.th;
                s.om_s = (s.om_s + hh / t.inertia_kg_m2 * ts) / (1.0 + hh * t.damping_nms / t.inertia_kg_m2);
            }
            a = accel(&s, &f, d);
        }
        let slot = (i % spp as u64) as usize;
        ring_sum += s.om - ring_om[slot];
        ring_om[slot] = s.om;
        if i > avg_start {
            let amp = s.qa.hypot(s.qb);
            let nn = n_nodes as f64;
            for (sum, v) in
                acc.iter_mut().zip([s.om, f.torque, amp, f.fz, f.n_contact as f64 / nn, f.n_stick as f64 / nn])
            {
                *sum += v;
            }
        }
        if i % p.record_every as u64 == 0 || i == steps {
            if !(s.qa.is_finite() && s.qb.is_finite() && s.z.is_finite() && s.om.is_finite()) {
                return Err(TransientError::Diverged { time_s: t });
            }
            series.time_s.push(t);
            series.speed_rpm.push(s.om * RAD_S_TO_RPM);
            series.speed_period_mean_rpm.push(ring_sum / spp as f64 * RAD_S_TO_RPM);
            series.amplitude_m.push(s.qa.hypot(s.qb));
            series.axial_position_m.push(s.z - z0);
            series.torque_nm.push(f.torque);
            series.axial_force_n.push(f.fz);
        }
        while next_snap < order.len() && (p.snapshot_times_s[order[next_snap]] <= t + 0.5 * h || i == steps) {
            let idx = order[next_snap];
            snaps[idx] = Some(model.snapshot(&s, p.snapshot_times_s[idx], t));
            next_snap += 1;
        }
    }
    let navg = avg_steps as f64;
    let averages = SteadyAverages {
        window_s: navg * h,
        speed_rpm: acc[0] / navg * RAD_S_TO_RPM,
        contact_torque_nm: acc[1] / navg,
        amplitude_m: acc[2] / navg,
        axial_force_n: acc[3] / navg,
        contact_fraction: acc[4] / navg,
        stick_fraction: acc[5] / navg,
    };
    Ok(RunOutput { series, averages, snapshots: snaps.into_iter().flatten().collect(), time_step_s: h, steps })
}
