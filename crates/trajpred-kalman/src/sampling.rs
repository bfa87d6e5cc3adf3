//! Gaussian sampling and densities, the one implementation in the workspace (the particle
//! filters of `trajpred-particle` use it too): a square-root factor of a positive
//! semi-definite covariance ([`covariance_sqrt`]), draws `m + L e` of `N(m, L L^T)` from
//! standard normals ([`push_standard_normals`], [`draw`]), and the log-density of a
//! zero-mean Gaussian `N(0, S)` through the Cholesky factor of `S` ([`ZeroMeanGaussian`]).
//! On top of them, what a bootstrap particle filter needs from the model traits: draw from
//! the transition density `p(x' | x) = N(f(x), Q)` ([`sample_transition`]) and evaluate the
//! observation density `ln p(z | x) = ln N(residual(z, h(x)); 0, R)`
//! ([`observation_log_likelihood`]).

use crate::error::Result;
use crate::linalg::{Chol, check_dim, check_finite, check_square, to_f64};
use crate::model::{Observation, Transition};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, Dim, OMatrix, OVector, RealField};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use trajpred_core::Error as CoreError;

/// A lower-triangular `L` with `L L^T = C` for a symmetric positive **semi**-definite `C`:
/// the Cholesky factor when it exists (every pivot positive, however small: a badly scaled
/// but positive definite `C` keeps all its directions); otherwise the Cholesky algorithm
/// where a pivot below `64 n eps max|C|` (a zero eigen-direction, as in the discrete
/// white-noise `Q`) gives a zero column instead of a failure. Either way `L L^T` equals `C`
/// to rounding, singular or not (`C = 0` gives `L = 0`), with no jitter added. Compute it
/// once per covariance, not per draw.
///
/// Errors: `DimensionMismatch` for a matrix that is not square, `NonFinite` for a NaN or
/// infinite entry, `NotPositiveDefinite` naming `what` for an asymmetric matrix (beyond
/// `sqrt(eps)` relative) or a pivot below minus that tolerance (a negative eigenvalue).
///
/// ```
/// use nalgebra::Matrix2;
/// use trajpred_kalman::sampling::covariance_sqrt;
/// // the rank-one discrete white-noise Q = g g^T, g = (1/2, 1): L L^T = Q exactly
/// let q = Matrix2::new(0.25, 0.5, 0.5, 1.0);
/// let l = covariance_sqrt(&q, "Q")?;
/// assert!((l * l.transpose() - q).amax() < 1e-15);
/// assert_eq!(l[(1, 1)], 0.0);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn covariance_sqrt<T, D>(c: &OMatrix<T, D, D>, what: &'static str) -> Result<OMatrix<T, D, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D, D>,
{
    let n = c.nrows();
    check_square(c, n, what)?;
    check_finite(c, what)?;
    let scale = c.amax();
    let sym_tol = T::default_epsilon().sqrt() * scale.max(T::one());
    for j in 0..n {
        for i in 0..j {
            if (c[(i, j)] - c[(j, i)]).abs() > sym_tol {
                return Err(CoreError::NotPositiveDefinite { what }.into());
            }
        }
    }
    if let Some(chol) = Chol::new(c.clone_owned()) {
        return Ok(chol.unpack());
    }
    let tol = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    Chol::semidefinite(c.clone_owned(), tol)
        .map(Chol::unpack)
        .ok_or(CoreError::NotPositiveDefinite { what }.into())
}

/// Appends `count` standard normal variates, drawn in `f64` and converted to `T` (a seeded
/// generator gives the same draws in any scalar type).
pub fn push_standard_normals<T: RealField + Copy, R: Rng + ?Sized>(
    rng: &mut R,
    count: usize,
    out: &mut Vec<T>,
) {
    out.reserve(count);
    out.extend((0..count).map(|_| standard_normal::<T, R>(rng)));
}

/// One standard normal variate, drawn in `f64` and converted to `T`.
fn standard_normal<T: RealField + Copy, R: Rng + ?Sized>(rng: &mut R) -> T {
    let e: f64 = StandardNormal.sample(rng);
    nalgebra::convert(e)
}

/// The draw `mean + L e` of `N(mean, L L^T)` from `n` standard normals `e` (`L` from
/// [`covariance_sqrt`] or [`ZeroMeanGaussian::factor`]). No allocation for static sizes.
pub fn draw<T, D>(
    mean: &OVector<T, D>,
    l: &OMatrix<T, D, D>,
    normals: impl IntoIterator<Item = T>,
) -> OVector<T, D>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let e = OVector::<T, D>::from_iterator_generic(mean.shape_generic().0, Const::<1>, normals);
    mean + l * e
}

/// A zero-mean Gaussian `N(0, S)` held through the lower Cholesky factor `L` of `S` and its
/// normalising constant: log-densities of residuals ([`ZeroMeanGaussian::log_density`]), of
/// its own draws `L e` ([`ZeroMeanGaussian::log_density_of_normals`]), and draws
/// ([`draw`] with [`ZeroMeanGaussian::factor`]). Log-densities are `f64` whatever `T`.
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use trajpred_kalman::sampling::ZeroMeanGaussian;
/// let g = ZeroMeanGaussian::new(&Matrix2::new(4.0, 0.0, 0.0, 1.0), "S")?;
/// // ln N((2, 0); 0, diag(4, 1)) = -(2 ln 2 pi + ln 4 + 2^2 / 4) / 2
/// let expected = -(2.0 * (2.0 * std::f64::consts::PI).ln() + 4f64.ln() + 1.0) / 2.0;
/// assert!((g.log_density(&Vector2::new(2.0, 0.0)) - expected).abs() < 1e-14);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ZeroMeanGaussian<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D, D>,
{
    l: OMatrix<T, D, D>,
    log_norm: f64,
}

