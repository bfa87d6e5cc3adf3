//! The interacting multiple model (IMM) filter: `r` mode-matched Gaussian filters on one
//! state space, switching by a Markov chain (Blom and Bar-Shalom; the recursion of filterpy's
//! `IMMEstimator`, which the tests match to 1e-10).
//!
//! One step from the mode states `N(x_i, P_i)` and mode probabilities `mu_i`, with the
//! transition matrix `M[i][j] = P(mode j now | mode i before)`:
//!
//! ```text
//! mixing      cbar_j = sum_i M[i][j] mu_i               (predicted mode probabilities)
//!             w_ij  = M[i][j] mu_i / cbar_j             (mixing probabilities)
//!             x0_j  = sum_i w_ij x_i
//!             P0_j  = sum_i w_ij (P_i + (x_i - x0_j)(x_i - x0_j)^T)
//! mode step   N(x_j, P_j) = filter_j.predict(N(x0_j, P0_j)), then its update by z,
//!             with ln L_j = ln N(y_j; 0, S_j)
//! modes       mu_j = cbar_j L_j / sum_i cbar_i L_i      (log-sum-exp, see below)
//!             ln L = ln sum_j cbar_j L_j                (the IMM's measurement likelihood)
//! combined    x = sum_j mu_j x_j,  P = sum_j mu_j (P_j + (x_j - x)(x_j - x)^T)
//! ```
//!
//! Without an observation the mode probabilities become `cbar`; a k-step [`Imm::forecast`]
//! repeats mixing and mode-matched prediction `k` times, so the mode probabilities follow
//! `mu M^k` and each forecast's combined moments are those of the mixture.
//!
//! **Likelihoods.** The mode likelihoods are never exponentiated alone: the new mode
//! probabilities are `exp(a_j - max a) / sum_i exp(a_i - max a)` with
//! `a_j = ln cbar_j + ln L_j`, so a step in which every mode's likelihood is below the
//! range of `f64` (`ln L_j < -745`, an observation far from every mode) still gives the exact
//! posterior mode probabilities and a finite `ln L`. (filterpy floors each likelihood at
//! `2.2e-308` and so returns `cbar` in that case.) A mode whose `ln L_j` is `-inf` or NaN, or
//! whose `cbar_j` is 0, gets probability 0; when no mode is left the step fails with
//! [`trajpred_core::Error::NonFinite`] (`"IMM mode log-likelihoods"`).
//!
//! **Unreachable modes.** When `cbar_j = 0` (no mode switches into `j`: a zero column of
//! `M`, or only modes of probability 0 do), `w_ij` is undefined; mode `j` then starts from
//! the combined estimate (`w_ij = mu_i`). It carries no weight until it becomes reachable.
//!
//! **One recursion.** [`Imm::filter`] and [`Imm::forecast`] run through
//! [`driver::scan`](crate::driver::scan), and [`TimedImm`] makes the IMM a
//! [`TimeStepFilter`] for [`drive`](crate::driver::drive). The IMM is not a
//! [`Filter`]: that trait's steps map one Gaussian to one Gaussian, while the IMM's state is
//! the `r` mode Gaussians and their probabilities (the combined Gaussian alone cannot be
//! mixed again). The mode filters are any [`Filter`]s of one state and observation size;
//! modes of different types go in as `Box<dyn Filter<T, D, M>>`.
//!
//! Decisions the method leaves open are in `docs/kalman.md` (section "IMM").
//!
//! ```
//! use nalgebra::{DMatrix, Matrix5, U2, U5, Vector2, Vector5};
//! use trajpred_core::Gaussian;
//! use trajpred_kalman::imm::{
//!     Imm, ImmState, constant_velocity_in_turn_state, coordinated_turn_continuous,
//!     turn_state_position_observation,
//! };
//! use trajpred_kalman::{Ekf, Filter, Kf};
//!
//! // state [x, vx, y, vy, omega]; a CV mode and a coordinated-turn mode (EKF), 1 s steps,
//! // positions observed with variance 4
//! let obs = turn_state_position_observation::<f64>(4.0)?;
//! let cv = Kf::new(constant_velocity_in_turn_state::<f64>(1.0, 0.05)?, obs.clone())?;
//! let ct = Ekf::new(coordinated_turn_continuous::<f64>(1.0, 0.05, 1e-4)?, obs)?;
//! let modes: Vec<Box<dyn Filter<f64, U5, U2>>> = vec![Box::new(cv), Box::new(ct)];
//! let imm = Imm::new(modes, DMatrix::from_row_slice(2, 2, &[0.95, 0.05, 0.05, 0.95]))?;
//!
//! // a target turning at 0.1 rad/s at 10 m/s
//! let start = Gaussian::new(Vector5::new(0.0, 10.0, 0.0, 0.0, 0.0),
//!                           Matrix5::from_diagonal(&Vector5::new(4.0, 4.0, 4.0, 4.0, 0.01)))?;
//! let zs: Vec<Option<Vector2<f64>>> = (1..=40)
//!     .map(|k| {
//!         let a = 0.1 * k as f64;
//!         Some(Vector2::new(100.0 * a.sin(), 100.0 * (1.0 - a.cos())))
//!     })
//!     .collect();
//! let steps = imm.filter(&ImmState::uniform(start, 2)?, &zs)?;
//! let last = &steps.last().unwrap().state;
//! assert!(last.probabilities()[1] > 0.8); // the turn mode explains the track
//! assert!((last.combined()?.mean[4] - 0.1).abs() < 0.01); // and its turn rate
//!
//! // 5-step forecast with covariance: the mixture's moments at each step
//! let ahead = imm.forecast(last, 5)?;
//! assert!(ahead[4].combined()?.covariance[(0, 0)] > last.combined()?.covariance[(0, 0)]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::alloc::FilterAllocator;
use crate::driver::{TimeStepFilter, check_dt, scan};
use crate::error::{KalmanError, Result};
use crate::filter::Filter;
use crate::linalg::{check_dim, check_finite, symmetrise};
use crate::model::{LinearObservation, LinearTransition};
use crate::motion::{CoordinatedTurn, KinematicLayout, StateOrder, kinematic_continuous};
use nalgebra::allocator::Allocator;
use nalgebra::{
    DMatrix, DefaultAllocator, Dim, Matrix2, Matrix2x5, Matrix5, OMatrix, OVector, RealField, U2,
    U4, U5,
};
use trajpred_core::Error as CoreError;
use trajpred_core::Gaussian;

