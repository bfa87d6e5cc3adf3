//! Segmentation and resampling of [`Trajectory`] values: split on gaps, keep the long ones,
//! resample to a fixed step by linear interpolation (the KF-dynamic experiments need a
//! uniform step).
//!
//! ```
//! use trajpred_core::Trajectory;
//! use trajpred_data::segment::{keep_min_points, resample, split_on_gaps};
//! let tr = Trajectory::new(vec![0.0, 1.0, 3.0, 100.0, 101.0], vec![[0.0], [1.0], [3.0], [0.0], [2.0]])?;
//! let parts = keep_min_points(split_on_gaps(&tr, 10.0)?, 3);
//! assert_eq!(parts.len(), 1);
//! let u = resample(&parts[0], 0.5)?;
//! assert_eq!(u.times(), &[0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]);
//! assert_eq!(u.axis(0)[3], 1.5);
//! # Ok::<(), trajpred_data::Error>(())
//! ```

use crate::error::{Error, Result};
use trajpred_core::Trajectory;

/// Splits where the time between successive points exceeds `max_gap` seconds (a gap equal
/// to `max_gap` does not split).
pub fn split_on_gaps(tr: &Trajectory, max_gap: f64) -> Result<Vec<Trajectory>> {
    if !(max_gap.is_finite() && max_gap > 0.0) {
        return Err(Error::param(
            "max_gap",
            format!("must be finite and positive, got {max_gap}"),
        ));
    }
    let t = tr.times();
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..t.len() {
        if t[i] - t[i - 1] > max_gap {
            out.push(tr.slice(start..i)?);
            start = i;
        }
    }
    out.push(tr.slice(start..t.len())?);
    Ok(out)
}

/// The trajectories with at least `n` points, in order.
pub fn keep_min_points(trs: Vec<Trajectory>, n: usize) -> Vec<Trajectory> {
    trs.into_iter().filter(|t| t.len() >= n).collect()
}

/// Resamples to times `t0, t0 + dt, ...` up to the last timestamp (included when it falls on
/// the grid, to 1e-9 relative), each axis by linear interpolation between the two
/// surrounding points. `dt` must be finite and positive.
pub fn resample(tr: &Trajectory, dt: f64) -> Result<Trajectory> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::param(
            "dt",
            format!("must be finite and positive, got {dt}"),
        ));
    }
    let t = tr.times();
    let (t0, t1) = (t[0], t[t.len() - 1]);
    let span = t1 - t0;
    let steps = (span / dt * (1.0 + 1e-9)).floor();
    if !(steps.is_finite() && steps < 1e8) {
        return Err(Error::param(
            "dt",
            format!("{dt} s over {span} s gives too many samples"),
        ));
    }
    let n = steps as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| (t0 + k as f64 * dt).min(t1)).collect();
    let mut axes: Vec<Vec<f64>> = (0..tr.dim()).map(|_| Vec::with_capacity(n)).collect();
    let mut j = 0; // t[j] <= s < t[j + 1]
    for &s in &times {
        while j + 1 < t.len() - 1 && t[j + 1] <= s {
            j += 1;
        }
        let (ta, tb) = (t[j], t[(j + 1).min(t.len() - 1)]);
        let w = if tb > ta {
            ((s - ta) / (tb - ta)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for (k, out) in axes.iter_mut().enumerate() {
            let a = tr.axis(k);
            let (va, vb) = (a[j], a[(j + 1).min(t.len() - 1)]);
            out.push(va + w * (vb - va));
        }
    }
    // a grid time that rounding put on t1 twice would not be strictly increasing
    if n >= 2 && times[n - 1] <= times[n - 2] {
        let keep = n - 1;
        let times = times[..keep].to_vec();
        let axes = axes.into_iter().map(|mut a| {
            a.truncate(keep);
            a
        });
        return Ok(Trajectory::from_axes(times, axes.collect())?);
    }
    Ok(Trajectory::from_axes(times, axes)?)
}
