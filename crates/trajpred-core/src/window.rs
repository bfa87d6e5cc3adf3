//! Sliding windows and the Hankel design matrices of multi-step linear prediction
//! (`docs/papers.md` A.3, eq. 4 and 14-16 of the GSKF paper).
//!
//! For a series `x_0 .. x_{h-1}`, window length `m` and horizon `t >= 1`, row `j` of the design
//! `D_t` is the window `(x_j, ..., x_{j+m-1})` and the target is `x_{j+m-1+t}`, for
//! `j = 0 .. p-1` with `p = h - t - m + 1` (every window whose `t`-step target exists).

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The design matrix and target of one horizon.
#[derive(Debug, Clone, PartialEq)]
pub struct HankelDesign {
    /// `p x m`: row `j` is the window `(x_j, ..., x_{j+m-1})`.
    pub design: DMatrix<f64>,
    /// Length `p`: `x_{j+m-1+t}`.
    pub target: DVector<f64>,
}

/// Number of rows `p = h - t - m + 1` of the design for a series of length `h`, or `None`
/// if no window has a `t`-step target.
pub fn design_rows(h: usize, m: usize, t: usize) -> Option<usize> {
    h.checked_sub(t + m)
        .map(|r| r + 1)
        .filter(|_| m > 0 && t > 0)
}

/// Builds `D_t` and `X_t` for window length `m` and horizon `t` (both at least 1).
///
/// ```
/// use trajpred_core::window::hankel_design;
/// let x = [1.0, 2.0, 3.0, 4.0, 5.0];
/// let d = hankel_design(&x, 2, 2)?; // p = 5 - 2 - 2 + 1 = 2
/// assert_eq!(d.design.row(0).iter().copied().collect::<Vec<_>>(), vec![1.0, 2.0]);
/// assert_eq!(d.design.row(1).iter().copied().collect::<Vec<_>>(), vec![2.0, 3.0]);
/// assert_eq!(d.target.as_slice(), &[4.0, 5.0]);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub fn hankel_design(series: &[f64], m: usize, t: usize) -> Result<HankelDesign> {
    check_window(m, t)?;
    let p = design_rows(series.len(), m, t).ok_or(Error::TooShort {
        what: "series for a Hankel design",
        needed: m + t,
        got: series.len(),
    })?;
    if let Some(index) = series.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "series",
            index,
        });
    }
    let design = DMatrix::from_fn(p, m, |j, k| series[j + k]);
    let target = DVector::from_fn(p, |j, _| series[j + m - 1 + t]);
    Ok(HankelDesign { design, target })
}

/// The windows of length `m` of a series, oldest first, each a borrowed slice (no copy).
///
/// ```
/// use trajpred_core::window::windows;
/// let w: Vec<&[f64]> = windows(&[1.0, 2.0, 3.0], 2)?.collect();
/// assert_eq!(w, vec![&[1.0, 2.0][..], &[2.0, 3.0][..]]);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
pub fn windows(series: &[f64], m: usize) -> Result<std::slice::Windows<'_, f64>> {
    if m == 0 {
        return Err(Error::InvalidParameter {
            name: "m",
            reason: format!("window length must be at least 1, got {m}"),
        });
    }
    if series.len() < m {
        return Err(Error::TooShort {
            what: "series for windows",
            needed: m,
            got: series.len(),
        });
    }
    Ok(series.windows(m))
}

/// The most recent window of length `m`: `(x_{i-m+1}, ..., x_i)` with `i` the last index.
pub fn last_window(series: &[f64], m: usize) -> Result<&[f64]> {
    let _ = windows(series, m)?;
    Ok(&series[series.len() - m..])
}

fn check_window(m: usize, t: usize) -> Result<()> {
    if m == 0 {
        return Err(Error::InvalidParameter {
            name: "m",
            reason: format!("window length must be at least 1, got {m}"),
        });
    }
    if t == 0 {
        return Err(Error::InvalidParameter {
            name: "t",
            reason: format!("horizon must be at least 1, got {t}"),
        });
    }
    Ok(())
}