/// How far a row of the transition matrix (or the initial mode probabilities) may sum from 1;
/// within it the row is divided by its sum.
pub const ROW_SUM_TOLERANCE: f64 = 1e-9;

/// The IMM's estimate: one Gaussian per mode and the mode probabilities.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmState<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    modes: Vec<Gaussian<T, D>>,
    probabilities: Vec<T>,
}

impl<T: RealField + Copy, D: Dim> ImmState<T, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// A state from the mode Gaussians and their probabilities (finite, non-negative, summing
    /// to 1 within [`ROW_SUM_TOLERANCE`]; then normalised). The Gaussians are validated by
    /// the mode filters at the first step.
    pub fn new(modes: Vec<Gaussian<T, D>>, probabilities: Vec<T>) -> Result<Self> {
        if modes.is_empty() {
            return Err(CoreError::Empty { what: "IMM modes" }.into());
        }
        check_dim("mode probabilities", modes.len(), probabilities.len())?;
        let n = modes[0].mean.nrows();
        for g in &modes {
            check_dim("IMM mode state", n, g.mean.nrows())?;
        }
        let probabilities = normalised_row(&probabilities, "mode probabilities")?;
        Ok(ImmState {
            modes,
            probabilities,
        })
    }

    /// Every one of `r` modes starting from `start`, with probability `1 / r` each.
    pub fn uniform(start: Gaussian<T, D>, r: usize) -> Result<Self> {
        let p = T::one() / nalgebra::convert::<f64, T>(r as f64);
        Self::new(vec![start; r], vec![p; r])
    }

    /// The mode Gaussians.
    pub fn modes(&self) -> &[Gaussian<T, D>] {
        &self.modes
    }

    /// The mode probabilities (summing to 1).
    pub fn probabilities(&self) -> &[T] {
        &self.probabilities
    }

    /// The combined estimate: the mean and covariance of the mixture
    /// `sum_j mu_j N(x_j, P_j)`. Errors with [`trajpred_core::Error::NonFinite`] when they overflow
    /// (modes of finite but huge means far apart).
    pub fn combined(&self) -> Result<Gaussian<T, D>> {
        let g = moments(&self.probabilities, &self.modes);
        check_finite(&g.mean, "IMM combined mean")?;
        check_finite(&g.covariance, "IMM combined covariance")?;
        Ok(g)
    }
}

