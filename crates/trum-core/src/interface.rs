//! Friction in the contact interface beyond the 2-D Coulomb law of the baseline: the
//! traction μ·p acts along the **total** slip velocity, which has a radial part when the
//! stator surface points also move radially (`radial_friction`, the radial-friction paper),
//! and its magnitude saturates smoothly over a slip-velocity scale set by the shear
//! compliance of the friction layer (`tangential_compliance`, Storck and Wallaschek 2003;
//! the bar-type transient paper).
//!
//! Kinematics in the wave frame (θ wave phase, 0 at the crest; everything divided by the
//! crest speed v0): tangential stator speed cos θ, rotor speed u = v_r/v0, radial stator
//! speed ρ·sin θ (the radial-friction paper eq. 10-12: the radial displacement
//! −z·∂R/∂r·A·cos(ωt−mθ) is in phase with the transverse one, so its velocity is in
//! quadrature with the tangential velocity — zero at the crest, largest towards the nodes).
//! Slip s = (cos θ − u, ρ·sin θ), |s| = D; traction direction s/D, magnitude μ·p·S(D/σ)
//! with S(x) = tanh x (σ = 0: S = 1, Coulomb).
//!
//! The factors returned generalise the baseline closed forms: with ρ = 0 and σ = 0 they
//! are exactly 2χ(θs) − χ(φ0) and 2E(θs) − E(φ0) (a test checks this).

use crate::contact;
use crate::contact::Contact;
use crate::effects::Effect;
use crate::solve::trial::Drive;
use crate::solve::Prepared;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Parameters of the generalised friction law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    /// ρ: peak radial surface speed over peak tangential surface speed [-].
    pub radial_ratio: f64,
    /// σ: slip-speed scale of the saturation over the crest speed [-].
    pub slip_scale: f64,
    /// Use the bench-truth form of the saturation (algebraic) instead of the candidate
    /// form the diagnosis fits (`tangential_compliance`'s). See docs/EFFECTS.md.
    pub truth: bool,
    /// Use the bench-truth form of the radial slip (radius-resolved) instead of the
    /// candidate form (`radial_friction`'s). See docs/EFFECTS.md.
    pub truth_radial: bool,
    /// n: sharpness of the candidate saturation's turn from stick to slip,
    /// S(x) = tanh(xⁿ)^(1/n) [-]; 1 is tanh (`tangential_compliance`'s `stick_sharpness`).
    pub sharpness: f64,
}

impl Law {
    /// True when the law is the baseline Coulomb law.
    pub fn is_coulomb(&self) -> bool {
        self.radial_ratio == 0.0 && self.slip_scale == 0.0
    }
}

/// Interface integrals per unit of k_f·W/k (one wave, both halves).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Factors {
    /// ∫ (cos θ − c)·g_t dθ over [0, φ0]: the torque factor.
    pub torque: f64,
    /// ∫ (cos θ − c)·(g_t·cos θ + g_r·ρ sin θ) dθ: power taken from the wave per v0.
    pub power: f64,
    /// ∫ (cos θ − c)·g_r·ρ sin θ dθ: radial slip power per v0.
    pub radial: f64,
    /// ∂torque/∂u at fixed contact (≤ 0: more rotor speed, less drive), for Newton steps.
    pub torque_du: f64,
    /// ∂power/∂u and ∂radial/∂u at fixed contact, to carry the factors over a last Newton
    /// step too small to need another integral ([`Factors::carried`]).
    pub power_du: f64,
    /// See `power_du`.
    pub radial_du: f64,
    /// ∂²torque/∂u² at fixed contact, for the speed solve's third-order (Halley) steps and
    /// its estimate of a Newton step's error; NaN where the route does not sum it (the
    /// general saturating laws), which leaves the speed solve to plain Newton steps.
    pub torque_uu: f64,
}

impl Factors {
    /// Adds `o` field by field.
    #[inline(always)]
    fn add(&mut self, o: &Factors) {
        self.torque += o.torque;
        self.power += o.power;
        self.radial += o.radial;
        self.torque_du += o.torque_du;
        self.power_du += o.power_du;
        self.radial_du += o.radial_du;
        self.torque_uu += o.torque_uu;
    }

    /// The factors at u + `du` to first order (the integrand's derivatives at fixed nodes,
    /// which agree with central differences of the rule to 1e-9 relative, test below): for
    /// a step |du| ≤ 1e-8, the error of the carry is below 1e-11 of the factors at worst and
    /// the step's own δ² term below 1e-16.
    pub fn carried(&self, du: f64) -> Factors {
        Factors {
            torque: self.torque + self.torque_du * du,
            power: self.power + self.power_du * du,
            radial: self.radial + self.radial_du * du,
            ..*self
        }
    }
}

const NODES: usize = 12;

thread_local! {
    /// Integrand evaluations at quadrature nodes summed on this thread so far: the meter of
    /// a solve's work bound (crate::solve's `Work`, read around each trial on the thread
    /// that runs it). A meter rather than a counter passed down: the integrals are reached
    /// through a dozen routes whose signatures the tests and the sensitivities share.
    static INTEGRAND_EVALUATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Adds `n` integrand evaluations to this thread's meter.
#[inline(always)]
fn count_evaluations(n: usize) {
    INTEGRAND_EVALUATIONS.with(|c| c.set(c.get().wrapping_add(n as u64)));
}

/// Integrand evaluations at quadrature nodes summed on this thread so far (wrapping): the
/// difference across a computation on the same thread is the nodes it summed.
pub(crate) fn integrand_evaluations() -> u64 {
    INTEGRAND_EVALUATIONS.with(std::cell::Cell::get)
}

fn gauss_legendre() -> &'static [(f64, f64); NODES] {
    static GL: OnceLock<[(f64, f64); NODES]> = OnceLock::new();
    GL.get_or_init(|| {
        // Newton iteration on P_n for the roots; weights 2/((1−x²)·P_n'(x)²).
        let n = NODES;
        let mut out = [(0.0, 0.0); NODES];
        for (i, slot) in out.iter_mut().enumerate() {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            *slot = (x, 2.0 / ((1.0 - x * x) * dp * dp));
        }
        out
    })
}

/// Saturation S(x) and its derivative S'(x).
#[inline]
fn saturation(x: f64, truth: bool) -> (f64, f64) {
    if truth {
        let r = 1.0 / (1.0 + x * x).sqrt();
        (x * r, r * r * r)
    } else {
        let t = tanh_nonneg(x);
        (t, 1.0 - t * t)
    }
}

/// The stick-then-slip family of saturations, S(x) = tanh(xⁿ)^(1/n) and S'(x), for x ≥ 0
/// and n ≥ 1: an elastic friction layer that carries traction in proportion to its shear
/// (S ≈ x) until the traction reaches μp and the layer slips (S → 1), the turn between the
/// two over a band that narrows as n grows (n = 1 is tanh, n → ∞ is min(x, 1), the
/// elastic–perfectly-plastic layer of Storck & Wallaschek 2003). Written with
/// t = tanh(y)/y, y = xⁿ: S = x·t^(1/n) and S' = t^(1/n − 1)·(1 − tanh²y), so both stay
/// finite at x → 0 (t by its series below y = 1e-3, first omitted term below 1e-13).
#[inline]
fn stick_slip_saturation(x: f64, n: f64) -> (f64, f64) {
    let y = x.powf(n);
    let (th, t) = if y < 1e-3 {
        let z = y * y;
        let t = 1.0 + z * (-1.0 / 3.0 + z * (2.0 / 15.0));
        (y * t, t)
    } else {
        let th = tanh_nonneg(y);
        (th, th / y)
    };
    let r = t.powf(1.0 / n);
    (x * r, r / t * (1.0 - th * th))
}

/// tanh x for x ≥ 0 (the slip speed over its scale): the odd series through x⁹ below
/// 0.02 (first omitted term below 1e-19 relative), (1 − e)/(1 + e) with e = exp(−2x)
/// above (rounding of 1 − e: at most 6e-15 relative, at x = 0.02), exactly 1 beyond 19.1
/// where tanh rounds to 1. Hand-written because glibc's `tanh` (through `expm1`) took 44 %
/// of a `tangential_compliance` solve and `exp` costs a fraction of that; agrees with
/// `f64::tanh` to 6e-15 relative (test below).
#[inline]
fn tanh_nonneg(x: f64) -> f64 {
    if x < 0.02 {
        let z = x * x;
        x * (1.0 + z * (-1.0 / 3.0 + z * (2.0 / 15.0 + z * (-17.0 / 315.0 + z * (62.0 / 2835.0)))))
    } else if x < 19.1 {
        let e = exp_nonpos(-2.0 * x);
        (1.0 - e) / (1.0 + e)
    } else {
        1.0
    }
}

/// e^x for −708 < x ≤ 0 (the saturations' exp(−2·|slip|/σ)): x = n·ln 2 + r with
/// |r| ≤ ln 2 / 2 (n by the round-to-nearest of adding 1.5·2^52, ln 2 split in two so
/// n·ln 2 is exact to 2^-60), e^r by its Taylor series to r¹³ (first omitted term below
/// 5e-18 relative), 2^n put into the exponent bits. Written out inline because glibc's
/// `exp` with its call costs about 50 instructions a node of the saturating laws and this
/// about 25; within 2 ulp of `f64::exp` (test below).
#[inline(always)]
fn exp_nonpos(x: f64) -> f64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5·2^52
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let t = x * std::f64::consts::LOG2_E + SHIFT;
    let n = t - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let p = 1.0 / 6_227_020_800.0;
    let p = p * r + 1.0 / 479_001_600.0;
    let p = p * r + 1.0 / 39_916_800.0;
    let p = p * r + 1.0 / 3_628_800.0;
    let p = p * r + 1.0 / 362_880.0;
    let p = p * r + 1.0 / 40_320.0;
    let p = p * r + 1.0 / 5_040.0;
    let p = p * r + 1.0 / 720.0;
    let p = p * r + 1.0 / 120.0;
    let p = p * r + 1.0 / 24.0;
    let p = p * r + 1.0 / 6.0;
    let p = p * r + 0.5;
    let p = p * r + 1.0;
    let p = p * r + 1.0;
    // the low bits of t hold n (two's complement): n + 1023 shifted into the exponent
    let scale = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    p * scale
}

/// sin y and cos y for |y| ≤ π/4 by their Taylor series to y¹⁷ and y¹⁸ (the first
/// omitted terms are below 1e-19): the quadrature nodes sit within π/4 of their
/// sub-panel's centre, so no range reduction is needed. Hand-written rather than a crate
/// because that is what makes it cheap: glibc's `sin` and `cos` (a separate call each
/// where the compiler does not fuse them) cost about 40 % of a `radial_friction` solve.
/// Agrees with `f64::sin_cos` to 2 ulp (test below).
#[inline(always)]
fn sin_cos_small(y: f64) -> (f64, f64) {
    let z = y * y;
    let s = -1.0 / 6.0
        + z * (1.0 / 120.0
            + z * (-1.0 / 5040.0
                + z * (1.0 / 362_880.0
                    + z * (-1.0 / 39_916_800.0
                        + z * (1.0 / 6_227_020_800.0
                            + z * (-1.0 / 1_307_674_368_000.0 + z * (1.0 / 355_687_428_096_000.0)))))));
    let c = 1.0 / 24.0
        + z * (-1.0 / 720.0
            + z * (1.0 / 40_320.0
                + z * (-1.0 / 3_628_800.0
                    + z * (1.0 / 479_001_600.0
                        + z * (-1.0 / 87_178_291_200.0
                            + z * (1.0 / 20_922_789_888_000.0 + z * (-1.0 / 6_402_373_705_728_000.0)))))));
    (y + y * z * s, 1.0 - 0.5 * z + z * z * c)
}

/// Quadrature nodes of up to two panels, each of two sub-panels of [`NODES`]
/// Gauss–Legendre nodes: sin θ, cos θ and weight. The plain rule has two panels (split at
/// the stick point); the graded rule sums its panels two at a time.
struct Nodes {
    sin: [f64; PANEL_PAIR_NODES],
    cos: [f64; PANEL_PAIR_NODES],
    weight: [f64; PANEL_PAIR_NODES],
    len: usize,
}

/// Nodes of two panels.
const PANEL_PAIR_NODES: usize = 4 * NODES;

impl Nodes {
    fn new() -> Self {
        Nodes { sin: [0.0; PANEL_PAIR_NODES], cos: [0.0; PANEL_PAIR_NODES], weight: [0.0; PANEL_PAIR_NODES], len: 0 }
    }

    /// Adds each [a, b] of `panels` (width at most π, at most two of them) as two equal
    /// sub-panels, given (sin, cos) of its centre. The nodes are symmetric about each
    /// sub-panel's centre m = centre ∓ r, so sin(m ± y) and cos(m ± y) follow by angle
    /// addition from the series of r and of y = r·x (|y| < π/4), which both sub-panels share.
    fn panels(&mut self, panels: &[(f64, f64, (f64, f64))]) {
        const HALF: usize = NODES / 2;
        let gl = gauss_legendre();
        // The series of all panels at once, lane by lane over fixed-size arrays (per panel:
        // the six offsets y = r·x of the positive nodes, which gauss_legendre() lists first,
        // then r). The compiler evaluates them two lanes at a time in vector registers, each
        // lane with the operations of a scalar call, so the nodes are the same to the bit;
        // the Horner chains of both panels overlap instead of running one after the other.
        debug_assert!(panels.len() <= 2 && self.len + 2 * NODES * panels.len() <= PANEL_PAIR_NODES);
        let mut y = [0.0; 16];
        for (p, &(a, b, _)) in panels.iter().enumerate() {
            let r = 0.25 * (b - a);
            for (yi, &(x, _)) in y[8 * p..].iter_mut().zip(&gl[..HALF]) {
                *yi = r * x;
            }
            y[8 * p + HALF] = r;
        }
        let (mut sy, mut cy) = ([0.0; 16], [0.0; 16]);
        for i in 0..16 {
            (sy[i], cy[i]) = sin_cos_small(y[i]);
        }
        for (p, &(_, _, (sc, cc))) in panels.iter().enumerate() {
            let (sy, cy) = (&sy[8 * p..8 * p + 8], &cy[8 * p..8 * p + 8]);
            let r = y[8 * p + HALF];
            let (sr, cr) = (sy[HALF], cy[HALF]);
            for (sm, cm) in [(sc * cr - cc * sr, cc * cr + sc * sr), (sc * cr + cc * sr, cc * cr - sc * sr)] {
                for i in 0..HALF {
                    let k = self.len + 2 * i;
                    let w = gl[i].1 * r;
                    self.sin[k] = sm * cy[i] + cm * sy[i];
                    self.cos[k] = cm * cy[i] - sm * sy[i];
                    self.weight[k] = w;
                    self.sin[k + 1] = sm * cy[i] - cm * sy[i];
                    self.cos[k + 1] = cm * cy[i] + sm * sy[i];
                    self.weight[k + 1] = w;
                }
                self.len += NODES;
            }
        }
    }
}

