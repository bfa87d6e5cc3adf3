//! The unscented Kalman filter [`Ukf`] with Merwe's scaled sigma points
//! ([`MerweSigmaPoints`]) and additive noise, and the unscented RTS smoother.

use crate::alloc::FilterAllocator;
use crate::error::{KalmanError, Result};
use crate::filter::{Filter, InputChecks, PredictionWithCross, Smoother, Update, validate_state};
use crate::linalg::{
    check_dim, check_finite, cholesky, ldl, mul, mul_tr_sym_plus, mul_vec, symmetrise, to_f64,
};
use crate::model::{Observation, SigmaImages, Transition, validate_models};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use std::marker::PhantomData;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

/// Merwe's scaled sigma points (`docs/papers.md` C.1 eq. 10-11): for a state of dimension `n`,
/// `lambda = alpha^2 (n + kappa) - n`, the `2n + 1` points `x`, `x + sqrt((n+lambda) P)_i`,
/// `x - sqrt((n+lambda) P)_i` (columns of the lower Cholesky factor; filterpy's order),
/// with weights `W0m = lambda / (n + lambda)`, `W0c = W0m + 1 - alpha^2 + beta`,
/// `Wi = 1 / (2 (n + lambda))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MerweSigmaPoints<T> {
    /// Spread of the points around the mean (typically `1e-3 <= alpha <= 1`).
    pub alpha: T,
    /// Prior knowledge of the distribution (2 is optimal for a Gaussian).
    pub beta: T,
    /// Secondary scaling (typically 0 or `3 - n`).
    pub kappa: T,
}

impl<T: RealField + Copy> MerweSigmaPoints<T> {
    /// The parameters `alpha`, `beta`, `kappa` (checked by [`MerweSigmaPoints::weights`]).
    pub fn new(alpha: T, beta: T, kappa: T) -> Self {
        MerweSigmaPoints { alpha, beta, kappa }
    }

    /// The weights for a state of dimension `n`. Errors with
    /// [`KalmanError::DegenerateSigmaPoints`] when a parameter is not finite, `alpha <= 0`
    /// or `n + lambda = alpha^2 (n + kappa) <= 0` (the weights `1 / (2 (n + lambda))` would
    /// be infinite or negative), and [`trajpred_core::Error::InvalidParameter`] for `n = 0`.
    pub fn weights(&self, n: usize) -> Result<SigmaWeights<T>> {
        if n == 0 {
            return Err(CoreError::InvalidParameter {
                name: "n",
                reason: format!("the state dimension must be at least 1, got {n}"),
            }
            .into());
        }
        let nt = nalgebra::convert::<f64, T>(n as f64);
        let lambda = self.alpha * self.alpha * (nt + self.kappa) - nt;
        let c = nt + lambda;
        let finite = self.alpha.is_finite() && self.beta.is_finite() && self.kappa.is_finite();
        if !finite || self.alpha <= T::zero() || c <= T::zero() || !c.is_finite() {
            return Err(KalmanError::DegenerateSigmaPoints {
                n_plus_lambda: to_f64(c),
                alpha: to_f64(self.alpha),
                kappa: to_f64(self.kappa),
                n,
            });
        }
        let mean0 = lambda / c;
        let other = T::one() / (c + c);
        if !mean0.is_finite() || !other.is_finite() {
            return Err(KalmanError::DegenerateSigmaPoints {
                n_plus_lambda: to_f64(c),
                alpha: to_f64(self.alpha),
                kappa: to_f64(self.kappa),
                n,
            });
        }
        Ok(SigmaWeights {
            n,
            lambda,
            mean0,
            covariance0: mean0 + T::one() - self.alpha * self.alpha + self.beta,
            other,
        })
    }