/// The mean and covariance of the mixture `sum_i w_i N(x_i, P_i)` (`w` summing to 1):
/// `x = sum w_i x_i`, `P = sum w_i (P_i + (x_i - x)(x_i - x)^T)`, exactly symmetric.
fn moments<T, D>(w: &[T], gs: &[Gaussian<T, D>]) -> Gaussian<T, D>
where
    T: RealField + Copy,
    D: Dim,
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let (rows, _) = gs[0].mean.shape_generic();
    let mut mean = OVector::<T, D>::zeros_generic(rows, nalgebra::Const::<1>);
    for (g, &wi) in gs.iter().zip(w) {
        mean.axpy(wi, &g.mean, T::one());
    }
    let mut cov = OMatrix::<T, D, D>::zeros_generic(rows, rows);
    for (g, &wi) in gs.iter().zip(w) {
        let d = &g.mean - &mean;
        let n = d.nrows();
        for j in 0..n {
            for i in 0..n {
                cov[(i, j)] += wi * (d[i] * d[j] + g.covariance[(i, j)]);
            }
        }
    }
    symmetrise(&mut cov);
    Gaussian {
        mean,
        covariance: cov,
    }
}

/// Validates a probability row (finite, non-negative, summing to 1 within
/// [`ROW_SUM_TOLERANCE`]) and divides it by its sum.
fn normalised_row<T: RealField + Copy>(row: &[T], what: &'static str) -> Result<Vec<T>> {
    if let Some(i) = row.iter().position(|p| !p.is_finite()) {
        return Err(CoreError::NonFinite { what, index: i }.into());
    }
    if let Some(p) = row.iter().find(|&&p| p < T::zero()) {
        return Err(CoreError::InvalidParameter {
            name: what,
            reason: format!("probabilities must be >= 0, got {p}"),
        }
        .into());
    }
    let sum = row.iter().fold(T::zero(), |a, &p| a + p);
    if (sum - T::one()).abs() > nalgebra::convert(ROW_SUM_TOLERANCE) {
        return Err(CoreError::InvalidParameter {
            name: what,
            reason: format!("must sum to 1 (within {ROW_SUM_TOLERANCE:e}), got {sum}"),
        }
        .into());
    }
    Ok(row.iter().map(|&p| p / sum).collect())
}

/// One IMM step: the predicted mode probabilities, the new state and the likelihoods.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmStep<T: RealField, D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// `cbar = mu M`: the mode probabilities before the observation.
    pub predicted_probabilities: Vec<T>,
    /// The mode states and probabilities after the step (the predictions and `cbar` when
    /// the observation was missing).
    pub state: ImmState<T, D>,
    /// `ln L_j` of each mode's update; empty when the observation was missing.
    pub mode_log_likelihoods: Vec<T>,
    /// `ln sum_j cbar_j L_j`, the IMM's log-likelihood of the observation (0 when missing).
    pub log_likelihood: T,
}

/// The mixing stage's result: `cbar` and each mode's mixed start.
type Mixed<T, D> = (Vec<T>, Vec<Gaussian<T, D>>);

/// The IMM filter over the mode filters `F` (see the module documentation).
#[derive(Debug, Clone)]
pub struct Imm<T: RealField, F> {
    modes: Vec<F>,
    transition: DMatrix<T>,
}

impl<T: RealField + Copy, F> Imm<T, F> {
    /// An IMM from its mode filters and the Markov transition matrix
    /// `M[i][j] = P(mode j | mode i)` (`r x r` for `r` modes; rows of finite non-negative
    /// entries summing to 1 within [`ROW_SUM_TOLERANCE`], then normalised).
    pub fn new(modes: Vec<F>, transition: DMatrix<T>) -> Result<Self> {
        let r = modes.len();
        if r == 0 {
            return Err(CoreError::Empty { what: "IMM modes" }.into());
        }
        check_dim("transition matrix rows", r, transition.nrows())?;
        check_dim("transition matrix columns", r, transition.ncols())?;
        check_finite(&transition, "transition matrix")?;
        let mut m = transition;
        for i in 0..r {
            let row: Vec<T> = m.row(i).iter().copied().collect();
            let row = normalised_row(&row, "transition matrix row")?;
            for (j, v) in row.into_iter().enumerate() {
                m[(i, j)] = v;
            }
        }
        Ok(Imm {
            modes,
            transition: m,
        })
    }

    /// The mode filters.
    pub fn modes(&self) -> &[F] {
        &self.modes
    }

