//! [`Trajectory`]: timestamps and points of 1, 2 or 3 axes, validated at construction.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::ops::{Deref, Range};

/// The largest number of axes a point may have.
pub const MAX_AXES: usize = 3;

/// One point of 1, 2 or 3 coordinates, stored inline (no allocation).
///
/// Dereferences to a slice of its coordinates.
///
/// ```
/// use trajpred_core::Point;
/// let p = Point::new(&[1.0, 2.0])?;
/// assert_eq!(p.dim(), 2);
/// assert_eq!(&p[..], &[1.0, 2.0]);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    coords: [f64; MAX_AXES],
    dim: u8,
}

impl Point {
    /// A point from 1..=3 coordinates; an error for any other count.
    pub fn new(coords: &[f64]) -> Result<Self> {
        if coords.is_empty() || coords.len() > MAX_AXES {
            return Err(Error::UnsupportedDimension { got: coords.len() });
        }
        let mut c = [0.0; MAX_AXES];
        c[..coords.len()].copy_from_slice(coords);
        Ok(Point {
            coords: c,
            dim: coords.len() as u8,
        })
    }

    /// Number of axes.
    pub fn dim(&self) -> usize {
        usize::from(self.dim)
    }
}

impl Deref for Point {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.coords[..self.dim()]
    }
}

impl AsRef<[f64]> for Point {
    fn as_ref(&self) -> &[f64] {
        self
    }
}

/// A time-ordered sequence of points `(t_i, p_i)`, `p_i` in R^d with d = 1, 2 or 3.
///
/// Invariants, checked by [`Trajectory::new`] and kept by every method:
/// - at least one point, and as many timestamps as points;
/// - every point has the same number of axes, 1 to 3;
/// - every value is finite;
/// - timestamps (seconds) strictly increase.
///
/// Coordinates are stored axis by axis, so [`Trajectory::axis`] is a contiguous slice (the
/// per-axis methods of the GSKF paper work on those directly).
///
/// ```
/// use trajpred_core::Trajectory;
/// let tr = Trajectory::new(vec![0.0, 1.0, 2.0], vec![vec![0.0, 0.0], vec![1.0, 0.5], vec![2.0, 1.0]])?;
/// assert_eq!(tr.len(), 3);
/// assert_eq!(tr.dim(), 2);
/// assert_eq!(tr.axis(1), &[0.0, 0.5, 1.0]);
/// assert_eq!(&tr.point(2)[..], &[2.0, 1.0]);
///
/// // the first bad index is named
/// let err = Trajectory::new(vec![0.0, 1.0, 1.0], vec![vec![0.0]; 3]).unwrap_err();
/// assert!(matches!(err, trajpred_core::Error::NonIncreasingTime { index: 2, .. }));
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    times: Vec<f64>,
    axes: Vec<Vec<f64>>,
}

impl Trajectory {
    /// Builds a trajectory from timestamps and points (each point a slice of 1..=3 values).
    pub fn new<P: AsRef<[f64]>>(times: Vec<f64>, points: Vec<P>) -> Result<Self> {
        if points.len() != times.len() {
            return Err(Error::LengthMismatch {
                what: "points vs timestamps",
                expected: times.len(),
                got: points.len(),
            });
        }
        let first = points.first().ok_or(Error::Empty { what: "trajectory" })?;
        let dim = first.as_ref().len();
        if dim == 0 || dim > MAX_AXES {
            return Err(Error::UnsupportedDimension { got: dim });
        }
        let mut axes = vec![Vec::with_capacity(points.len()); dim];
        for (i, p) in points.iter().enumerate() {
            let p = p.as_ref();
            if p.len() != dim {
                return Err(Error::PointDimension {
                    index: i,
                    expected: dim,
                    got: p.len(),
                });
            }
            for (axis, &v) in axes.iter_mut().zip(p) {
                axis.push(v);
            }
        }
        Self::from_axes(times, axes)
    }

