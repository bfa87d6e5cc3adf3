//! The particle filters under the filter driver of `trajpred-kalman`
//! ([`trajpred_kalman::driver`]): [`TimedParticles`] runs a [`ParticleFilter`] or an
//! [`Mkpf`] by time steps, rebuilding its transition (and so its process noise)
//! when the step changes, with its own injected random number generator.
//!
//! ```
//! use nalgebra::{Matrix2, Matrix2x4, Matrix4, U2, U4, Vector2, Vector4};
//! use rand::SeedableRng;
//! use rand_chacha::ChaCha8Rng;
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::driver::{TimeStepFilter, drive};
//! use trajpred_kalman::motion::{StateOrder, constant_velocity};
//! use trajpred_kalman::LinearObservation;
//! use trajpred_particle::{ParticleFilter, driver::TimedParticles};
//!
//! let make = |dt: f64| constant_velocity::<f64, U4>(2, dt, 0.5, StateOrder::PositionsFirst);
//! let obs = LinearObservation::new(
//!     Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
//!     Matrix2::identity() * 4.0,
//! )?;
//! let start = Gaussian::new(Vector4::new(0.0, 0.0, 1.0, 0.0), Matrix4::identity() * 4.0)?;
//! let mut rng = ChaCha8Rng::seed_from_u64(7);
//! let pf = ParticleFilter::<f64, U4, U2, _, _>::from_gaussian(make(1.0)?, obs, &start, 400, &mut rng)?;
//! let mut f = TimedParticles::new(make, pf, 1.0, rng);
//! let times = [0.0, 1.0, 2.0, 4.0];
//! let z = [None, Some(Vector2::new(1.0, 0.0)), Some(Vector2::new(2.1, 0.0)), Some(Vector2::new(3.9, 0.1))];
//! let est = drive(&mut f, &times, &z, |_, _| Ok(()))?;
//! assert!((est[2].mean[0] - 4.0).abs() < 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::alloc::ParticleAllocator;
use crate::error::{ParticleError, Result};
use crate::mkpf::Mkpf;
use crate::pf::{ParticleFilter, ParticleFiltering};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OVector, RealField};
use rand::Rng;
use trajpred_core::Gaussian;
use trajpred_kalman::driver::{TimeStepFilter, check_dt};
use trajpred_kalman::{
    NoisyObservation, NoisyTransition, Observation, ObservationJacobian, Transition,
    TransitionJacobian,
};

/// A particle filter whose transition can be replaced (for another time step).
pub trait WithTransition<Tr>: Sized {
    /// The same filter with `transition` in place of its own.
    fn with_transition(&self, transition: Tr) -> Result<Self>;
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> WithTransition<Tr>
    for ParticleFilter<T, D, M, Tr, Ob>
where
    Tr: Transition<T, D> + Sync,
    Ob: Observation<T, D, M> + Sync + Clone,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    fn with_transition(&self, transition: Tr) -> Result<Self> {
        ParticleFilter::with_transition(self, transition)
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, Tr, Ob> WithTransition<Tr> for Mkpf<T, D, M, Tr, Ob>
where
    Tr: TransitionJacobian<T, D> + NoisyTransition<T, D> + Sync,
    Ob: ObservationJacobian<T, D, M> + NoisyObservation<T, D, M> + Sync + Clone,
    DefaultAllocator: ParticleAllocator<T, D, M>,
{
    fn with_transition(&self, transition: Tr) -> Result<Self> {
        Mkpf::with_transition(self, transition)
    }
}

/// A particle filter run by time steps: `make(dt)` builds the transition of a step of `dt`
/// seconds; when the step changes the filter takes the new transition
/// ([`WithTransition`]). The generator `rng` drives every random draw, so a seed reproduces a
/// run exactly.
#[derive(Debug, Clone)]
pub struct TimedParticles<T, F, Make, R> {
    make: Make,
    filter: F,
    dt: T,
    rng: R,
}

impl<T, F, Make, R> TimedParticles<T, F, Make, R> {
    /// Runs `filter`, whose transition was built for steps of `dt` seconds.
    pub fn new(make: Make, filter: F, dt: T, rng: R) -> Self {
        TimedParticles {
            make,
            filter,
            dt,
            rng,
        }
    }

    /// The filter as it stands.
    pub fn filter(&self) -> &F {
        &self.filter
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, F, Tr, Make, R> TimeStepFilter<T, D, M>
    for TimedParticles<T, F, Make, R>
where
    F: ParticleFiltering<T, D, M> + WithTransition<Tr>,
    Tr: Transition<T, D>,
    Make: Fn(T) -> trajpred_kalman::Result<Tr>,
    R: Rng,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M> + Allocator<M, M>,
{
    type Error = ParticleError;

    fn advance(&mut self, dt: T, z: Option<&OVector<T, M>>) -> Result<()> {
        check_dt(dt, "dt")?;
        if dt != self.dt {
            self.filter = self.filter.with_transition((self.make)(dt)?)?;
            self.dt = dt;
        }
        self.filter.step(z, &mut self.rng)?;
        Ok(())
    }

    fn estimate(&self) -> Result<Gaussian<T, D>> {
        Ok(self.filter.cloud().estimate())
    }

    /// The weighted mean of the particles pushed through the transition of each offset
    /// without noise (the expected state: the process noise has mean zero), and their
    /// weighted covariance plus that transition's `Q`.
    fn forecast_at(&self, offsets: &[T]) -> Result<Vec<Gaussian<T, D>>> {
        let cloud = self.filter.cloud();
        let w: Vec<T> = cloud
            .weights()
            .into_iter()
            .map(nalgebra::convert::<f64, T>)
            .collect();
        offsets
            .iter()
            .map(|&dt| {
                check_dt(dt, "forecast offset")?;
                let tr = (self.make)(dt)?;
                let moved = cloud
                    .particles()
                    .iter()
                    .map(|x| tr.transition(x))
                    .collect::<trajpred_kalman::Result<Vec<_>>>()?;
                let q = tr.process_noise();
                let mut mean =
                    OVector::<T, D>::zeros_generic(D::from_usize(q.nrows()), nalgebra::U1);
                for (y, &wi) in moved.iter().zip(&w) {
                    for c in 0..mean.nrows() {
                        mean[c] += wi * y[c];
                    }
                }
                let mut covariance = q.clone();
                for (y, &wi) in moved.iter().zip(&w) {
                    let r = y - &mean;
                    covariance.ger(wi, &r, &r, T::one());
                }
                Ok(Gaussian { mean, covariance })
            })
            .collect()
    }
}
