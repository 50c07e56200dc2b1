//! Nonlinear stator dynamics.
//!
//! * [`hertz`]: the single-sided Hertzian-contact forced oscillator of the Hertzian driving-circuit paper (2022)
//!   (m·w'' + c·w' + k·w + β·w³ = F_n + F_d, eq. 2-4): softening backbone, amplitude–
//!   frequency response with jumps (multiple scales, eq. 10-12, and one-term harmonic
//!   balance), harmonic-balance identification of β from the isolated-electrode
//!   (feedback) voltage (eq. 5-9) and a fixed-step RK4 time simulation with constant
//!   frequency and slow linear sweeps. The steady model's counterpart is the `hertz_softening` effect.
//!
//! * [`transient`]: the step response with a discretised stick-slip contact (ring motor).
//! * [`bar_type`]: the bar-type motor (rigid-disc stator driven by a moment) on the same
//!   integrator and contact step.
//!
//! Equations, deviations from the printed forms and the test tolerances are collected in
//! `docs/DYNAMICS.md`, section "Hertzian oscillator".

pub mod bar_type;
pub mod hertz;
pub mod transient;
