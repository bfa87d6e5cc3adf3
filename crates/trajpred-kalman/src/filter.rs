//! The filtering loop shared by every filter: [`Filter`] (predict, update, step, batch,
//! k-step forecast, control input), the result types [`Update`] and [`Step`], the covariance
//! update forms [`CovarianceUpdate`], and the RTS smoother [`Smoother`].

use crate::alloc::FilterAllocator;
use crate::driver::scan;
use crate::error::Result;
use crate::linalg::{
    Ldl, all_finite, check_dim, check_finite, check_square, check_state, congruence_ldl,
    congruence_simd, congruence_simd_applies, is_static, joseph, ldl, mean_finite_and_symmetric,
    mul, mul_tr_sym_plus, mul_vec, positive_definite_minors, symmetrise,
};
use crate::model::{LinearTransitionModel, Observation};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, Dim, OMatrix, OVector, RealField};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

/// How much of the input state `predict` and `update` verify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputChecks {
    /// Shapes, finite values, symmetry, and `P` positive semi-definite (a Cholesky
    /// factorisation of `P + 64 n eps max|P| I`). The default.
    #[default]
    Full,
    /// Shapes, finite values, symmetry and a non-negative diagonal of `P`, without the
    /// factorisation: for hot loops that feed the filter its own outputs (a particle filter,
    /// a long batch). An indefinite `P` is then not detected at the input.
    Cheap,
}

/// How the posterior covariance is computed from the prior `P`, the gain `K` and `H`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CovarianceUpdate {
    /// Joseph form `(I - K H) P (I - K H)^T + K R K^T`, then symmetrised: stays symmetric
    /// positive semi-definite under rounding and for any gain. The default.
    #[default]
    Joseph,
    /// The plain form `(I - K H) P`, as printed in most papers; not symmetrised.
    Plain,
    /// The plain form followed by symmetrisation `(P + P^T) / 2`.
    Symmetrised,
}

/// Everything an update step computed: the posterior and, for the caller's diagnostics
/// (NIS, gating, likelihood-based model selection), the innovation `y = z - h(x)`, its
/// covariance `S`, the gain `K` and the log-likelihood `ln N(y; 0, S)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Update<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M>,
{
    /// The posterior `N(x(k|k), P(k|k))`.
    pub posterior: Gaussian<T, D>,
    /// The innovation `y = z - h(x(k|k-1))` (through the observation's residual function).
    pub innovation: OVector<T, M>,
    /// The innovation covariance `S`.
    pub innovation_covariance: OMatrix<T, M, M>,
    /// The gain `K`.
    pub gain: OMatrix<T, D, M>,
    /// The normalised innovation squared `y^T S^-1 y` (the squared Mahalanobis distance of
    /// the innovation, chi-square with `m` degrees of freedom under the model: for gating
    /// and consistency tests).
    pub nis: T,
    /// `det S` from the factorisation of the update (for the log-likelihood, formed on
    /// demand; 0 or infinite when it under- or overflows).
    det_innovation_covariance: T,
}

impl<T: RealField + Copy, D: Dim, M: Dim> Update<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M>,
{
    /// An update from its parts, `nis` and `det S` taken from the factorisation of `S`.
    #[inline(always)]
    pub(crate) fn new(
        posterior: Gaussian<T, D>,
        innovation: OVector<T, M>,
        factor: &Ldl<T, M>,
        innovation_covariance: OMatrix<T, M, M>,
        gain: OMatrix<T, D, M>,
    ) -> Self {
        let nis = factor.quadratic_form(&innovation);
        Update {
            posterior,
            innovation,
            innovation_covariance,
            gain,
            nis,
            det_innovation_covariance: factor.det(),
        }
    }

