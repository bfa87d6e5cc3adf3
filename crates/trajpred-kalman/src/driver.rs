//! The filter driver: one small trait that every filter of trajpred implements, and one loop
//! that runs any of them over a track sampled at irregular times, with missing observations.
//!
//! A [`TimeStepFilter`] holds its current estimate and advances it by a time step `dt`
//! (building whatever model that step needs), updates it with an observation when there is
//! one, and forecasts at time offsets after it. [`drive`] is the loop; [`Timed`] makes any
//! Gaussian [`Filter`] (KF, EKF, UKF, augmented UKF) a `TimeStepFilter` from a function that
//! builds the filter for a time step, and `trajpred-particle` does the same for its particle
//! filters (the MKPF proposal needs the observation inside the step, which is why the trait
//! advances and updates in one call).
//!
//! ```
//! use nalgebra::{Vector2, Vector4};
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::driver::{Timed, TimeStepFilter, drive};
//! use trajpred_kalman::motion::{StateOrder, constant_velocity};
//! use trajpred_kalman::{Kf, KalmanError, LinearObservation, LinearTransition};
//! use nalgebra::{Matrix2, Matrix2x4, Matrix4, U4};
//!
//! // constant velocity in 2-D, white-noise acceleration; the model is built for each step
//! let make = |dt: f64| -> Result<_, KalmanError> {
//!     let cv = constant_velocity::<f64, U4>(2, dt, 0.5, StateOrder::PositionsFirst)?;
//!     let obs = LinearObservation::new(
//!         Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
//!         Matrix2::identity() * 4.0,
//!     )?;
//!     Kf::new(cv, obs)
//! };
//! let start = Gaussian::new(Vector4::new(0.0, 0.0, 1.0, 0.0), Matrix4::identity() * 10.0)?;
//! let mut f = Timed::new(make, start);
//! // fixes at irregular times, one missing
//! let times = [0.0, 1.0, 2.5, 3.0, 5.0];
//! let z = [None, Some(Vector2::new(1.1, 0.0)), None, Some(Vector2::new(3.0, 0.1)),
//!          Some(Vector2::new(5.1, -0.1))];
//! let estimates = drive(&mut f, &times, &z, |_, _| Ok(()))?;
//! assert_eq!(estimates.len(), 4); // one per time after the first
//! let ahead = f.forecast_at(&[1.0, 2.0])?;
//! assert!((ahead[1].mean[0] - 7.0).abs() < 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::alloc::FilterAllocator;
use crate::error::{KalmanError, Result};
use crate::filter::Filter;
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OVector, RealField};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

/// A filter that the driver can run: it holds its estimate, advances it over a time step
/// (and updates it when an observation comes), and forecasts ahead of it.
pub trait TimeStepFilter<T: RealField + Copy, D: Dim, M: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M>,
{
    /// The errors of the filter; the driver's own errors (a bad time step) convert into it.
    type Error: From<KalmanError>;

    /// Advances the estimate `dt > 0` seconds, then updates it with `z` when it is `Some`.
    fn advance(&mut self, dt: T, z: Option<&OVector<T, M>>)
    -> std::result::Result<(), Self::Error>;

    /// The current estimate.
    fn estimate(&self) -> std::result::Result<Gaussian<T, D>, Self::Error>;

    /// The forecasts `offsets[j]` seconds after the current estimate (each offset > 0, in
    /// any order), leaving the filter as it is. Each is one prediction over the whole offset.
    fn forecast_at(&self, offsets: &[T]) -> std::result::Result<Vec<Gaussian<T, D>>, Self::Error>;
}

/// Checks a time step: finite and positive.
pub fn check_dt<T: RealField + Copy>(dt: T, what: &'static str) -> Result<()> {
    if dt.is_finite() && dt > T::zero() {
        Ok(())
    } else {
        Err(CoreError::InvalidParameter {
            name: what,
            reason: format!("time step must be finite and positive, got {dt}"),
        }
        .into())
    }
}

