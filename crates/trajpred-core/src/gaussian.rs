//! [`Gaussian`]: a mean and covariance, generic over nalgebra dimensions (static or dynamic).

use crate::error::{Error, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};

/// A Gaussian state estimate N(mean, covariance), the currency of the Kalman family.
///
/// Generic over the scalar `T` (f64 tested, f32 compiling) and the dimension `D`: a static
/// `nalgebra::Const<N>` (stack storage, no heap) or `nalgebra::Dyn` (size chosen at run time).
///
/// The fields are public so that filters can update them in place without copies;
/// [`Gaussian::new`] and [`Gaussian::validate`] check the invariants (matching square shapes,
/// finite values, a symmetric covariance).
///
/// ```
/// use nalgebra::{Matrix2, Vector2};
/// use trajpred_core::Gaussian;
/// let g = Gaussian::new(Vector2::new(1.0f64, 2.0), Matrix2::new(4.0, 0.0, 0.0, 1.0))?;
/// // squared Mahalanobis distance of (3, 2): (2^2)/4 = 1
/// assert!((g.mahalanobis_squared(&Vector2::new(3.0, 2.0))? - 1.0).abs() < 1e-12);
/// # Ok::<(), trajpred_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The mean vector.
    pub mean: OVector<T, D>,
    /// The covariance matrix (symmetric positive semi-definite).
    pub covariance: OMatrix<T, D, D>,
}

impl<T: RealField + Copy, D: Dim> Gaussian<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// A Gaussian from its mean and covariance, validated (see [`Gaussian::validate`]).
    pub fn new(mean: OVector<T, D>, covariance: OMatrix<T, D, D>) -> Result<Self> {
        let g = Gaussian { mean, covariance };
        g.validate()?;
        Ok(g)
    }

    /// Number of dimensions.
    pub fn dim(&self) -> usize {
        self.mean.nrows()
    }

    /// Checks that the covariance is square and matches the mean, that every value is finite
    /// and that the covariance is symmetric to a relative tolerance of `1e-9` (f64) /
    /// `1e-4`-ish for f32 (`sqrt(epsilon)` times the largest magnitude).
    pub fn validate(&self) -> Result<()> {
        let n = self.mean.nrows();
        if self.covariance.nrows() != n || self.covariance.ncols() != n {
            return Err(Error::DimensionMismatch {
                what: "covariance vs mean",
                expected: n,
                got: if self.covariance.nrows() != n {
                    self.covariance.nrows()
                } else {
                    self.covariance.ncols()
                },
            });
        }
        if let Some(index) = self.mean.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "mean",
                index,
            });
        }
        if let Some(index) = self.covariance.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "covariance",
                index,
            });
        }
        let scale = self.covariance.amax().max(T::one());
        let tol = T::default_epsilon().sqrt() * scale;
        for i in 0..n {
            if self.covariance[(i, i)] < T::zero() {
                return Err(Error::NotPositiveDefinite { what: "covariance" });
            }
            for j in 0..i {
                if (self.covariance[(i, j)] - self.covariance[(j, i)]).abs() > tol {
                    return Err(Error::NotPositiveDefinite { what: "covariance" });
                }
            }
        }
        Ok(())
    }

    /// Squared Mahalanobis distance `(x - mean)^T covariance^-1 (x - mean)`, solved through
    /// a Cholesky factorisation (no inverse). Errors if the covariance is not positive
    /// definite or `x` has the wrong length.
    pub fn mahalanobis_squared(&self, x: &OVector<T, D>) -> Result<T> {
        if x.nrows() != self.dim() {
            return Err(Error::DimensionMismatch {
                what: "point vs Gaussian",
                expected: self.dim(),
                got: x.nrows(),
            });
        }
        let chol = self
            .covariance
            .clone()
            .cholesky()
            .ok_or(Error::NotPositiveDefinite { what: "covariance" })?;
        let d = x - &self.mean;
        let mut l_inv_d = d;
        chol.l_dirty()
            .solve_lower_triangular_mut(&mut l_inv_d)
            .then_some(())
            .ok_or(Error::NotPositiveDefinite { what: "covariance" })?;
        Ok(l_inv_d.norm_squared())
    }

    /// Log of the density at `x`: `-(n ln 2pi + ln det P + d^T P^-1 d) / 2`.
    pub fn log_density(&self, x: &OVector<T, D>) -> Result<T> {
        let m2 = self.mahalanobis_squared(x)?;
        let chol = self
            .covariance
            .clone()
            .cholesky()
            .ok_or(Error::NotPositiveDefinite { what: "covariance" })?;
        let two = T::one() + T::one();
        let log_det = chol
            .l_dirty()
            .diagonal()
            .iter()
            .fold(T::zero(), |acc, &l| acc + l.ln())
            * two;
        let n = T::from_usize(self.dim()).unwrap_or_else(T::zero);
        Ok(-(n * T::two_pi().ln() + log_det + m2) / two)
    }
}
