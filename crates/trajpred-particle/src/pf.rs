//! The bootstrap particle filter [`ParticleFilter`], the interface shared with
//! [`Mkpf`](crate::Mkpf) ([`ParticleFiltering`]), its configuration ([`PfConfig`]) and the
//! per-step summary ([`StepSummary`]).

use crate::alloc::ParticleAllocator;
use crate::cloud::{ParticleCloud, first_non_finite};
use crate::error::Result;
use crate::resample::{Resampler, Resampling};
use crate::weights::{ResamplePolicy, effective_sample_size_log, normalize_log_weights};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use rand::Rng;
use rayon::prelude::*;
use std::marker::PhantomData;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::driver::scan;
use trajpred_kalman::sampling::{ZeroMeanGaussian, covariance_sqrt, draw, push_standard_normals};
use trajpred_kalman::{Observation, Transition};

/// Minimum particles per rayon task: below this the work per particle of the bootstrap
/// filter is too small to pay for a task.
pub(crate) const MIN_PARTICLES_PER_TASK: usize = 256;

/// How a particle filter resamples.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PfConfig {
    /// The scheme (residual by default, as the MKPF paper).
    pub resampling: Resampling,
    /// When (every step by default, as the MKPF paper).
    pub policy: ResamplePolicy,
}

/// What one filter step did.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSummary<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The weighted mean and covariance after the update, computed before resampling (the
    /// lower-variance estimate).
    pub estimate: Gaussian<T, D>,
    /// The effective sample size after weighting, before resampling.
    pub ess: f64,
    /// Whether the particles were resampled at the end of the step.
    pub resampled: bool,
    /// `ln p^(z_k | z_1:k-1) = ln sum_i w_(k-1)^i * (weight increment)_i`, the particle
    /// estimate of the observation's log-likelihood (0 for a missing observation).
    pub log_likelihood: f64,
    /// Particles whose Gaussian proposal failed (a UKF/EKF error) and fell back to the
    /// transition prior (always 0 for the bootstrap filter).
    pub fallbacks: usize,
}

/// The interface shared by [`ParticleFilter`] and [`Mkpf`](crate::Mkpf): one step with an
/// optional observation, a run over a sequence, and the k-step prediction of the cloud.
///
/// Randomness is injected: a seeded generator reproduces a run exactly, whatever the number
/// of rayon threads (all random numbers of a step are drawn sequentially, before the
/// parallel part).
pub trait ParticleFiltering<T: RealField + Copy, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    /// Advances the filter by one time step; `z` is the observation at the new time
    /// (`None`: predict only, weights unchanged).
    ///
    /// On error the filter is left as it was before the call (in particular for
    /// [`ParticleError::AllWeightsZero`](crate::ParticleError::AllWeightsZero), an observation impossible under every particle:
    /// the caller may skip it and continue).
    fn step<R: Rng + ?Sized>(
        &mut self,
        z: Option<&OVector<T, M>>,
        rng: &mut R,
    ) -> Result<StepSummary<T, D>>;

    /// The current weighted particles.
    fn cloud(&self) -> &ParticleCloud<T, D>;

    /// The k-step prediction of the cloud without observations: for `j = 1..=steps`, the
    /// particles propagated `j` times through the transition (with process noise), weights
    /// unchanged. The filter itself is not modified.
    fn predict<R: Rng + ?Sized>(
        &self,
        steps: usize,
        rng: &mut R,
    ) -> Result<Vec<ParticleCloud<T, D>>>;

    /// Runs [`ParticleFiltering::step`] over a sequence (missing observations are `None`),
    /// returning one summary per observation. Stops at the first error (the filter then holds
    /// the state after the last successful step).
    fn filter<R: Rng + ?Sized>(
        &mut self,
        observations: &[Option<OVector<T, M>>],
        rng: &mut R,
    ) -> Result<Vec<StepSummary<T, D>>> {
        scan(observations, |_, z| self.step(z.as_ref(), rng))
    }

    /// The k-step forecast as Gaussians (the weighted mean and covariance of each predicted
    /// cloud of [`ParticleFiltering::predict`]).
    fn forecast<R: Rng + ?Sized>(&self, steps: usize, rng: &mut R) -> Result<Vec<Gaussian<T, D>>> {
        Ok(self
            .predict(steps, rng)?
            .iter()
            .map(ParticleCloud::estimate)
            .collect())
    }
}