/// The one recursion behind every run of a trajpred filter over a sequence: `step` is called
/// for each input in order with the output of the previous call (`None` for the first), and
/// the outputs are collected; the first error stops the run. [`drive`],
/// [`drive_each`], [`Filter::filter`], [`Filter::forecast`],
/// the IKF, the augmented UKF and the predictor form all run through it.
///
/// ```
/// use trajpred_kalman::driver::scan;
/// // running sums
/// let sums = scan([1, 2, 3], |prev: Option<&i32>, x| Ok::<_, ()>(prev.copied().unwrap_or(0) + x));
/// assert_eq!(sums, Ok(vec![1, 3, 6]));
/// ```
pub fn scan<I, S, E, F>(inputs: I, mut step: F) -> std::result::Result<Vec<S>, E>
where
    I: IntoIterator,
    F: FnMut(Option<&S>, I::Item) -> std::result::Result<S, E>,
{
    let inputs = inputs.into_iter();
    let mut out: Vec<S> = Vec::with_capacity(inputs.size_hint().0);
    for input in inputs {
        let next = step(out.last(), input)?;
        out.push(next);
    }
    Ok(out)
}

/// The driver's loop: the filter's estimate is at `times[0]`; for each later time it advances by
/// the interval and updates with the observation there (`None`: missing), then calls
/// `after(k, filter)` (for example to forecast from there, or to keep the estimate). Nothing
/// is collected: [`drive`] is this loop keeping every estimate. `observations[0]` is not used
/// (the estimate at `times[0]` is the filter's starting point); times must increase strictly.
pub fn drive_each<T, D, M, F, A>(
    filter: &mut F,
    times: &[T],
    observations: &[Option<OVector<T, M>>],
    mut after: A,
) -> std::result::Result<(), F::Error>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    F: TimeStepFilter<T, D, M> + ?Sized,
    A: FnMut(usize, &F) -> std::result::Result<(), F::Error>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M>,
{
    if times.len() != observations.len() {
        return Err(KalmanError::Core(CoreError::DimensionMismatch {
            what: "times vs observations",
            expected: times.len(),
            got: observations.len(),
        })
        .into());
    }
    // a `Vec<()>` never allocates
    scan(1..times.len(), |_, k| {
        let dt = times[k] - times[k - 1];
        check_dt(dt, "times")?;
        filter.advance(dt, observations[k].as_ref())?;
        after(k, filter)
    })
    .map(drop)
}

/// [`drive_each`] keeping the estimate after each time `times[1..]` (taken before
/// `after(k, filter)` is called), which it returns.
pub fn drive<T, D, M, F, A>(
    filter: &mut F,
    times: &[T],
    observations: &[Option<OVector<T, M>>],
    mut after: A,
) -> std::result::Result<Vec<Gaussian<T, D>>, F::Error>
where
    T: RealField + Copy,
    D: Dim,
    M: Dim,
    F: TimeStepFilter<T, D, M> + ?Sized,
    A: FnMut(usize, &F) -> std::result::Result<(), F::Error>,
    DefaultAllocator: Allocator<D> + Allocator<D, D> + Allocator<M>,
{
    let mut estimates = Vec::with_capacity(times.len().saturating_sub(1));
    drive_each(filter, times, observations, |k, f| {
        estimates.push(f.estimate()?);
        after(k, f)
    })?;
    Ok(estimates)
}

/// What builds the filter of a time step for [`Timed`]: any function `Fn(dt) -> Result<F>`,
/// or a type that can also rebuild a filter of another step in place
/// ([`StepBuilder::rebuild`], by default a new [`StepBuilder::build`] over it).
pub trait StepBuilder<T, F> {
    /// The filter for a step of `dt` seconds.
    fn build(&self, dt: T) -> Result<F>;

    /// `filter`, built for another step, made the filter for a step of `dt` seconds (the
    /// same value as [`StepBuilder::build`]`(dt)`); by default built anew. An in-place
    /// rebuild (a linear KF whose transition is rewritten,
    /// [`Kf::update_transition`](crate::Kf::update_transition)) moves no filter.
    fn rebuild(&self, dt: T, filter: &mut F) -> Result<()> {
        *filter = self.build(dt)?;
        Ok(())
    }
}