    /// `ln N(y; 0, S) = -(m ln 2 pi + ln det S + y^T S^-1 y) / 2`, formed on demand from
    /// [`Update::nis`] and `det S` (one logarithm; when `det S` under- or overflowed, `S`
    /// is factorised again and the logarithms of its pivots are summed).
    pub fn log_likelihood(&self) -> T {
        let det = self.det_innovation_covariance;
        let big = T::max_value().unwrap_or(T::one() / T::zero());
        let log_det = if det >= T::one() / big && det <= big {
            det.ln()
        } else {
            Ldl::factor(self.innovation_covariance.clone(), T::zero())
                .0
                .log_det()
        };
        log_likelihood_from(self.innovation.nrows(), log_det, self.nis)
    }
}

/// `-(m ln 2 pi + ln det S + q) / 2`.
fn log_likelihood_from<T: RealField + Copy>(m: usize, log_det: T, q: T) -> T {
    let m = nalgebra::convert::<f64, T>(m as f64);
    let half = nalgebra::convert::<f64, T>(0.5);
    // ln(2 pi)
    let ln_two_pi = nalgebra::convert::<f64, T>(1.837_877_066_409_345_5);
    -half * (m * ln_two_pi + log_det + q)
}

/// One filter step: the prior `N(x(k|k-1), P(k|k-1))` and, when there was an observation,
/// its update.
#[derive(Debug, Clone, PartialEq)]
pub struct Step<T: RealField, D: Dim, M: Dim>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M>,
{
    /// The predicted state.
    pub prior: Gaussian<T, D>,
    /// The update, `None` for a missing observation.
    pub update: Option<Update<T, D, M>>,
}

impl<T: RealField, D: Dim, M: Dim> Step<T, D, M>
where
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<D, M>,
{
    /// The filtered state: the update's posterior, or the prior when the observation was
    /// missing.
    pub fn posterior(&self) -> &Gaussian<T, D> {
        match &self.update {
            Some(u) => &u.posterior,
            None => &self.prior,
        }
    }

    /// The filtered state by value ([`Step::posterior`] without a copy).
    pub fn into_posterior(self) -> Gaussian<T, D> {
        match self.update {
            Some(u) => u.posterior,
            None => self.prior,
        }
    }

    /// The log-likelihood of this step's observation (0 when it was missing).
    pub fn log_likelihood(&self) -> T
    where
        T: Copy,
    {
        self.update
            .as_ref()
            .map_or_else(T::zero, |u| u.log_likelihood())
    }
}

