//! Closed forms of the source papers, each implemented **exactly as printed** and, where the
//! printed form disagrees with its own defining integral, also in a corrected form.
//!
//! * [`chen2020`]: Chen et al. 2020, Chen, Zheng, Fan, *Pre-pressure optimization for ultrasonic
//!   motors based on multi-sensor fusion*, Sensors 2020, 20, 2096.
//! * [`sun2021`]: Sun et al. 2021, Sun, Yin, Liu, Zhang, *Efficiency model for traveling wave-type
//!   ultrasonic motors based on contact variables and preload*, Actuators 2021, 10, 158.
//!
//! Every closed form is checked in the module tests against adaptive Gauss–Kronrod
//! quadrature ([`crate::quad`]) of its defining integral; `docs/PAPERS.md` lists the verdicts.
//!
//! Shared 2-D contact model (both papers): with wave phase θ = k·x (k = N/R0 the wave
//! number, N the number of waves), contact half-angle φ0 = k·x0, the pressure per unit
//! circumferential length is p(θ) = k_f·W·(cos θ − cos φ0) for |θ| ≤ φ0, the axial force is
//! F_N = 2N·(k_f·W/k)·(sin φ0 − φ0·cos φ0), and with χ(θ) = sin θ − θ·cos φ0 the torque is
//! T = R0·μ·F_N·\[2χ(θs) − χ(φ0)\]/χ(φ0) (θs the stick half-angle).
//!
//! Conventions: SI units, names carry their unit; dimensionless quantities are named for
//! what they are (`wave_number` = N, `friction_coefficient`, `loss_tangent`). Plain
//! arithmetic closed forms return `f64` and propagate non-finite inputs as IEEE does;
//! functions with a restricted domain return `Option` and give `None` outside it. No
//! function panics.

pub mod chen2020;
pub mod sun2021;
