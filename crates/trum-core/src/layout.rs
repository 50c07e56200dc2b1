//! Output layouts the command-line tool and the Python module share, so that both write
//! the same words, codes and columns: the status of an operating point (word, code,
//! meaning) and the table of an amplitude–frequency response (`trum resonance -o`,
//! `trum.resonance(...).to_dict()`). Pure data and formatting-free: the front ends turn
//! the rows into CSV text or NumPy arrays.

use crate::dynamics::hertz::{FamilyCurve, HertzError};
use crate::solve::Status;

/// Every status, in code order: the code of a status is its index here. Python's
/// `status_code` arrays index [`STATUS_NAMES`] with it.
pub const STATUSES: [Status; 5] =
    [Status::Ok, Status::Stall, Status::Clamped, Status::NoConvergence, Status::InvalidInput];

/// The status words in code order: [`Status::as_str`] of each of [`STATUSES`].
pub const STATUS_NAMES: [&str; 5] =
    [STATUSES[0].as_str(), STATUSES[1].as_str(), STATUSES[2].as_str(), STATUSES[3].as_str(), STATUSES[4].as_str()];

/// The code of a status: its index in [`STATUSES`].
pub fn status_code(s: Status) -> u8 {
    // (every status is in STATUSES, which has five entries: the cast cannot truncate)
    STATUSES.iter().position(|&x| x == s).unwrap_or(STATUSES.len()) as u8
}

/// The status with code `code`, if there is one.
pub fn status_of_code(code: u8) -> Option<Status> {
    STATUSES.get(usize::from(code)).copied()
}

/// What a status means, in words (`trum point` prints it next to the status; Python gives
/// it as the reason of a point without a steady state).
pub fn status_meaning(s: Status) -> &'static str {
    match s {
        Status::Ok => "rotor turning",
        Status::Stall => "load torque at or above the stall torque: rotor at rest",
        Status::Clamped => "friction clamps the stator: no vibration at this drive",
        Status::NoConvergence => "no steady state found: not converged, or the motor hunts between states",
        Status::InvalidInput => "invalid operating point",
    }
}

/// Why a point has no steady state when its solve spent its work bound
/// ([`crate::Solution::work_bound_reached`], [`crate::solve::WORK_BOUND`] units by default):
/// the search was stopped, not proven fruitless (docs/RELIABILITY.md, "The work bound of a
/// solve").
pub fn work_bound_meaning() -> String {
    format!(
        "no steady state found: the solve spent its work bound ({} units by default) before it found one",
        crate::solve::WORK_BOUND
    )
}

/// The columns of the response table, in order.
pub const RESPONSE_COLUMNS: [&str; 8] =
    ["voltage_v", "preload_n", "frequency_hz", "branch", "status", "amplitude_m", "phase_lag_rad", "stable"];

/// One row of the response table. Numbers that a row does not have are NaN (written as
/// empty CSV cells, NaN in Python); `stable` is `None` where stability does not apply.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ResponseRow {
    /// Drive voltage of the curve [V].
    pub voltage_v: f64,
    /// Static preload of the curve [N].
    pub preload_n: f64,
    /// Drive frequency [Hz] (for the backbone: the free-oscillation frequency).
    pub frequency_hz: f64,
    /// `single`, `lower`, `middle`, `upper`, `backbone`, `jump_up`, `jump_down`; empty in
    /// the one row of a curve without a response.
    pub branch: &'static str,
    /// [`response_status`] of the curve.
    pub status: &'static str,
    /// Amplitude [m].
    pub amplitude_m: f64,
    /// Phase lag behind the drive [rad] (branch rows only).
    pub phase_lag_rad: f64,
    /// Stability of the solution (branch rows; `false` at the saddle nodes).
    pub stable: Option<bool>,
}

/// One cell of the response table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ResponseCell {
    /// A number (NaN where the row has none).
    Number(f64),
    /// A word (`branch`, `status`).
    Word(&'static str),
    /// A flag that may not apply (`stable`).
    Flag(Option<bool>),
}

impl ResponseRow {
    /// The row's cells, in [`RESPONSE_COLUMNS`] order.
    pub fn cells(&self) -> [ResponseCell; 8] {
        use ResponseCell::{Flag, Number, Word};
        [
            Number(self.voltage_v),
            Number(self.preload_n),
            Number(self.frequency_hz),
            Word(self.branch),
            Word(self.status),
            Number(self.amplitude_m),
            Number(self.phase_lag_rad),
            Flag(self.stable),
        ]
    }
}