/// Adds the integrand at a node (sin θ, cos θ) with weight `w`, any law (the tests'
/// reference for [`coulomb_sums`] and the saturating laws' route). The node's scalars are
/// passed one by one: this runs once per node and radius in the innermost loop.
#[inline]
#[allow(clippy::too_many_arguments)]
fn accumulate(f: &mut Factors, s: f64, co: f64, w: f64, c: f64, u: f64, rho: f64, law: &Law) {
    let q = co - c;
    if q <= 0.0 {
        return;
    }
    let dt = co - u;
    let dr = rho * s;
    // O(1) components: a plain square root is safe and several times cheaper than hypot
    let d = (dt * dt + dr * dr).sqrt();
    if d == 0.0 {
        return;
    }
    let inv_d = 1.0 / d;
    // traction per unit μp over the slip speed, g(D) = S(D/σ)/D, and dg/dD
    let (g, dg) = if law.slip_scale > 0.0 {
        let (sv, ds) = if law.sharpness != 1.0 && !law.truth {
            stick_slip_saturation(d / law.slip_scale, law.sharpness)
        } else {
            saturation(d / law.slip_scale, law.truth)
        };
        (sv * inv_d, (ds / law.slip_scale - sv * inv_d) * inv_d)
    } else {
        (inv_d, -inv_d * inv_d)
    };
    let (gt, gr) = (dt * g, dr * g);
    f.torque += w * q * gt;
    // g_t = dt·g(D), g_r = dr·g(D) with ∂dt/∂u = −1 and ∂D/∂u = −dt/D
    let gt_u = -g - dt * dt * inv_d * dg;
    let gr_u = -dr * dt * inv_d * dg;
    f.torque_du += w * q * gt_u;
    f.power += w * q * (gt * co + gr * dr);
    f.power_du += w * q * (gt_u * co + gr_u * dr);
    f.radial += w * q * gr * dr;
    f.radial_du += w * q * gr_u * dr;
}

/// The node sums of the Coulomb law with radial slip (g = 1/D), in local accumulators.
/// With D² = dt² + dr² and dt = cos θ − u the integrands simplify: power = u·torque +
/// ∫q·D, ∂torque/∂u = −∫q·dr²/D³, ∂power/∂u = u·∂torque/∂u, ∂radial/∂u = ∫q·dr²·dt/D³,
/// ∂²torque/∂u² = −3∫q·dr²·dt/D⁵ (∂D/∂u = −dt/D).
/// One square root and one division a node (the general route: the same plus six more
/// products and two more accumulators through memory; callgrind: 60 % more instructions).
/// Node k adds to partial sum k mod 4 and the node terms have no branch, so the compiler
/// runs the square roots and divisions two nodes at a time in vector registers (SSE2, in
/// every x86-64): 19 % less time a `factors` call, results within a few ulp of sequential
/// sums (docs/PERFORMANCE.md). The order of the sums is fixed, so results do not
/// depend on the machine. A node with q ≤ 0 (outside the contact, possible only by
/// rounding at its edge) gets weight 0; D = 0 cannot occur at an interior node with ρ > 0,
/// and with ρ = 0 only where u = cos θ at a node, which the split at θs rules out; the
/// floor on D² keeps even that case at zero terms instead of NaN.
fn coulomb_sums(nodes: &Nodes, c: f64, u: f64, rho: f64, weight: f64) -> Factors {
    const L: usize = 4;
    let (mut t, mut slip, mut t_u, mut rad, mut rad_u) = ([0.0; L], [0.0; L], [0.0; L], [0.0; L], [0.0; L]);
    let mut t_uu = [0.0; L];
    // (panels add NODES = 12 nodes at a time)
    debug_assert_eq!(nodes.len % L, 0);
    count_evaluations(nodes.len);
    for k0 in (0..nodes.len).step_by(L) {
        for l in 0..L {
            let k = k0 + l;
            let (s, co, w) = (nodes.sin[k], nodes.cos[k], nodes.weight[k]);
            let wq = w * (co - c).max(0.0);
            let dt = co - u;
            let dr = rho * s;
            let d2 = dt * dt + dr * dr;
            // 1/D
            let id = 1.0 / d2.max(f64::MIN_POSITIVE).sqrt();
            let a = wq * id;
            let dr2 = dr * dr;
            let id2 = id * id;
            let b = a * dr2 * id2;
            let bdt = b * dt;
            t[l] += a * dt;
            slip[l] += wq * (d2 * id);
            t_u[l] -= b;
            rad[l] += a * dr2;
            rad_u[l] += bdt;
            t_uu[l] += bdt * id2;
        }
    }
    let sum = |x: [f64; L]| (x[0] + x[1]) + (x[2] + x[3]);
    let (t, slip, t_u, rad, rad_u) = (sum(t), sum(slip), sum(t_u), sum(rad), sum(rad_u));
    Factors {
        torque: weight * t,
        power: weight * (u * t + slip),
        radial: weight * rad,
        torque_du: weight * t_u,
        power_du: weight * u * t_u,
        radial_du: weight * rad_u,
        torque_uu: -3.0 * weight * sum(t_uu),
    }
}

/// The node sums of the candidate saturating law without radial slip (ρ = 0, S = tanh):
/// the traction per unit μp is g_t = tanh(dt/σ) (odd in the slip, so its sign needs no
/// branch), ∂g_t/∂u = −(1 − g_t²)/σ and ∂²g_t/∂u² = −2·g_t·(1 − g_t²)/σ² =
/// 2·g_t·(∂g_t/∂u)/σ, with power = ∫q·g_t·cos θ: one exp and one division a node (the
/// general route, [`accumulate`], takes D = |dt|, g = S(D/σ)/D and dg/dD: a square root
/// and two more divisions). The two agree to rounding (test below).
fn compliance_sums(nodes: &Nodes, c: f64, u: f64, slip_scale: f64, weight: f64) -> Factors {
    let inv_s = 1.0 / slip_scale;
    let (mut t, mut t_u, mut p, mut p_u, mut t_uu) = (0.0, 0.0, 0.0, 0.0, 0.0);
    count_evaluations(nodes.len);
    for k in 0..nodes.len {
        let (co, w) = (nodes.cos[k], nodes.weight[k]);
        let wq = w * (co - c).max(0.0);
        let x = (co - u) * inv_s;
        let g = tanh_nonneg(x.abs()).copysign(x);
        let dg = -(1.0 - g * g) * inv_s;
        t += wq * g;
        t_u += wq * dg;
        p += wq * g * co;
        p_u += wq * dg * co;
        t_uu += wq * g * dg;
    }
    Factors {
        torque: weight * t,
        power: weight * p,
        radial: 0.0,
        torque_du: weight * t_u,
        power_du: weight * p_u,
        radial_du: 0.0,
        torque_uu: 2.0 * inv_s * weight * t_uu,
    }
}

/// Interface factors for contact `ct`, rotor speed ratio u = v_r/v0 ∈ [0, 1] and `law`.
/// The integration splits at the stick point θs = acos u where the tangential slip
/// changes sign, and where the integrand has a complex singularity close to the contact
/// (the law turns from driving to braking within a narrow band: small ρ or σ, or the
/// slip nearly vanishes at the crest, u → 1), it grades the panels towards it
/// ([`nearest_singularity`], [`graded_ends`]). The candidate's tanh saturation without
/// radial slip takes the Coulomb closed forms plus the saturation's difference from them
/// on a window about θs ([`compliance_factors`]), and so do its sharper stick-then-slip
/// forms ([`stick_slip_window_factors`]).
pub fn factors(ct: &Contact, u: f64, law: &Law) -> Factors {
    let uc = u.clamp(-1.0, 1.0);
    if law.sharpness != 1.0 && law.slip_scale > 0.0 && !law.truth {
        if law.radial_ratio == 0.0 {
            return stick_slip_window_factors(ct, uc, u, law);
        }
        return stick_slip_factors(ct, uc, u, law);
    }
    factors_about(ct, u, law, nearest_singularity(law, uc, ct.half_angle_rad))
}

/// [`factors`] of the laws other than the stick-then-slip ones, given the integrand's
/// nearest singularity `z` ([`nearest_singularity`] at u clamped to [−1, 1]).
fn factors_about(ct: &Contact, u: f64, law: &Law, z: Option<(f64, f64)>) -> Factors {
    if law.slip_scale > 0.0 && law.radial_ratio == 0.0 && !law.truth {
        return compliance_factors(ct, u.clamp(-1.0, 1.0), u, law, z);
    }
    quadrature_factors_about(ct, u, law, z)
}

/// Nodes of the rules that do not depend on the rotor speed: [0, φ0] in two and in four
/// equal sub-panels of [`NODES`] Gauss–Legendre nodes, each built once per contact.
pub(crate) struct SpeedFreeRule([Option<Nodes>; 2]);

impl SpeedFreeRule {
    /// No nodes yet (built at the first speed that can use them).
    pub(crate) fn new() -> Self {
        SpeedFreeRule([None, None])
    }
}

/// Least distance of the integrand's nearest singularity from [0, φ0], over φ0, at which a
/// speed-free rule of `SPEED_FREE_SUB_PANELS[k]` equal sub-panels is used: 3/4 of a
/// sub-panel's width, 1.5 of its half-widths, which puts the singularity on or outside
/// the Bernstein ellipse E = 1.5 + √3.25 ≈ 3.3 (12-node error of order E⁻²⁴ ≈ 3e-13, as
/// the graded rule's panels next to a singularity).
const SPEED_FREE_REACH: [f64; 2] = [0.375, 0.1875];
const SPEED_FREE_SUB_PANELS: [usize; 2] = [2, 4];

/// [`factors`] for the rotor-speed solve of one trial (one contact, many speeds u): where
/// the integrand's nearest complex singularity ([`nearest_singularity`]) is at least a
/// few sub-panel widths from [0, φ0] ([`SPEED_FREE_REACH`]), the integrand is analytic
/// and slowly varying on the scale of a sub-panel: the rule `rule` (built at the first
/// such speed, the same nodes at every later one) integrates it without the split at θs,
/// in 24 nodes where the singularity is far, 48 where it is nearer. That saves the nodes'
/// sines and cosines (about 30 % of a call) at every Newton step of the speed but the
/// first, and half the node sums where 24 nodes do. Elsewhere, at u = ±1, and for the
/// stick-then-slip laws, [`factors`]. Within 1e-12 of the graded rule (test below).
pub(crate) fn factors_reusing(ct: &Contact, u: f64, law: &Law, rule: &mut SpeedFreeRule) -> Factors {
    let phi0 = ct.half_angle_rad;
    let stick_slip = law.sharpness != 1.0 && law.slip_scale > 0.0 && !law.truth;
    // (at u = ±1 the slip vanishes on the axis, at θ = 0 or π, where the traction's
    // derivative in u has a log singularity that the graded rule's panels resolve)
    if !stick_slip && u.abs() < 1.0 {
        let z = nearest_singularity(law, u.clamp(-1.0, 1.0), phi0);
        if let Some(z) = z {
            let reach = distance(z, phi0) / phi0;
            if let Some(k) = (0..2).find(|&k| reach >= SPEED_FREE_REACH[k]) {
                let nodes = rule.0[k].get_or_insert_with(|| {
                    let mut n = Nodes::new();
                    if SPEED_FREE_SUB_PANELS[k] == 2 {
                        n.panels(&[(0.0, phi0, (0.5 * phi0).sin_cos())]);
                    } else {
                        let h = 0.5 * phi0;
                        n.panels(&[(0.0, h, (0.5 * h).sin_cos()), (h, phi0, (0.5 * (h + phi0)).sin_cos())]);
                    }
                    n
                });
                return node_sums(nodes, ct.offset, u, law);
            }
        }
        return factors_about(ct, u, law, z);
    }
    factors(ct, u, law)
}

/// [`factors`] by the graded rule over the whole contact split at θs, for every law: the
/// independent reference of [`compliance_factors`] and [`factors_reusing`] in the tests.
#[cfg(test)]
fn quadrature_factors(ct: &Contact, u: f64, law: &Law) -> Factors {
    let uc = u.clamp(-1.0, 1.0);
    if law.sharpness != 1.0 && law.slip_scale > 0.0 && !law.truth {
        return stick_slip_factors(ct, uc, u, law);
    }
    quadrature_factors_about(ct, u, law, nearest_singularity(law, uc, ct.half_angle_rad))
}

/// The graded rule over the whole contact split at θs for the laws other than the
/// stick-then-slip ones, given the integrand's nearest singularity `z`: the route of the
/// laws without a closed-form part.
fn quadrature_factors_about(ct: &Contact, u: f64, law: &Law, z: Option<(f64, f64)>) -> Factors {
    let phi0 = ct.half_angle_rad;
    let uc = u.clamp(-1.0, 1.0);
    let ts = uc.acos();
    if let Some((ends, n)) = z.and_then(|z| graded_ends(ts, phi0, z)) {
        return graded_factors(&ends[..n], ct.offset, u, law);
    }
    let mut nodes = Nodes::new();
    if ts > 0.0 && ts < phi0 {
        // the centre of [0, θs] by the half-angle formulas of cos θs = u (no sin_cos call)
        nodes.panels(&[
            (0.0, ts, ((0.5 * (1.0 - uc)).sqrt(), (0.5 * (1.0 + uc)).sqrt())),
            (ts, phi0, (0.5 * (ts + phi0)).sin_cos()),
        ]);
    } else {
        nodes.panels(&[(0.0, phi0, (0.5 * phi0).sin_cos())]);
    }
    node_sums(&nodes, ct.offset, u, law)
}

