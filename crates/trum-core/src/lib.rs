//! # trum-core
//!
//! Steady-state model of traveling-wave rotary ultrasonic motors (TRUMs): contact zone
//! from preload, driving and braking zones under load, stator amplitude solved together
//! with the contact forces, torque, losses, efficiency, temperature rise, speed
//! fluctuation and the preload optimisation criterion. Pure Rust, no file or network I/O:
//! parsers take strings, progress is reported through callbacks.
//!
//! Sources are the five papers in `shared/seeds/` (cited as seed 000 … 004 with their
//! equation numbers). SI units everywhere; every public quantity name carries its unit.
#![warn(missing_docs)]

pub mod calibrate;
pub mod contact;
pub mod criterion;
pub mod diagnose;
pub mod dynamics;
pub mod effects;
pub mod error;
pub mod fluctuation;
mod golden;
pub mod interface;
pub mod layout;
pub mod losses;
pub mod measurements;
pub mod noise;
pub mod observations;
pub mod papers;
pub mod params;
pub mod presets;
pub mod quad;
pub mod quantities;
mod sensitivity;
pub mod solve;
pub mod stator;
pub mod sweep;
pub mod synth;
pub mod thermal;

pub use effects::{Effect, Effects};
pub use error::{ParamError, TrumError};
pub use params::Motor;
pub use solve::{solve, OperatingPoint, Solution, Status};

/// Bench (test-rig) data ↔ model observations under the path `trum_core::bench`, which the
/// CLI, the Python module and the blind benchmark's support code use: [`observations`].
pub use observations as bench;
