//! The augmented unscented Kalman filter of the MKPF paper (`docs/papers.md` C.1, eq. 12-19): the
//! sigma points are drawn once per step in the augmented space `[x; w; v]` with covariance
//! `blockdiag(P, Q, R)`, propagated through `f(x, w)` and then `h(f(x, w), v)`, so noise that
//! enters the models non-additively is handled exactly as the paper does.

use crate::alloc::FilterAllocator;
use crate::driver::scan;
use crate::error::Result;
use crate::filter::{InputChecks, Step, Update, validate_state};
use crate::linalg::{check_dim, check_finite, ldl, symmetrise};
use crate::model::{LinearObservation, LinearTransition, Observation, Transition};
use crate::motion::{CoordinatedTurn, RangeBearing};
use crate::ukf::{AugmentedNoise, SigmaPointFilter};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DMatrix, DefaultAllocator, Dim, OMatrix, OVector, RealField, U2, U5};
use trajpred_core::Gaussian;

/// A transition with an explicit process-noise input `x' = f(x, w)`, `w ~ N(0, Q)` of the
/// state's dimension. The default is additive noise `f(x) + w`.
pub trait NoisyTransition<T: RealField + Copy, D: Dim>: Transition<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `f(x, w)`.
    fn transition_with_noise(&self, x: &OVector<T, D>, w: &OVector<T, D>) -> Result<OVector<T, D>> {
        Ok(self.transition(x)? + w)
    }
}

/// An observation with an explicit measurement-noise input `z = h(x, v)`, `v ~ N(0, R)`.
/// The default is additive noise `h(x) + v`.
pub trait NoisyObservation<T: RealField + Copy, D: Dim, M: Dim>: Observation<T, D, M>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    /// `h(x, v)`.
    fn observe_with_noise(&self, x: &OVector<T, D>, v: &OVector<T, M>) -> Result<OVector<T, M>> {
        Ok(self.observe(x)? + v)
    }
}

impl<T: RealField + Copy, D: Dim, X: NoisyTransition<T, D> + ?Sized> NoisyTransition<T, D> for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn transition_with_noise(&self, x: &OVector<T, D>, w: &OVector<T, D>) -> Result<OVector<T, D>> {
        (**self).transition_with_noise(x, w)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, X: NoisyObservation<T, D, M> + ?Sized>
    NoisyObservation<T, D, M> for &X
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    fn observe_with_noise(&self, x: &OVector<T, D>, v: &OVector<T, M>) -> Result<OVector<T, M>> {
        (**self).observe_with_noise(x, v)
    }
}

impl<T: RealField + Copy, D: Dim> NoisyTransition<T, D> for LinearTransition<T, D> where
    DefaultAllocator: Allocator<D> + Allocator<D, D>
{
}
impl<T: RealField + Copy> NoisyTransition<T, U5> for CoordinatedTurn<T> {}
impl<T: RealField + Copy, D: Dim, M: Dim> NoisyObservation<T, D, M> for LinearObservation<T, D, M> where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>
{
}
impl<T: RealField + Copy, D: Dim> NoisyObservation<T, D, U2> for RangeBearing<T> where
    DefaultAllocator: Allocator<D> + Allocator<D, D>
{
}

/// The augmented UKF (`docs/papers.md` C.1 eq. 12-19). One [`AugmentedUkf::step`] draws `2L + 1`
/// sigma points of `N([x; 0; 0], blockdiag(P, Q, R))`, `L = 2n + m`, with Merwe's weights for
/// dimension `L`; the prior is the weighted mean and spread of `Y_i = f(x_i, w_i)`; the
/// update uses `Z_i = h(Y_i, v_i)` (no redraw): `z_hat`, `S`, `Pxz` from the same points,
/// `K = Pxz S^-1`, `x = y_bar + K (z - z_hat)`, `P = P_bar - K S K^T`. No `Q` or `R` is added:
/// the noise is inside the points. Works on heap storage for the augmented matrices.
pub type AugmentedUkf<T, Tr, Ob> = SigmaPointFilter<T, Tr, Ob, AugmentedNoise>;

/// Moments of the propagated augmented sigma points.
struct AugmentedMoments<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M>,
{
    prior: Gaussian<T, D>,
    z_hat: OVector<T, M>,
    s: OMatrix<T, M, M>,
    cross: OMatrix<T, D, M>,
}