/// The interface of every Gaussian filter of the crate: the two steps as pure functions of
/// an explicit Gaussian state (no hidden state, so one filter value can serve many particles
/// or tracks), and, built on them once for all filters, the step with an optional
/// observation, the batch over a sequence and the k-step forecast.
///
/// Inputs are validated (shapes, finite values, `P` symmetric positive semi-definite);
/// failures are typed [`KalmanError`](crate::KalmanError)s.
pub trait Filter<T: RealField + Copy, D: Dim, M: Dim>
where
    DefaultAllocator: FilterAllocator<D, M>,
{
    /// The prediction `N(x(k|k-1), P(k|k-1))` from the previous estimate.
    fn predict(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>>;

    /// The update of `prior` by the observation `z`.
    fn update(&self, prior: &Gaussian<T, D>, z: &OVector<T, M>) -> Result<Update<T, D, M>>;

    /// The update of a prior that this filter's own [`Filter::predict`] just returned: the
    /// same as [`Filter::update`] but without re-validating `prior` (`predict` validated its
    /// input, and its output is symmetric positive semi-definite by construction).
    /// [`Filter::step`] uses it. With any other prior, call [`Filter::update`].
    ///
    /// A speed path of the filter driver, hidden from the documented API: users call
    /// [`Filter::update`] or [`Filter::step`].
    #[doc(hidden)]
    fn update_predicted(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Update<T, D, M>> {
        self.update(prior, z)
    }

    /// The prediction from a state that this filter produced itself (the posterior or the
    /// prediction of an earlier step): the same result as [`Filter::predict`], but a filter
    /// may skip the factorisation that checks `P` positive semi-definite, since its own
    /// outputs are by construction (shapes, finite values and symmetry are still checked).
    /// [`Filter::filter`] and [`Filter::forecast`] use it after their first step, so a batch
    /// validates the user's initial state fully once.
    ///
    /// A speed path of the filter driver, hidden from the documented API: users call
    /// [`Filter::predict`].
    #[doc(hidden)]
    fn predict_own_output(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        self.predict(state)
    }

    /// The prediction with a known control effect `B u` (already mapped to the state space)
    /// added to the predicted mean: `x(k|k-1) = f(x) + B u`. The covariance is unchanged,
    /// since the control input carries no noise.
    fn predict_with_control(
        &self,
        state: &Gaussian<T, D>,
        control_effect: &OVector<T, D>,
    ) -> Result<Gaussian<T, D>> {
        check_dim("control effect", state.mean.nrows(), control_effect.nrows())?;
        check_finite(control_effect, "control effect")?;
        let mut prior = self.predict(state)?;
        prior.mean += control_effect;
        Ok(prior)
    }

    /// [`Filter::predict`] (or [`Filter::predict_own_output`] when `own_output`), then
    /// [`Filter::update_predicted`] of that prediction by `z`: the work of an observed step
    /// of [`Filter::step`] and [`Filter::filter`]. A filter may fuse the two calls (the KF
    /// checks the prediction's finiteness through its update's); the results and the errors
    /// are those of the two calls.
    #[inline(always)]
    fn predict_update(
        &self,
        state: &Gaussian<T, D>,
        z: &OVector<T, M>,
        own_output: bool,
    ) -> Result<PredictionAndUpdate<T, D, M>> {
        let prior = if own_output {
            self.predict_own_output(state)?
        } else {
            self.predict(state)?
        };
        let update = self.update_predicted(&prior, z)?;
        Ok((prior, update))
    }

    /// Predict, then update when `z` is `Some` (a missing observation is `None`).
    #[inline(always)]
    fn step(&self, state: &Gaussian<T, D>, z: Option<&OVector<T, M>>) -> Result<Step<T, D, M>> {
        match z {
            Some(z) => {
                let (prior, update) = self.predict_update(state, z, false)?;
                Ok(Step {
                    prior,
                    update: Some(update),
                })
            }
            None => Ok(Step {
                prior: self.predict(state)?,
                update: None,
            }),
        }
    }

    /// Runs [`Filter::step`] over a sequence of observations starting from `initial` (the
    /// estimate before the first observation's time). Returns one [`Step`] per observation.
    fn filter(
        &self,
        initial: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<Step<T, D, M>>> {
        scan(observations, |prev: Option<&Step<T, D, M>>, z| {
            Ok(match (prev, z) {
                (Some(prev), Some(z)) => {
                    let (prior, update) = self.predict_update(prev.posterior(), z, true)?;
                    Step {
                        prior,
                        update: Some(update),
                    }
                }
                (Some(prev), None) => Step {
                    prior: self.predict_own_output(prev.posterior())?,
                    update: None,
                },
                (None, z) => self.step(initial, z.as_ref())?,
            })
        })
    }

    /// The total log-likelihood `sum_k ln N(y_k; 0, S_k)` of a sequence (missing
    /// observations contribute nothing).
    fn log_likelihood(
        &self,
        initial: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<T> {
        Ok(self
            .filter(initial, observations)?
            .iter()
            .fold(T::zero(), |acc, s| acc + s.log_likelihood()))
    }

    /// The forecast `N(x(k+j|k), P(k+j|k))` for `j = 1..=steps`: the prediction applied
    /// `steps` times without observations.
    fn forecast(&self, state: &Gaussian<T, D>, steps: usize) -> Result<Vec<Gaussian<T, D>>> {
        scan(0..steps, |prev: Option<&Gaussian<T, D>>, _| match prev {
            Some(prev) => self.predict_own_output(prev),
            None => self.predict(state),
        })
    }
}

/// A boxed filter is a filter (every method forwarded), so that filters of different types
/// can serve together, as the modes of an [`Imm`](crate::Imm).
impl<T: RealField + Copy, D: Dim, M: Dim, F: Filter<T, D, M> + ?Sized> Filter<T, D, M> for Box<F>
where
    DefaultAllocator: FilterAllocator<D, M>,
{
    fn predict(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        (**self).predict(state)
    }

    fn update(&self, prior: &Gaussian<T, D>, z: &OVector<T, M>) -> Result<Update<T, D, M>> {
        (**self).update(prior, z)
    }

    fn update_predicted(
        &self,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> Result<Update<T, D, M>> {
        (**self).update_predicted(prior, z)
    }

    fn predict_own_output(&self, state: &Gaussian<T, D>) -> Result<Gaussian<T, D>> {
        (**self).predict_own_output(state)
    }

    fn predict_update(
        &self,
        state: &Gaussian<T, D>,
        z: &OVector<T, M>,
        own_output: bool,
    ) -> Result<PredictionAndUpdate<T, D, M>> {
        (**self).predict_update(state, z, own_output)
    }
}

/// A prediction and its update by an observation ([`Filter::predict_update`]).
pub type PredictionAndUpdate<T, D, M> = (Gaussian<T, D>, Update<T, D, M>);

/// A prediction `N(x(k+1|k), P(k+1|k))` with the cross-covariance `Cov(x(k), x(k+1))`.
pub type PredictionWithCross<T, D> = (Gaussian<T, D>, OMatrix<T, D, D>);

/// What [`Smoother::smooth_with_gains`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct RtsSmoothed<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The smoothed states, in time order (the last one is the last filtered state).
    pub states: Vec<Gaussian<T, D>>,
    /// The smoother gains `G(k)`, `k = 0 .. N-2`, in time order.
    pub gains: Vec<OMatrix<T, D, D>>,
}

/// The Rauch-Tung-Striebel smoother, for any filter that can say how one filtered state maps
/// to the next prediction (for the KF `F P` and `F P F^T + Q`; for the UKF through sigma
/// points).
///
/// For `k = N-2 .. 0`: `G = C(k) P(k+1|k)^-1`, `x_s(k) = x(k|k) + G (x_s(k+1) - x(k+1|k))`,
/// `P_s(k) = P(k|k) + G (P_s(k+1) - P(k+1|k)) G^T`, where `C(k)` is the cross-covariance of
/// `x(k)` and `x(k+1)`.
pub trait Smoother<T: RealField + Copy, D: Dim, M: Dim>: Filter<T, D, M>
where
    DefaultAllocator: FilterAllocator<D, M>,
{
    /// The prediction from `filtered` and the cross-covariance `C = Cov(x(k), x(k+1))`.
    fn prediction_with_cross_covariance(
        &self,
        filtered: &Gaussian<T, D>,
    ) -> Result<PredictionWithCross<T, D>>;

    /// Smooths filtered estimates (e.g. the posteriors of [`Filter::filter`]'s steps, in
    /// time order). Errors with [`trajpred_core::Error::Empty`] for no states.
    fn smooth(&self, filtered: &[Gaussian<T, D>]) -> Result<Vec<Gaussian<T, D>>> {
        self.smooth_with_gains(filtered).map(|s| s.states)
    }

    /// [`Smoother::smooth`], also returning the smoother gains `G(k) = C(k) P(k+1|k)^-1`
    /// (`k = 0 .. N-2`), as filterpy's `rts_smoother` returns `K` (filterpy returns `N`
    /// gains, the last one zero; here there are `N - 1`, none for the last state, which
    /// the smoother leaves as filtered). Errors with [`trajpred_core::Error::Empty`] for no states.
    fn smooth_with_gains(&self, filtered: &[Gaussian<T, D>]) -> Result<RtsSmoothed<T, D>> {
        rts_backward(filtered, |_| self)
    }

    /// Filters and smooths a sequence in one call.
    fn filter_smooth(
        &self,
        initial: &Gaussian<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<Gaussian<T, D>>> {
        let steps = self.filter(initial, observations)?;
        let filtered: Vec<Gaussian<T, D>> = steps.iter().map(|s| s.posterior().clone()).collect();
        self.smooth(&filtered)
    }
}

/// The backward pass of the RTS smoother over `filtered` (time order), with the filter
/// `filter_at(k)` of the step from state `k` to `k + 1`: one filter for every step
/// ([`Smoother::smooth_with_gains`]) or one per step
/// ([`smooth_steps`](crate::smoother::smooth_steps)). Errors with
/// [`trajpred_core::Error::Empty`] for no states.
pub(crate) fn rts_backward<'a, T, D, M, S>(
    filtered: &[Gaussian<T, D>],
    filter_at: impl Fn(usize) -> &'a S,
) -> Result<RtsSmoothed<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    S: Smoother<T, D, M> + ?Sized + 'a,
    DefaultAllocator: FilterAllocator<D, M>,
{
    if filtered.is_empty() {
        return Err(CoreError::Empty {
            what: "filtered states",
        }
        .into());
    }
    let mut out: Vec<Gaussian<T, D>> = filtered.to_vec();
    let mut gains = Vec::with_capacity(filtered.len() - 1);
    for k in (0..filtered.len() - 1).rev() {
        let (pred, cross) = filter_at(k).prediction_with_cross_covariance(&filtered[k])?;
        let factors = ldl(pred.covariance.clone(), "P(k+1|k)")?;
        // G^T = P(k+1|k)^-1 C^T, since P(k+1|k) is symmetric
        let mut gt = cross.transpose();
        factors.solve_mut(&mut gt);
        let gain = gt.transpose();
        let next = &out[k + 1];
        let dx = &next.mean - &pred.mean;
        let dp = &next.covariance - &pred.covariance;
        let mean = &filtered[k].mean + &gain * dx;
        let mut cov = &filtered[k].covariance + &gain * dp * gain.transpose();
        symmetrise(&mut cov);
        check_finite(&mean, "smoothed mean")?;
        check_finite(&cov, "smoothed covariance")?;
        out[k] = Gaussian {
            mean,
            covariance: cov,
        };
        gains.push(gain);
    }
    gains.reverse();
    Ok(RtsSmoothed { states: out, gains })
}

/// The prediction of a linearised model: mean given, `P' = F P F^T + Q`, symmetrised.
#[inline(always)]
pub(crate) fn linearized_predict<T, D>(
    mean: OVector<T, D>,
    f: &OMatrix<T, D, D>,
    state: &Gaussian<T, D>,
    q: &OMatrix<T, D, D>,
) -> Result<Gaussian<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let n = state.mean.nrows();
    check_dim("F rows", n, f.nrows())?;
    check_dim("F columns", n, f.ncols())?;
    // F P F^T + Q, symmetric by construction
    let p = mul_tr_sym_plus(&mul(f, &state.covariance), f, q);
    check_finite(&mean, "predicted mean")?;
    check_finite(&p, "predicted covariance")?;
    Ok(Gaussian {
        mean,
        covariance: p,
    })
}

/// A prediction's mean and covariance are finite, or [`trajpred_core::Error::NonFinite`] naming the
/// first that is not (one branch; the element is located only on failure).
#[inline(always)]
pub(crate) fn check_prediction<T, D>(prior: &Gaussian<T, D>) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    if !(all_finite(&prior.mean) & all_finite(&prior.covariance)) {
        check_finite(&prior.mean, "predicted mean")?;
        check_finite(&prior.covariance, "predicted covariance")?;
    }
    Ok(())
}

/// The prediction of the linear KF, `x' = F x`, `P' = F P F^T + Q`, with the input checks
/// `checks`, through the model's [`LinearTransitionModel::propagate_mean`] and
/// [`LinearTransitionModel::propagate_covariance`]. With `factorise` and static sizes the
/// definiteness check of `P` is an `L D L^T` factorisation: for a dense `F` the one from
/// which `F P F^T` is then formed ([`congruence_ldl`]), for a structured `F` a factorisation
/// of its own before the cheap structured product; for a dense `F` of 5 to 8 states in
/// `f64` on a machine with AVX2 or AVX-512 (or 4 states with AVX2), the leading-minors check
/// and then the SIMD products ([`congruence_simd`]); either way a `P` that is only
/// semi-definite (or fails any check) takes the check `checks` of [`validate_state`]. Without
/// `factorise`, that check, then the SIMD products without the minors where they apply. The
/// caller passes the same `factorise` for `predict` and `predict_own_output`, so a batch
/// and the same steps one by one give identical results.
///
/// The result's finiteness is not checked: the caller calls [`check_prediction`] or proves
/// it finite otherwise.
#[inline(always)]
pub(crate) fn linear_predict_unchecked_output<T, D, Tr>(
    tr: &Tr,
    state: &Gaussian<T, D>,
    n: usize,
    factorise: bool,
    checks: InputChecks,
) -> Result<Gaussian<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    Tr: LinearTransitionModel<T, D> + ?Sized,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let f = tr.transition_matrix();
    if factorise && is_static::<D, D>() {
        check_dim("state mean", n, state.mean.nrows())?;
        check_square(&state.covariance, n, "state covariance")?;
        check_dim("F rows", n, f.nrows())?;
        // with the factorisation below, this proves the input finite, symmetric and
        // positive definite
        let fast_ok = mean_finite_and_symmetric(state);
        let p = if tr.has_structured_propagation() {
            (fast_ok && positive_definite_minors(state.covariance.clone()))
                .then(|| tr.propagate_covariance(&state.covariance))
        } else if congruence_simd_applies::<T, D>() {
            congruence_simd(f, &state.covariance, tr.process_noise(), true).filter(|_| fast_ok)
        } else {
            congruence_ldl(f, &state.covariance, tr.process_noise()).filter(|_| fast_ok)
        };
        if let Some(p) = p {
            return Ok(Gaussian {
                mean: tr.propagate_mean(&state.mean),
                covariance: p,
            });
        }
    }
    validate_state(state, n, checks)?;
    check_dim("F rows", n, f.nrows())?;
    check_dim("F columns", n, f.ncols())?;
    // without the factorisation (`InputChecks::Cheap`), the SIMD product still applies where
    // the factorising path would have used it: the same covariance for a `P` that passes
    let simd = (!factorise && is_static::<D, D>() && !tr.has_structured_propagation())
        .then(|| congruence_simd(f, &state.covariance, tr.process_noise(), false))
        .flatten();
    Ok(Gaussian {
        mean: tr.propagate_mean(&state.mean),
        covariance: simd.unwrap_or_else(|| tr.propagate_covariance(&state.covariance)),
    })
}

/// `H x`, `H P` and `S = H P H^T + R` (exactly symmetric) for a linear observation model
/// whose row `a` selects the state component `at(a)`
/// ([`LinearObservationModel::selected_components`]): picks of components, rows and a block
/// of `P` instead of products. `at(a) < n` for `a < m` (the caller checks the selection
/// once; `at` clamps so that the compiler drops the bounds checks for static sizes).
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(crate) fn selection_products<T, D, M>(
    at: impl Fn(usize) -> usize,
    prior: &Gaussian<T, D>,
    r: &OMatrix<T, M, M>,
) -> (OVector<T, M>, OMatrix<T, M, D>, OMatrix<T, M, M>)
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    let p = &prior.covariance;
    let (mm, _) = r.shape_generic();
    let (dd, _) = p.shape_generic();
    let m = mm.value();
    let zp = OVector::<T, M>::from_fn_generic(mm, Const::<1>, |a, _| prior.mean[at(a)]);
    let hp = OMatrix::<T, M, D>::from_fn_generic(mm, dd, |a, c| p[(at(a), c)]);
    let half = nalgebra::convert::<f64, T>(0.5);
    let mut s = OMatrix::<T, M, M>::zeros_generic(mm, mm);
    for b in 0..m {
        for a in b..m {
            // from `P`, not from `hp` (element reads of elements just written one by one
            // would be combined into wide reads that stall store forwarding)
            let v = p[(at(a), at(b))] + (r[(a, b)] + r[(b, a)]) * half;
            s[(a, b)] = v;
            s[(b, a)] = v;
        }
    }
    (zp, hp, s)
}