    /// Builds a trajectory from timestamps and one vector per axis.
    pub fn from_axes(times: Vec<f64>, axes: Vec<Vec<f64>>) -> Result<Self> {
        if axes.is_empty() || axes.len() > MAX_AXES {
            return Err(Error::UnsupportedDimension { got: axes.len() });
        }
        if times.is_empty() {
            return Err(Error::Empty { what: "trajectory" });
        }
        for axis in &axes {
            if axis.len() != times.len() {
                return Err(Error::LengthMismatch {
                    what: "axis vs timestamps",
                    expected: times.len(),
                    got: axis.len(),
                });
            }
        }
        if let Some(index) = times.iter().position(|t| !t.is_finite()) {
            return Err(Error::NonFinite {
                what: "timestamps",
                index,
            });
        }
        for i in 1..times.len() {
            if times[i] <= times[i - 1] {
                return Err(Error::NonIncreasingTime {
                    index: i,
                    time: times[i],
                    previous: times[i - 1],
                });
            }
        }
        let bad = axes
            .iter()
            .filter_map(|a| a.iter().position(|v| !v.is_finite()))
            .min();
        if let Some(index) = bad {
            return Err(Error::NonFinite {
                what: "points",
                index,
            });
        }
        Ok(Trajectory { times, axes })
    }

    /// A trajectory sampled every `dt` seconds from `t0`, one vector per axis.
    pub fn uniform(t0: f64, dt: f64, axes: Vec<Vec<f64>>) -> Result<Self> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidParameter {
                name: "dt",
                reason: format!("must be finite and positive, got {dt}"),
            });
        }
        let n = axes.first().map_or(0, Vec::len);
        let times = (0..n).map(|i| t0 + dt * i as f64).collect();
        Self::from_axes(times, axes)
    }

    /// Number of points (never zero).
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Always `false`: a trajectory holds at least one point. Present for API symmetry.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Number of axes, 1 to 3.
    pub fn dim(&self) -> usize {
        self.axes.len()
    }

    /// Timestamps in seconds.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// All values of axis `k` (0-based), contiguous. Panics if `k >= dim()`, like slice indexing.
    pub fn axis(&self, k: usize) -> &[f64] {
        &self.axes[k]
    }

    /// Every axis, in order.
    pub fn axes(&self) -> impl ExactSizeIterator<Item = &[f64]> {
        self.axes.iter().map(Vec::as_slice)
    }

    /// Point `i`. Panics if `i >= len()`, like slice indexing.
    pub fn point(&self, i: usize) -> Point {
        let mut coords = [0.0; MAX_AXES];
        for (c, a) in coords.iter_mut().zip(&self.axes) {
            *c = a[i];
        }
        Point {
            coords,
            dim: self.axes.len() as u8,
        }
    }

    /// Iterator over the points, in time order.
    pub fn points(&self) -> impl ExactSizeIterator<Item = Point> + '_ {
        (0..self.len()).map(move |i| self.point(i))
    }

    /// The last point.
    pub fn last_point(&self) -> Point {
        self.point(self.len() - 1)
    }

    /// The points with indices in `range`, as a new trajectory (a copy of that part).
    pub fn slice(&self, range: Range<usize>) -> Result<Self> {
        if range.start >= range.end || range.end > self.len() {
            return Err(Error::OutOfBounds {
                start: range.start,
                end: range.end,
                len: self.len(),
            });
        }
        Ok(Trajectory {
            times: self.times[range.clone()].to_vec(),
            axes: self
                .axes
                .iter()
                .map(|a| a[range.clone()].to_vec())
                .collect(),
        })
    }

    /// The first `n` points: the history available at forecast origin `n - 1`.
    pub fn prefix(&self, n: usize) -> Result<Self> {
        self.slice(0..n)
    }

    /// Time between the last two points, or `None` for a single point.
    pub fn last_interval(&self) -> Option<f64> {
        let n = self.len();
        (n >= 2).then(|| self.times[n - 1] - self.times[n - 2])
    }
}

impl<'de> Deserialize<'de> for Trajectory {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Raw {
            times: Vec<f64>,
            axes: Vec<Vec<f64>>,
        }
        let raw = Raw::deserialize(d)?;
        Trajectory::from_axes(raw.times, raw.axes).map_err(serde::de::Error::custom)
    }
}