/// The start of a step of either filter: checks the observation `z` (size `m`), then draws
/// the standard normals of every particle's process noise (`n` per particle, in order).
pub(crate) fn step_noise<T, D, M, R>(
    cloud: &ParticleCloud<T, D>,
    m: usize,
    z: Option<&OVector<T, M>>,
    rng: &mut R,
) -> Result<Vec<T>>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    R: Rng + ?Sized,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M>,
{
    if let Some(z) = z {
        check_observation(z, m)?;
    }
    let mut noise: Vec<T> = Vec::new();
    push_standard_normals(rng, cloud.len() * cloud.dim(), &mut noise);
    Ok(noise)
}

/// Validates an observation: its size and finite values.
pub(crate) fn check_observation<T: RealField + Copy, M: Dim>(
    z: &OVector<T, M>,
    m: usize,
) -> Result<()>
where
    DefaultAllocator: Allocator<M>,
{
    if z.nrows() != m {
        return Err(CoreError::DimensionMismatch {
            what: "observation",
            expected: m,
            got: z.nrows(),
        }
        .into());
    }
    if let Some(index) = first_non_finite(z) {
        return Err(CoreError::NonFinite {
            what: "observation",
            index,
        }
        .into());
    }
    Ok(())
}

/// `ln p(z | x) = ln N(residual(z, h(x)); 0, R)`.
pub(crate) fn log_likelihood<T, D, M, Ob>(
    observation: &Ob,
    density: &ZeroMeanGaussian<T, M>,
    x: &OVector<T, D>,
    z: &OVector<T, M>,
) -> Result<f64>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    Ob: Observation<T, D, M>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    let zp = observation.observe(x)?;
    if zp.nrows() != z.nrows() {
        return Err(CoreError::DimensionMismatch {
            what: "h(x)",
            expected: z.nrows(),
            got: zp.nrows(),
        }
        .into());
    }
    Ok(density.log_density(&observation.observation_residual(z, &zp)))
}

/// `f(x) + L e` for one particle, checked.
pub(crate) fn propagate_one<T, D, Tr>(
    transition: &Tr,
    q_factor: &OMatrix<T, D, D>,
    x: &OVector<T, D>,
    e: &[T],
) -> Result<OVector<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    Tr: Transition<T, D>,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let fx = transition.transition(x)?;
    if fx.nrows() != x.nrows() {
        return Err(CoreError::DimensionMismatch {
            what: "f(x)",
            expected: x.nrows(),
            got: fx.nrows(),
        }
        .into());
    }
    let out = draw(&fx, q_factor, e.iter().copied());
    if let Some(index) = first_non_finite(&out) {
        return Err(CoreError::NonFinite {
            what: "propagated particle",
            index,
        }
        .into());
    }
    Ok(out)
}

/// The k-step prediction shared by both filters.
pub(crate) fn predict_clouds<T, D, Tr, R>(
    transition: &Tr,
    q_factor: &OMatrix<T, D, D>,
    cloud: &ParticleCloud<T, D>,
    steps: usize,
    rng: &mut R,
) -> Result<Vec<ParticleCloud<T, D>>>
where
    T: RealField + Copy,
    D: Dim,
    Tr: Transition<T, D> + Sync,
    R: Rng + ?Sized,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
    OVector<T, D>: Send + Sync,
    OMatrix<T, D, D>: Send + Sync,
{
    let n = cloud.dim();
    let mut noise: Vec<T> = Vec::new();
    scan(0..steps, |prev: Option<&ParticleCloud<T, D>>, _| {
        let prev = prev.unwrap_or(cloud);
        noise.clear();
        push_standard_normals(rng, prev.len() * n, &mut noise);
        let particles: Vec<OVector<T, D>> = prev
            .particles()
            .par_iter()
            .zip(noise.par_chunks(n))
            .with_min_len(MIN_PARTICLES_PER_TASK)
            .map(|(x, e)| propagate_one(transition, q_factor, x, e))
            .collect::<Result<_>>()?;
        ParticleCloud::new(particles, prev.log_weights().to_vec())
    })
}

