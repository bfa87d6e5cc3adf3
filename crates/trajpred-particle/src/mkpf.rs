//! [`Mkpf`]: the particle filter of the MKPF paper (`docs/papers.md` C.1), whose every particle
//! carries a mean and a covariance and proposes from a UKF step followed by an EKF step, both the
//! Kalman crate's own (`trajpred_kalman::Ukf`, `trajpred_kalman::Ekf`).

use crate::alloc::ParticleAllocator;
use crate::cloud::{ParticleCloud, first_non_finite};
use crate::error::Result;
use crate::pf::{
    MIN_PARTICLES_PER_TASK, ParticleFiltering, PfConfig, StepSummary, finish_step, log_likelihood,
    predict_clouds, propagate_one, step_noise, weigh_and_select,
};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use rand::Rng;
use rayon::prelude::*;
use std::marker::PhantomData;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::sampling::{ZeroMeanGaussian, covariance_sqrt, draw};
use trajpred_kalman::{
    AugmentedUkf, Ekf, Filter, KalmanError, MerweSigmaPoints, NoisyObservation, NoisyTransition,
    Observation, ObservationJacobian, TransitionJacobian, Ukf,
};

/// How the EKF step of the MKPF proposal uses the UKF step's result (`docs/papers.md` C.1 leaves it
/// open; see `docs/particle.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EkfStage {
    /// Default. The EKF update starts from the UKF **prediction** `N(x(k|k-1), P(k|k-1))` and
    /// linearises `h` at the UKF **estimate** `x_ukf(k|k)` (one iterated-EKF refinement):
    /// `y = z - h(x_ukf) - H (x(k|k-1) - x_ukf)`, `H = dh/dx(x_ukf)`. The observation is
    /// used once, and the linearisation point is the best one available.
    #[default]
    Relinearized,
    /// The literal sequence "UKF update, then EKF update": the UKF posterior is the prior
    /// of an EKF update by the same `z_k`. Uses `z_k` twice, so the proposal is narrower
    /// than the posterior (the weights of eq. 9 still correct for it).
    Sequential,
    /// No EKF step: the proposal is the UKF posterior (van der Merwe's unscented particle
    /// filter), for comparison.
    UkfOnly,
}

/// Which prior the UKF step of particle `i` starts from (`docs/papers.md` C.1 leaves the meaning of
/// the particle's "mean and covariance" open; see `docs/particle.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParticlePrior {
    /// The UKF step starts from `N(x_(k-1)^i, P_(k-1)^i)`: the particle's *drawn* state with
    /// its previous proposal covariance (`P_0` at the start). The spread of the draw is then
    /// counted twice (once in the drawn state, once in `P`), the proposal is wider than the
    /// transition density of eq. 9, and the weights degenerate when `Q` is small against
    /// `P^i` in the directions the observation does not fix (see `docs/particle.md`).
    Carried,
    /// The UKF step conditions on the particle: its prediction is exactly
    /// `N(f(x_(k-1)^i), Q)` (the unscented transform of a point mass), so the UKF+EKF update
    /// approximates the optimal proposal `p(x_k | x_(k-1)^i, z_k)`. The covariance each
    /// particle carries is then its last proposal covariance, reported but not fed back.
    Conditioned,
    /// Default: the paper's Algorithm 1 read literally, as van der Merwe's unscented particle
    /// filter keeps them: every particle carries a mean and a covariance, and its UKF step
    /// starts from `N(x̄_(k-1)^i, P_(k-1)^i)`, its previous proposal's mean and covariance
    /// (`x̄_0^i` the particle itself, `P_0^i = P_0`). The drawn state `x_(k-1)^i` enters only
    /// the transition density of eq. 9.
    #[default]
    ProposalMean,
}

/// Which UKF of the Kalman crate runs the UKF stage of the proposal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UkfVariant {
    /// Default: the augmented UKF of the paper (eq. 12-19, `trajpred_kalman::AugmentedUkf`):
    /// sigma points of `N([x; 0; 0], blockdiag(P, Q, R))`, propagated through `f(x, w)` and
    /// `h(f(x, w), v)`, the update from the same points. Used with [`ParticlePrior::Carried`]
    /// and [`ParticlePrior::ProposalMean`];
    /// with [`ParticlePrior::Conditioned`] the prior covariance is zero, so the update is the
    /// additive one.
    #[default]
    Augmented,
    /// The additive-noise UKF (`trajpred_kalman::Ukf`): `Q` and `R` added to the spreads,
    /// the update's sigma points redrawn from the prediction.
    Additive,
}