    /// The `2n + 1` sigma points of `state` in filterpy's order (`x`, then `x + L_i`, then
    /// `x - L_i`, with `L L^T = (n + lambda) P`). Errors if `P` is not positive definite.
    pub fn sigma_points<D: Dim>(&self, state: &Gaussian<T, D>) -> Result<Vec<OVector<T, D>>>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = state.mean.nrows();
        let w = self.weights(n)?;
        validate_state(state, n, InputChecks::Full)?;
        let l = w.spread(&state.covariance)?;
        let mut out = Vec::with_capacity(2 * n + 1);
        out.push(state.mean.clone());
        for j in 0..n {
            out.push(&state.mean + l.column(j));
        }
        for j in 0..n {
            out.push(&state.mean - l.column(j));
        }
        Ok(out)
    }
}

impl<T: RealField + Copy> Default for MerweSigmaPoints<T> {
    /// `alpha = 1e-3`, `beta = 2`, `kappa = 0`: the typical values of `docs/papers.md` C.1.
    fn default() -> Self {
        MerweSigmaPoints {
            alpha: nalgebra::convert(1e-3),
            beta: nalgebra::convert(2.0),
            kappa: T::zero(),
        }
    }
}

/// The weights of Merwe's sigma points for one state dimension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmaWeights<T> {
    /// The state dimension `n`.
    pub n: usize,
    /// `lambda = alpha^2 (n + kappa) - n`.
    pub lambda: T,
    /// Mean weight of the central point `W0m = lambda / (n + lambda)`.
    pub mean0: T,
    /// Covariance weight of the central point `W0c = W0m + 1 - alpha^2 + beta`.
    pub covariance0: T,
    /// Weight of every other point (mean and covariance) `1 / (2 (n + lambda))`.
    pub other: T,
}

impl<T: RealField + Copy> SigmaWeights<T> {
    /// The `2n + 1` mean weights, in sigma-point order.
    pub fn mean_weights(&self) -> Vec<T> {
        let mut w = vec![self.other; 2 * self.n + 1];
        w[0] = self.mean0;
        w
    }

    /// The `2n + 1` covariance weights, in sigma-point order.
    pub fn covariance_weights(&self) -> Vec<T> {
        let mut w = vec![self.other; 2 * self.n + 1];
        w[0] = self.covariance0;
        w
    }

    /// `L` with `L L^T = (n + lambda) P` (lower Cholesky factor): its columns are the
    /// sigma-point offsets.
    #[inline(always)]
    fn spread<D: Dim>(&self, p: &OMatrix<T, D, D>) -> Result<OMatrix<T, D, D>>
    where
        DefaultAllocator: Allocator<D, D>,
    {
        let c = self.lambda + nalgebra::convert::<f64, T>(self.n as f64);
        Ok(cholesky(p * c, "P")?.unpack())
    }
}

/// The result of an unscented transform of `N(x, P)` through `g`: mean, covariance (without
/// noise) and cross-covariance `Cov(x, g(x))`.
struct Transformed<T: RealField, D: Dim, E: Dim>
where
    DefaultAllocator: Allocator<E> + Allocator<E, E> + Allocator<D, E>,
{
    mean: OVector<T, E>,
    covariance: OMatrix<T, E, E>,
    cross: OMatrix<T, D, E>,
}