    /// The (row-normalised) transition matrix.
    pub fn transition_matrix(&self) -> &DMatrix<T> {
        &self.transition
    }

    /// The mixing stage: `cbar` and the mixed start `N(x0_j, P0_j)` of every mode.
    fn mix<D: Dim>(&self, state: &ImmState<T, D>) -> Result<Mixed<T, D>>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let r = self.modes.len();
        check_dim("IMM state modes", r, state.modes.len())?;
        let mu = &state.probabilities;
        let mut cbar = Vec::with_capacity(r);
        let mut mixed = Vec::with_capacity(r);
        let mut w = vec![T::zero(); r];
        for j in 0..r {
            let c = (0..r).fold(T::zero(), |a, i| a + self.transition[(i, j)] * mu[i]);
            for (i, wi) in w.iter_mut().enumerate() {
                *wi = if c > T::zero() {
                    self.transition[(i, j)] * mu[i] / c
                } else {
                    mu[i]
                };
            }
            cbar.push(c);
            mixed.push(moments(&w, &state.modes));
        }
        Ok((cbar, mixed))
    }

    /// The prediction: mixing, then every mode's prediction; the mode probabilities become
    /// `cbar = mu M`.
    pub fn predict<D: Dim, M: Dim>(&self, state: &ImmState<T, D>) -> Result<ImmState<T, D>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        self.predict_checked(state, false)
    }

    fn predict_checked<D: Dim, M: Dim>(
        &self,
        state: &ImmState<T, D>,
        own_output: bool,
    ) -> Result<ImmState<T, D>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let (cbar, mixed) = self.mix(state)?;
        let modes = self
            .modes
            .iter()
            .zip(&mixed)
            .map(|(f, g)| {
                if own_output {
                    f.predict_own_output(g)
                } else {
                    f.predict(g)
                }
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ImmState {
            modes,
            probabilities: cbar,
        })
    }

    /// One step: mixing, the modes' predictions and, when `z` is `Some`, their updates and
    /// the new mode probabilities. The input state is validated in full by the mode filters.
    pub fn step<D: Dim, M: Dim>(
        &self,
        state: &ImmState<T, D>,
        z: Option<&OVector<T, M>>,
    ) -> Result<ImmStep<T, D>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        self.step_checked(state, z, false)
    }

    /// [`Imm::step`]; `own_output` when `state` came from this IMM (the mixed covariances,
    /// convex combinations of the filters' own outputs, are then checked without a
    /// factorisation, as [`Filter::predict_own_output`] does).
    fn step_checked<D: Dim, M: Dim>(
        &self,
        state: &ImmState<T, D>,
        z: Option<&OVector<T, M>>,
        own_output: bool,
    ) -> Result<ImmStep<T, D>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        let Some(z) = z else {
            let state = self.predict_checked(state, own_output)?;
            return Ok(ImmStep {
                predicted_probabilities: state.probabilities.clone(),
                state,
                mode_log_likelihoods: Vec::new(),
                log_likelihood: T::zero(),
            });
        };
        let (cbar, mixed) = self.mix(state)?;
        let r = self.modes.len();
        let mut modes = Vec::with_capacity(r);
        let mut lls = Vec::with_capacity(r);
        for (f, g) in self.modes.iter().zip(&mixed) {
            let (_, update) = f.predict_update(g, z, own_output)?;
            lls.push(update.log_likelihood());
            modes.push(update.posterior);
        }
        // a_j = ln cbar_j + ln L_j; None drops the mode (cbar_j = 0, ln L_j = -inf or NaN)
        let a: Vec<Option<T>> = cbar
            .iter()
            .zip(&lls)
            .map(|(&c, &l)| (c > T::zero() && l.is_finite()).then(|| c.ln() + l))
            .collect();
        let top = a
            .iter()
            .flatten()
            .fold(None, |m: Option<T>, &v| Some(m.map_or(v, |m| m.max(v))));
        let Some(top) = top else {
            return Err(CoreError::NonFinite {
                what: "IMM mode log-likelihoods",
                index: lls.iter().position(|l| !l.is_finite()).unwrap_or(0),
            }
            .into());
        };
        let e: Vec<T> = a
            .iter()
            .map(|v| v.map_or(T::zero(), |v| (v - top).exp()))
            .collect();
        let sum = e.iter().fold(T::zero(), |s, &v| s + v);
        let probabilities: Vec<T> = e.iter().map(|&v| v / sum).collect();
        Ok(ImmStep {
            predicted_probabilities: cbar,
            state: ImmState {
                modes,
                probabilities,
            },
            mode_log_likelihoods: lls,
            log_likelihood: top + sum.ln(),
        })
    }

    /// Runs [`Imm::step`] over a sequence (`None`: a missing observation) from `initial`.
    pub fn filter<D: Dim, M: Dim>(
        &self,
        initial: &ImmState<T, D>,
        observations: &[Option<OVector<T, M>>],
    ) -> Result<Vec<ImmStep<T, D>>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        scan(observations, |prev: Option<&ImmStep<T, D>>, z| match prev {
            Some(prev) => self.step_checked(&prev.state, z.as_ref(), true),
            None => self.step(initial, z.as_ref()),
        })
    }

    /// The forecast `j = 1..=steps` steps ahead: [`Imm::predict`] repeated (mode
    /// probabilities `mu M^j`). [`ImmState::combined`] gives each step's mean and covariance.
    pub fn forecast<D: Dim, M: Dim>(
        &self,
        state: &ImmState<T, D>,
        steps: usize,
    ) -> Result<Vec<ImmState<T, D>>>
    where
        F: Filter<T, D, M>,
        DefaultAllocator: FilterAllocator<D, M>,
    {
        scan(0..steps, |prev: Option<&ImmState<T, D>>, _| match prev {
            Some(prev) => self.predict_checked(prev, true),
            None => self.predict(state),
        })
    }
}