/// Slip speeds beyond REACH·σ saturate the candidate's traction completely:
/// [`tanh_nonneg`] is exactly 1 above 19.1 (tanh x rounds to 1 there), so outside the
/// window |cos θ − u| ≤ REACH·σ the saturating law is the Coulomb law to the last bit.
const REACH: f64 = 19.5;

/// [`factors`] of the candidate saturating law without radial slip (ρ = 0, S = tanh,
/// Storck and Wallaschek 2003): the Coulomb law's closed forms (torque 2χ(θs) − χ(φ0),
/// power 2E(θs) − E(φ0), Sun et al. 2021 eq. 10-11) plus the integrals of the saturation's
/// difference from it, q·(tanh(dt/σ) − sign dt), and of ∂/∂u, −q·(1 − tanh²)/σ, which
/// vanish outside the window |cos θ − u| ≤ [`REACH`]·σ about the stick point θs. The
/// graded rule ([`graded_ends_in`]) integrates them on the window alone: where σ is small
/// (the contact wider than the band of partial stick) that is a few panels about θs
/// however small σ is, instead of panels graded across the whole contact (their number
/// grows with log(1/σ)), and the difference 1 − tanh x = 2e/(1 + e) (e = exp(−2x)) is
/// formed without cancellation. `uc` is `u` clamped to [−1, 1], `z` the nearest
/// singularity. Within 1e-12 of the graded rule over the whole contact
/// (`quadrature_factors`, test below).
fn compliance_factors(ct: &Contact, uc: f64, u: f64, law: &Law, z: Option<(f64, f64)>) -> Factors {
    let sigma = law.slip_scale;
    let Some((mut f, plain, np)) = coulomb_part_and_window(ct, uc, u, REACH * sigma) else {
        // a window over the whole contact saves nothing: the plain rule's one pass is cheaper
        return quadrature_factors_about(ct, u, law, z);
    };
    if np == 0 {
        return f;
    }
    let (ends, n) = z.and_then(|z| graded_ends_in(&plain[..np], z)).unwrap_or_else(|| plain_ends(&plain[..np]));
    for_panel_pairs(&ends[..n], |nodes| f.add(&compliance_window_sums(nodes, ct.offset, u, sigma)));
    f
}

/// The Coulomb law's closed forms (torque 2χ(θs) − χ(φ0), power 2E(θs) − E(φ0), Sun et
/// al. 2021 eq. 10-11; no derivatives in u: a saturating law's come from its window alone)
/// and the window |cos θ − u| ≤ `reach` about the stick point θs within the contact, as
/// one or two panels split at θs (none where the window misses the contact). `None` where
/// the window covers the whole contact. `uc` is `u` clamped to [−1, 1].
fn coulomb_part_and_window(ct: &Contact, uc: f64, u: f64, reach: f64) -> Option<(Factors, WindowPanels, usize)> {
    let (phi0, c) = (ct.half_angle_rad, ct.offset);
    if u + reach >= 1.0 && u - reach <= c.max(-1.0) {
        return None;
    }
    let ts = uc.acos();
    let (s0, c0) = phi0.sin_cos();
    // sign(cos θ − u) = +1 on [0, θs) and −1 beyond
    let te = ts.min(phi0);
    let (se, ce) = if ts < phi0 { (((1.0 - uc) * (1.0 + uc)).sqrt(), uc) } else { (s0, c0) };
    let chi = |t: f64, s: f64| s - t * c;
    let e_int = |t: f64, s: f64, co: f64| 0.5 * t + 0.5 * s * co - c * s;
    let f = Factors {
        torque: 2.0 * chi(te, se) - chi(phi0, s0),
        power: 2.0 * e_int(te, se, ce) - e_int(phi0, s0, c0),
        ..Factors::default()
    };
    let lo = if u + reach >= 1.0 { 0.0 } else { (u + reach).acos() };
    let hi = if u - reach <= -1.0 { phi0 } else { (u - reach).acos().min(phi0) };
    let mut plain = [(0.0, 0.0); 2];
    let mut np = 0;
    if te > lo {
        plain[np] = (lo, te);
        np += 1;
    }
    if ts < phi0 && hi > ts {
        plain[np] = (ts, hi);
        np += 1;
    }
    Some((f, plain, np))
}

/// The window's panels about θs: the first `n` of two, ascending.
type WindowPanels = [(f64, f64); 2];

/// The ends of the contiguous panels `plain` (at least one), ungraded.
fn plain_ends(plain: &[(f64, f64)]) -> ([f64; MAX_PANELS + 1], usize) {
    let mut e = [0.0; MAX_PANELS + 1];
    e[0] = plain[0].0;
    for (k, &(_, b)) in plain.iter().enumerate() {
        e[k + 1] = b;
    }
    (e, plain.len() + 1)
}

/// Calls `sum` with the nodes of the panels between `ends`, two panels at a time (one node
/// array of the plain rule's size, rather than one for all panels: zeroing 11.5 kB a call
/// had cost 1-14 % of a graded call, most at few panels).
#[inline(always)]
fn for_panel_pairs(ends: &[f64], mut sum: impl FnMut(&Nodes)) {
    let panel = |a: f64, b: f64| (a, b, (0.5 * (a + b)).sin_cos());
    for k in (0..ends.len() - 1).step_by(2) {
        let mut nodes = Nodes::new();
        if k + 2 < ends.len() {
            nodes.panels(&[panel(ends[k], ends[k + 1]), panel(ends[k + 1], ends[k + 2])]);
        } else {
            nodes.panels(&[panel(ends[k], ends[k + 1])]);
        }
        sum(&nodes);
    }
}

/// The node sums of [`compliance_factors`]: q·(tanh x − sign x) and q·∂tanh(x)/∂u with
/// x = (cos θ − u)/σ, and the same times cos θ; and q·∂²tanh(x)/∂u² =
/// −q·2·tanh x·(1 − tanh² x)/σ², the whole torque's second derivative (the Coulomb part's
/// step at θs moves with u, but the difference's step cancels it). A node with x = +0
/// (cos θ rounded onto u) counts as beyond θs, where the Coulomb part takes the sign −1.
fn compliance_window_sums(nodes: &Nodes, c: f64, u: f64, slip_scale: f64) -> Factors {
    let inv_s = 1.0 / slip_scale;
    let (mut t, mut t_u, mut p, mut p_u, mut t_uu) = (0.0, 0.0, 0.0, 0.0, 0.0);
    count_evaluations(nodes.len);
    for k in 0..nodes.len {
        let (co, w) = (nodes.cos[k], nodes.weight[k]);
        let wq = w * (co - c).max(0.0);
        let x = (co - u) * inv_s;
        let ax = x.abs();
        // 1 − tanh|x| and 1 − tanh²|x|
        let (a, sech2) = if ax < 0.02 {
            let th = tanh_nonneg(ax);
            (1.0 - th, 1.0 - th * th)
        } else if ax < 19.1 {
            let e = exp_nonpos(-2.0 * ax);
            let r = 1.0 / (1.0 + e);
            (2.0 * e * r, 4.0 * e * r * r)
        } else {
            (0.0, 0.0)
        };
        // tanh x − sign x, and tanh x = sign x·(1 − a)
        let (d, g) = if x > 0.0 { (-a, 1.0 - a) } else { (a, a - 1.0) };
        let dg = -sech2 * inv_s;
        t += wq * d;
        t_u += wq * dg;
        p += wq * d * co;
        p_u += wq * dg * co;
        t_uu += wq * g * dg;
    }
    Factors {
        torque: t,
        power: p,
        radial: 0.0,
        torque_du: t_u,
        power_du: p_u,
        radial_du: 0.0,
        torque_uu: 2.0 * inv_s * t_uu,
    }
}

/// [`factors`] on the graded panels between `ends` ([`for_panel_pairs`]). Kept out of
/// `factors` (never inlined), so that the node sums are not compiled into it twice. (The
/// panels' centres by angle addition from θs and the series of their offsets saved another
/// 4 %, but their 2-ulp rounding moved the torque at the crest, u = 1, where cos θ − u
/// cancels, by 2e-14 of 0.05.)
#[inline(never)]
fn graded_factors(ends: &[f64], c: f64, u: f64, law: &Law) -> Factors {
    let mut f = Factors::default();
    for_panel_pairs(ends, |nodes| f.add(&node_sums(nodes, c, u, law)));
    f
}

/// The factors as sums over `nodes`, each of the law's radii by the cheapest route.
/// Inlined: as a call of its own, the plain rule's node sums lost their two-lane vector
/// form (`coulomb_sums`) and a `radial_friction` map took 20 % longer.
#[inline(always)]
fn node_sums(nodes: &Nodes, c: f64, u: f64, law: &Law) -> Factors {
    let mut f = Factors::default();
    for (rho, weight) in radii(law) {
        let part = if law.slip_scale > 0.0 && rho == 0.0 && !law.truth && law.sharpness == 1.0 {
            compliance_sums(nodes, c, u, law.slip_scale, weight)
        } else if law.slip_scale > 0.0 {
            // (no second derivative on this route)
            let mut g = Factors { torque_uu: f64::NAN, ..Factors::default() };
            count_evaluations(nodes.len);
            for k in 0..nodes.len {
                accumulate(&mut g, nodes.sin[k], nodes.cos[k], weight * nodes.weight[k], c, u, rho, law);
            }
            g
        } else {
            coulomb_sums(nodes, c, u, rho, weight)
        };
        f.add(&part);
    }
    f
}

/// Most panels of the graded rule: 0, θs and φ0, and in each of the plain rule's two panels
/// the singularity's nearest point and at most twelve graded ends either side of it (at the
/// narrowest distance, [`MIN_FEATURE_WIDTH`], 3w·6^k < π for k ≤ 11).
const MAX_PANELS: usize = 56;
/// The first graded end sits GRADE_FIRST singularity distances from the point nearest to
/// it, each further one GRADE_RATIO times as far. A panel [d, 6d] is then split into
/// sub-panels whose nearer one sees the singularity (at distance w ≤ d/3 from its end)
/// from its end; the Gauss–Legendre error on it is of order E⁻²⁴ with E ≈ 3.4 the
/// Bernstein ellipse through the singularity: 2e-13. The panel [n, n + 3w] next to it:
/// E ≈ 3.5, 1e-13 (with θ* straight over n; see [`SNAP`]).
const GRADE_FIRST: f64 = 3.0;
const GRADE_RATIO: f64 = 6.0;
/// Nearer singularities are graded as this far (at most MAX_PANELS panels). Below it the
/// turn is a step at θs on the scale of the panel next to it, which the split at θs
/// integrates like the Coulomb law's sign change (ρ = 1e-14: within 1.1e-8 of adaptive
/// quadrature at u = 1, test below). A floor of 1e-6 would leave 7.8e-9 at ρ = 1,
/// u = 1 − 1.7e-8, where θ* is 1.7e-8 from the axis.
const MIN_FEATURE_WIDTH: f64 = 1e-9;
/// A singularity whose real part is within SNAP × its distance from the real axis of a
/// panel end is graded from that end ([`graded_ends`]), one end fewer: where the
/// first-order estimate Re θ* ≈ θs holds, Re θ* is that close to θs, and the ends are those
/// of the first-order rule. Seen from the end, θ* is then a little off the point the
/// grading starts from, and the first sub-panel's Bernstein ellipse shrinks (E ≈ 3.3 at
/// 0.1, 2.8 at 0.5). Against adaptive quadrature on a dense sweep the worst relative error
/// is about 1e-13 at SNAP = 0.1, 2.4e-11 at 0.5 (σ = 0.2), and where the snap sets in the
/// factors step by that much (2.5e-11 at 0.5). Without snapping (0) the ends move
/// continuously, for 12 % more instructions on a `tangential_compliance` map and 13 % on a
/// `radial_friction=0.05` one; 0.1 costs 21 % and 5 % more than the first-order rule, 0.5
/// 10 % and 5 %.
const SNAP: f64 = 0.1;

/// The complex singularity of the integrand nearest to the real θ axis, (Re θ*, |Im θ*|),
/// for rotor speed `u` ∈ [−1, 1]; `None` for the Coulomb law without radial slip, whose
/// one feature, the sign change at θs, the split there integrates exactly.
///
/// The slip D = √((cos θ − u)² + ρ² sin² θ) enters the Coulomb law's traction s/D with
/// branch points at D² = 0, and the saturating laws through S(D/σ)/D, even in D, whose
/// singularities are at D² = −κ²: κ = πσ/2 (tanh's poles) or σ (the algebraic truth
/// form's branch points). In c = cos θ, D² = −κ² is the quadratic
/// (1 − ρ²)·c² − 2u·c + (u² + ρ² + κ²) = 0, so θ* = arccos c at its roots (complex, or real
/// beyond ±1: then θ* = i·arcosh c or π + i·arcosh(−c)). Away from the crest the nearest
/// root sits about the band's half-width w = √(κ² + ρ² sin² θs)/sin θs from θs (to first
/// order in w); at the crest (u → 1, sin θs → 0) that estimate diverges while θ*
/// approaches 0 (ρ = 1: |Im θ*| = arcosh((1 + u²)/2u) ≈ 1 − u), where ungraded panels
/// have relative errors up to 8e-5: hence the exact root. The truth form's radii each
/// have theirs; the nearest counts.
fn nearest_singularity(law: &Law, u: f64, phi0: f64) -> Option<(f64, f64)> {
    let kappa = if law.slip_scale > 0.0 {
        law.slip_scale * if law.truth { 1.0 } else { std::f64::consts::FRAC_PI_2 }
    } else {
        0.0
    };
    // 1 − u² and sin θs without cancellation at the crest
    let one_minus_u2 = (1.0 - u) * (1.0 + u);
    let sin_ts = one_minus_u2.max(0.0).sqrt();
    let mut best: Option<(f64, f64)> = None;
    for (rho, _) in radii(law) {
        if rho == 0.0 && kappa == 0.0 {
            continue;
        }
        if kappa == 0.0 && u.abs() == 1.0 {
            // At u = ±1 the slip vanishes on the axis, at θ = 0 (or π), where the factor
            // |sin θ| of D cancels in the traction: D = |sin θ|·√(tan²(θ/2) + ρ²) at u = 1, so
            // the traction is singular where tan(θ/2) = ±iρ, θ = ±2i·artanh ρ (ρ < 1; none
            // at ρ = 1; π ± 2i·artanh(1/ρ) for ρ > 1). (At u = −1, mirrored about π/2.)
            let z = match rho {
                r if r < 1.0 => Some((0.0, 2.0 * r.atanh())),
                r if r > 1.0 => Some((std::f64::consts::PI, 2.0 * (1.0 / r).atanh())),
                _ => None,
            };
            let z = z.map(|(re, im)| if u < 0.0 { (std::f64::consts::PI - re, im) } else { (re, im) });
            if let Some(z) = z.filter(|z| best.is_none_or(|b| distance(*z, phi0) < distance(b, phi0))) {
                best = Some(z);
            }
            continue;
        }
        let rho2 = rho * rho;
        let a = (1.0 - rho) * (1.0 + rho);
        // the roots as offsets Δc = c − u from cos θs = u, computed without cancellation:
        // the discriminant (over 4) is ρ²u² − a·(ρ² + κ²) = ρ²(ρ² − (1 − u²)) − a·κ², and
        // the two offsets' product is (ρ²(1 − u²) + κ²)/a
        let disc = rho2 * (rho2 - one_minus_u2) - a * kappa * kappa;
        let offsets: [Option<C64>; 2] = if disc < 0.0 {
            // a conjugate pair (then a > 0); arccos of the other one is the conjugate
            [Some(C64::new(u * rho2 / a, (-disc).sqrt() / a)), None]
        } else {
            // (both terms of one sign, so no cancellation for u < 0 either)
            let far = u * rho2 + disc.sqrt().copysign(u);
            [
                (a != 0.0).then(|| C64::new(far / a, 0.0)),
                (far != 0.0).then(|| C64::new((rho2 * one_minus_u2 + kappa * kappa) / far, 0.0)),
            ]
        };
        for dc in offsets.into_iter().flatten() {
            let th = arccos_near(u, sin_ts, dc);
            let z = (th.re, th.im.abs());
            // nearest to the contact [0, φ0], not merely to the axis (at u = 0 with ρ > 1 the
            // roots at 0 and at π are equally far from the axis)
            if z.0.is_finite() && z.1.is_finite() && best.is_none_or(|b| distance(z, phi0) < distance(b, phi0)) {
                best = Some(z);
            }
        }
    }
    best
}