/// The unscented transform of `state` through a model's sigma-point `images`, the image
/// dimension checked (`what`, `dim`), the model's `noise` added to the covariance
/// (symmetrised): the common core of the UKF's prediction and update.
#[inline(always)]
fn noisy_transform<T, D, E, I, R>(
    w: &SigmaWeights<T>,
    state: &Gaussian<T, D>,
    images: I,
    residual: R,
    with_cross: bool,
    noise: &OMatrix<T, E, E>,
    (what, dim): (&'static str, usize),
) -> Result<Transformed<T, D, E>>
where
    T: RealField + Copy,
    D: Dim,
    E: Dim,
    I: FnOnce(&OVector<T, D>, &OMatrix<T, D, D>) -> Result<SigmaImages<T, D, E>>,
    R: Fn(&OVector<T, E>, &OVector<T, E>) -> OVector<T, E>,
    DefaultAllocator: Allocator<D>
        + Allocator<D, D>
        + Allocator<E>
        + Allocator<E, E>
        + Allocator<E, D>
        + Allocator<D, E>,
{
    let l = w.spread(&state.covariance)?;
    let images = images(&state.mean, &l)?;
    let mut t = unscented_transform(&l, &images, w, residual, with_cross)?;
    check_dim(what, dim, t.mean.nrows())?;
    t.covariance += noise;
    symmetrise(&mut t.covariance);
    Ok(t)
}

/// The unscented transform with symmetric points, from the images `g(x)`, `g(x +- L_j)`
/// of the sigma points ([`SigmaImages`]): the mean is computed as
/// `g(x) + sum_i Wi residual(g(x_i), g(x))` (equal to `sum_i Wm_i g(x_i)` for a linear
/// residual, and a correct circular mean when `residual` wraps angles), the spread with
/// `residual(g(x_i), mean)`.
#[inline(always)]
fn unscented_transform<T, D, E, R>(
    l: &OMatrix<T, D, D>,
    images: &SigmaImages<T, D, E>,
    w: &SigmaWeights<T>,
    residual: R,
    with_cross: bool,
) -> Result<Transformed<T, D, E>>
where
    T: RealField + Copy,
    D: Dim,
    E: Dim,
    R: Fn(&OVector<T, E>, &OVector<T, E>) -> OVector<T, E>,
    DefaultAllocator: Allocator<D>
        + Allocator<D, D>
        + Allocator<E>
        + Allocator<E, E>
        + Allocator<E, D>
        + Allocator<D, E>,
{
    let SigmaImages {
        center: y0,
        plus,
        minus,
    } = images;
    let n = l.nrows();
    let e = y0.shape_generic().0;
    let d = l.shape_generic().0;
    let ne = e.value();
    check_dim("transformed sigma points", ne, plus.nrows())?;
    check_dim("transformed sigma points", n, plus.ncols())?;
    check_dim("transformed sigma points", ne, minus.nrows())?;
    check_dim("transformed sigma points", n, minus.ncols())?;
    let mut sum = OVector::<T, E>::zeros_generic(e, nalgebra::Const::<1>);
    for j in 0..n {
        sum += residual(&plus.column(j).into_owned(), y0);
        sum += residual(&minus.column(j).into_owned(), y0);
    }
    let mean = y0 + sum * w.other;
    // the weighted spread: lower triangle accumulated column by column, then mirrored
    let mut covariance = OMatrix::<T, E, E>::zeros_generic(e, e);
    let r0 = residual(y0, &mean);
    for b in 0..ne {
        let wb = r0[b] * w.covariance0;
        for a in b..ne {
            covariance[(a, b)] = r0[a] * wb;
        }
    }
    let mut cross = OMatrix::<T, D, E>::zeros_generic(d, e);
    for j in 0..n {
        let rp = residual(&plus.column(j).into_owned(), &mean);
        let rm = residual(&minus.column(j).into_owned(), &mean);
        for b in 0..ne {
            let (pb, mb) = (rp[b] * w.other, rm[b] * w.other);
            for a in b..ne {
                covariance[(a, b)] += rp[a] * pb + rm[a] * mb;
            }
        }
        if with_cross {
            for b in 0..ne {
                let db = (rp[b] - rm[b]) * w.other;
                for i in j..n {
                    cross[(i, b)] += l[(i, j)] * db;
                }
            }
        }
    }
    for b in 0..ne {
        for a in 0..b {
            covariance[(a, b)] = covariance[(b, a)];
        }
    }
    Ok(Transformed {
        mean,
        covariance,
        cross,
    })
}

/// The UKF validates shapes, finiteness and symmetry of its input state; definiteness is
/// checked by the Cholesky factorisation of `(n + lambda) P` that the sigma points need
/// anyway (stricter: `P` must be positive definite), so no second factorisation is spent.
const UKF_CHECKS: InputChecks = InputChecks::Cheap;

/// The unscented Kalman filter with additive noise and Merwe's scaled sigma points.
///
/// Predict: sigma points of `N(x(k-1|k-1), P(k-1|k-1))` through `f`; `x(k|k-1)` their
/// weighted mean, `P(k|k-1)` their weighted spread `+ Q`.
/// Update: sigma points **regenerated from the prior** `N(x(k|k-1), P(k|k-1))` (as filterpy
/// 2.0.0 does after its predict), through `h`; `z_hat` their mean, `S` their spread `+ R`,
/// `Pxz` the cross-covariance, `K = Pxz S^-1` (Cholesky solve), `x + K y`,
/// `P - K S K^T` (symmetrised).
///
/// The weights are computed once, at construction, for the transition's state size; a
/// parameter set with degenerate weights is rejected there.
pub type Ukf<T, Tr, Ob> = SigmaPointFilter<T, Tr, Ob, AdditiveNoise>;

/// An unscented filter: the models, Merwe's sigma-point parameters and their weights for the
/// space `S` the sigma points are drawn in. [`Ukf`] draws them in the state space
/// ([`AdditiveNoise`]), [`AugmentedUkf`](crate::AugmentedUkf) in the space of the state and
/// both noises ([`AugmentedNoise`]); the two differ only in their steps.
#[derive(Debug, Clone)]
pub struct SigmaPointFilter<T, Tr, Ob, S> {
    pub(crate) transition: Tr,
    pub(crate) observation: Ob,
    pub(crate) points: MerweSigmaPoints<T>,
    pub(crate) weights: SigmaWeights<T>,
    space: PhantomData<fn() -> S>,
}

/// The space an unscented filter draws its sigma points in: its dimension for a state of
/// size `n` and an observation of size `m`. Implemented by [`AdditiveNoise`] and
/// [`AugmentedNoise`] only.
pub trait SigmaSpace: sealed::Sealed {
    /// The number of dimensions the sigma points have (the weights are for it).
    fn dim(n: usize, m: usize) -> usize;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::AdditiveNoise {}
    impl Sealed for super::AugmentedNoise {}
}

/// The state space, `n` dimensions: the noise covariances are added to the moments
/// ([`Ukf`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AdditiveNoise;

/// The state and both noises, `2n + m` dimensions: the noise is inside the points
/// ([`AugmentedUkf`](crate::AugmentedUkf)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AugmentedNoise;

impl SigmaSpace for AdditiveNoise {
    fn dim(n: usize, _m: usize) -> usize {
        n
    }
}

impl SigmaSpace for AugmentedNoise {
    fn dim(n: usize, m: usize) -> usize {
        2 * n + m
    }
}

impl<T: RealField + Copy, Tr, Ob, S: SigmaSpace> SigmaPointFilter<T, Tr, Ob, S> {
    /// A filter from a transition (`f`, `Q`), an observation (`h`, `R`) and sigma-point
    /// parameters, the weights computed once for the dimension of `S` (`n` for [`Ukf`],
    /// `2n + m` for [`AugmentedUkf`](crate::AugmentedUkf)). Errors:
    /// [`KalmanError::DegenerateSigmaPoints`], and the model checks of `Q` and `R`.
    pub fn new<D: Dim, M: Dim>(
        transition: Tr,
        observation: Ob,
        points: MerweSigmaPoints<T>,
    ) -> Result<Self>
    where
        Tr: Transition<T, D>,
        Ob: Observation<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        validate_models(&transition, &observation)?;
        let dim = S::dim(transition.state_dim(), observation.observation_dim());
        let weights = points.weights(dim)?;
        Ok(SigmaPointFilter {
            transition,
            observation,
            points,
            weights,
            space: PhantomData,
        })
    }

    /// The sigma-point parameters.
    pub fn points(&self) -> &MerweSigmaPoints<T> {
        &self.points
    }

    /// The sigma-point weights, for the dimension of `S`.
    pub fn weights(&self) -> &SigmaWeights<T> {
        &self.weights
    }

    /// The transition model.
    pub fn transition(&self) -> &Tr {
        &self.transition
    }

    /// The observation model.
    pub fn observation(&self) -> &Ob {
        &self.observation
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Filter<T, D, M> for Ukf<T, Tr, Ob>
where
    Tr: Transition<T, D>,
    Ob: Observation<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    #[inline(always)]
    fn predict(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        self.predict_transform(state, false).map(|(g, _)| g)
    }

    fn update(&self, prior: &Gaussian<T, D>, z: &OVector<T, M>) -> Result<Update<T, D, M>> {
        validate_state(prior, self.transition.state_dim(), UKF_CHECKS)?;
        self.update_predicted(prior, z)
    }

    #[inline(always)]
    fn update_predicted(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Update<T, D, M>> {
        check_dim("prior", self.transition.state_dim(), prior.mean.nrows())?;
        let m = self.observation.observation_dim();
        check_dim("observation", m, z.nrows())?;
        check_finite(z, "observation")?;
        let ob = &self.observation;
        let images = |x: &OVector<T, D>, l: &OMatrix<T, D, D>| ob.observe_sigma_points(x, l);
        let residual = |a: &OVector<T, M>, b: &OVector<T, M>| ob.observation_residual(a, b);
        let noise = ob.observation_noise();
        let t = noisy_transform(
            &self.weights,
            prior,
            images,
            residual,
            true,
            noise,
            ("h(x)", m),
        )?;
        let z_hat = ob.normalize_observation(t.mean);
        let s = t.covariance;
        let factors = ldl(s.clone(), "S")?;
        let mut kt = t.cross.transpose();
        factors.solve_mut(&mut kt);
        let gain = kt.transpose();
        let y = ob.observation_residual(z, &z_hat);
        let mut mean = mul_vec(&gain, &y);
        mean += &prior.mean;
        // P - K S K^T, lower triangle mirrored (symmetric)
        let neg_ks = -mul(&gain, &s);
        let cov = mul_tr_sym_plus(&neg_ks, &gain, &prior.covariance);
        check_finite(&mean, "posterior mean")?;
        check_finite(&cov, "posterior covariance")?;
        Ok(Update::new(
            Gaussian {
                mean,
                covariance: cov,
            },
            y,
            &factors,
            s,
            gain,
        ))
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Smoother<T, D, M> for Ukf<T, Tr, Ob>
where
    Tr: Transition<T, D>,
    Ob: Observation<T, D, M>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    fn prediction_with_cross_covariance(
        &self,
        filtered: &Gaussian<T, D>,
    ) -> Result<PredictionWithCross<T, D>> {
        self.predict_transform(filtered, true)
    }
}

impl<T: RealField + Copy, Tr, Ob> Ukf<T, Tr, Ob> {
    /// The prediction, and when `with_cross` the cross-covariance `Cov(x(k), x(k+1))` (the
    /// smoother's; zero otherwise, not computed).
    #[inline(always)]
    fn predict_transform<D>(
        &self,
        filtered: &Gaussian<T, D>,
        with_cross: bool,
    ) -> Result<PredictionWithCross<T, D>>
    where
        D: Dim,
        Tr: Transition<T, D>,
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = self.transition.state_dim();
        validate_state(filtered, n, UKF_CHECKS)?;
        let tr = &self.transition;
        let t = noisy_transform(
            &self.weights,
            filtered,
            |x, l| tr.transition_sigma_points(x, l),
            |a, b| tr.state_residual(a, b),
            with_cross,
            tr.process_noise(),
            ("f(x)", n),
        )?;
        let p = t.covariance;
        check_finite(&t.mean, "predicted mean")?;
        check_finite(&p, "predicted covariance")?;
        Ok((
            Gaussian {
                mean: t.mean,
                covariance: p,
            },
            t.cross,
        ))
    }
}