/// The status word of a response curve: `ok`, `no_static_equilibrium` (the softening
/// spring cannot carry the preload) or `invalid_input`.
pub fn response_status(c: &FamilyCurve) -> &'static str {
    match &c.response {
        Ok(_) => "ok",
        Err(HertzError::NoStaticEquilibrium { .. }) => "no_static_equilibrium",
        Err(_) => "invalid_input",
    }
}

/// The response table of a family of curves: per curve, every branch point at every
/// frequency, then the backbone, then the jump-up and jump-down saddle nodes (with the
/// amplitude before the jump); a curve without a response is one row with its status.
pub fn response_rows(curves: &[FamilyCurve]) -> Vec<ResponseRow> {
    let mut rows = Vec::new();
    for c in curves {
        let (v, n) = (c.operating_point.voltage_v, c.operating_point.preload_n);
        let row = |frequency_hz, branch, amplitude_m, phase_lag_rad, stable| ResponseRow {
            voltage_v: v,
            preload_n: n,
            frequency_hz,
            branch,
            status: "ok",
            amplitude_m,
            phase_lag_rad,
            stable,
        };
        let r = match &c.response {
            Ok(r) => r,
            Err(_) => {
                rows.push(ResponseRow { status: response_status(c), ..row(f64::NAN, "", f64::NAN, f64::NAN, None) });
                continue;
            }
        };
        for p in &r.points {
            rows.push(row(p.frequency_hz, p.branch.as_str(), p.amplitude_m, p.phase_lag_rad, Some(p.stable)));
        }
        for b in &c.backbone {
            rows.push(row(b.frequency_hz, "backbone", b.amplitude_m, f64::NAN, None));
        }
        if let Some(j) = &r.jumps {
            rows.push(row(j.jump_up_hz, "jump_up", j.jump_up_amplitude_m, f64::NAN, Some(false)));
            rows.push(row(j.jump_down_hz, "jump_down", j.jump_down_amplitude_m, f64::NAN, Some(false)));
        }
    }
    rows
}

/// The figures of one response curve that `trum resonance` tabulates and Python's
/// `ResonanceCurve` carries; NaN where a curve does not have them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResponseSummary {
    /// Linear resonance: the backbone's frequency at zero amplitude [Hz].
    pub linear_resonance_hz: f64,
    /// Equivalent cubic coefficient about the static deflection [N/m³].
    pub equivalent_beta_n_per_m3: f64,
    /// Largest amplitude of any branch [m].
    pub peak_amplitude_m: f64,
    /// Jump-up saddle node [Hz].
    pub jump_up_hz: f64,
    /// Jump-down saddle node [Hz].
    pub jump_down_hz: f64,
    /// Width of the bistable band, |jump_up − jump_down| [Hz].
    pub hysteresis_hz: f64,
}