/// [`factors`] for the candidate's sharper stick-then-slip saturations (n ≠ 1,
/// [`stick_slip_saturation`]). Their singularities do not sit over the stick point θs as
/// tanh's do but off it on either side (at θs ± Re δ), so the panels are graded towards
/// the nearest one on each side ([`stick_slip_singularities`]): the union of the two
/// gradings. `uc` is `u` clamped to [−1, 1].
fn stick_slip_factors(ct: &Contact, uc: f64, u: f64, law: &Law) -> Factors {
    let (phi0, ts) = (ct.half_angle_rad, uc.acos());
    let split = ts > 0.0 && ts < phi0;
    let plain: &[(f64, f64)] = if split { &[(0.0, ts), (ts, phi0)] } else { &[(0.0, phi0)] };
    let mut ends = [0.0; 2 * (MAX_PANELS + 1)];
    let len = union_of_gradings(plain, stick_slip_singularities(law, uc, phi0), &mut ends);
    graded_factors(&ends[..len], ct.offset, u, law)
}

/// The panel ends of the contiguous panels `plain` graded towards each singularity of
/// `singularities` ([`graded_ends_in`]), merged: sorted and distinct, in `out`, with their
/// count returned. Where neither grades (none is near enough) they are `plain`'s own ends.
fn union_of_gradings(
    plain: &[(f64, f64)],
    singularities: [Option<(f64, f64)>; 2],
    out: &mut [f64; 2 * (MAX_PANELS + 1)],
) -> usize {
    let mut len = 0;
    for z in singularities.into_iter().flatten() {
        if let Some((e, k)) = graded_ends_in(plain, z) {
            out[len..len + k].copy_from_slice(&e[..k]);
            len += k;
        }
    }
    if len == 0 {
        let (e, k) = plain_ends(plain);
        out[..k].copy_from_slice(&e[..k]);
        len = k;
    }
    let ends = &mut out[..len];
    ends.sort_unstable_by(f64::total_cmp);
    let mut distinct = 1;
    for k in 1..ends.len() {
        if ends[k] != ends[distinct - 1] {
            ends[distinct] = ends[k];
            distinct += 1;
        }
    }
    distinct
}

/// [`factors`] of the stick-then-slip saturations without radial slip (ρ = 0, n ≠ 1): as
/// [`compliance_factors`] for tanh, the Coulomb closed forms plus the saturation's
/// difference from them, q·(S(|x|) − 1)·sign x and q·∂/∂u = −q·S'(|x|)/σ with
/// x = (cos θ − u)/σ, on the window |x| ≤ REACH^(1/n) alone (beyond it tanh(xⁿ) rounds to
/// 1, S' is 0 and S is 1 within a few ulp), graded towards the law's singularities on both
/// sides of θs ([`stick_slip_singularities`]). The whole-contact rule
/// ([`stick_slip_factors`]) grades its panels across the contact and evaluates the general
/// integrand, with its square root and three divisions, at every node; the window is a
/// fraction of the contact where σ is small. No second derivative in u (NaN), as on the
/// whole-contact route. Within 1e-12 of that route (test below).
fn stick_slip_window_factors(ct: &Contact, uc: f64, u: f64, law: &Law) -> Factors {
    let (sigma, n) = (law.slip_scale, law.sharpness);
    let Some((mut f, plain, np)) = coulomb_part_and_window(ct, uc, u, sigma * REACH.powf(1.0 / n)) else {
        return stick_slip_factors(ct, uc, u, law);
    };
    f.torque_uu = f64::NAN;
    if np == 0 {
        return f;
    }
    let mut ends = [0.0; 2 * (MAX_PANELS + 1)];
    let len = union_of_gradings(&plain[..np], stick_slip_singularities(law, uc, ct.half_angle_rad), &mut ends);
    for_panel_pairs(&ends[..len], |nodes| f.add(&stick_slip_window_sums(nodes, ct.offset, u, sigma, n)));
    f
}

/// The node sums of [`stick_slip_window_factors`]. A node with x = +0 (cos θ rounded onto
/// u) counts as beyond θs, where the Coulomb part takes the sign −1.
fn stick_slip_window_sums(nodes: &Nodes, c: f64, u: f64, slip_scale: f64, sharpness: f64) -> Factors {
    let inv_s = 1.0 / slip_scale;
    let (mut t, mut t_u, mut p, mut p_u) = (0.0, 0.0, 0.0, 0.0);
    count_evaluations(nodes.len);
    for k in 0..nodes.len {
        let (co, w) = (nodes.cos[k], nodes.weight[k]);
        let wq = w * (co - c).max(0.0);
        let x = (co - u) * inv_s;
        let (sv, ds) = stick_slip_saturation(x.abs(), sharpness);
        let d = if x > 0.0 { sv - 1.0 } else { 1.0 - sv };
        let dg = -ds * inv_s;
        t += wq * d;
        t_u += wq * dg;
        p += wq * d * co;
        p_u += wq * dg * co;
    }
    Factors { torque: t, power: p, radial: 0.0, torque_du: t_u, power_du: p_u, radial_du: 0.0, torque_uu: f64::NAN }
}

/// The singularities of the stick-then-slip law S(D/σ)/D with S(x) = tanh(xⁿ)^(1/n)
/// nearest to the contact on either side of θs, as (Re θ*, |Im θ*|): tanh's pole at
/// xⁿ = iπ/2 puts them where D² = ζ = σ²·(π/2)^(2/n)·e^(iπ/n) (for n = 1, ζ = −(πσ/2)²,
/// [`nearest_singularity`]'s κ). In the offset Δc = cos θ − u that is the quadratic
/// (1 − ρ²)·Δc² − 2uρ²·Δc + ρ²(1 − u²) − ζ = 0 (its conjugate ζ̄ gives the conjugate
/// roots, as far from the axis); θ* = arccos(u + Δc), and θ* mirrored about θs (the other
/// branch of the arccos near θs, δ → −δ) for the other side. The branch points of the
/// 1/n-th power (tanh's zeros, |xⁿ| = π) lie a little farther out in the same directions.
fn stick_slip_singularities(law: &Law, u: f64, phi0: f64) -> [Option<(f64, f64)>; 2] {
    let n = law.sharpness;
    let zeta = C64::from_polar(law.slip_scale.powi(2) * FRAC_PI_2_F.powf(2.0 / n), PI / n);
    let one_minus_u2 = (1.0 - u) * (1.0 + u);
    let sin_ts = one_minus_u2.max(0.0).sqrt();
    let ts = u.acos();
    let mut best: [Option<(f64, f64)>; 2] = [None, None];
    for (rho, _) in radii(law) {
        let rho2 = rho * rho;
        let a = (1.0 - rho) * (1.0 + rho);
        // ρ²(1 − u²) − ζ, and half the linear coefficient
        let c0 = C64::new(rho2 * one_minus_u2, 0.0) - zeta;
        let b = C64::new(u * rho2, 0.0);
        let root = csqrt(b * b - c0 * a);
        // the root of larger modulus without cancellation, the other from the product
        let far = if (b + root).norm() >= (b - root).norm() { b + root } else { b - root };
        let mut offsets: Vec<C64> = Vec::with_capacity(2);
        if a != 0.0 {
            offsets.push(far / a);
        }
        if far.norm() > 0.0 {
            offsets.push(c0 / far);
        }
        for dc in offsets {
            let th = arccos_near(u, sin_ts, dc);
            for z in [(th.re, th.im.abs()), (2.0 * ts - th.re, th.im.abs())] {
                let side = usize::from(z.0 >= ts);
                if z.0.is_finite()
                    && z.1.is_finite()
                    && best[side].is_none_or(|bz| distance(z, phi0) < distance(bz, phi0))
                {
                    best[side] = Some(z);
                }
            }
        }
    }
    best
}

const FRAC_PI_2_F: f64 = std::f64::consts::FRAC_PI_2;

/// Distance [rad] of the point z = (Re, |Im|) from the segment [0, φ0] of the real axis.
fn distance(z: (f64, f64), phi0: f64) -> f64 {
    let d = z.0 - z.0.clamp(0.0, phi0);
    (d * d + z.1 * z.1).sqrt()
}

type C64 = nalgebra::Complex<f64>;

/// Principal square root of an O(1) complex number by its real formulas (the library's goes
/// through polar form: an atan2, a hypot and a sin_cos, most of the cost of grading).
fn csqrt(z: C64) -> C64 {
    let r = (z.re * z.re + z.im * z.im).sqrt();
    let re = (0.5 * (r + z.re)).max(0.0).sqrt();
    let im = (0.5 * (r - z.re)).max(0.0).sqrt();
    C64::new(re, im.copysign(z.im))
}

/// arccos(u + Δc) for u = cos θs ∈ [−1, 1], `sin_ts` = sin θs, accurate in its imaginary
/// part where u + Δc is near 1 (the crest). A real offset: arccos of c = u + Δc in [−1, 1],
/// else i·arcosh c (c > 1) or π + i·arcosh(−c), with c ∓ 1 = (u ∓ 1) + Δc (exact
/// differences, no cancellation). A complex one: small (|δ| ≤ 0.1), as θs + δ with δ the
/// root nearest zero of the quadratic expansion of −2u·sin²(δ/2) − sin θs·sin δ = Δc (the
/// identity for cos(θs + δ) − u, free of the cancellation in cos θ − u), within about
/// |δ|²/6 of δ relative, plenty for grading panels; larger, by [`acos_complex`], on the
/// branch ±arccos nearer that estimate (the one a continuation from θs reaches), and where
/// |Δc| > 1/2 the principal one.
fn arccos_near(u: f64, sin_ts: f64, dc: C64) -> C64 {
    if dc.im == 0.0 {
        let c = u + dc.re;
        return if c > 1.0 {
            let e = (u - 1.0) + dc.re;
            C64::new(0.0, (e + (e * (2.0 + e)).sqrt()).ln_1p())
        } else if c < -1.0 {
            let e = -(u + 1.0) - dc.re;
            C64::new(std::f64::consts::PI, (e + (e * (2.0 + e)).sqrt()).ln_1p())
        } else {
            C64::new(c.acos(), 0.0)
        };
    }
    if dc.norm_sqr() > 0.25 {
        return acos_complex(u + dc.re, dc.im);
    }
    let root = csqrt(C64::new(sin_ts * sin_ts, 0.0) - dc * (2.0 * u));
    let d = -dc * 2.0 / (root + sin_ts);
    let ts = u.clamp(-1.0, 1.0).acos();
    if d.norm_sqr() <= 0.01 {
        return d + ts;
    }
    let estimate = d + ts;
    let p = acos_complex(u + dc.re, dc.im);
    if (p - estimate).norm_sqr() <= (p + estimate).norm_sqr() {
        p
    } else {
        -p
    }
}

/// The principal arccos of the complex number x + iy, y ≠ 0 (Re in [0, π], Im of the sign
/// of −y), from A = (|z + 1| + |z − 1|)/2 ≥ 1: Im = −sign(y)·arcosh A and
/// Re = atan(√((A − x)(A + x))/x) (cos Re = x/A), each difference formed without
/// cancellation (Hull, Fairgrieve and Tang 1997, ACM TOMS 23(3), 299-335, §3; x ≥ 0 here,
/// arccos(−z) = π − arccos z). A few ulp in both parts: no series, no iteration, one
/// `atan` and one `ln_1p` (Newton steps on the cosine identity need two or three complex
/// sines and cosines to the same accuracy).
fn acos_complex(x: f64, y: f64) -> C64 {
    let xa = x.abs();
    let y2 = y * y;
    // |z + 1| and |z − 1| for z = |x| + iy (both O(1) or larger: no overflow before 1e150)
    let r = ((xa + 1.0) * (xa + 1.0) + y2).sqrt();
    let s = ((xa - 1.0) * (xa - 1.0) + y2).sqrt();
    let a = 0.5 * (r + s);
    // r − (|x| + 1) = y²/(r + |x| + 1) exactly; s − (1 − |x|) or s − (|x| − 1) likewise
    let r_m = y2 / (r + xa + 1.0);
    let (a_m1, a_mx) = if xa <= 1.0 {
        (0.5 * (r_m + y2 / (s + 1.0 - xa)), 0.5 * (r_m + s + 1.0 - xa))
    } else {
        (0.5 * (r_m + s + xa - 1.0), 0.5 * (r_m + y2 / (s + xa - 1.0)))
    };
    let im = (a_m1 + (a_m1 * (a + 1.0)).sqrt()).ln_1p();
    let re = if xa == 0.0 { std::f64::consts::FRAC_PI_2 } else { ((a_mx * (a + xa)).sqrt() / xa).atan() };
    let re = if x < 0.0 { std::f64::consts::PI - re } else { re };
    C64::new(re, -im.copysign(y))
}