impl<T: RealField + Copy, Tr, Ob> AugmentedUkf<T, Tr, Ob> {
    fn moments<D: Dim, M: Dim>(&self, state: &Gaussian<T, D>) -> Result<AugmentedMoments<T, D, M>>
    where
        Tr: NoisyTransition<T, D>,
        Ob: NoisyObservation<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let (tr, ob) = (&self.transition, &self.observation);
        let n = tr.state_dim();
        let m = ob.observation_dim();
        validate_state(state, n, InputChecks::Full)?;
        let l = 2 * n + m;
        let mut pa = DMatrix::<T>::zeros(l, l);
        let q = tr.process_noise();
        let r = ob.observation_noise();
        for j in 0..n {
            for i in 0..n {
                pa[(i, j)] = state.covariance[(i, j)];
                pa[(n + i, n + j)] = q[(i, j)];
            }
        }
        for j in 0..m {
            for i in 0..m {
                pa[(2 * n + i, 2 * n + j)] = r[(i, j)];
            }
        }
        let c = self.weights.lambda + nalgebra::convert::<f64, T>(l as f64);
        // the augmented covariance: Q may be singular, so a semi-definite square root
        let la = crate::sampling::covariance_sqrt(&(pa * c), "augmented covariance")?;
        let d = state.mean.shape_generic().0;
        let md = M::from_usize(m);
        let split = |sign: T, j: Option<usize>| -> (OVector<T, D>, OVector<T, D>, OVector<T, M>) {
            let off = |i: usize| j.map_or(T::zero(), |j| sign * la[(i, j)]);
            (
                OVector::<T, D>::from_fn_generic(d, Const::<1>, |i, _| state.mean[i] + off(i)),
                OVector::<T, D>::from_fn_generic(d, Const::<1>, |i, _| off(n + i)),
                OVector::<T, M>::from_fn_generic(md, Const::<1>, |i, _| off(2 * n + i)),
            )
        };
        let mut ys: Vec<OVector<T, D>> = Vec::with_capacity(2 * l + 1);
        let mut zs: Vec<OVector<T, M>> = Vec::with_capacity(2 * l + 1);
        let mut push = |x: OVector<T, D>, w: OVector<T, D>, v: OVector<T, M>| -> Result<()> {
            let y = tr.transition_with_noise(&x, &w)?;
            check_dim("f(x, w)", n, y.nrows())?;
            let z = ob.observe_with_noise(&y, &v)?;
            check_dim("h(x, v)", m, z.nrows())?;
            ys.push(y);
            zs.push(z);
            Ok(())
        };
        let (x0, w0, v0) = split(T::one(), None);
        push(x0, w0, v0)?;
        for j in 0..l {
            let (x, w, v) = split(T::one(), Some(j));
            push(x, w, v)?;
            let (x, w, v) = split(-T::one(), Some(j));
            push(x, w, v)?;
        }
        let w = &self.weights;
        let mut ysum = OVector::<T, D>::zeros_generic(d, Const::<1>);
        let mut zsum = OVector::<T, M>::zeros_generic(md, Const::<1>);
        for i in 1..ys.len() {
            ysum += tr.state_residual(&ys[i], &ys[0]);
            zsum += ob.observation_residual(&zs[i], &zs[0]);
        }
        let y_bar = &ys[0] + ysum * w.other;
        let z_hat = ob.normalize_observation(&zs[0] + zsum * w.other);
        let mut p = OMatrix::<T, D, D>::zeros_generic(d, d);
        let mut s = OMatrix::<T, M, M>::zeros_generic(md, md);
        let mut cross = OMatrix::<T, D, M>::zeros_generic(d, md);
        for i in 0..ys.len() {
            let wc = if i == 0 { w.covariance0 } else { w.other };
            let ry = tr.state_residual(&ys[i], &y_bar);
            let rz = ob.observation_residual(&zs[i], &z_hat);
            p.ger(wc, &ry, &ry, T::one());
            s.ger(wc, &rz, &rz, T::one());
            cross.ger(wc, &ry, &rz, T::one());
        }
        symmetrise(&mut p);
        symmetrise(&mut s);
        check_finite(&y_bar, "predicted mean")?;
        check_finite(&p, "predicted covariance")?;
        Ok(AugmentedMoments {
            prior: Gaussian {
                mean: y_bar,
                covariance: p,
            },
            z_hat,
            s,
            cross,
        })
    }

    /// The prior `N(y_bar, P_bar)` of one augmented step (the same as [`AugmentedUkf::step`]'s
    /// prior).
    pub fn predict<D: Dim, M: Dim>(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>>
    where
        Tr: NoisyTransition<T, D>,
        Ob: NoisyObservation<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        Ok(self.moments::<D, M>(state)?.prior)
    }

    /// One augmented step: prior from the propagated points, then (when `z` is observed) the
    /// update from the same points.
    pub fn step<D: Dim, M: Dim>(
        &self,
        state: &Gaussian<T, D>,
        z: Option<&OVector<T, M>>,
    ) -> Result<Step<T, D, M>>
    where
        Tr: NoisyTransition<T, D>,
        Ob: NoisyObservation<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let mo = self.moments::<D, M>(state)?;
        let Some(z) = z else {
            return Ok(Step {
                prior: mo.prior,
                update: None,
            });
        };
        let ob = &self.observation;
        check_dim("observation", ob.observation_dim(), z.nrows())?;
        check_finite(z, "observation")?;
        let factors = ldl(mo.s.clone(), "S")?;
        let mut kt = mo.cross.transpose();
        factors.solve_mut(&mut kt);
        let gain = kt.transpose();
        let y = ob.observation_residual(z, &mo.z_hat);
        let mean = &mo.prior.mean + &gain * &y;
        let mut cov = &mo.prior.covariance - &gain * &mo.s * gain.transpose();
        symmetrise(&mut cov);
        check_finite(&mean, "posterior mean")?;
        check_finite(&cov, "posterior covariance")?;
        Ok(Step {
            prior: mo.prior,
            update: Some(Update::new(
                Gaussian {
                    mean,
                    covariance: cov,
                },
                y,
                &factors,
                mo.s,
                gain,
            )),
        })
    }

    /// [`AugmentedUkf::step`] over a sequence (missing observations are `None`).
    pub fn filter<D: Dim, M: Dim>(
        &self,
        initial: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<Step<T, D, M>>>
    where
        Tr: NoisyTransition<T, D>,
        Ob: NoisyObservation<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        scan(observations, |prev: Option<&Step<T, D, M>>, z| {
            self.step(prev.map_or(initial, Step::posterior), z.as_ref())
        })
    }
}