/// The transition matrix over `dt` seconds of `modes` modes that switch at random, every
/// switch to any other mode alike, staying in a mode `mean_sojourn` seconds on average: the
/// continuous-time chain with generator `G = k (1 1^T / r - I)`, `k = r / ((r - 1) tau)`,
/// whose `exp(G dt)` has `M[i][i] = 1/r + (1 - 1/r) e` and `M[i][j] = (1 - e) / r`,
/// `e = exp(-k dt)`. Two steps of `dt / 2` give one step of `dt`.
///
/// ```
/// use trajpred_kalman::imm::uniform_switching;
/// let m = uniform_switching::<f64>(2, 1.0, 10.0)?;
/// // leaving rate 1/10 per second: stay with probability (1 + exp(-0.2)) / 2
/// assert!((m[(0, 0)] - (1.0 + (-0.2f64).exp()) / 2.0).abs() < 1e-15);
/// assert!((&m * &m - uniform_switching::<f64>(2, 2.0, 10.0)?).amax() < 1e-15);
/// # Ok::<(), trajpred_kalman::KalmanError>(())
/// ```
pub fn uniform_switching<T: RealField + Copy>(
    modes: usize,
    dt: f64,
    mean_sojourn: f64,
) -> Result<DMatrix<T>> {
    if modes == 0 {
        return Err(CoreError::Empty { what: "IMM modes" }.into());
    }
    check_dt(dt, "dt")?;
    if !(mean_sojourn.is_finite() && mean_sojourn > 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "mean_sojourn",
            reason: format!("must be finite and positive, got {mean_sojourn}"),
        }
        .into());
    }
    if modes == 1 {
        return Ok(DMatrix::from_element(1, 1, T::one()));
    }
    let r = modes as f64;
    let e = (-r / ((r - 1.0) * mean_sojourn) * dt).exp();
    let (stay, leave) = (1.0 / r + (1.0 - 1.0 / r) * e, (1.0 - e) / r);
    Ok(DMatrix::from_fn(modes, modes, |i, j| {
        nalgebra::convert(if i == j { stay } else { leave })
    }))
}

/// Constant velocity on the coordinated-turn state `[x, vx, y, vy, omega]`
/// ([`CoordinatedTurn`]'s): the position-velocity blocks of [`kinematic_continuous`]
/// (continuous white-noise acceleration of density `spectral_density`), and the turn rate
/// carried unchanged without noise (it does not move the target in this mode; mixing
/// passes it to the turn mode).
pub fn constant_velocity_in_turn_state<T: RealField + Copy>(
    dt: f64,
    spectral_density: f64,
) -> Result<LinearTransition<T, U5>> {
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks)?;
    let cv = kinematic_continuous::<T, U4>(layout, dt, spectral_density)?;
    let mut f = Matrix5::<T>::identity();
    let mut q = Matrix5::<T>::zeros();
    f.fixed_view_mut::<4, 4>(0, 0).copy_from(cv.f());
    q.fixed_view_mut::<4, 4>(0, 0).copy_from(cv.q());
    LinearTransition::new(f, q)
}

