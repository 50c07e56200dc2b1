//! Vectorised solving without Python types: broadcasting of the five input columns,
//! chunked (optionally rayon-parallel) solves into column buffers, full-factorial maps.
//! Every point is solved independently of the chunking, so results are bitwise the same
//! serial, parallel, or split over processes.

use rayon::prelude::*;
use trum_core::quantities::{values, QUANTITIES};
use trum_core::solve::{solve_prepared, OperatingPoint, Prepared};
use trum_core::sweep::{solve_range, Grid};
use trum_core::{Motor, Solution, Status};

/// Status words in code order (`status_code` indexes this).
pub const STATUS_NAMES: [&str; 5] = ["ok", "stall", "clamped", "no_convergence", "invalid_input"];

/// Inputs with at least this many points are solved in parallel by default.
pub const PARALLEL_MIN_POINTS: usize = 4096;

/// Points per work item.
const CHUNK: usize = 1024;

/// Input names in the order of [`solve_points`]'s columns.
pub const INPUTS: [&str; 5] = ["preload_n", "torque_nm", "voltage_v", "frequency_hz", "elapsed_s"];

/// Code of a status in [`STATUS_NAMES`].
pub fn status_code(s: Status) -> u8 {
    match s {
        Status::Ok => 0,
        Status::Stall => 1,
        Status::Clamped => 2,
        Status::NoConvergence => 3,
        Status::InvalidInput => 4,
    }
}

/// One broadcast input column: a scalar, a borrowed contiguous buffer (zero-copy) or a
/// gathered copy of a strided view.
pub enum Column<'a> {
    /// Same value everywhere.
    Scalar(f64),
    /// Contiguous, already in row-major broadcast order.
    Slice(&'a [f64]),
    /// Gathered from a strided or broadcast view.
    Owned(Vec<f64>),
}

impl Column<'_> {
    #[inline]
    fn at(&self, i: usize) -> f64 {
        match self {
            Column::Scalar(v) => *v,
            Column::Slice(s) => s[i],
            Column::Owned(v) => v[i],
        }
    }
}

/// NumPy broadcasting of `shapes`; the error names the clashing inputs.
pub fn broadcast_shape(names: &[&str], shapes: &[&[usize]]) -> Result<Vec<usize>, String> {
    let nd = shapes.iter().map(|s| s.len()).max().unwrap_or(0);
    let mut out = vec![1usize; nd];
    let mut owner: Vec<Option<usize>> = vec![None; nd];
    for (k, s) in shapes.iter().enumerate() {
        for (j, &d) in s.iter().enumerate() {
            let axis = nd - s.len() + j;
            if d == out[axis] || d == 1 {
                continue;
            }
            if out[axis] == 1 {
                out[axis] = d;
                owner[axis] = Some(k);
            } else {
                let other = owner[axis].unwrap_or(0);
                return Err(format!(
                    "inputs could not be broadcast together: {} has shape {:?}, {} has shape {:?}",
                    names[other], shapes[other], names[k], s
                ));
            }
        }
    }
    Ok(out)
}

/// Output columns of a vectorised solve, in [`QUANTITIES`] order, plus status codes.
pub struct Columns {
    /// One column per quantity (NaN where the status is not valid).
    pub values: Vec<Vec<f64>>,
    /// Status codes (see [`STATUS_NAMES`]).
    pub status: Vec<u8>,
}

/// Mutable views of one chunk of every output column.
struct ChunkOut<'a> {
    start: usize,
    values: Vec<&'a mut [f64]>,
    status: &'a mut [u8],
}

impl ChunkOut<'_> {
    #[inline]
    fn write(&mut self, j: usize, s: &Solution) {
        self.status[j] = status_code(s.status);
        let valid = s.status.is_valid();
        for (col, v) in self.values.iter_mut().zip(values(s)) {
            col[j] = if valid { v } else { f64::NAN };
        }
    }
}

impl Columns {
    /// Zeroed buffers for `n` points; `None` when the memory cannot be had (a huge
    /// broadcast must not abort the process).
    fn try_new(n: usize) -> Option<Columns> {
        fn zeros<T: Clone + Default>(n: usize) -> Option<Vec<T>> {
            let mut v = Vec::new();
            v.try_reserve_exact(n).ok()?;
            v.resize(n, T::default());
            Some(v)
        }
        let values = (0..QUANTITIES.len()).map(|_| zeros(n)).collect::<Option<Vec<_>>>()?;
        Some(Columns { values, status: zeros(n)? })
    }

    /// Splits every column into chunks of `chunk` points.
    fn chunks(&mut self, chunk: usize) -> Vec<ChunkOut<'_>> {
        let chunk = chunk.max(1);
        let mut out: Vec<ChunkOut<'_>> = self
            .status
            .chunks_mut(chunk)
            .enumerate()
            .map(|(c, status)| ChunkOut { start: c * chunk, values: Vec::with_capacity(QUANTITIES.len()), status })
            .collect();
        for col in self.values.iter_mut() {
            for (c, s) in col.chunks_mut(chunk).enumerate() {
                out[c].values.push(s);
            }
        }
        out
    }
}

