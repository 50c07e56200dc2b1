//! # trum-core
//!
//! Steady-state model of traveling-wave rotary ultrasonic motors (TRUMs): contact zone
//! from preload, driving and braking zones under load, stator amplitude solved together
//! with the contact forces, torque, losses, efficiency, temperature rise, speed
//! fluctuation and the preload optimisation criterion. Pure Rust, no file or network I/O:
//! parsers take strings, progress is reported through callbacks.
//!
//! Sources are five papers, cited with their equation numbers under these keys:
//! - Chen et al. 2020: N. Chen, J. Zheng, D. Fan, *Pre-pressure optimization for
//!   ultrasonic motors based on multi-sensor fusion*, Sensors 2020 (the TRUM60A motor);
//! - Sun et al. 2021: H. Sun, H. Yin, J. Liu, X. Zhang, *Efficiency model for traveling
//!   wave-type ultrasonic motors based on contact variables and preload*, Actuators 2021;
//! - the radial-friction paper: *A novel model of ultrasonic motors with effect of radial
//!   friction in contact mechanism*;
//! - the Hertzian driving-circuit paper (2022): *A design method of traveling wave rotary
//!   ultrasonic motors driving circuit under high voltage using single-sided Hertzian
//!   contact forced oscillator model*, 2022;
//! - the bar-type transient paper: *Transient analysis of bar-type ultrasonic motors*.
//!
//! SI units everywhere; every public quantity name carries its unit.
//!
//! ## Code map
//!
//! Entry points: `solve` (one operating point of a `Motor`, re-exported here), `sweep`
//! (grids with warm starts), `criterion` (the preload criterion), `calibrate`, `diagnose`,
//! `estimate`, `synth` and `dynamics`.
//!
//! - Motor and data: `params` (the `Motor` and its TOML file), `presets` (the built-in
//!   motors, `crates/trum-core/presets/*.toml`), `effects` (the registry of unmodelled
//!   effects), `limits`, `tolerances`, `measurements` (the measurement CSV),
//!   `observable` and `observations` (bench data as observed rows).
//! - Steady-state physics: `contact` (contact and stick zones, torque), `stator` (modal
//!   dynamics and modal stiffness), `interface` (friction laws beyond 2-D Coulomb),
//!   `losses`, `thermal`, `fluctuation`; `solve/` puts them together (its `mod.rs` maps
//!   its files); `solution` and `quantities` hold what it reports.
//! - Bench data and fits: `synth`, `noise`, `calibrate` (with `sensitivity`, and `lsq`,
//!   dense least squares on the SVD of the Jacobian), and `diagnose/`, one file per stage
//!   (`baseline`, `candidates`, `scan`, `signature`, `pairs`, `verdict`, `where_`, `json`).
//! - Dynamics: `dynamics::hertz` (the Hertzian-contact oscillator), `dynamics::transient`
//!   (stick-slip start-up), `dynamics::bar_type`.
//! - Checks of the papers: `papers` (closed forms as printed and corrected) and `quad`.
//!
//! The physics of an effect lives in the module of the part of the model it changes
//! (`interface`, `stator`, `solve/trial.rs`, ...), read once per motor in
//! `solve/prepared.rs`. Where a new effect, quantity, parameter or command goes, and how
//! to run the tests (`bash scripts/test.sh`, `cargo test -p trum-core`) and the
//! benchmarks (`cargo bench --bench solve`): `docs/CONTRIBUTING.md`. The equations are in
//! `docs/MODEL.md`.
#![warn(missing_docs)]

pub mod axis;
pub mod calibrate;
pub mod contact;
pub mod criterion;
pub mod diagnose;
pub mod dynamics;
pub mod effects;
pub mod error;
pub mod estimate;
pub mod fluctuation;
mod golden;
pub mod interface;
pub mod layout;
pub mod limits;
pub mod losses;
mod lsq;
pub mod measurements;
pub mod noise;
mod normal;
pub mod observable;
pub mod observations;
pub mod operating_point;
pub mod papers;
pub mod params;
pub mod presets;
pub mod quad;
pub mod quantities;
mod sensitivity;
pub mod solution;
pub mod solve;
pub mod stator;
pub mod sweep;
pub mod synth;
pub mod thermal;
pub mod tolerances;
mod toml_text;

pub use effects::{Effect, Effects};
pub use error::{ParamError, TrumError};
pub use params::Motor;
pub use solve::{solve, OperatingPoint, Solution, Status};

/// Bench (test-rig) data ↔ model observations under the path `trum_core::bench`, which the
/// CLI, the Python module and the blind benchmark's support code use: [`observations`].
pub use observations as bench;
