//! [`ParticleCloud`]: weighted particles and the estimates drawn from them (mean,
//! covariance, quantiles, effective sample size).

use crate::error::{ParticleError, Result};
use crate::weights::{effective_sample_size_log, normalize_log_weights};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, RealField};
use rand::Rng;
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;
use trajpred_kalman::sampling::{covariance_sqrt, draw, push_standard_normals};

/// Weighted particles `{x_i, w_i}`: the empirical approximation
/// `p(x) ~ sum_i w_i delta(x - x_i)` (`docs/papers.md` C eq. 2), with the weights kept in log space
/// and normalised (`sum_i exp(l_i) = 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleCloud<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    particles: Vec<OVector<T, D>>,
    log_weights: Vec<f64>,
}

impl<T: RealField + Copy, D: Dim> ParticleCloud<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Particles with log-weights (normalised here). Errors: [`trajpred_core::Error::Empty`],
    /// [`trajpred_core::Error::LengthMismatch`], [`trajpred_core::Error::DimensionMismatch`] (particles of
    /// different sizes or of size 0), [`trajpred_core::Error::NonFinite`] (a particle),
    /// [`ParticleError::InvalidWeight`], [`ParticleError::AllWeightsZero`].
    pub fn new(particles: Vec<OVector<T, D>>, mut log_weights: Vec<f64>) -> Result<Self> {
        let Some(first) = particles.first() else {
            return Err(CoreError::Empty { what: "particles" }.into());
        };
        if log_weights.len() != particles.len() {
            return Err(CoreError::LengthMismatch {
                what: "log-weights vs particles",
                expected: particles.len(),
                got: log_weights.len(),
            }
            .into());
        }
        let n = first.nrows();
        if n == 0 {
            return Err(CoreError::DimensionMismatch {
                what: "particle (state dimension must be at least 1)",
                expected: 1,
                got: 0,
            }
            .into());
        }
        for (i, p) in particles.iter().enumerate() {
            if p.nrows() != n {
                return Err(CoreError::DimensionMismatch {
                    what: "particle",
                    expected: n,
                    got: p.nrows(),
                }
                .into());
            }
            if first_non_finite(p).is_some() {
                return Err(CoreError::NonFinite {
                    what: "particle",
                    index: i,
                }
                .into());
            }
        }
        normalize_log_weights(&mut log_weights)?;
        Ok(ParticleCloud {
            particles,
            log_weights,
        })
    }

    /// Equally weighted particles.
    pub fn uniform(particles: Vec<OVector<T, D>>) -> Result<Self> {
        let n = particles.len();
        Self::new(particles, vec![0.0; n])
    }

    /// `n` equally weighted particles drawn from `N(mean, P)` (`P` may be singular).
    /// Errors: [`trajpred_core::Error::Empty`] for `n = 0`, [`trajpred_core::Error::NonFinite`],
    /// [`trajpred_core::Error::NotPositiveDefinite`].
    pub fn sample<R: Rng + ?Sized>(
        initial: &Gaussian<T, D>,
        n: usize,
        rng: &mut R,
    ) -> Result<Self> {
        if n == 0 {
            return Err(CoreError::Empty { what: "particles" }.into());
        }
        if let Some(index) = first_non_finite(&initial.mean) {
            return Err(CoreError::NonFinite {
                what: "initial mean",
                index,
            }
            .into());
        }
        let dim = initial.mean.nrows();
        if initial.covariance.nrows() != dim {
            return Err(CoreError::DimensionMismatch {
                what: "initial covariance vs mean",
                expected: dim,
                got: initial.covariance.nrows(),
            }
            .into());
        }
        let l = covariance_sqrt(&initial.covariance, "P")?;
        let mut noise: Vec<T> = Vec::new();
        push_standard_normals(rng, n * dim, &mut noise);
        let particles = noise
            .chunks(dim.max(1))
            .take(n)
            .map(|e| draw(&initial.mean, &l, e.iter().copied()))
            .collect();
        Self::uniform(particles)
    }

    /// Number of particles `N` (at least 1).
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Always `false`: a cloud holds at least one particle.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// The state dimension `n`.
    pub fn dim(&self) -> usize {
        self.particles[0].nrows()
    }

    /// The particles `x_i`.
    pub fn particles(&self) -> &[OVector<T, D>] {
        &self.particles
    }

    /// The normalised log-weights `ln w_i`.
    pub fn log_weights(&self) -> &[f64] {
        &self.log_weights
    }

    /// The normalised linear weights `w_i`.
    pub fn weights(&self) -> Vec<f64> {
        self.log_weights.iter().map(|l| l.exp()).collect()
    }

    /// The effective sample size `1 / sum w_i^2`.
    pub fn ess(&self) -> f64 {
        effective_sample_size_log(&self.log_weights).unwrap_or(0.0)
    }

    /// The weighted mean `sum_i w_i x_i`.
    pub fn mean(&self) -> OVector<T, D> {
        let mut m = self.particles[0].clone() * T::zero();
        for (x, &l) in self.particles.iter().zip(&self.log_weights) {
            let w: T = nalgebra::convert(l.exp());
            m.axpy(w, x, T::one());
        }
        m
    }

    /// The weighted covariance `sum_i w_i (x_i - m)(x_i - m)^T` (the plug-in estimate of
    /// the posterior covariance, no small-sample correction).
    pub fn covariance(&self) -> OMatrix<T, D, D> {
        self.estimate().covariance
    }

    /// Mean and covariance as a [`Gaussian`].
    pub fn estimate(&self) -> Gaussian<T, D> {
        let mean = self.mean();
        let d = mean.shape_generic().0;
        let mut cov = OMatrix::<T, D, D>::zeros_generic(d, d);
        for (x, &l) in self.particles.iter().zip(&self.log_weights) {
            let w: T = nalgebra::convert(l.exp());
            let r = x - &mean;
            cov.ger(w, &r, &r, T::one());
        }
        Gaussian {
            mean,
            covariance: cov,
        }
    }

    /// The weighted `q`-quantile of state component `component`: the smallest particle
    /// value `v` whose cumulative weight `sum_{x_i <= v} w_i` reaches `q` (the inverse of the
    /// weighted empirical distribution function; particles of zero weight are ignored).
    /// Errors: [`trajpred_core::Error::InvalidParameter`] for `q` outside `[0, 1]` or a component
    /// out of range.
    pub fn quantile(&self, component: usize, q: f64) -> Result<T> {
        if !(0.0..=1.0).contains(&q) {
            return Err(CoreError::InvalidParameter {
                name: "q",
                reason: format!("quantile level must be in [0, 1], got {q}"),
            }
            .into());
        }
        if component >= self.dim() {
            return Err(CoreError::InvalidParameter {
                name: "component",
                reason: format!("{component} >= state dimension {}", self.dim()),
            }
            .into());
        }
        let mut pairs: Vec<(T, f64)> = self
            .particles
            .iter()
            .zip(&self.log_weights)
            .map(|(x, &l)| (x[component], l.exp()))
            .filter(|&(_, w)| w > 0.0)
            .collect();
        pairs.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
        let total: f64 = pairs.iter().map(|p| p.1).sum();
        let target = q * total;
        let mut acc = 0.0;
        for &(v, w) in &pairs {
            acc += w;
            if acc >= target {
                return Ok(v);
            }
        }
        // rounding left the sum just below q * total: the largest value
        pairs
            .last()
            .map(|p| p.0)
            .ok_or(ParticleError::AllWeightsZero { count: self.len() })
    }

    /// The `q`-quantile of every component (see [`ParticleCloud::quantile`]).
    pub fn quantiles(&self, q: f64) -> Result<OVector<T, D>> {
        let mut out = self.particles[0].clone();
        for c in 0..self.dim() {
            out[c] = self.quantile(c, q)?;
        }
        Ok(out)
    }

    /// Mutable access for the filters of this crate (weights stay normalised by their
    /// callers).
    pub(crate) fn parts_mut(&mut self) -> (&mut Vec<OVector<T, D>>, &mut Vec<f64>) {
        (&mut self.particles, &mut self.log_weights)
    }
}

/// Index of the first non-finite element, if any.
pub(crate) fn first_non_finite<T: RealField + Copy, D: Dim>(v: &OVector<T, D>) -> Option<usize>
where
    DefaultAllocator: Allocator<D>,
{
    v.iter().position(|x| !x.is_finite())
}
