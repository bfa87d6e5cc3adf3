//! Particle filters for trajpred: resampling, log-space weights, the bootstrap particle
//! filter and the MKPF of Zhao, Xiong, Xiao and Xu (2015), whose proposal is a UKF step
//! followed by an EKF step (`docs/papers.md` C).
//!
//! # The method (`docs/papers.md` C.1, the paper's equations)
//!
//! The posterior is approximated by weighted particles (eq. 2)
//! `p(x_0:k | z_1:k) ≈ sum_i w_k^i δ(x_0:k - x_0:k^i)`, so expectations become weighted sums
//! (eq. 4). Drawing `x_k^i` from a proposal `q(x_k | x_(k-1)^i, z_k)`, the weights update by
//! (eq. 9)
//!
//! ```text
//! w_k^i ∝ w_(k-1)^i p(z_k | x_k^i) p(x_k^i | x_(k-1)^i) / q(x_k^i | x_(k-1)^i, z_k)
//! ```
//!
//! The bootstrap filter ([`ParticleFilter`]) takes `q = p(x_k | x_(k-1))`, so the weight is
//! the likelihood. The MKPF ([`Mkpf`]) builds `q` per particle: Merwe's scaled sigma points
//! (eq. 10-11) `χ_0 = x`, `χ_i = x ± (sqrt((n + λ) P))_i`, `λ = α² (n + κ) - n`,
//! `W_0^m = λ / (n + λ)`, `W_0^c = W_0^m + 1 - α² + β`, `W_i = 1 / (2 (n + λ))`
//! (`α = 1e-3, β = 2, κ = 0`); the UKF step (eq. 12-19) predicts through `f`, predicts the
//! observation through `h` and corrects with `K = P_xz P_zz^-1`; the EKF step (eq. 20-24)
//! then corrects again with the Jacobians `F = ∂f/∂x`, `H = ∂h/∂x`:
//! `K = P H^T (H P H^T + R)^-1`, `P_ekf = P - K H P`, `x_ekf = x + K (z - h(x))`. The result
//! `N(x̄_k^i, P_k^i)` is the proposal; `x_k^i` is drawn from it and weighted by eq. 9; the
//! particles are resampled by the residual scheme (`floor(N w_i)` copies, the rest drawn
//! from the residuals `N w_i - floor(N w_i)`) and the weights reset to `1/N`.
//!
//! Both filters reuse the Kalman crate's steps and model traits
//! ([`trajpred_kalman::Transition`], [`trajpred_kalman::Observation`] and their Jacobian
//! versions; the MKPF calls [`trajpred_kalman::Ukf`] and [`trajpred_kalman::Ekf`]). What
//! `docs/papers.md` C leaves open, and what this crate chose, is in `docs/particle.md`: the prior
//! of each particle's UKF step ([`ParticlePrior`]), how the EKF step uses the UKF result
//! ([`EkfStage`]), the ESS rule ([`ResamplePolicy`]), the recovery when every weight is zero
//! ([`ParticleError::AllWeightsZero`], filter left unchanged).
//!
//! # Pieces
//!
//! - [`resample`]: [`Residual`], [`Systematic`], [`Stratified`], [`Multinomial`] behind the
//!   [`Resampler`] trait (injected generator, allocation-free `resample_into`), the
//!   deterministic versions for given uniforms ([`systematic_indices`], ...).
//! - [`weights`]: [`log_sum_exp`], [`normalize_log_weights`], [`effective_sample_size`].
//! - [`ParticleCloud`]: weighted particles with mean, covariance, quantiles, ESS.
//! - [`ParticleFiltering`]: `step` (optional observation), `filter` (a sequence), `predict`
//!   (the cloud k steps ahead) and `forecast` (their Gaussians), for both filters.
//!
//! Randomness is injected (`&mut R where R: rand::Rng + ?Sized`); a seed reproduces a run
//! exactly, on any number of rayon threads.
//!
//! # Example: tracking a turning target
//!
//! ```
//! use nalgebra::{Matrix5, Vector2, Vector5, U2, U5};
//! use rand::SeedableRng;
//! use rand_distr::{Distribution, StandardNormal};
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::{CoordinatedTurn, MerweSigmaPoints, Observation, RangeBearing, Transition};
//! use trajpred_particle::{Mkpf, ParticleFilter, ParticleFiltering, PfConfig, ResamplePolicy, Resampling};
//!
//! // state [x, vx, y, vy, turn rate]; range (sd 1 m) and bearing (sd 1 mrad) from the origin
//! let q = Matrix5::from_diagonal(&Vector5::new(4.0, 1.0, 4.0, 1.0, 1e-4));
//! let ct = CoordinatedTurn::with_process_noise(1.0, q)?;
//! let rb = RangeBearing::new(Vector2::new(0.0, 0.0), 0, 2, 1.0, 1e-6)?;
//!
//! // simulate 20 observations, the 10th missing
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(42);
//! let mut x = Vector5::new(1000.0, 10.0, 1000.0, 0.0, 0.05);
//! let x0 = Gaussian { mean: x, covariance: Matrix5::from_diagonal(&Vector5::new(25.0, 4.0, 25.0, 4.0, 1e-3)) };
//! let mut zs = Vec::new();
//! for k in 0..20 {
//!     x = ct.transition(&x)?;
//!     let e: [f64; 2] = [StandardNormal.sample(&mut rng), StandardNormal.sample(&mut rng)];
//!     let z = rb.observe(&x)? + Vector2::new(e[0], 1e-3 * e[1]);
//!     zs.push((k != 9).then_some(z));
//! }
//!
//! // the MKPF with 30 particles (residual resampling every step, as the paper) ...
//! let mut mkpf = Mkpf::<f64, U5, U2, _, _>::from_gaussian(
//!     ct.clone(), rb.clone(), &x0, 30, MerweSigmaPoints::default(), &mut rng)?;
//! let steps = mkpf.filter(&zs, &mut rng)?;
//! let last = &steps.last().expect("20 steps").estimate;
//! assert!(((last.mean[0] - x[0]).powi(2) + (last.mean[2] - x[2]).powi(2)).sqrt() < 10.0);
//!
//! // ... and a bootstrap filter with systematic resampling when the ESS drops below N/2
//! let mut pf = ParticleFilter::<f64, U5, U2, _, _>::from_gaussian(ct, rb, &x0, 500, &mut rng)?
//!     .with_config(PfConfig { resampling: Resampling::Systematic, policy: ResamplePolicy::EssBelow(0.5) })?;
//! pf.filter(&zs, &mut rng)?;
//!
//! // predict 5 steps ahead: particle clouds with means, covariances and quantiles
//! let ahead = mkpf.predict(5, &mut rng)?;
//! let spread = ahead[4].quantile(0, 0.95)? - ahead[4].quantile(0, 0.05)?;
//! assert!(spread > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]

pub mod cloud;
pub mod driver;
pub mod error;
mod gauss;
pub mod mkpf;
pub mod pf;
pub mod resample;
pub mod weights;

pub use cloud::ParticleCloud;
pub use error::{ParticleError, Result};
pub use mkpf::{EkfStage, Mkpf, ParticlePrior, UkfVariant};
pub use pf::{ParticleFilter, ParticleFiltering, PfConfig, StepSummary};
pub use resample::{
    Multinomial, Resampler, Resampling, Residual, Stratified, Systematic, multinomial_indices,
    residual_indices, stratified_indices, systematic_indices,
};
pub use weights::{
    ResamplePolicy, effective_sample_size, effective_sample_size_log, log_sum_exp,
    normalize_log_weights, weights_from_log_into,
};