/// The summary of a curve (all NaN for a curve without a response).
pub fn response_summary(c: &FamilyCurve) -> ResponseSummary {
    let nan = f64::NAN;
    let Ok(r) = &c.response else {
        return ResponseSummary {
            linear_resonance_hz: nan,
            equivalent_beta_n_per_m3: nan,
            peak_amplitude_m: nan,
            jump_up_hz: nan,
            jump_down_hz: nan,
            hysteresis_hz: nan,
        };
    };
    // the backbone starts at zero amplitude, i.e. at the linear resonance
    let linear_resonance_hz = c.backbone.first().map_or(nan, |p| p.frequency_hz);
    let peak_amplitude_m = r.points.iter().map(|p| p.amplitude_m).fold(nan, f64::max);
    let (jump_up_hz, jump_down_hz) = r.jumps.as_ref().map_or((nan, nan), |j| (j.jump_up_hz, j.jump_down_hz));
    ResponseSummary {
        linear_resonance_hz,
        equivalent_beta_n_per_m3: r.equivalent_beta_n_per_m3,
        peak_amplitude_m,
        jump_up_hz,
        jump_down_hz,
        hysteresis_hz: (jump_up_hz - jump_down_hz).abs(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::hertz::{HertzOscillator, OperatingPoint, ResponseMethod};

    #[test]
    fn status_words_codes_and_enum_agree() {
        for (i, s) in STATUSES.iter().enumerate() {
            assert_eq!(STATUS_NAMES[i], s.as_str());
            assert_eq!(usize::from(status_code(*s)), i);
            assert_eq!(status_of_code(status_code(*s)), Some(*s));
            // a solved point is one without a reason to withhold its numbers
            assert_eq!(s.is_valid(), i < 3, "{s:?}");
        }
        assert_eq!(status_of_code(5), None);
        // every status is listed: a new one stops this match compiling until it is
        let listed = |s: Status| match s {
            Status::Ok | Status::Stall | Status::Clamped | Status::NoConvergence | Status::InvalidInput => {
                STATUSES.contains(&s)
            }
        };
        assert!(STATUSES.iter().all(|&s| listed(s)) && STATUSES.len() == 5);
    }

    /// Each cell of a row sits under its own column, with the row's value.
    #[test]
    fn response_cells_follow_the_columns() {
        let r = ResponseRow {
            voltage_v: 1.0,
            preload_n: 2.0,
            frequency_hz: 3.0,
            branch: "upper",
            status: "ok",
            amplitude_m: 4.0,
            phase_lag_rad: 5.0,
            stable: Some(false),
        };
        let cells = r.cells();
        let expect = [
            ("voltage_v", ResponseCell::Number(1.0)),
            ("preload_n", ResponseCell::Number(2.0)),
            ("frequency_hz", ResponseCell::Number(3.0)),
            ("branch", ResponseCell::Word("upper")),
            ("status", ResponseCell::Word("ok")),
            ("amplitude_m", ResponseCell::Number(4.0)),
            ("phase_lag_rad", ResponseCell::Number(5.0)),
            ("stable", ResponseCell::Flag(Some(false))),
        ];
        assert_eq!(expect.len(), RESPONSE_COLUMNS.len());
        for (name, cell) in expect {
            let j = RESPONSE_COLUMNS.iter().position(|c| *c == name);
            assert_eq!(j.map(|j| cells[j]), Some(cell), "{name}");
        }
    }

    #[test]
    fn response_rows_hold_every_branch_point_backbone_and_saddle() {
        let o = HertzOscillator::default();
        let ops = [
            OperatingPoint { voltage_v: 200.0, preload_n: 400.0 },
            // a preload the softening spring cannot carry
            OperatingPoint { voltage_v: 200.0, preload_n: 1e12 },
        ];
        let freqs: Vec<f64> = (0..251).map(|i| 40_800.0 + i as f64).collect();
        let curves = o.response_family(&ops, &freqs, ResponseMethod::MultipleScales).expect("family");
        let rows = response_rows(&curves);
        let r = curves[0].response.as_ref().expect("a response at 400 N");
        let j = r.jumps.expect("200 V, 400 N is bistable in this band");
        let n = r.points.len() + curves[0].backbone.len() + 2;
        assert_eq!(rows.len(), n + 1);
        assert!(rows[..r.points.len()].iter().zip(&r.points).all(|(row, p)| row.frequency_hz == p.frequency_hz
            && row.amplitude_m == p.amplitude_m
            && row.stable == Some(p.stable)
            && row.branch == p.branch.as_str()));
        // only the middle branch is unstable
        assert!(rows.iter().filter(|r| r.branch == "middle").all(|r| r.stable == Some(false)));
        assert!(rows.iter().any(|r| r.branch == "middle"));
        assert_eq!((rows[n - 2].branch, rows[n - 2].frequency_hz), ("jump_up", j.jump_up_hz));
        assert_eq!((rows[n - 1].branch, rows[n - 1].frequency_hz), ("jump_down", j.jump_down_hz));
        assert_eq!(rows[n].status, "no_static_equilibrium");
        assert!(rows[n].frequency_hz.is_nan() && rows[n].branch.is_empty() && rows[n].stable.is_none());
        let s = response_summary(&curves[0]);
        assert_eq!(s.hysteresis_hz, (j.jump_up_hz - j.jump_down_hz).abs());
        assert!(s.peak_amplitude_m > 0.0 && s.linear_resonance_hz > 40_800.0);
        assert!(response_summary(&curves[1]).linear_resonance_hz.is_nan());
    }
}