/// The UKF stage for one step: both filters share the models by reference.
struct UkfStage<'a, T, Tr, Ob> {
    additive: Ukf<T, &'a Tr, &'a Ob>,
    augmented: Option<AugmentedUkf<T, &'a Tr, &'a Ob>>,
}

/// `h` linearised at a point `a`: `h(a) + H(a) (x - a)`, with `h`'s residual, noise and
/// normalisation. Lets the Kalman crate's `Ekf::update` (which linearises at the prior
/// mean) linearise at the UKF estimate instead.
struct Linearized<'a, T: RealField, D: Dim, M: Dim, Ob>
where
    DefaultAllocator: Allocator<D> + Allocator<M> + Allocator<M, D>,
{
    inner: &'a Ob,
    at: OVector<T, D>,
    h_at: OVector<T, M>,
    jacobian: OMatrix<T, M, D>,
}

impl<T: RealField + Copy, D: Dim, M: Dim, Ob> Observation<T, D, M> for Linearized<'_, T, D, M, Ob>
where
    Ob: Observation<T, D, M>,
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observe(&self, x: &OVector<T, D>) -> trajpred_kalman::Result<OVector<T, M>> {
        Ok(&self.h_at + &self.jacobian * (x - &self.at))
    }
    fn observation_noise(&self) -> &OMatrix<T, M, M> {
        self.inner.observation_noise()
    }
    fn observation_dim(&self) -> usize {
        self.inner.observation_dim()
    }
    fn observation_residual(&self, a: &OVector<T, M>, b: &OVector<T, M>) -> OVector<T, M> {
        self.inner.observation_residual(a, b)
    }
    fn normalize_observation(&self, z: OVector<T, M>) -> OVector<T, M> {
        self.inner.normalize_observation(z)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Ob> ObservationJacobian<T, D, M>
    for Linearized<'_, T, D, M, Ob>
where
    Ob: Observation<T, D, M>,
    DefaultAllocator:
        Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M> + Allocator<M, D>,
{
    fn observation_jacobian(
        &self,
        _x: &OVector<T, D>,
    ) -> trajpred_kalman::Result<OMatrix<T, M, D>> {
        Ok(self.jacobian.clone())
    }
}

/// The MKPF of Zhao et al. 2015 (`docs/papers.md` C.1, Algorithm 1). Particle `i` carries a sample
/// `x^i` and a covariance `P^i`. At step `k`, for each particle:
///
/// 1. a UKF step (Merwe sigma points, eq. 10-19) from `N(x_(k-1)^i, P_(k-1)^i)` by the
///    observation `z_k`: prediction `N(x(k|k-1), P(k|k-1))` and estimate `x_ukf`;
/// 2. an EKF step (eq. 20-24) that uses the UKF result as its prior (see [`EkfStage`]),
///    giving the proposal `q = N(x_bar_k^i, P_k^i)`;
/// 3. a draw `x_k^i ~ q`, weighted by eq. 9:
///    `w_k^i ∝ w_(k-1)^i p(z_k | x_k^i) p(x_k^i | x_(k-1)^i) / q(x_k^i | x_(k-1)^i, z_k)`,
///    with `p(z | x) = N(z; h(x), R)` and `p(x_k | x_(k-1)) = N(x_k; f(x_(k-1)), Q)`;
///
/// then the log-weights are normalised and the particles (with their covariances)
/// resampled, by the residual scheme every step by default ([`PfConfig`]).
///
/// The transition density needs `Q` positive definite (a singular `Q` is
/// [`trajpred_core::Error::NotPositiveDefinite`] at construction). A particle whose UKF or EKF step
/// fails (e.g. `S` not positive definite) falls back to the transition prior as its proposal
/// for that step (counted in [`StepSummary::fallbacks`]). A missing observation propagates
/// each particle through the transition (weights unchanged) and its covariance by the UKF
/// prediction. The per-particle work runs in parallel with rayon; every random number is
/// drawn before it, so a seed gives the same result on any number of threads.
///
/// ```
/// use nalgebra::{Matrix5, Vector2, Vector5, U2, U5};
/// use rand::SeedableRng;
/// use trajpred_core::Gaussian;
/// use trajpred_kalman::{CoordinatedTurn, MerweSigmaPoints, Observation, RangeBearing, Transition};
/// use trajpred_particle::{Mkpf, ParticleFiltering};
/// // a target turning at 0.05 rad/s, seen in range (sd 1 m) and bearing (sd 1 mrad)
/// let q = Matrix5::from_diagonal(&Vector5::new(4.0, 1.0, 4.0, 1.0, 1e-4));
/// let ct = CoordinatedTurn::with_process_noise(1.0, q)?;
/// let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, 1.0, 1e-6)?;
/// let mut truth = Vector5::new(1000.0, 10.0, 1000.0, 0.0, 0.05);
/// let p0 = Matrix5::from_diagonal(&Vector5::new(25.0, 4.0, 25.0, 4.0, 1e-3));
/// let x0 = Gaussian { mean: truth, covariance: p0 };
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
/// let mut mkpf = Mkpf::<f64, U5, U2, _, _>::from_gaussian(
///     ct.clone(), rb.clone(), &x0, 20, MerweSigmaPoints::default(), &mut rng)?;
/// for _ in 0..10 {
///     truth = ct.transition(&truth)?;
///     let z = rb.observe(&truth)?; // noise-free here, to keep the example short
///     mkpf.step(Some(&z), &mut rng)?;
/// }
/// let est = mkpf.cloud().estimate();
/// let err = ((est.mean[0] - truth[0]).powi(2) + (est.mean[2] - truth[2]).powi(2)).sqrt();
/// assert!(err < 10.0, "position error {err}");
/// // the particle cloud five steps ahead, and its 90% interval of x
/// let ahead = mkpf.predict(5, &mut rng)?;
/// let (lo, hi) = (ahead[4].quantile(0, 0.05)?, ahead[4].quantile(0, 0.95)?);
/// assert!(lo < hi);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Mkpf<T, D, M, Tr, Ob>
where
    T: RealField,
    D: Dim,
    M: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    transition: Tr,
    observation: Ob,
    points: MerweSigmaPoints<T>,
    stage: EkfStage,
    prior_mode: ParticlePrior,
    ukf_variant: UkfVariant,
    cloud: ParticleCloud<T, D>,
    covariances: Vec<OMatrix<T, D, D>>,
    /// Each particle's last proposal mean (used by [`ParticlePrior::ProposalMean`]).
    means: Vec<OVector<T, D>>,
    config: PfConfig,
    q_factor: OMatrix<T, D, D>,
    transition_density: ZeroMeanGaussian<T, D>,
    likelihood: ZeroMeanGaussian<T, M>,
    _m: PhantomData<fn() -> M>,
}