fn run<F>(chunks: Vec<ChunkOut<'_>>, parallel: bool, work: F)
where
    F: Fn(&mut ChunkOut<'_>) + Sync + Send,
{
    if parallel {
        chunks.into_par_iter().for_each(|mut c| work(&mut c));
    } else {
        chunks.into_iter().for_each(|mut c| work(&mut c));
    }
}

/// Solves `n` points whose inputs are `cols` (in [`INPUTS`] order), each from a cold
/// start, so a point's result does not depend on its neighbours.
pub fn solve_points(motor: &Motor, cols: &[Column<'_>; 5], n: usize, parallel: bool) -> Option<Columns> {
    let p = Prepared::new(motor);
    let mut out = Columns::try_new(n)?;
    run(out.chunks(CHUNK), parallel, |c| {
        for j in 0..c.status.len() {
            let i = c.start + j;
            let op = OperatingPoint {
                preload_n: cols[0].at(i),
                torque_nm: cols[1].at(i),
                voltage_v: cols[2].at(i),
                frequency_hz: cols[3].at(i),
                elapsed_s: cols[4].at(i),
            };
            c.write(j, &solve_prepared(&p, motor, &op, None));
        }
    });
    Some(out)
}

/// Whether a status code is of a solved point (ok, stall, clamped): one without a reason.
pub fn is_valid_code(status: u8) -> bool {
    status < 3
}

/// Why the point `i` of a solve is not valid (`None` when it is).
pub fn reason(status: u8, op: &OperatingPoint) -> Option<String> {
    match status {
        3 => Some("no steady state found: the iteration did not converge, or the motor hunts between states".into()),
        4 => Some(op.invalid_reason().unwrap_or_else(|| "invalid operating point".into())),
        _ => None,
    }
}

/// Reasons for every non-valid point of a vectorised solve.
pub fn reasons(cols: &[Column<'_>; 5], status: &[u8]) -> Vec<(usize, String)> {
    status
        .iter()
        .enumerate()
        .filter(|(_, &s)| !is_valid_code(s))
        .filter_map(|(i, &s)| {
            let op = OperatingPoint {
                preload_n: cols[0].at(i),
                torque_nm: cols[1].at(i),
                voltage_v: cols[2].at(i),
                frequency_hz: cols[3].at(i),
                elapsed_s: cols[4].at(i),
            };
            reason(s, &op).map(|r| (i, r))
        })
        .collect()
}

/// Solves a validated grid. Rows along the torque axis (the fastest) are warm-started
/// from their previous point like the core's sweeps; each row starts cold, so the result
/// does not depend on the chunking.
pub fn solve_grid(motor: &Motor, grid: &Grid, n: usize, parallel: bool) -> Option<Columns> {
    let p = Prepared::new(motor);
    let row = grid.torque_nm.n.max(1);
    let rows_per_chunk = (CHUNK / row).max(1);
    let mut out = Columns::try_new(n)?;
    run(out.chunks(rows_per_chunk * row), parallel, |c| {
        let (start, end) = (c.start, c.start + c.status.len());
        let mut r0 = start;
        while r0 < end {
            let r1 = (r0 + row).min(end);
            solve_range(motor, &p, grid, r0 as u64..r1 as u64, |i, _, s| c.write(i as usize - start, s));
            r0 = r1;
        }
    });
    Some(out)
}

/// The input columns of a grid, in [`trum_core::sweep::AXES`] order.
pub fn grid_inputs(grid: &Grid, n: usize) -> [Vec<f64>; 4] {
    let mut cols: [Vec<f64>; 4] = std::array::from_fn(|_| Vec::with_capacity(n));
    for i in 0..n as u64 {
        let op = grid.point(i);
        for (c, v) in cols.iter_mut().zip([op.preload_n, op.voltage_v, op.frequency_hz, op.torque_nm]) {
            c.push(v);
        }
    }
    cols
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn broadcasting_follows_numpy() {
        let n = ["a", "b", "c"];
        assert_eq!(broadcast_shape(&n, &[&[], &[3], &[2, 1]]), Ok(vec![2, 3]));
        assert_eq!(broadcast_shape(&n, &[&[0], &[1], &[]]), Ok(vec![0]));
        let e = broadcast_shape(&n, &[&[2], &[3], &[]]).unwrap_err();
        assert!(e.contains("a has shape [2], b has shape [3]"), "{e}");
    }

    #[test]
    fn parallel_equals_serial_equals_core() {
        let m = trum_core::presets::preset("trum60a").unwrap();
        let pre: Vec<f64> = (0..5000).map(|i| 100.0 + (i % 300) as f64).collect();
        let cols = [
            Column::Slice(&pre),
            Column::Scalar(0.1),
            Column::Scalar(200.0),
            Column::Scalar(43e3),
            Column::Scalar(0.0),
        ];
        let a = solve_points(&m, &cols, pre.len(), false).unwrap();
        let b = solve_points(&m, &cols, pre.len(), true).unwrap();
        assert_eq!(a.status, b.status);
        for (x, y) in a.values.iter().zip(&b.values) {
            assert!(x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits()));
        }
        let s = trum_core::solve(&m, &OperatingPoint::new(pre[7], 0.1, 200.0, 43e3));
        assert_eq!(a.values[0][7].to_bits(), s.speed_rpm.to_bits());
    }
}