/// (sin z, cos z) of a complex z = x + iy: sin x·cosh y + i·cos x·sinh y and
/// cos x·cosh y − i·sin x·sinh y, with sinh y and cosh y from one e^y − 1 (no cancellation
/// in sinh y for small y). The Newton reference of [`acos_complex`] in the tests.
#[cfg(test)]
fn sin_cos_complex(z: C64) -> (C64, C64) {
    let (sx, cx) = z.re.sin_cos();
    let em = z.im.exp_m1();
    let e = em + 1.0;
    let sinh = 0.5 * em * (em + 2.0) / e;
    let cosh = 0.5 * (e + 1.0 / e);
    (C64::new(sx * cosh, cx * sinh), C64::new(cx * cosh, -sx * sinh))
}

/// Panel ends of the graded rule on [0, φ0] about the singularity `z` = (Re θ*, |Im θ*|):
/// 0, θs when inside, φ0, and in each of the plain rule's panels [0, θs] and [θs, φ0] the
/// point n nearest to θ* (when strictly inside) and the ends n ∓ 3w·6^k that fall inside
/// the panel, w the distance from θ* to n (ascending; the count is the second value).
/// `None` when no end is added: the plain rule's panels are then no wider than 3w each side
/// of n, and as accurate. With θ* near θs (Re θ* = θs to first order in w) this is the
/// first-order rule, graded about θs. The ends move continuously with u, w and φ0, and a
/// panel appears or leaves with zero width, so the factors are continuous in u except where
/// n snaps to a panel end ([`SNAP`]): there they step by up to the rule's error (about
/// 1e-13 relative). (The plain rule alone, its panels much wider than w, has relative
/// errors up to 3.5e-4 and a ∂torque/∂u 20-30 % off at ρ = 0.0035 or σ = 0.003; with it 89
/// of 18 697 points of a trum60a map at ρ = 0.0035 end without convergence, the same
/// amplitude trial returning two rotor speeds depending on its start:
/// tests/solver_convergence.rs.)
fn graded_ends(ts: f64, phi0: f64, z: (f64, f64)) -> Option<([f64; MAX_PANELS + 1], usize)> {
    let split = ts > 0.0 && ts < phi0;
    let plain: &[(f64, f64)] = if split { &[(0.0, ts), (ts, phi0)] } else { &[(0.0, phi0)] };
    graded_ends_in(plain, z)
}

/// [`graded_ends`] on the contiguous panels `plain` (one or two, ascending) instead of the
/// plain rule's panels of [0, φ0]: the same grading about `z` inside each.
fn graded_ends_in(plain: &[(f64, f64)], z: (f64, f64)) -> Option<([f64; MAX_PANELS + 1], usize)> {
    let mut ends = [0.0; MAX_PANELS + 1];
    ends[0] = plain[0].0;
    // ends in ascending order, panel by panel: graded ends below its nearest point (made
    // nearest first, stored reversed), the point itself, graded ends above it, its far end
    let mut n = 1;
    let mut graded = 0;
    let dist = |x: f64| ((z.0 - x) * (z.0 - x) + z.1 * z.1).sqrt().max(MIN_FEATURE_WIDTH);
    for &(p, q) in plain {
        let mut near = z.0.clamp(p, q);
        // θ* over a point within SNAP × its distance of an end is graded from that end
        if near - p < SNAP * z.1 {
            near = p;
        } else if q - near < SNAP * z.1 {
            near = q;
        }
        let w = dist(near);
        if w < q - p {
            let first = n;
            let mut d = GRADE_FIRST * w;
            while near - d > p && n < MAX_PANELS - 1 {
                ends[n] = near - d;
                n += 1;
                d *= GRADE_RATIO;
            }
            ends[first..n].reverse();
            if near > p && near < q && n < MAX_PANELS - 1 {
                ends[n] = near;
                n += 1;
            }
            let mut d = GRADE_FIRST * w;
            while near + d < q && n < MAX_PANELS - 1 {
                ends[n] = near + d;
                n += 1;
                d *= GRADE_RATIO;
            }
            graded += n - first;
        }
        ends[n] = q;
        n += 1;
    }
    (graded > 0).then_some((ends, n))
}

/// Five-point Gauss–Legendre nodes and weights on [−1, 1], across the contact width.
const WIDTH_NODES: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// The radial-speed ratios ρ the integral is taken at, with their weights. Truth form:
/// the radial slope ∂R/∂r of the mode shape, hence ρ, varies linearly across the contact
/// width (±40 % between inner and outer edge); otherwise one ρ.
fn radii(law: &Law) -> impl Iterator<Item = (f64, f64)> + '_ {
    let resolved = law.truth_radial && law.radial_ratio > 0.0;
    let width =
        WIDTH_NODES.iter().filter(move |_| resolved).map(|&(y, w)| (law.radial_ratio * (1.0 + 0.4 * y), 0.5 * w));
    width.chain(std::iter::once((law.radial_ratio, 1.0)).filter(move |_| !resolved))
}

// The interface's state at one trial amplitude of the steady-state solve
// (crate::solve::trial): the baseline Coulomb closed forms and the generalised law's
// speed root.

/// An angle of a trial with its sine and cosine and its derivative in the amplitude: the
/// next trial's angle solve starts at the angle moved along that derivative, its sine and
/// cosine carried by [`contact::sin_cos_rotated`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngleCarry {
    /// The angle [rad].
    rad: f64,
    /// Its (sine, cosine).
    sin_cos: (f64, f64),
    /// Its derivative in the amplitude [rad/m].
    per_w: f64,
}

impl AngleCarry {
    /// The start of the same angle's solve at amplitude `w`, the carry made at `from`, where
    /// [`contact::rotation_carries`] allows the step.
    pub(crate) fn start_at(&self, from: f64, w: f64) -> Option<contact::AngleStart> {
        let step = self.per_w * (w - from);
        contact::rotation_carries(self.sin_cos.0, step)
            .then(|| (self.rad + step, Some(contact::sin_cos_rotated(self.sin_cos, step))))
    }
}

/// The baseline Coulomb interface's state at one trial amplitude.
pub(crate) struct Coulomb {
    /// Stick half-angle θs [rad].
    pub(crate) ts: f64,
    /// Rotor surface speed v_r [m/s].
    pub(crate) vr: f64,
    /// True when the rotor is at rest.
    pub(crate) stalled: bool,
    /// Torque factor 2χ(θs) − χ(φ0) [-].
    pub(crate) tf: f64,
    /// Power factor 2E(θs) − E(φ0) [-].
    pub(crate) pf: f64,
    /// Torque factor with the rotor at rest [-].
    pub(crate) tf0: f64,
    /// d(power factor)/dW.
    pub(crate) pf_per_w: f64,
    /// Contact and stick angles to start the next trial from (the stick angle where it is
    /// a root of the torque balance, not the end of its range).
    pub(crate) carry: [Option<AngleCarry>; 2],
}

/// Baseline 2-D Coulomb interface at amplitude `w`: closed forms (Sun et al. 2021 eq. 10-11;
/// crate::contact). `sc0` = (sin φ0, cos φ0). χ and E are written out here with the sines
/// and cosines the root finds already have: one `sin_cos` per Newton step is the whole
/// transcendental cost of a trial, and none where the angles carried from the previous
/// trial are already roots.
#[allow(clippy::too_many_arguments)]
pub(crate) fn coulomb_interface(
    p: &Prepared,
    d: &Drive,
    ct: &Contact,
    (s0, c0): (f64, f64),
    w: f64,
    tscale: f64,
    v0: f64,
    ts_guess: Option<contact::AngleStart>,
) -> Coulomb {
    let (phi, c) = (ct.half_angle_rad, ct.offset);
    let chi0 = s0 - phi * c;
    let e0 = 0.5 * phi + 0.5 * s0 * c0 - c * s0;
    let tmax = contact::stall_stick_half_angle_rad(ct);
    let (smax, cmax) = if tmax < phi { (1.0, 0.0) } else { (s0, c0) };
    let tf0 = 2.0 * (smax - tmax * c) - chi0;
    let visc = p.dr * v0 / p.r0;
    // How the contact moves with W (A ∝ W, so y = F/A ∝ 1/W): in partial contact
    // g(φ0) = χ(φ0) = y gives dφ0/dW = −χ(φ0)/(W·φ0·sin φ0) and dc/dW = −sin φ0·dφ0/dW;
    // in full contact c = −y/π, dc/dW = −c/W.
    let (dphi, dc) = if ct.full { (0.0, -c / w) } else { (-chi0 / (w * phi * s0), chi0 / (w * phi)) };
    let running = contact::stick_half_angle_sin_cos(ct, (s0, c0), tscale, d.t_load, visc, ts_guess);
    let (ts, st, cs, vr, stalled) = match running {
        Some((t, st, cs)) => (t, st, cs, v0 * cs, false),
        None => {
            // Narrow contact (φ0 < π/2): below v_r = v0·cos φ0 the whole contact drives with
            // the constant torque R0·μ·F, and the rotor's viscous torque sets the speed.
            let drive = tscale * tf0;
            if tmax < 0.5 * PI && p.dr > 0.0 && d.t_load < drive {
                (tmax, smax, cmax, ((drive - d.t_load) / p.dr * p.r0).min(v0 * cmax), false)
            } else {
                (tmax, smax, cmax, 0.0, true)
            }
        }
    };
    let tf = 2.0 * (st - ts * c) - chi0;
    // c_t·ω = 2Nμk_f·h0·[2E(θs) − E(φ0)]: friction power taken from the wave over (ωW)².
    let pf = 2.0 * (0.5 * ts + 0.5 * st * cs - c * st) - e0;
    // dθs/dW: implicit in the torque balance F(θs, W) = R0μA·(2χ(θs) − χ(φ0)) − T −
    // d_r·v0·cos θs/R0 = 0, whose ∂F/∂W is T/W + R0μA·(φ0 − 2θs)·dc/dW on the root
    // (R0μA and v0 are ∝ W); at the end of the range θs is θmax = min(φ0, π/2).
    let dts = match running {
        Some(_) => -(d.t_load / w + tscale * dc * (phi - 2.0 * ts)) / (2.0 * tscale * (cs - c) + visc * st),
        None if tmax < phi => 0.0,
        None => dphi,
    };
    // dE(θ)/dθ = cos θ·(cos θ − c), ∂E/∂c = −sin θ; E(φ0)'s own θ-derivative vanishes.
    let pf_per_w = 2.0 * (cs * (cs - c) * dts - st * dc) + s0 * dc;
    let contact_carry = (!ct.full).then_some(AngleCarry { rad: phi, sin_cos: (s0, c0), per_w: dphi });
    let stick_carry = running.map(|_| AngleCarry { rad: ts, sin_cos: (st, cs), per_w: dts });
    Coulomb { ts, vr, stalled, tf, pf, tf0, pf_per_w, carry: [contact_carry, stick_carry] }
}