/// Normalises new log-weights and, if the policy says so, resamples: returns the ancestor
/// indices (or `None`), the ESS before resampling and the log-likelihood increment.
pub(crate) fn weigh_and_select<R: Rng + ?Sized>(
    log_weights: &mut [f64],
    config: &PfConfig,
    rng: &mut R,
) -> Result<(Option<Vec<usize>>, f64, f64)> {
    let lse = normalize_log_weights(log_weights)?;
    let ess = effective_sample_size_log(log_weights)?;
    let n = log_weights.len();
    if !config.policy.should_resample(ess, n) {
        return Ok((None, ess, lse));
    }
    let w: Vec<f64> = log_weights.iter().map(|l| l.exp()).collect();
    let idx = config.resampling.resample(&w, n, rng)?;
    Ok((Some(idx), ess, lse))
}

/// The end of a step, the same for both filters: the estimate of the moved particles under
/// their new normalised `log_w`; then the particles (the ancestors in `select` when it is
/// `Some`, with equal weights) become the cloud. Returns the step's summary, with the ESS
/// and log-likelihood increment `lse` of [`weigh_and_select`] (the increment reported only
/// when the step had an observation) and the count of `fallbacks`.
pub(crate) fn finish_step<T, D>(
    cloud: &mut ParticleCloud<T, D>,
    mut particles: Vec<OVector<T, D>>,
    mut log_w: Vec<f64>,
    (select, ess, lse): (Option<&[usize]>, f64, f64),
    observed: bool,
    fallbacks: usize,
) -> Result<StepSummary<T, D>>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let count = cloud.len();
    let weighted = ParticleCloud::new(particles.clone(), log_w.clone())?;
    let estimate = weighted.estimate();
    let resampled = select.is_some();
    if let Some(idx) = select {
        particles = idx.iter().map(|&i| particles[i].clone()).collect();
        log_w = vec![0.0; count];
    }
    let (ps, ws) = cloud.parts_mut();
    *ps = particles;
    *ws = log_w;
    if resampled {
        normalize_log_weights(ws)?;
    }
    Ok(StepSummary {
        estimate,
        ess,
        resampled,
        log_likelihood: if observed { lse } else { 0.0 },
        fallbacks,
    })
}