/// The update of a linearised observation model: `S = H P H^T + R`, `K = P H^T S^-1` by a
/// Cholesky solve, `x + K y`, covariance by `form`, log-likelihood from the same factor.
#[inline(always)]
pub(crate) fn linearized_update<T, D, M, Ob>(
    observation: &Ob,
    prior: &Gaussian<T, D>,
    predicted_z: &OVector<T, M>,
    h: &OMatrix<T, M, D>,
    z: &OVector<T, M>,
    form: CovarianceUpdate,
) -> Result<Update<T, D, M>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    Ob: Observation<T, D, M> + ?Sized,
    DefaultAllocator: FilterAllocator<D, M>,
{
    let n = prior.mean.nrows();
    let m = observation.observation_dim();
    check_dim("observation", m, z.nrows())?;
    check_finite(z, "observation")?;
    check_dim("H rows", m, h.nrows())?;
    check_dim("H columns", n, h.ncols())?;
    check_dim("h(x)", m, predicted_z.nrows())?;
    let r = observation.observation_noise();
    let hp = mul(h, &prior.covariance);
    // S = H P H^T + R, symmetric by construction
    let s = mul_tr_sym_plus(&hp, h, r);
    finish_update(observation, prior, predicted_z, hp, s, z, form)
}

/// The update from `H P` and `S = H P H^T + R` (symmetric): `K = P H^T S^-1` by a Cholesky
/// solve, `x + K y`, covariance by `form`, log-likelihood from the same factor.
#[inline(always)]
pub(crate) fn finish_update<T, D, M, Ob>(
    observation: &Ob,
    prior: &Gaussian<T, D>,
    predicted_z: &OVector<T, M>,
    hp: OMatrix<T, M, D>,
    s: OMatrix<T, M, M>,
    z: &OVector<T, M>,
    form: CovarianceUpdate,
) -> Result<Update<T, D, M>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    Ob: Observation<T, D, M> + ?Sized,
    DefaultAllocator: FilterAllocator<D, M>,
{
    let p = &prior.covariance;
    let factors = ldl(s.clone(), "S")?;
    // K^T = S^-1 H P (P symmetric)
    let mut kt = hp.clone();
    factors.solve_mut(&mut kt);
    let gain = kt.transpose();
    let y = observation.observation_residual(z, predicted_z);
    let mut mean = mul_vec(&gain, &y);
    mean += &prior.mean;
    let mut cov = match form {
        // (I - K H) P (I - K H)^T + K R K^T from the products already formed; symmetric
        CovarianceUpdate::Joseph => joseph(p, &gain, &hp, &s),
        CovarianceUpdate::Plain | CovarianceUpdate::Symmetrised => p - mul(&gain, &hp),
    };
    if form == CovarianceUpdate::Symmetrised {
        symmetrise(&mut cov);
    }
    // one branch for the three output checks (the error is located only on failure), then
    // the update built as the returned value (built first and then checked, it was copied
    // into the result: two 520-byte copies per step for 6 states)
    let nis = factors.quadratic_form(&y);
    if !(all_finite(&mean) & all_finite(&cov) & nis.is_finite()) {
        check_finite(&mean, "posterior mean")?;
        check_finite(&cov, "posterior covariance")?;
        return Err(CoreError::NonFinite {
            what: "normalised innovation squared",
            index: 0,
        }
        .into());
    }
    Ok(Update {
        posterior: Gaussian {
            mean,
            covariance: cov,
        },
        innovation: y,
        innovation_covariance: s,
        gain,
        nis,
        det_innovation_covariance: factors.det(),
    })
}

/// Validates a state against the transition's dimension (shared by every filter's steps).
pub(crate) fn validate_state<T, D>(
    state: &Gaussian<T, D>,
    n: usize,
    checks: InputChecks,
) -> Result<()>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    check_state(state, n, checks == InputChecks::Full)
}