/// Generalised interface (radial slip, saturating traction): the rotor speed ratio
/// u = v_r/v0 solves R0·μ·A·torque(u) = T_load + d_r·v0·u/R0 by Newton steps with the
/// analytic ∂torque/∂u, safeguarded by a bracket (torque(u) decreases with u, so the root
/// is unique); a step that leaves the bracket falls back to regula falsi.
///
/// Returns (θs, v_r, stalled, factors at the root, torque factor at u = 0 or NaN). The
/// rotor-at-rest integral decides stall and gives the stall torque, but with a warm guess
/// where the drive still exceeds the load (f(guess) ≥ 0, so f(0) ≥ 0 too) it is not needed
/// for the root: it is left NaN and computed once for the converged trial (`finish`),
/// which saves one of the ~4 integrals per trial.
///
/// `rest_first`: take the rotor-at-rest integral before the guess (the previous trial of
/// the descent stalled, so this one likely does too). torque(u) falls with u, so the rotor
/// stalls exactly where f(0) < 0 whatever the start: a stalled trial then costs that one
/// integral instead of the guess's and it, and a running one the same steps from the
/// same guess, with f(0) known (the same root, the same factors).
#[allow(clippy::too_many_arguments)]
pub(crate) fn general_interface(
    p: &Prepared,
    d: &Drive,
    ct: &Contact,
    tscale: f64,
    v0: f64,
    law: &Law,
    ts_guess: Option<f64>,
    rest_first: bool,
) -> (f64, f64, bool, Factors, f64) {
    let visc = p.dr * v0 / p.r0;
    let plain = plain_speed_solve();
    let rest_first = rest_first && !plain;
    let rule = std::cell::RefCell::new(SpeedFreeRule::new());
    let f = |u: f64| {
        #[cfg(test)]
        SPEED_SOLVE_INTEGRALS.with(|n| n.set(n.get() + 1));
        let fac = factors_reusing(ct, u, law, &mut rule.borrow_mut());
        (tscale * fac.torque - d.t_load - visc * u, fac)
    };
    // Bracket [lo, hi] with f(lo) ≥ 0 > f(hi). f(1) (the rotor at crest speed) is only
    // evaluated when the iteration needs it: with a warm guess it rarely does. f(0) too:
    // until it is needed, lo = 0 stands with f(lo) unknown (NaN).
    let (mut lo, mut flo, mut hi, mut fhi) = (0.0, f64::NAN, 1.0, f64::NAN);
    let mut tf0 = f64::NAN;
    let at_rest = |tf0: &mut f64| {
        let (f0, fac0) = f(0.0);
        *tf0 = fac0.torque;
        (f0, fac0)
    };
    let stall = |fac0, tf0| (contact::stall_stick_half_angle_rad(ct), 0.0, true, fac0, tf0);
    if rest_first {
        let (f0, fac0) = at_rest(&mut tf0);
        if f0 < 0.0 {
            return stall(fac0, tf0);
        }
        flo = f0;
    }
    let (mut u, mut fu, mut fac) = match ts_guess.map(f64::cos).filter(|g| *g > 0.0 && *g < 1.0) {
        Some(g) => {
            let (fg, fac) = f(g);
            (g, fg, fac)
        }
        None => {
            if flo.is_nan() {
                let (f0, fac0) = at_rest(&mut tf0);
                if f0 < 0.0 {
                    return stall(fac0, tf0);
                }
                flo = f0;
            }
            let (f1, fac1) = f(1.0);
            if f1 >= 0.0 {
                return (0.0, v0, false, fac1, tf0);
            }
            fhi = f1;
            let u = lo - flo * (hi - lo) / (fhi - flo);
            let (fu, fac) = f(u);
            (u, fu, fac)
        }
    };
    // length of the previous step when it was a Newton step
    let mut last_newton: Option<f64> = None;
    for _ in 0..60 {
        if fu >= 0.0 {
            (lo, flo) = (u, fu);
        } else {
            (hi, fhi) = (u, fu);
        }
        if flo.is_nan() && hi < 1e-14 {
            // the iterates sank onto u = 0 from above: stall, unless the load is met there
            let (f0, fac0) = at_rest(&mut tf0);
            if f0 < 0.0 {
                return stall(fac0, tf0);
            }
            fac = fac0;
            u = 0.0;
            break;
        }
        if hi - lo < 1e-14 || fu.abs() <= 1e-14 * tscale {
            break;
        }
        let slope = tscale * fac.torque_du - visc;
        // f'' where the route sums ∂²torque/∂u² (NaN elsewhere)
        let curv = if plain { f64::NAN } else { tscale * fac.torque_uu };
        // Halley's step where f'' is known and the correction moderate: Newton's step
        // −f/f' divided by 1 − L/2, L = f·f''/f'² (|L| ≤ 1: the divisor within [1/2, 3/2]).
        // Its error is third order in the step, Newton's second: from the ~1e-2 to 1e-3
        // of a cold start one integral fewer to the 1e-16 below which the step is carried.
        let l = fu * curv / (slope * slope);
        let newton = if l.abs() <= 1.0 { u - fu / slope / (1.0 - 0.5 * l) } else { u - fu / slope };
        let step = newton - u;
        let is_newton = slope < 0.0 && newton > lo && newton < hi;
        if is_newton {
            // Below 1e-16 in u a step is taken without another integral, the factors
            // carried over it to first order (steps ≤ 1e-8). With f'' known, the error left
            // after it is at most Newton's, |f''/(2f')|·δ², to leading order. Without it,
            // after steps δ₁ then δ₂ the next would be about δ₂²/δ₁ (linear convergence at
            // the observed ratio; quadratic gives less). Most such integrals would only
            // confirm a root already found (the first step of a trial started from the
            // previous trials' extrapolated stick angle, the second from a cold start).
            let small = |d: Option<f64>| {
                if curv.is_finite() {
                    (0.5 * curv / slope).abs() * step * step <= 1e-16
                } else {
                    d.is_some_and(|d| step * step <= 1e-16 * d)
                }
            };
            if step.abs() <= 1e-8 && small(last_newton) {
                fac = fac.carried(step);
                u = newton;
                break;
            }
            last_newton = Some(step.abs());
        } else {
            last_newton = None;
        }
        let next = if is_newton {
            newton
        } else if flo.is_nan() {
            // the step leaves [0, hi]: the rotor at rest decides between stall and a root
            let (f0, fac0) = at_rest(&mut tf0);
            if f0 < 0.0 {
                return stall(fac0, tf0);
            }
            flo = f0;
            lo - flo * (hi - lo) / (fhi - flo)
        } else if fhi.is_nan() {
            // the root may sit at u = 1 (no load, no viscous drag): test that end now
            let (f1, fac1) = f(1.0);
            if f1 >= 0.0 {
                return (0.0, v0, false, fac1, tf0);
            }
            fhi = f1;
            lo - flo * (hi - lo) / (fhi - flo)
        } else {
            let rf = lo - flo * (hi - lo) / (fhi - flo);
            if rf > lo && rf < hi {
                rf
            } else {
                0.5 * (lo + hi)
            }
        };
        if (next - u).abs() < 1e-15 {
            break;
        }
        u = next;
        (fu, fac) = f(u);
    }
    let ts = u.clamp(-1.0, 1.0).acos().min(ct.half_angle_rad);
    (ts, u * v0, false, fac, tf0)
}

/// True when a test asks for the speed solve by plain Newton steps from the guess (no
/// rest-first start, no Halley steps, no carry judged by f''): the reference the faster
/// route is compared with.
fn plain_speed_solve() -> bool {
    #[cfg(test)]
    if REFERENCE_SPEED_SOLVE.with(std::cell::Cell::get) {
        return true;
    }
    false
}

