//! What a bootstrap particle filter needs from the same model traits: draw from the
//! transition density `p(x' | x) = N(f(x), Q)` and evaluate the observation density
//! `ln p(z | x) = ln N(residual(z, h(x)); 0, R)`.

use crate::error::Result;
use crate::filter::gaussian_log_likelihood;
use crate::linalg::{Chol, check_dim, check_finite, cholesky, ldl};
use crate::model::{Observation, Transition};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use rand::Rng;
use rand::RngExt;
use rand_distr::StandardNormal;

/// A square root `L` of a covariance (`L L^T = C`) for sampling: the Cholesky factor, or for a
/// positive semi-definite but singular `C` (the discrete white-noise `Q`), the factor of
/// `C + 64 n eps max|C| I`; for `C = 0` the zero matrix.
pub fn covariance_sqrt<T: RealField + Copy, D: Dim>(
    c: &OMatrix<T, D, D>,
    what: &'static str,
) -> Result<OMatrix<T, D, D>>
where
    DefaultAllocator: Allocator<D, D> + Allocator<D>,
{
    crate::linalg::check_psd(c, what)?;
    if let Some(ch) = Chol::new(c.clone()) {
        return Ok(ch.unpack());
    }
    let n = c.nrows();
    let scale = c.amax();
    if scale == T::zero() {
        return Ok(c.clone());
    }
    let jitter = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0 * n as f64) * scale;
    let mut shifted = c.clone();
    for i in 0..n {
        shifted[(i, i)] += jitter;
    }
    Ok(cholesky(shifted, what)?.unpack())
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
    let e = OVector::<T, D>::from_fn_generic(x.shape_generic().0, nalgebra::Const::<1>, |_, _| {
        nalgebra::convert::<f64, T>(rng.sample(StandardNormal))
    });
    let out = mean + q_sqrt * e;
    check_finite(&out, "sampled state")?;
    Ok(out)
}

/// `ln p(z | x) = ln N(residual(z, h(x)); 0, R)`.
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
    let factors = ldl(observation.observation_noise().clone(), "R")?;
    Ok(gaussian_log_likelihood(&factors, &y))
}