/// The outcome of one particle's proposal.
struct Moved<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    x: OVector<T, D>,
    p: OMatrix<T, D, D>,
    /// The proposal mean (the drawn state when there was no proposal).
    m: OVector<T, D>,
    log_increment: f64,
    fallback: bool,
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> Mkpf<T, D, M, Tr, Ob>
where
    Tr: TransitionJacobian<T, D> + NoisyTransition<T, D> + Sync,
    Ob: ObservationJacobian<T, D, M> + NoisyObservation<T, D, M> + Sync,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    /// An MKPF over `cloud`, every particle starting with the covariance `initial_covariance`
    /// (the paper's `P_0^i = P_0`), with the sigma-point parameters `points` (the paper:
    /// `alpha = 1e-3, beta = 2, kappa = 0`, [`MerweSigmaPoints::default`]). Errors:
    /// [`trajpred_core::Error::DimensionMismatch`], [`trajpred_core::Error::NotPositiveDefinite`] (`"Q"`
    /// must be positive definite, `"R"`, `"P"`), [`ParticleError::Kalman`](crate::ParticleError::Kalman) (degenerate
    /// sigma points).
    pub fn new(
        transition: Tr,
        observation: Ob,
        cloud: ParticleCloud<T, D>,
        initial_covariance: OMatrix<T, D, D>,
        points: MerweSigmaPoints<T>,
    ) -> Result<Self> {
        let n = transition.state_dim();
        if cloud.dim() != n {
            return Err(CoreError::DimensionMismatch {
                what: "particles vs transition",
                expected: n,
                got: cloud.dim(),
            }
            .into());
        }
        if initial_covariance.nrows() != n || initial_covariance.ncols() != n {
            return Err(CoreError::DimensionMismatch {
                what: "initial covariance vs transition",
                expected: n,
                got: initial_covariance.nrows(),
            }
            .into());
        }
        covariance_sqrt(&initial_covariance, "P")?;
        points.weights(n)?;
        let q_factor = covariance_sqrt(transition.process_noise(), "Q")?;
        let transition_density = ZeroMeanGaussian::new(transition.process_noise(), "Q")?;
        let likelihood = ZeroMeanGaussian::new(observation.observation_noise(), "R")?;
        let covariances = vec![initial_covariance; cloud.len()];
        let means = cloud.particles().to_vec();
        Ok(Mkpf {
            transition,
            observation,
            points,
            stage: EkfStage::default(),
            prior_mode: ParticlePrior::default(),
            ukf_variant: UkfVariant::default(),
            cloud,
            covariances,
            means,
            config: PfConfig::default(),
            q_factor,
            transition_density,
            likelihood,
            _m: PhantomData,
        })
    }

    /// An MKPF whose `n` particles are drawn from `initial`, each with the covariance
    /// `initial.covariance` (Algorithm 1, step 1).
    pub fn from_gaussian<R: Rng + ?Sized>(
        transition: Tr,
        observation: Ob,
        initial: &Gaussian<T, D>,
        n: usize,
        points: MerweSigmaPoints<T>,
        rng: &mut R,
    ) -> Result<Self> {
        let cloud = ParticleCloud::sample(initial, n, rng)?;
        Self::new(
            transition,
            observation,
            cloud,
            initial.covariance.clone(),
            points,
        )
    }

    /// Sets the resampling configuration (validated).
    pub fn with_config(mut self, config: PfConfig) -> Result<Self> {
        config.policy.validate()?;
        self.config = config;
        Ok(self)
    }

    /// Selects how the EKF step uses the UKF result.
    pub fn with_ekf_stage(mut self, stage: EkfStage) -> Self {
        self.stage = stage;
        self
    }

    /// Selects the prior of each particle's UKF step.
    pub fn with_particle_prior(mut self, prior: ParticlePrior) -> Self {
        self.prior_mode = prior;
        self
    }

    /// The prior of each particle's UKF step.
    pub fn particle_prior(&self) -> ParticlePrior {
        self.prior_mode
    }

    /// Selects the UKF of the UKF stage.
    pub fn with_ukf_variant(mut self, variant: UkfVariant) -> Self {
        self.ukf_variant = variant;
        self
    }

    /// The UKF of the UKF stage.
    pub fn ukf_variant(&self) -> UkfVariant {
        self.ukf_variant
    }

    /// The UKF filters of one step.
    fn ukf_stage(&self) -> Result<UkfStage<'_, T, Tr, Ob>> {
        let additive = Ukf::new(&self.transition, &self.observation, self.points)?;
        let augmented = match (self.ukf_variant, self.prior_mode) {
            (UkfVariant::Augmented, ParticlePrior::Carried | ParticlePrior::ProposalMean) => Some(
                AugmentedUkf::new(&self.transition, &self.observation, self.points)?,
            ),
            _ => None,
        };
        Ok(UkfStage {
            additive,
            augmented,
        })
    }

    /// The resampling configuration.
    pub fn config(&self) -> &PfConfig {
        &self.config
    }

    /// The EKF stage in use.
    pub fn ekf_stage(&self) -> EkfStage {
        self.stage
    }

    /// The per-particle covariances `P^i`, in particle order.
    pub fn covariances(&self) -> &[OMatrix<T, D, D>] {
        &self.covariances
    }

    /// The same filter (particles, weights, observation, settings) with another transition,
    /// e.g. the model of another time step. Every particle then carries the mean of the
    /// particles' covariances (a new `Q` changes what each particle's covariance means; their
    /// mean is the cloud's own uncertainty estimate); each particle keeps its last proposal
    /// mean ([`ParticlePrior::ProposalMean`]).
    pub fn with_transition(&self, transition: Tr) -> Result<Self>
    where
        Ob: Clone,
    {
        let covs = &self.covariances;
        let n = self.cloud.dim();
        let mean_cov = covs.iter().fold(
            OMatrix::<T, D, D>::zeros_generic(D::from_usize(n), D::from_usize(n)),
            |a, c| a + c,
        ) / nalgebra::convert::<f64, T>(covs.len().max(1) as f64);
        let mut rebuilt = Self::new(
            transition,
            self.observation.clone(),
            self.cloud.clone(),
            mean_cov,
            self.points,
        )?
        .with_config(self.config)?
        .with_ekf_stage(self.stage)
        .with_particle_prior(self.prior_mode)
        .with_ukf_variant(self.ukf_variant);
        // the particles' proposal means are states, whatever the model
        rebuilt.means.clone_from(&self.means);
        Ok(rebuilt)
    }

    /// The UKF prediction of one particle by [`ParticlePrior`].
    fn ukf_prediction(
        &self,
        ukf: &UkfStage<'_, T, Tr, Ob>,
        prior: &Gaussian<T, D>,
    ) -> trajpred_kalman::Result<Gaussian<T, D>> {
        match self.prior_mode {
            ParticlePrior::Carried | ParticlePrior::ProposalMean => match &ukf.augmented {
                Some(a) => a.predict(prior),
                None => ukf.additive.predict(prior),
            },
            ParticlePrior::Conditioned => Ok(Gaussian {
                mean: self.transition.transition(&prior.mean)?,
                covariance: self.transition.process_noise().clone(),
            }),
        }
    }

    /// The Gaussian proposal `q = N(x_bar, P)` of one particle (UKF step, then EKF step).
    fn proposal(
        &self,
        ukf: &UkfStage<'_, T, Tr, Ob>,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
    ) -> trajpred_kalman::Result<(Gaussian<T, D>, Gaussian<T, D>)> {
        let (pred, ukf_post) = match (&ukf.augmented, self.prior_mode) {
            (Some(a), ParticlePrior::Carried | ParticlePrior::ProposalMean) => {
                let step = a.step(prior, Some(z))?;
                let post = step.posterior().clone();
                (step.prior, post)
            }
            _ => {
                let pred = self.ukf_prediction(ukf, prior)?;
                let post = ukf.additive.update(&pred, z)?.posterior;
                (pred, post)
            }
        };
        let q = match self.stage {
            EkfStage::UkfOnly => ukf_post,
            EkfStage::Sequential => {
                let ekf = Ekf::new(&self.transition, &self.observation)?;
                ekf.update(&ukf_post, z)?.posterior
            }
            EkfStage::Relinearized => {
                let lin = Linearized {
                    inner: &self.observation,
                    h_at: self.observation.observe(&ukf_post.mean)?,
                    jacobian: self.observation.observation_jacobian(&ukf_post.mean)?,
                    at: ukf_post.mean,
                };
                let ekf = Ekf::new(&self.transition, &lin)?;
                ekf.update(&pred, z)?.posterior
            }
        };
        Ok((pred, q))
    }

    /// One particle's move (its drawn state `x`, last proposal mean `m` and covariance `p`):
    /// the proposal draw and its weight increment (eq. 9), or the fallback to the transition
    /// prior.
    fn move_particle(
        &self,
        ukf: &UkfStage<'_, T, Tr, Ob>,
        x: &OVector<T, D>,
        m: &OVector<T, D>,
        p: &OMatrix<T, D, D>,
        e: &[T],
        z: Option<&OVector<T, M>>,
    ) -> Result<Moved<T, D>> {
        let prior = Gaussian {
            mean: match self.prior_mode {
                ParticlePrior::ProposalMean => m.clone(),
                ParticlePrior::Carried | ParticlePrior::Conditioned => x.clone(),
            },
            covariance: p.clone(),
        };
        let Some(z) = z else {
            let xn = propagate_one(&self.transition, &self.q_factor, x, e)?;
            let (mn, pn) = self
                .ukf_prediction(ukf, &prior)
                .map_or_else(|_| (xn.clone(), p.clone()), |g| (g.mean, g.covariance));
            return Ok(Moved {
                x: xn,
                p: pn,
                m: mn,
                log_increment: 0.0,
                fallback: false,
            });
        };
        match self.propose(ukf, x, &prior, z, e) {
            Ok(Some(m)) => Ok(m),
            Ok(None) | Err(_) => {
                let xn = propagate_one(&self.transition, &self.q_factor, x, e)?;
                let ll = log_likelihood(&self.observation, &self.likelihood, &xn, z)?;
                Ok(Moved {
                    m: xn.clone(),
                    x: xn,
                    p: p.clone(),
                    log_increment: ll,
                    fallback: true,
                })
            }
        }
    }

    /// The MKPF proposal draw for the particle at `x` whose UKF starts from `prior`;
    /// `Ok(None)` or `Err` asks for the fallback.
    fn propose(
        &self,
        ukf: &UkfStage<'_, T, Tr, Ob>,
        x: &OVector<T, D>,
        prior: &Gaussian<T, D>,
        z: &OVector<T, M>,
        e: &[T],
    ) -> std::result::Result<Option<Moved<T, D>>, KalmanError> {
        let (_, q) = self.proposal(ukf, prior, z)?;
        let Ok(spread) = ZeroMeanGaussian::new(&q.covariance, "proposal covariance") else {
            return Ok(None);
        };
        let xn = draw(&q.mean, spread.factor(), e.iter().copied());
        if first_non_finite(&xn).is_some() {
            return Ok(None);
        }
        // ln q(x) with x - mean = L e: -(n ln 2 pi + ln det P + |e|^2) / 2
        let log_q = spread.log_density_of_normals(e);
        let fx = self.transition.transition(x)?;
        let log_trans = self
            .transition_density
            .log_density(&self.transition.state_residual(&xn, &fx));
        let Ok(log_lik) = log_likelihood(&self.observation, &self.likelihood, &xn, z) else {
            return Ok(None);
        };
        let inc = log_lik + log_trans - log_q;
        if inc.is_nan() || inc == f64::INFINITY {
            return Ok(None);
        }
        Ok(Some(Moved {
            x: xn,
            p: q.covariance,
            m: q.mean,
            log_increment: inc,
            fallback: false,
        }))
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> ParticleFiltering<T, D, M>
    for Mkpf<T, D, M, Tr, Ob>
where
    Tr: TransitionJacobian<T, D> + NoisyTransition<T, D> + Sync,
    Ob: ObservationJacobian<T, D, M> + NoisyObservation<T, D, M> + Sync,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    fn step<R: Rng + ?Sized>(
        &mut self,
        z: Option<&OVector<T, M>>,
        rng: &mut R,
    ) -> Result<StepSummary<T, D>> {
        let noise = step_noise(&self.cloud, self.observation.observation_dim(), z, rng)?;
        let n = self.cloud.dim();
        let this = &*self;
        let ukf = this.ukf_stage()?;
        let moved: Vec<Moved<T, D>> = this
            .cloud
            .particles()
            .par_iter()
            .zip(this.means.par_iter())
            .zip(this.covariances.par_iter())
            .zip(noise.par_chunks(n))
            .with_min_len((MIN_PARTICLES_PER_TASK / 64).max(1))
            .map(|(((x, m), p), e)| this.move_particle(&ukf, x, m, p, e, z))
            .collect::<Result<_>>()?;
        let mut log_w: Vec<f64> = this
            .cloud
            .log_weights()
            .iter()
            .zip(&moved)
            .map(|(l, m)| l + m.log_increment)
            .collect();
        let (select, ess, lse) = weigh_and_select(&mut log_w, &self.config, rng)?;
        let fallbacks = moved.iter().filter(|m| m.fallback).count();
        let mut particles = Vec::with_capacity(moved.len());
        let mut covs = Vec::with_capacity(moved.len());
        let mut means = Vec::with_capacity(moved.len());
        for m in moved {
            particles.push(m.x);
            covs.push(m.p);
            means.push(m.m);
        }
        if let Some(idx) = &select {
            covs = idx.iter().map(|&i| covs[i].clone()).collect();
            means = idx.iter().map(|&i| means[i].clone()).collect();
        }
        self.covariances = covs;
        self.means = means;
        finish_step(
            &mut self.cloud,
            particles,
            log_w,
            (select.as_deref(), ess, lse),
            z.is_some(),
            fallbacks,
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