#[cfg(test)]
thread_local! {
    /// Set by a test: [`general_interface`] runs its reference route ([`plain_speed_solve`]).
    pub(crate) static REFERENCE_SPEED_SOLVE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Interface integrals taken by [`general_interface`]'s speed solves on this thread.
    pub(crate) static SPEED_SOLVE_INTEGRALS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The friction law of the generalised interface at contact `ct` (the compliance's slip
/// scale depends on the contact offset).
pub(crate) fn interface_law(p: &Prepared, d: &Drive, ct: &Contact) -> Law {
    let mut law = p.law;
    if p.compliance > 0.0 {
        // Slip-speed scale of the layer's shear compliance: the layer deflects κ·μ times
        // its normal deflection W·(1 − c) before it slips, at the wave's frequency,
        // relative to the crest speed k·h0·ω·W.
        law.slip_scale = p.compliance * d.mu * (1.0 - ct.offset.max(-1.0)) / (p.k * p.h0);
        if p.truth_b(Effect::TangentialCompliance) {
            // the second truth family: a layer whose shear deflection before slip grows
            // with the square root of its normal deflection
            law.slip_scale = p.compliance * d.mu * 0.7 * (1.0 - ct.offset.max(-1.0)).sqrt() / (p.k * p.h0);
        }
    }
    if p.truth_b(Effect::RadialFriction) && law.radial_ratio > 0.0 {
        // the second truth family: radial slip that grows with the width of a Hertzian
        // line contact (∝ √F_N) until the contact spans the tooth face at 300 N, then
        // stays: a kink no power of the preload follows
        law.radial_ratio = p.law.radial_ratio * (d.f_n.max(0.0) / 300.0).sqrt().min(1.0);
    }
    if !p.truth(Effect::RadialFriction) && p.radial_exponent != 0.0 && law.radial_ratio > 0.0 {
        law.radial_ratio = preload_grown_radial_ratio(p.law.radial_ratio, p.radial_exponent, d.f_n);
    }
    law
}

/// `radial_friction`'s preload family: ρ(F_N) = ρ·(F_N/100 N)^q, capped at 10 (where the
/// radial slip dwarfs the tangential one). The radial surface speed a contact point sees
/// follows the radial slope of the mode shape across the contact's width (the
/// radial-friction paper, eq. 10-12); a wider contact, pressed harder, reaches further
/// into the slope: q = 0.5 is the width of a Hertzian line contact (∝ √F_N), q = 1 a slope
/// in proportion to the load. ρ is the ratio at 100 N.
pub(crate) fn preload_grown_radial_ratio(rho: f64, q: f64, f_n: f64) -> f64 {
    (rho * (f_n.max(0.0) / 100.0).powf(q)).min(10.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{chi, contact_from_ratio, e_int};

    /// Break points of a reference quadrature over [0, φ0] of an interface integrand: the
    /// ends, the stick point θs, and about each singularity (re, im) of the slip law the
    /// real part and points at powers of ten of its distance from both it and θs (a band
    /// narrower than the first Kronrod nodes' spacing is invisible to the adaptive rule's
    /// error estimate).
    fn quadrature_cuts(ts: f64, phi0: f64, singularities: impl IntoIterator<Item = (f64, f64)>) -> Vec<f64> {
        let mut cuts = vec![0.0, phi0, ts];
        for (re, im) in singularities {
            let mut d = im.max(1e-9);
            while d < phi0 {
                cuts.extend([ts - d, ts + d, re - d, re + d]);
                d *= 10.0;
            }
            cuts.push(re);
        }
        cuts.retain(|&x| (0.0..=phi0).contains(&x));
        cuts.sort_by(f64::total_cmp);
        cuts
    }

    /// The complex arccos by Newton steps from the quadratic estimate (the reference of
    /// [`acos_complex`] in [`arccos_near`]): steps on −2u·sin²(δ/2) − sin θs·sin δ = Δc
    /// until one is below 1e-13 of δ; above |Δc| = 1/2 the library's arccos.
    fn arccos_near_by_newton(u: f64, sin_ts: f64, dc: C64) -> C64 {
        if dc.norm_sqr() > 0.25 {
            return (dc + u).acos();
        }
        let root = csqrt(C64::new(sin_ts * sin_ts, 0.0) - dc * (2.0 * u));
        let mut d = -dc * 2.0 / (root + sin_ts);
        for _ in 0..40 {
            let (half, half_cos) = sin_cos_complex(d * 0.5);
            let sd = half * half_cos * 2.0;
            let cd = C64::new(1.0, 0.0) - half * half * 2.0;
            let g = -half * half * (2.0 * u) - sd * sin_ts - dc;
            let dg = -(sd * u + cd * sin_ts);
            let step = g / dg;
            d -= step;
            if step.norm_sqr() <= 1e-26 * d.norm_sqr() {
                break;
            }
        }
        d + u.clamp(-1.0, 1.0).acos()
    }

    /// The arccos of a complex offset in closed form against Newton's root of the same
    /// identity and the library's arccos: 200 000 random u ∈ [−1, 1] and Δc (|Δc| up to
    /// 0.7, Im Δc down to 1e-12, at both ends of u), the same branch and each part within
    /// 1e-12 (absolute, or relative where larger); every result's cosine is u + Δc.
    #[test]
    fn closed_form_complex_arccos_matches_newtons_root_and_the_library() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(91);
        use rand::{RngExt, SeedableRng};
        let (mut worst, mut closed, mut newton_failed) = (0.0f64, 0, 0);
        for i in 0..200_000 {
            let u: f64 = match i % 4 {
                0 => 1.0 - 10f64.powf(rng.random_range(-12.0..0.0)),
                1 => -1.0 + 10f64.powf(rng.random_range(-12.0..0.0)),
                _ => rng.random_range(-1.0..1.0),
            };
            let sin_ts = ((1.0 - u) * (1.0 + u)).max(0.0).sqrt();
            let m = rng.random_range(0.0..0.7);
            let arg = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            let mut dc = C64::from_polar(m, arg);
            if i % 3 == 0 {
                dc.im = 10f64.powf(rng.random_range(-12.0..-1.0)).copysign(dc.im);
            }
            if dc.im == 0.0 {
                continue;
            }
            let root = csqrt(C64::new(sin_ts * sin_ts, 0.0) - dc * (2.0 * u));
            let d0 = -dc * 2.0 / (root + sin_ts);
            if dc.norm_sqr() <= 0.25 && d0.norm_sqr() <= 0.01 {
                continue;
            }
            closed += 1;
            let (a, b) = (arccos_near(u, sin_ts, dc), arccos_near_by_newton(u, sin_ts, dc));
            // the same point of {±θ* + 2πk}, where Newton's steps may have crossed to another
            // (compared as the representative with Re in [0, π])
            let canonical = |z: C64| {
                let re = z.re - 2.0 * PI * (z.re / (2.0 * PI)).round();
                if re < 0.0 {
                    C64::new(-re, -z.im)
                } else {
                    C64::new(re, z.im)
                }
            };
            let root_of = |z: C64| (z.cos() - (dc + u)).norm() <= 1e-12 * (1.0 + z.norm()).powi(2);
            assert!(root_of(a), "u {u}, dc {dc}: cos {a} is {}", a.cos());
            // (Newton's steps stall short of the root in a few cases beyond c = ±1)
            if !root_of(b) {
                newton_failed += 1;
                continue;
            }
            let (a, b) = (canonical(a), canonical(b));
            for (x, y) in [(a.re, b.re), (a.im, b.im)] {
                let err = (x - y).abs() / y.abs().max(1.0);
                worst = worst.max(err);
                assert!(err <= 1e-12, "u {u}, dc {dc}: closed form {a}, Newton {b}");
            }
        }
        assert!(
            closed > 50_000 && newton_failed * 100 < closed,
            "{closed} closed forms, {newton_failed} Newton failures"
        );
        eprintln!(
            "{closed} offsets by the closed form ({newton_failed} where Newton fails), worst difference {worst:.1e}"
        );
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let s: f64 = gauss_legendre().iter().map(|(x, w)| w * x.powi(22)).sum();
        assert!((s - 2.0 / 23.0).abs() < 1e-14);
        let s: f64 = gauss_legendre().iter().map(|(_, w)| w).sum();
        assert!((s - 2.0).abs() < 1e-14);
    }

    #[test]
    fn small_angle_series_matches_the_library() {
        for i in 0..=20_000 {
            let y = std::f64::consts::FRAC_PI_4 * (i as f64 / 10_000.0 - 1.0);
            let (s, c) = sin_cos_small(y);
            let (s0, c0) = y.sin_cos();
            assert!((s - s0).abs() <= 2.0 * f64::EPSILON * s0.abs(), "sin {y}: {s} vs {s0}");
            assert!((c - c0).abs() <= 2.0 * f64::EPSILON * c0.abs(), "cos {y}: {c} vs {c0}");
        }
    }

    #[test]
    fn saturation_tanh_matches_the_library() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let x = 25.0 * (i as f64 / 200_000.0).powi(3);
            let (a, b) = (tanh_nonneg(x), x.tanh());
            let rel = (a - b).abs() / b.max(1e-300);
            worst = worst.max(rel);
            assert!(rel <= 6e-15 || a == b, "x {x}: {a} vs {b}");
        }
        assert_eq!(tanh_nonneg(0.0), 0.0);
        eprintln!("worst relative difference {worst:.2e}");
    }

    #[test]
    fn inline_exp_matches_the_library() {
        let mut worst: f64 = 0.0;
        for i in 0..=400_000 {
            let x = -40.0 * (i as f64 / 400_000.0).powi(2);
            let (a, b) = (exp_nonpos(x), x.exp());
            let rel = (a - b).abs() / b;
            worst = worst.max(rel);
            assert!(rel <= 2.0 * f64::EPSILON, "x {x}: {a} vs {b}");
        }
        assert_eq!(exp_nonpos(0.0), 1.0);
        assert!((exp_nonpos(-700.0) / (-700.0f64).exp() - 1.0).abs() < 1e-15);
        eprintln!("worst relative difference {worst:.2e}");
    }

    /// The same quadrature written out directly: every node's angle θ = m + r·x and the
    /// library's sin/cos of it.
    fn factors_direct(ct: &Contact, u: f64, law: &Law) -> Factors {
        let mut f = Factors::default();
        let ts = u.clamp(-1.0, 1.0).acos();
        let phi0 = ct.half_angle_rad;
        let ends = match nearest_singularity(law, u.clamp(-1.0, 1.0), phi0).and_then(|z| graded_ends(ts, phi0, z)) {
            Some((ends, n)) => ends[..n].to_vec(),
            None if ts > 0.0 && ts < phi0 => vec![0.0, ts, phi0],
            None => vec![0.0, phi0],
        };
        let panels: Vec<(f64, f64)> = ends.windows(2).map(|e| (e[0], e[1])).collect();
        for (rho, wr) in radii(law) {
            for &(a, b) in &panels {
                let h = 0.5 * (b - a);
                for j in 0..2 {
                    let (m, r) = (a + h * (j as f64 + 0.5), 0.5 * h);
                    for &(x, w) in gauss_legendre() {
                        let (s, co) = (m + r * x).sin_cos();
                        accumulate(&mut f, s, co, wr * w * r, ct.offset, u, rho, law);
                    }
                }
            }
        }
        f
    }

    #[test]
    fn node_angles_by_angle_addition_match_direct_evaluation() {
        for law in [
            Law { radial_ratio: 0.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.7, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.05, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0035, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.03, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.003, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.3, slip_scale: 0.02, truth: true, truth_radial: true, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.2, truth: true, truth_radial: true, sharpness: 1.0 },
        ] {
            for &y in &[0.05, 0.8, 2.0, 3.1, 5.0] {
                let ct = contact_from_ratio(y);
                for &u in &[0.0, 0.03, 0.4, 0.77, 0.999, 1.0] {
                    let (a, b) = (factors(&ct, u, &law), factors_direct(&ct, u, &law));
                    // (rounding on the order of the integrand's magnitude, O(0.1) and more, not
                    // of a near-cancelling sum: at u = 1 a torque of −0.05 differs by up to
                    // 2.4e-14 with the crest's panels graded towards θ = 0)
                    let scale = b.torque.abs().max(b.power.abs()).max(0.1);
                    for (x, z) in [(a.torque, b.torque), (a.power, b.power), (a.radial, b.radial)] {
                        assert!((x - z).abs() <= 5e-13 * scale, "{law:?} y={y} u={u}: {x} vs {z}");
                    }
                    // (at u = 1 with radial slip, ∂torque/∂u is log-divergent at θ = 0: the
                    // graded rule's many panels next to 0 sum ~1/θ terms, 1.3e-11 apart at
                    // ρ = 0.0035 with them graded about the exact singularity there)
                    for (x, z) in [(a.torque_du, b.torque_du), (a.power_du, b.power_du), (a.radial_du, b.radial_du)] {
                        assert!((x - z).abs() <= 3e-11 * z.abs().max(1.0), "{law:?} u={u}: {x} vs {z}");
                    }
                }
            }
        }
    }

    #[test]
    fn coulomb_limit_reproduces_the_closed_forms() {
        let law = Law { radial_ratio: 0.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 };
        for &y in &[0.3, 1.5, 3.0, 4.0] {
            let ct = contact_from_ratio(y);
            for &u in &[0.0f64, 0.2, 0.6, 0.95] {
                let ts = u.acos().min(ct.half_angle_rad);
                let f = factors(&ct, u, &law);
                let tf = 2.0 * chi(ts, ct.offset) - ct.chi0();
                let pf = 2.0 * e_int(ts, ct.offset) - e_int(ct.half_angle_rad, ct.offset);
                assert!((f.torque - tf).abs() < 1e-10, "y={y} u={u}: {} vs {tf}", f.torque);
                assert!((f.power - pf).abs() < 1e-10);
                assert_eq!(f.radial, 0.0);
            }
        }
    }

    /// The derivatives at fixed nodes against central differences of the rule. For weak
    /// radial slip or compliance (ρ = 0.0035, σ = 0.003) ∂torque/∂u is a narrow peak at θs
    /// that the plain rule's nodes straddle (20-30 % too small without graded panels),
    /// and the rotor-speed solve's Newton steps and their carried last step
    /// (`general_interface`) rest on it. ∂²torque/∂u², which its Halley steps and its
    /// judgement of a carried step rest on, against the same differences of ∂torque/∂u where
    /// the route sums it (the Coulomb law with radial slip, the tanh saturation without it),
    /// and NaN on the routes that do not (the truth forms), which keeps those to Newton.
    #[test]
    fn torque_derivative_matches_central_differences() {
        let (mut worst, mut worst_uu): (f64, f64) = (0.0, 0.0);
        for law in [
            Law { radial_ratio: 0.5, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.05, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.3, slip_scale: 0.02, truth: true, truth_radial: true, sharpness: 1.0 },
            Law { radial_ratio: 0.0035, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.003, truth: false, truth_radial: false, sharpness: 1.0 },
        ] {
            for (&y, &u) in [0.8, 1.5].iter().flat_map(|y| [0.1, 0.5, 0.9, 0.99, 0.999].iter().map(move |u| (y, u))) {
                let ct = contact_from_ratio(y);
                // fourth-order central differences on the scale of the crest's distance (the
                // factors vary over 1 − u near it)
                let h = 1e-3 * (1.0f64 - u).min(1.0);
                let f = |k: f64| factors(&ct, u + k * h, &law);
                let (p2, p1, m1, m2, at) = (f(2.0), f(1.0), f(-1.0), f(-2.0), f(0.0));
                let d = |g: fn(&Factors) -> f64| (g(&m2) - 8.0 * g(&m1) + 8.0 * g(&p1) - g(&p2)) / (12.0 * h);
                let pairs =
                    [(at.torque_du, d(|x| x.torque)), (at.power_du, d(|x| x.power)), (at.radial_du, d(|x| x.radial))];
                // the panels move with θs and θ*, so the two agree to the rule's accuracy
                // (1.1e-10 measured, up to u = 0.999)
                for (an, fd) in pairs {
                    worst = worst.max((an - fd).abs() / fd.abs().max(1.0));
                    assert!((an - fd).abs() < 1e-9 * fd.abs().max(1.0), "{law:?} y={y} u={u}: {an} vs {fd}");
                }
                assert!(at.torque_du < 0.0);
                let fd = d(|x| x.torque_du);
                if law.truth {
                    assert!(at.torque_uu.is_nan(), "{law:?} y={y} u={u}: {}", at.torque_uu);
                } else {
                    worst_uu = worst_uu.max((at.torque_uu - fd).abs() / fd.abs().max(1.0));
                    assert!(
                        (at.torque_uu - fd).abs() < 1e-6 * fd.abs().max(1.0),
                        "{law:?} y={y} u={u}: ∂²torque/∂u² {} vs {fd}",
                        at.torque_uu
                    );
                }
                // carried over a last Newton step (≤ 1e-8, solve::general_interface)
                let du = 1e-8;
                let (c, e) = (at.carried(du), factors(&ct, u + du, &law));
                for (x, y) in [(c.torque, e.torque), (c.power, e.power), (c.radial, e.radial)] {
                    assert!((x - y).abs() <= 1e-11 * y.abs().max(1.0), "{law:?} u={u}: carried {x} vs {y}");
                }
            }
        }
        eprintln!("worst relative difference {worst:.1e}, of ∂²torque/∂u² {worst_uu:.1e}");
    }

    /// The rule against adaptive Gauss–Kronrod (`crate::quad`, 1e-12 relative) of the
    /// defining integrals ∫₀^φ0 (cos θ − c)·(…) dθ, split at the stick point θs, over both
    /// friction laws in both forms, contacts from small to full and rotor speeds up to the
    /// crest speed. The panels are graded about the integrand's nearest complex singularity
    /// (`nearest_singularity`), not about a first-order estimate of it near θs, which
    /// diverges at the crest (u → 1, θs → 0; there its errors reach 3.3e-5 at ρ = 1 and
    /// u = 0.9999, 7.1e-4 at u = 0.999999; ungraded panels give 7.2e-5 at ρ = 0.05 and
    /// 3.5e-4 at σ = 0.02 at any u). Measured worst relative errors (of the larger of
    /// torque and power) over 8 contacts and 17 rotor speeds from 0 to 1 (1 − 1e-9 and 1
    /// included, denser near the crest and where the errors peak): 6.3e-13 (σ = 0.02),
    /// 4.3e-13 up to u = 0.8 (σ = 0.2); the bounds below are 1.5e-12 and 1e-12. Not
    /// covered: a singularity nearer than MIN_FEATURE_WIDTH is graded as that far
    /// (ρ = 1e-14 at u = 1: 1.1e-8), and at u = 1 exactly ρ = 1e-7 leaves 5.5e-10 (its
    /// singularity, 2e-7 off θ = 0, is graded).
    #[test]
    fn factors_agree_with_adaptive_quadrature_of_their_integrals() {
        use crate::quad::integrate;
        let laws = [
            (Law { radial_ratio: 0.0035, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.05, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.3, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 1.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.003, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.02, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.003, slip_scale: 0.0, truth: true, truth_radial: true, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.003, truth: true, truth_radial: true, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.2, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.5, slip_scale: 0.0, truth: true, truth_radial: true, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.05, truth: true, truth_radial: true, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.0, slip_scale: 0.1, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 1.0, slip_scale: 0.0, truth: true, truth_radial: true, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 1.5, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 0.5, slip_scale: 0.02, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            // nearer than MIN_FEATURE_WIDTH (graded as that far), or at u = 1 exactly
            (Law { radial_ratio: 1e-7, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-9),
            (Law { radial_ratio: 0.0, slip_scale: 1e-7, truth: false, truth_radial: false, sharpness: 1.0 }, 1.5e-12),
            (Law { radial_ratio: 1e-14, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 }, 3e-8),
        ];
        for (law, tol) in laws {
            let (mut worst, mut worst_mid): (f64, f64) = (0.0, 0.0);
            for &y in &[0.3, 0.7, 1.0, 1.5, 1.8, 2.0, 3.0, 4.0] {
                let ct = contact_from_ratio(y);
                for &u in &[
                    0.0,
                    0.3,
                    0.5,
                    0.8,
                    0.9,
                    0.9375,
                    0.9425,
                    0.95,
                    0.9675,
                    0.99,
                    0.999,
                    0.9999,
                    0.999999,
                    1.0 - 1e-7,
                    1.0 - 1.7e-8,
                    1.0 - 1e-9,
                    1.0,
                ] {
                    let rule = factors(&ct, u, &law);
                    let ts = u.acos();
                    let phi0 = ct.half_angle_rad;
                    // (cut at θs, at the singularity's real part and at powers of ten of its
                    // distance about both: a band narrower than its first Kronrod nodes'
                    // spacing is invisible to the adaptive rule's error estimate, and at
                    // ρ = 1e-7 it missed 1.8e-7)
                    let cuts = quadrature_cuts(ts, phi0, nearest_singularity(&law, u, phi0));
                    // one component of the integrand at θ, summed over the law's radii
                    let part = |pick: fn(&Factors) -> f64, th: f64| {
                        let mut f = Factors::default();
                        for (rho, w) in radii(&law) {
                            accumulate(&mut f, th.sin(), th.cos(), w, ct.offset, u, rho, &law);
                        }
                        pick(&f)
                    };
                    // (name, the factor it picks, the rule's value)
                    type Pick = (&'static str, fn(&Factors) -> f64, f64);
                    let picks: [Pick; 3] = [
                        ("torque", |f| f.torque, rule.torque),
                        ("power", |f| f.power, rule.power),
                        ("radial", |f| f.radial, rule.radial),
                    ];
                    let scale = rule.torque.abs().max(rule.power.abs()).max(1e-3);
                    for (name, pick, got) in picks {
                        let want: f64 =
                            cuts.windows(2).map(|w| integrate(|th| part(pick, th), w[0], w[1], 1e-15, 1e-12).0).sum();
                        let err = (got - want).abs() / scale;
                        worst = worst.max(err);
                        if u <= 0.8 {
                            worst_mid = worst_mid.max(err);
                            assert!(err <= 1e-12, "{law:?} y={y} u={u} {name}: rule {got} vs adaptive {want}");
                        }
                        assert!(err <= tol, "{law:?} y={y} u={u} {name}: rule {got} vs adaptive {want}");
                    }
                }
            }
            eprintln!("{law:?}: worst relative error of the rule {worst:.1e} ({worst_mid:.1e} up to u = 0.8)");
        }
    }

    /// `nearest_singularity` returns a zero of D² + κ² to within 1 % of its distance from
    /// the axis (the quadratic's root, without Newton steps where |δ| ≤ 0.1; of tan²(θ/2) +
    /// ρ² exactly at u = ±1 with the Coulomb law), for rotor speeds from −1 to 1 and radial
    /// ratios below, at and above 1; for u < 0 too (at ρ = 1, u = −0.6 the nearest root has
    /// Im 0.51, not the other root's 37), and of the two equally high roots at u = 0, ρ >
    /// 1, the one at θ = 0, next to the contact.
    #[test]
    fn the_nearest_singularity_is_a_zero_of_the_slip() {
        let laws = [
            Law { radial_ratio: 0.05, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 1.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 1.5, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.0, slip_scale: 0.02, truth: false, truth_radial: false, sharpness: 1.0 },
            Law { radial_ratio: 0.3, slip_scale: 0.01, truth: true, truth_radial: true, sharpness: 1.0 },
        ];
        for law in laws {
            let kappa = law.slip_scale * if law.truth { 1.0 } else { std::f64::consts::FRAC_PI_2 };
            for &u in &[-1.0, -0.6, -0.1, 0.0, 0.2, 0.7, 0.95, 0.9999, 1.0] {
                let Some((re, im)) = nearest_singularity(&law, u, 1.0) else {
                    // none only where D² + κ² has no zero: ρ = 1 at u = 0 or ±1 (Coulomb)
                    assert!(law.radial_ratio == 1.0 && kappa == 0.0 && (u == 0.0 || u.abs() == 1.0), "{law:?} u={u}");
                    continue;
                };
                assert!(im >= 0.0 && (0.0..=std::f64::consts::PI).contains(&re), "{law:?} u={u}: ({re}, {im})");
                let th = C64::new(re, im);
                if kappa == 0.0 && u.abs() == 1.0 {
                    // (at u = −1 mirrored about π/2)
                    let t = if u > 0.0 { th * 0.5 } else { (C64::new(std::f64::consts::PI, 0.0) - th) * 0.5 }.tan();
                    let r2 = law.radial_ratio.powi(2);
                    assert!(((t * t).norm() - r2).abs() <= 1e-12 * r2, "{law:?} u={u}: ({re}, {im})");
                    continue;
                }
                // distance to the zero, to first order: |F/F'| with F = D² + κ² (the truth
                // form's radius whose zero it is); the grading needs it to a fraction of Im θ*
                let step = radii(&law)
                    .map(|(r, _)| {
                        let (c, sn) = (th.cos(), th.sin());
                        let f = (c - u) * (c - u) + sn * sn * (r * r) + kappa * kappa;
                        let df = -(c - u) * sn * 2.0 + sn * c * (2.0 * r * r);
                        (f / df).norm()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(step <= 0.01 * im, "{law:?} u={u}: ({re}, {im}) is {step} from a zero");
            }
        }
        let z = nearest_singularity(
            &Law { radial_ratio: 1.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            -0.6,
            1.0,
        )
        .expect("a zero");
        assert!((z.1 - 0.5108).abs() < 1e-3, "{z:?}");
        let z = nearest_singularity(
            &Law { radial_ratio: 1.5, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
            0.0,
            1.0,
        )
        .expect("a zero");
        assert_eq!(z.0, 0.0, "{z:?}");
    }

    /// `graded_ends` on random singularities, stick points and contacts: strictly ascending
    /// from 0 to φ0, θs among them when inside, within MAX_PANELS + 1 ends.
    #[test]
    fn graded_ends_ascend_from_zero_to_the_contact_edge() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(34);
        let mut graded = 0;
        for _ in 0..200_000 {
            let phi0 = rng.random_range(1e-3..std::f64::consts::PI);
            let ts = rng.random_range(0.0..1.2 * phi0);
            let z = (rng.random_range(-0.2..3.4), 10f64.powf(rng.random_range(-12.0..0.5)));
            let Some((ends, n)) = graded_ends(ts, phi0, z) else { continue };
            graded += 1;
            let e = &ends[..n];
            assert!(n <= MAX_PANELS + 1 && e[0] == 0.0 && e[n - 1] == phi0, "{e:?}");
            assert!(e.windows(2).all(|w| w[0] < w[1]), "not ascending: {e:?} (θs {ts}, z {z:?})");
            assert!(!(ts > 0.0 && ts < phi0) || e.contains(&ts), "θs {ts} missing: {e:?}");
        }
        assert!(graded > 100_000, "{graded}");
    }

    /// The saturating laws by their Coulomb closed forms plus the windowed difference
    /// (`compliance_factors` for tanh, `stick_slip_window_factors` for the sharper
    /// stick-then-slip forms) against the graded rule over the whole contact
    /// (`quadrature_factors`, an independent route: no closed form, the saturation itself at
    /// every node), over slip scales from 1e-7 (a step at θs) to 3 (the window is the whole
    /// contact), sharpness from tanh's 1 to 4, contacts from narrow to full and rotor speeds
    /// from rest past the crest: torque and power within 1e-12 of their scale, the
    /// derivatives within 1e-12 of that over σ.
    #[test]
    fn windowed_saturating_factors_agree_with_the_whole_contact_rule() {
        let mut worst: f64 = 0.0;
        let laws = [1e-7, 1e-5, 3e-4, 0.003, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 3.0]
            .into_iter()
            .flat_map(|sigma| [1.0, 1.5, 2.0, 3.0, 4.0].map(|n| (sigma, n)));
        for (sigma, n) in laws {
            let law = Law { radial_ratio: 0.0, slip_scale: sigma, truth: false, truth_radial: false, sharpness: n };
            for &y in &[0.02, 0.3, 0.7, 1.0, 1.5, 2.0, 3.0, 3.2, 4.0, 6.0] {
                let ct = contact_from_ratio(y);
                for &u in &[
                    0.0,
                    1e-9,
                    0.05,
                    0.3,
                    0.5,
                    0.7,
                    0.8,
                    0.9,
                    0.95,
                    0.99,
                    0.999,
                    0.999_999,
                    1.0 - 1e-9,
                    1.0,
                    1.0 + 1e-12,
                ] {
                    let (a, b) = (factors(&ct, u, &law), quadrature_factors(&ct, u, &law));
                    let scale = b.torque.abs().max(b.power.abs()).max(1e-3);
                    for (k, (x, z)) in
                        [(a.torque, b.torque), (a.power, b.power), (a.torque_du, b.torque_du), (a.power_du, b.power_du)]
                            .into_iter()
                            .enumerate()
                    {
                        let sc = if k < 2 { scale } else { scale / sigma };
                        let err = (x - z).abs() / sc;
                        worst = worst.max(err);
                        assert!(err <= 1e-12, "σ={sigma} n={n} y={y} u={u} [{k}]: windowed {x} vs whole contact {z}");
                    }
                    assert_eq!((a.radial, a.radial_du), (0.0, 0.0));
                }
            }
        }
        eprintln!("windowed against whole-contact rule: worst relative difference {worst:.1e}");
    }

    /// The speed-free rule (`factors_reusing`, its nodes built at one speed and kept for
    /// the others) against the graded rule split at θs (`quadrature_factors`) over the laws
    /// of both forms, contacts from narrow to full and rotor speeds from rest to the crest,
    /// the rule's nodes first built at each of three speeds: within 1e-12 of the torque and
    /// power scale, the derivatives (which only steer the Newton steps) within 1e-10 of
    /// theirs (3.6e-11 at ρ = 0.5, σ = 0.2 next to the crest); and the speed-free rule taken at
    /// some of them (it would not be tested otherwise).
    #[test]
    fn speed_free_rule_agrees_with_the_split_rule() {
        let law = |rho: f64, sigma: f64, truth: bool| Law {
            radial_ratio: rho,
            slip_scale: sigma,
            truth,
            truth_radial: truth,
            sharpness: 1.0,
        };
        let laws = [
            law(1.0, 0.0, false),
            law(0.3, 0.0, false),
            law(1.5, 0.0, false),
            law(0.05, 0.0, false),
            law(2.0, 0.0, false),
            law(0.0, 0.2, false),
            law(0.0, 0.5, false),
            law(0.0, 0.05, false),
            law(1.0, 0.0, true),
            law(0.3, 0.0, true),
            law(0.0, 0.3, true),
            law(0.5, 0.2, false),
            law(1.0, 0.1, true),
        ];
        let (mut worst, mut reused): (f64, usize) = (0.0, 0);
        for l in laws {
            for &y in &[0.02, 0.3, 1.0, 2.0, 3.0, 4.0, 6.0] {
                let ct = contact_from_ratio(y);
                for &first in &[0.0, 0.5, 0.95] {
                    let mut rule = SpeedFreeRule::new();
                    factors_reusing(&ct, first, &l, &mut rule);
                    for &u in &[0.0, 0.1, 0.3, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 0.999, 1.0] {
                        let (a, b) = (factors_reusing(&ct, u, &l, &mut rule), quadrature_factors(&ct, u, &l));
                        let z = nearest_singularity(&l, u, ct.half_angle_rad);
                        reused += usize::from(
                            z.is_some_and(|z| distance(z, ct.half_angle_rad) >= 0.1875 * ct.half_angle_rad),
                        );
                        let scale = b.torque.abs().max(b.power.abs()).max(1e-3);
                        for (x, w) in [(a.torque, b.torque), (a.power, b.power), (a.radial, b.radial)] {
                            worst = worst.max((x - w).abs() / scale);
                            assert!((x - w).abs() <= 1e-12 * scale, "{l:?} y={y} u={u}: {x} vs {w}");
                        }
                        for (x, w) in [(a.torque_du, b.torque_du), (a.power_du, b.power_du), (a.radial_du, b.radial_du)]
                        {
                            assert!((x - w).abs() <= 1e-10 * w.abs().max(scale), "{l:?} y={y} u={u}: {x} vs {w}");
                        }
                    }
                }
            }
        }
        assert!(reused > 1000, "{reused}");
        eprintln!("speed-free rule against the split rule: worst relative difference {worst:.1e} ({reused} reused)");
    }

    #[test]
    fn radial_slip_lowers_torque_and_dissipates() {
        let ct = contact_from_ratio(1.5);
        let base = factors(
            &ct,
            0.5,
            &Law { radial_ratio: 0.0, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
        );
        let rad = factors(
            &ct,
            0.5,
            &Law { radial_ratio: 0.5, slip_scale: 0.0, truth: false, truth_radial: false, sharpness: 1.0 },
        );
        assert!(rad.torque < base.torque);
        assert!(rad.radial > 0.0);
        // dissipation ∫ μ p |s| ≥ 0: power − u·torque
        assert!(rad.power - 0.5 * rad.torque > base.power - 0.5 * base.torque);
    }

    /// The stick-then-slip saturations tanh(xⁿ)^(1/n): S and S' against tanh at n = 1, the
    /// series and the closed form agreeing where they meet, S' against central differences,
    /// and S ≥ tanh x (a sharper layer carries more traction before it slips).
    #[test]
    fn stick_slip_saturation_is_tanh_at_one_and_sharpens_above() {
        for &x in &[0.0, 1e-4, 0.01, 0.3, 0.999, 1.0, 2.0, 7.0, 30.0] {
            let (s1, d1) = stick_slip_saturation(x, 1.0);
            assert!((s1 - x.tanh()).abs() <= 1e-14 && (d1 - (1.0 - x.tanh().powi(2))).abs() <= 1e-13, "x={x}");
            for n in [1.5, 2.0, 3.0, 4.0] {
                let (sv, ds) = stick_slip_saturation(x, n);
                let want = x.powf(n).tanh().powf(1.0 / n);
                assert!((sv - want).abs() <= 1e-14, "x={x} n={n}: {sv} vs {want}");
                assert!(sv >= x.tanh() - 1e-15, "x={x} n={n}");
                if x > 1e-3 {
                    let h = 1e-6 * x;
                    let fd = (stick_slip_saturation(x + h, n).0 - stick_slip_saturation(x - h, n).0) / (2.0 * h);
                    assert!((ds - fd).abs() <= 1e-7, "x={x} n={n}: S' {ds} vs {fd}");
                }
            }
        }
        // the series branch and the closed form meet at y = 1e-3
        let y = 1e-3f64;
        for n in [2.0, 4.0] {
            let x = y.powf(1.0 / n);
            let (below, above) =
                (stick_slip_saturation(x * (1.0 - 1e-12), n).0, stick_slip_saturation(x * (1.0 + 1e-12), n).0);
            assert!((below - above).abs() <= 3e-12 * x, "n={n}");
        }
    }

    /// The rule with the stick-then-slip laws, graded towards their own singularities on
    /// both sides of θs, against adaptive Gauss–Kronrod of the same integrals: within 2e-12
    /// of the torque and power scale (∂torque/∂u of that over σ) over contacts from small
    /// to full and rotor speeds up to the crest (6.8e-13 worst). Graded towards one side
    /// only, as tanh's singularity over θs is, the rule left 5e-7 at n = 4.
    #[test]
    fn stick_slip_factors_agree_with_adaptive_quadrature() {
        use crate::quad::integrate;
        let law = |rho: f64, sigma: f64, n: f64| Law {
            radial_ratio: rho,
            slip_scale: sigma,
            truth: false,
            truth_radial: false,
            sharpness: n,
        };
        let laws =
            [law(0.0, 0.02, 2.0), law(0.0, 0.02, 4.0), law(0.0, 0.2, 3.0), law(0.0, 0.003, 4.0), law(0.3, 0.05, 2.0)];
        let mut worst: f64 = 0.0;
        for l in laws {
            for &y in &[0.3, 1.0, 2.0, 4.0] {
                let ct = contact_from_ratio(y);
                for &u in &[0.0, 0.3, 0.8, 0.95, 0.99, 0.999, 1.0] {
                    let rule = factors(&ct, u, &l);
                    let (ts, phi0) = (u.acos(), ct.half_angle_rad);
                    let cuts = quadrature_cuts(ts, phi0, stick_slip_singularities(&l, u, phi0).into_iter().flatten());
                    let part = |pick: fn(&Factors) -> f64, th: f64| {
                        let mut f = Factors::default();
                        for (rho, w) in radii(&l) {
                            accumulate(&mut f, th.sin(), th.cos(), w, ct.offset, u, rho, &l);
                        }
                        pick(&f)
                    };
                    let scale = rule.torque.abs().max(rule.power.abs()).max(1e-3);
                    type Pick = (fn(&Factors) -> f64, f64);
                    let picks: [Pick; 3] =
                        [(|f| f.torque, rule.torque), (|f| f.power, rule.power), (|f| f.torque_du, rule.torque_du)];
                    for (k, (pick, got)) in picks.into_iter().enumerate() {
                        let want: f64 =
                            cuts.windows(2).map(|w| integrate(|th| part(pick, th), w[0], w[1], 1e-15, 1e-12).0).sum();
                        // (∂torque/∂u scales with 1/σ)
                        let sc = if k == 2 { scale / l.slip_scale } else { scale };
                        let err = (got - want).abs() / sc;
                        worst = worst.max(err);
                        assert!(err <= 2e-12, "{l:?} y={y} u={u} [{k}]: rule {got} vs adaptive {want} ({err:.1e})");
                    }
                }
            }
        }
        eprintln!("stick-then-slip laws: worst relative error of the rule {worst:.1e}");
    }
}