/// The bootstrap (sampling importance resampling) particle filter of Gordon et al.: propose
/// from the transition, `x_k^i = f(x_(k-1)^i) + w`, `w ~ N(0, Q)` (a singular `Q`, such as
/// the discrete white-noise model, is fine), weight by the likelihood
/// `w_k^i ∝ w_(k-1)^i p(z_k | x_k^i)` (eq. 9 with `q = p(x_k | x_(k-1))`), normalise in log
/// space, resample by [`PfConfig`].
///
/// ```
/// use nalgebra::{Matrix1, Matrix1x2, Matrix2, U1, U2, Vector1, Vector2};
/// use rand::SeedableRng;
/// use trajpred_core::Gaussian;
/// use trajpred_kalman::{LinearObservation, LinearTransition};
/// use trajpred_particle::{ParticleFilter, ParticleFiltering};
/// let tr = LinearTransition::new(Matrix2::new(1.0, 1.0, 0.0, 1.0), Matrix2::identity() * 0.01)?;
/// let ob = LinearObservation::new(Matrix1x2::new(1.0, 0.0), Matrix1::new(0.25))?;
/// let x0 = Gaussian { mean: Vector2::new(0.0, 1.0), covariance: Matrix2::identity() };
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
/// let mut pf = ParticleFilter::<f64, U2, U1, _, _>::from_gaussian(tr, ob, &x0, 500, &mut rng)?;
/// for k in 1..=5 {
///     pf.step(Some(&Vector1::new(k as f64)), &mut rng)?;
/// }
/// let est = pf.cloud().estimate();
/// assert!((est.mean[0] - 5.0).abs() < 0.5);
/// // three steps ahead, the cloud spreads out
/// let ahead = pf.predict(3, &mut rng)?;
/// assert!(ahead[2].covariance()[(0, 0)] > est.covariance[(0, 0)]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct ParticleFilter<T, D, M, Tr, Ob>
where
    T: RealField,
    D: Dim,
    M: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    transition: Tr,
    observation: Ob,
    cloud: ParticleCloud<T, D>,
    config: PfConfig,
    q_factor: OMatrix<T, D, D>,
    likelihood: ZeroMeanGaussian<T, M>,
    _m: PhantomData<fn() -> M>,
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> ParticleFilter<T, D, M, Tr, Ob>
where
    Tr: Transition<T, D> + Sync,
    Ob: Observation<T, D, M> + Sync,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    /// A filter over `cloud` with the transition (`f`, `Q` positive semi-definite) and the
    /// observation (`h`, `R` positive definite). Errors:
    /// [`trajpred_core::Error::DimensionMismatch`], [`trajpred_core::Error::NotPositiveDefinite`] (`"Q"`,
    /// `"R"`).
    pub fn new(transition: Tr, observation: Ob, cloud: ParticleCloud<T, D>) -> Result<Self> {
        let n = transition.state_dim();
        if cloud.dim() != n {
            return Err(CoreError::DimensionMismatch {
                what: "particles vs transition",
                expected: n,
                got: cloud.dim(),
            }
            .into());
        }
        let q_factor = covariance_sqrt(transition.process_noise(), "Q")?;
        let likelihood = ZeroMeanGaussian::new(observation.observation_noise(), "R")?;
        Ok(ParticleFilter {
            transition,
            observation,
            cloud,
            config: PfConfig::default(),
            q_factor,
            likelihood,
            _m: PhantomData,
        })
    }

    /// A filter whose `n` particles are drawn from `initial` (see [`ParticleCloud::sample`]).
    pub fn from_gaussian<R: Rng + ?Sized>(
        transition: Tr,
        observation: Ob,
        initial: &Gaussian<T, D>,
        n: usize,
        rng: &mut R,
    ) -> Result<Self> {
        let cloud = ParticleCloud::sample(initial, n, rng)?;
        Self::new(transition, observation, cloud)
    }

    /// Sets the resampling configuration (validated).
    pub fn with_config(mut self, config: PfConfig) -> Result<Self> {
        config.policy.validate()?;
        self.config = config;
        Ok(self)
    }

    /// The resampling configuration.
    pub fn config(&self) -> &PfConfig {
        &self.config
    }

    /// The transition model.
    pub fn transition(&self) -> &Tr {
        &self.transition
    }

    /// The observation model.
    pub fn observation(&self) -> &Ob {
        &self.observation
    }

    /// The same filter (particles, weights, observation, configuration) with another
    /// transition, e.g. the model of another time step.
    pub fn with_transition(&self, transition: Tr) -> Result<Self>
    where
        Ob: Clone,
    {
        Self::new(transition, self.observation.clone(), self.cloud.clone())?
            .with_config(self.config)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> ParticleFiltering<T, D, M>
    for ParticleFilter<T, D, M, Tr, Ob>
where
    Tr: Transition<T, D> + Sync,
    Ob: Observation<T, D, M> + Sync,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    fn step<R: Rng + ?Sized>(
        &mut self,
        z: Option<&OVector<T, M>>,
        rng: &mut R,
    ) -> Result<StepSummary<T, D>> {
        let noise = step_noise(&self.cloud, self.observation.observation_dim(), z, rng)?;
        let n = self.cloud.dim();
        let (tr, ob, lik, qf) = (
            &self.transition,
            &self.observation,
            &self.likelihood,
            &self.q_factor,
        );
        let moved: Vec<(OVector<T, D>, f64)> = self
            .cloud
            .particles()
            .par_iter()
            .zip(noise.par_chunks(n))
            .with_min_len(MIN_PARTICLES_PER_TASK)
            .map(|(x, e)| {
                let xn = propagate_one(tr, qf, x, e)?;
                let ll = match z {
                    Some(z) => log_likelihood(ob, lik, &xn, z)?,
                    None => 0.0,
                };
                Ok((xn, ll))
            })
            .collect::<Result<_>>()?;
        let mut log_w: Vec<f64> = self
            .cloud
            .log_weights()
            .iter()
            .zip(&moved)
            .map(|(l, (_, ll))| l + ll)
            .collect();
        let (select, ess, lse) = weigh_and_select(&mut log_w, &self.config, rng)?;
        let particles: Vec<OVector<T, D>> = moved.into_iter().map(|(x, _)| x).collect();
        finish_step(
            &mut self.cloud,
            particles,
            log_w,
            (select.as_deref(), ess, lse),
            z.is_some(),
            0,
        )
    }

    fn cloud(&self) -> &ParticleCloud<T, D> {
        &self.cloud
    }

    fn predict<R: Rng + ?Sized>(
        &self,
        steps: usize,
        rng: &mut R,
    ) -> Result<Vec<ParticleCloud<T, D>>> {
        predict_clouds(&self.transition, &self.q_factor, &self.cloud, steps, rng)
    }
}