impl<T: RealField + Copy, D: Dim> ZeroMeanGaussian<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `N(0, S)` for a symmetric positive definite `S` (the lower triangle is read). Errors:
    /// `DimensionMismatch` for a matrix that is not square, `NonFinite`, and
    /// `NotPositiveDefinite` naming `what` when the factorisation fails or a pivot `L_ii^2`
    /// is not above `64 n eps max|S|` (a singular `S` can pass the factorisation with a
    /// rounding-size pivot, and its density is not defined).
    pub fn new(s: &OMatrix<T, D, D>, what: &'static str) -> Result<Self> {
        let n = s.nrows();
        check_square(s, n, what)?;
        check_finite(s, what)?;
        let l = Chol::new(s.clone_owned())
            .ok_or(CoreError::NotPositiveDefinite { what })?
            .unpack();
        let floor = to_f64(s.amax()) * f64::EPSILON * 64.0 * n as f64;
        let mut log_det_half = 0.0;
        for i in 0..n {
            let d = to_f64(l[(i, i)]);
            if d.is_nan() || d * d <= floor {
                return Err(CoreError::NotPositiveDefinite { what }.into());
            }
            log_det_half += d.ln();
        }
        let log_norm = -0.5 * (n as f64 * (2.0 * std::f64::consts::PI).ln()) - log_det_half;
        if !log_norm.is_finite() {
            return Err(CoreError::NotPositiveDefinite { what }.into());
        }
        Ok(ZeroMeanGaussian { l, log_norm })
    }

    /// The lower Cholesky factor `L` of `S` (`L L^T = S`), for [`draw`].
    pub fn factor(&self) -> &OMatrix<T, D, D> {
        &self.l
    }

    /// `ln N(r; 0, S) = -(n ln 2 pi + ln det S + r^T S^-1 r) / 2`, by one triangular solve;
    /// `-inf` for a non-finite residual (or one whose quadratic form overflows).
    pub fn log_density(&self, r: &OVector<T, D>) -> f64 {
        if r.iter().any(|v| !v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let mut y = r.clone_owned();
        self.l.solve_lower_triangular_unchecked_mut(&mut y);
        self.quadratic(to_f64(y.norm_squared()))
    }

    /// `ln N(L e; 0, S)` of the draw `L e` made from the standard normals `e`:
    /// `-(n ln 2 pi + ln det S + e^T e) / 2`, exact without a solve.
    pub fn log_density_of_normals(&self, e: &[T]) -> f64 {
        self.quadratic(e.iter().map(|v| to_f64(*v) * to_f64(*v)).sum())
    }

    /// The log-density at a point whose `r^T S^-1 r` is `q`.
    fn quadratic(&self, q: f64) -> f64 {
        if q.is_finite() {
            self.log_norm - 0.5 * q
        } else {
            f64::NEG_INFINITY
        }
    }
}

/// A draw `x' = f(x) + L e`, `e ~ N(0, I)`, with `L = covariance_sqrt(Q)` supplied by the
/// caller (compute it once with [`covariance_sqrt`], not per particle).
pub fn sample_transition<T, D, Tr, R>(
    transition: &Tr,
    q_sqrt: &OMatrix<T, D, D>,
    x: &OVector<T, D>,
    rng: &mut R,
) -> Result<OVector<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    Tr: Transition<T, D> + ?Sized,
    R: Rng + ?Sized,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let n = transition.state_dim();
    check_dim("state", n, x.nrows())?;
    check_dim("sqrt(Q)", n, q_sqrt.nrows())?;
    check_finite(x, "state")?;
    let mean = transition.transition(x)?;
    check_dim("f(x)", n, mean.nrows())?;
    let out = draw(&mean, q_sqrt, (0..n).map(|_| standard_normal(rng)));
    check_finite(&out, "sampled state")?;
    Ok(out)
}

/// `ln p(z | x) = ln N(residual(z, h(x)); 0, R)` (through [`ZeroMeanGaussian`]; a particle
/// filter builds that once for `R` and calls [`ZeroMeanGaussian::log_density`] per particle).
pub fn observation_log_likelihood<T, D, M, Ob>(
    observation: &Ob,
    x: &OVector<T, D>,
    z: &OVector<T, M>,
) -> Result<T>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    Ob: Observation<T, D, M> + ?Sized,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    let m = observation.observation_dim();
    check_dim("observation", m, z.nrows())?;
    check_finite(z, "observation")?;
    check_finite(x, "state")?;
    let zp = observation.observe(x)?;
    check_dim("h(x)", m, zp.nrows())?;
    let y = observation.observation_residual(z, &zp);
    let density = ZeroMeanGaussian::new(observation.observation_noise(), "R")?;
    Ok(nalgebra::convert(density.log_density(&y)))
}