/// The coordinated turn with continuous white noise: acceleration of density
/// `accel_density` on each axis (the position-velocity blocks of
/// [`kinematic_continuous`]) and a turn rate that random-walks with density
/// `turn_rate_density` (`Q[4][4] = turn_rate_density dt`), so that, as for the kinematic
/// models, the noise follows the length of the step.
pub fn coordinated_turn_continuous<T: RealField + Copy>(
    dt: f64,
    accel_density: f64,
    turn_rate_density: f64,
) -> Result<CoordinatedTurn<T>> {
    let mut q = *constant_velocity_in_turn_state::<T>(dt, accel_density)?.q();
    if !(turn_rate_density.is_finite() && turn_rate_density >= 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "turn_rate_density",
            reason: format!("must be finite and >= 0, got {turn_rate_density}"),
        }
        .into());
    }
    q[(4, 4)] = nalgebra::convert(turn_rate_density * dt);
    CoordinatedTurn::with_process_noise(dt, q)
}

/// The observation of the position `(x, y)` of the turn state `[x, vx, y, vy, omega]`, with
/// independent noise of variance `var` per axis.
pub fn turn_state_position_observation<T: RealField + Copy>(
    var: f64,
) -> Result<LinearObservation<T, U5, U2>> {
    let mut h = Matrix2x5::<T>::zeros();
    h[(0, 0)] = T::one();
    h[(1, 2)] = T::one();
    if !(var.is_finite() && var > 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "var",
            reason: format!("observation variance must be finite and positive, got {var}"),
        }
        .into());
    }
    LinearObservation::new(h, Matrix2::identity() * nalgebra::convert::<f64, T>(var))
}

/// An [`Imm`] run by time steps, for [`drive`](crate::driver::drive): `make(dt)` builds the
/// IMM (its mode filters and transition matrix) for a step of `dt` seconds; the last one
/// built is reused while the step stays the same.
#[derive(Debug, Clone)]
pub struct TimedImm<T: RealField, D: Dim, F, Make>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    make: Make,
    state: ImmState<T, D>,
    built: Option<(T, Imm<T, F>)>,
    log_likelihood: T,
    own_output: bool,
}

impl<T: RealField + Copy, D: Dim, F, Make> TimedImm<T, D, F, Make>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// An IMM starting from `state`, `make` building it for each time step.
    pub fn new(make: Make, state: ImmState<T, D>) -> Self {
        TimedImm {
            make,
            state,
            built: None,
            log_likelihood: T::zero(),
            own_output: false,
        }
    }

    /// The total log-likelihood `sum_k ln L_k` of the observations so far.
    pub fn log_likelihood(&self) -> T {
        self.log_likelihood
    }

    /// The current mode states and probabilities.
    pub fn state(&self) -> &ImmState<T, D> {
        &self.state
    }
}

impl<T: RealField + Copy, D: Dim, M: Dim, F, Make> TimeStepFilter<T, D, M>
    for TimedImm<T, D, F, Make>
where
    F: Filter<T, D, M>,
    Make: Fn(T) -> Result<Imm<T, F>>,
    DefaultAllocator: FilterAllocator<D, M>,
{
    type Error = KalmanError;

    fn advance(&mut self, dt: T, z: Option<&OVector<T, M>>) -> Result<()> {
        check_dt(dt, "dt")?;
        let imm = match self.built.take() {
            Some((built_dt, imm)) if built_dt == dt => imm,
            _ => (self.make)(dt)?,
        };
        let result = imm.step_checked(&self.state, z, self.own_output);
        self.built = Some((dt, imm));
        let step = result?;
        self.log_likelihood += step.log_likelihood;
        self.state = step.state;
        self.own_output = true;
        Ok(())
    }

    fn estimate(&self) -> Result<Gaussian<T, D>> {
        self.state.combined()
    }

    fn forecast_at(&self, offsets: &[T]) -> Result<Vec<Gaussian<T, D>>> {
        offsets
            .iter()
            .map(|&dt| {
                check_dt(dt, "forecast offset")?;
                let state = match &self.built {
                    Some((built_dt, imm)) if *built_dt == dt => imm.predict(&self.state),
                    _ => (self.make)(dt)?.predict(&self.state),
                }?;
                state.combined()
            })
            .collect()
    }
}