impl<T, F, Make: Fn(T) -> Result<F>> StepBuilder<T, F> for Make {
    fn build(&self, dt: T) -> Result<F> {
        self(dt)
    }
}

/// A Gaussian [`Filter`] run by time steps: `make(dt)` builds the filter (its transition and
/// noise) for a step of `dt` seconds; the last one built is kept and reused while the step
/// stays the same, so a regularly sampled track builds it once.
#[derive(Debug, Clone)]
pub struct Timed<T: RealField, D: Dim, F, Make>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    make: Make,
    state: Gaussian<T, D>,
    built: Option<(T, F)>,
    /// `None`: not summed ([`Timed::without_log_likelihood`]).
    log_likelihood: Option<T>,
}

impl<T, D, F, Make> Timed<T, D, F, Make>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// A filter starting from `state`, with `make` building the filter for each time step.
    pub fn new(make: Make, state: Gaussian<T, D>) -> Self {
        Timed {
            make,
            state,
            built: None,
            log_likelihood: Some(T::zero()),
        }
    }

    /// The same filter without summing the log-likelihood of its updates (one logarithm a
    /// step saved, for runs that only want the estimate, such as a forecast);
    /// [`Timed::log_likelihood`] is then `None`.
    pub fn without_log_likelihood(mut self) -> Self {
        self.log_likelihood = None;
        self
    }

    /// The total log-likelihood `sum_k ln N(y_k; 0, S_k)` of the observations this filter
    /// has been updated with (what a maximum-likelihood fit of the noise maximises); `None`
    /// after [`Timed::without_log_likelihood`].
    pub fn log_likelihood(&self) -> Option<T> {
        self.log_likelihood
    }

    /// The current estimate, by reference.
    pub fn state(&self) -> &Gaussian<T, D> {
        &self.state
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, F, Make> TimeStepFilter<T, D, M> for Timed<T, D, F, Make>
where
    F: Filter<T, D, M>,
    Make: StepBuilder<T, F>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    type Error = KalmanError;

    fn advance(&mut self, dt: T, z: Option<&OVector<T, M>>) -> Result<()> {
        check_dt(dt, "dt")?;
        // built in its slot, used by reference: a filter is never moved once built
        let filter = match &mut self.built {
            Some((built_dt, f)) if *built_dt == dt => &*f,
            Some((built_dt, f)) => {
                // on an error the slot holds no filter (a rebuild may have been left halfway)
                if let Err(e) = self.make.rebuild(dt, f) {
                    self.built = None;
                    return Err(e);
                }
                *built_dt = dt;
                &*f
            }
            slot => &slot.insert((dt, self.make.build(dt)?)).1,
        };
        let step = filter.step(&self.state, z)?;
        if let Some(sum) = &mut self.log_likelihood {
            *sum += step.log_likelihood();
        }
        self.state = step.into_posterior();
        Ok(())
    }

    fn estimate(&self) -> Result<Gaussian<T, D>> {
        Ok(self.state.clone())
    }

    /// The filter of the last step serves an offset equal to it; the others share one
    /// scratch filter, built for the first and rebuilt for each next
    /// ([`StepBuilder::rebuild`]).
    fn forecast_at(&self, offsets: &[T]) -> Result<Vec<Gaussian<T, D>>> {
        let mut scratch: Option<F> = None;
        offsets
            .iter()
            .map(|&dt| {
                check_dt(dt, "forecast offset")?;
                if let Some((built_dt, f)) = &self.built
                    && *built_dt == dt
                {
                    return f.predict(&self.state);
                }
                let f = match &mut scratch {
                    Some(f) => {
                        self.make.rebuild(dt, f)?;
                        &*f
                    }
                    None => &*scratch.insert(self.make.build(dt)?),
                };
                f.predict(&self.state)
            })
            .collect()
    }
}
