//! The inputs shared by the criterion benchmarks (`benches/kalman.rs`) and the timing loop
//! (`examples/profile_step_loop.rs`, which includes this file): the KF problems with their adskalman
//! twins, and the UKF problem.
#![allow(non_snake_case)]

use adskalman::{ObservationModel, StateAndCovariance, TransitionModelLinearNoControl};
use nalgebra::allocator::Allocator;
use nalgebra::{
    DefaultAllocator, DimMin, DimName, Matrix2, Matrix2x4, Matrix4, Matrix5, OMatrix, OVector,
    SMatrix, SVector, U2, U3, U4, U6, Vector2, Vector3, Vector4, Vector5,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trajpred_core::Gaussian;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, constant_velocity, position_observation,
};
use trajpred_kalman::{
    CoordinatedTurn, FilterAllocator, Kf, LinearObservation, LinearTransition, MerweSigmaPoints,
    RangeBearing, Ukf,
};

/// The dimensions of a KF problem: `N` states, `M` observed values, sizes known at compile
/// time as both filters need them.
pub trait Dims<N: DimName, M: DimName + DimMin<M, Output = M>>:
    FilterAllocator<N, M> + Allocator<N, N> + Allocator<M, M>
{
}

impl<N: DimName, M: DimName + DimMin<M, Output = M>> Dims<N, M> for DefaultAllocator where
    DefaultAllocator: FilterAllocator<N, M>
{
}

/// adskalman's transition model from our `F` and `Q`.
pub struct AdsTransition<N: DimName>
where
    DefaultAllocator: Allocator<N, N>,
{
    f: OMatrix<f64, N, N>,
    ft: OMatrix<f64, N, N>,
    q: OMatrix<f64, N, N>,
}

impl<N: DimName> TransitionModelLinearNoControl<f64, N> for AdsTransition<N>
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    fn F(&self) -> &OMatrix<f64, N, N> {
        &self.f
    }
    fn FT(&self) -> &OMatrix<f64, N, N> {
        &self.ft
    }
    fn Q(&self) -> &OMatrix<f64, N, N> {
        &self.q
    }
}

/// adskalman's observation model from our `H` and `R`.
pub struct AdsObservation<N: DimName, M: DimName + DimMin<M, Output = M>>
where
    DefaultAllocator: Dims<N, M>,
{
    h: OMatrix<f64, M, N>,
    ht: OMatrix<f64, N, M>,
    r: OMatrix<f64, M, M>,
}

impl<N: DimName, M: DimName + DimMin<M, Output = M>> ObservationModel<f64, N, M>
    for AdsObservation<N, M>
where
    DefaultAllocator: Dims<N, M>,
{
    fn H(&self) -> &OMatrix<f64, M, N> {
        &self.h
    }
    fn HT(&self) -> &OMatrix<f64, N, M> {
        &self.ht
    }
    fn R(&self) -> &OMatrix<f64, M, M> {
        &self.r
    }
}

/// One KF step problem: our filter (Joseph form, default checks), the same models for
/// adskalman (build its filter with `KalmanFilterNoControl::new(&ads_tr, &ads_ob)`), the
/// input state for both and the observation.
pub struct KfCase<N: DimName = U4, M: DimName + DimMin<M, Output = M> = U2>
where
    DefaultAllocator: Dims<N, M>,
{
    pub kf: Kf<LinearTransition<f64, N>, LinearObservation<f64, N, M>>,
    pub ads_tr: AdsTransition<N>,
    pub ads_ob: AdsObservation<N, M>,
    pub state: Gaussian<f64, N>,
    pub ads_state: StateAndCovariance<f64, N>,
    pub z: OVector<f64, M>,
}

fn kf_case<N: DimName, M: DimName + DimMin<M, Output = M>>(
    tr: LinearTransition<f64, N>,
    ob: LinearObservation<f64, N, M>,
    state: Gaussian<f64, N>,
    z: OVector<f64, M>,
) -> KfCase<N, M>
where
    DefaultAllocator: Dims<N, M>,
{
    let ads_tr = AdsTransition {
        f: tr.f().clone(),
        ft: tr.f().transpose(),
        q: tr.q().clone(),
    };
    let ads_ob = AdsObservation {
        h: ob.h().clone(),
        ht: ob.h().transpose(),
        r: ob.r().clone(),
    };
    let ads_state = StateAndCovariance::new(state.mean.clone(), state.covariance.clone());
    KfCase {
        kf: Kf::new(tr, ob).expect("filter"),
        ads_tr,
        ads_ob,
        state,
        ads_state,
        z,
    }
}

/// The input state of the two 4-state problems.
fn cv_state() -> Gaussian<f64, U4> {
    Gaussian {
        mean: Vector4::new(1.0, 0.5, -2.0, 0.3),
        covariance: Matrix4::from_diagonal(&Vector4::new(0.5, 0.2, 0.5, 0.2)),
    }
}

/// The benchmark's problem: 2-D constant velocity (`dt = 0.1`, axis blocks) with a position
/// observation.
pub fn cv_case() -> KfCase {
    let tr = constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).expect("model");
    let layout = KinematicLayout::new(2, 2, StateOrder::AxisBlocks).expect("layout");
    let ob = position_observation(layout, 0.3).expect("model");
    kf_case(tr, ob, cv_state(), Vector2::new(1.07, -1.95))
}

/// The same problem changed so that neither model has the structure the KF exploits:
/// velocities damped by 2 % per step (`F` no longer `I + N`: the dense products and the
/// `L D L^T` check fused with them) and positions measured at twice their scale (`H` not a
/// selection: the products with `H`).
pub fn general_case() -> KfCase {
    let cv: LinearTransition<f64, U4> =
        constant_velocity(2, 0.1, 0.5, StateOrder::AxisBlocks).expect("model");
    let mut f = *cv.f();
    f[(1, 1)] = 0.98;
    f[(3, 3)] = 0.98;
    let mut h = Matrix2x4::zeros();
    h[(0, 0)] = 2.0;
    h[(1, 2)] = 2.0;
    let tr = LinearTransition::new(f, *cv.q()).expect("model");
    let ob = LinearObservation::new(h, Matrix2::identity() * 0.3).expect("model");
    kf_case(tr, ob, cv_state(), Vector2::new(2.14, -3.9))
}

/// A matrix of independent uniform entries on `[-1, 1)`.
fn uniform<const R: usize, const C: usize>(rng: &mut ChaCha8Rng) -> SMatrix<f64, R, C> {
    SMatrix::from_fn(|_, _| rng.random_range(-1.0..1.0))
}

/// A random symmetric positive definite matrix `B B^T / N + floor I`.
fn spd<const N: usize>(rng: &mut ChaCha8Rng, floor: f64) -> SMatrix<f64, N, N> {
    let b = uniform::<N, N>(rng);
    b * b.transpose() / N as f64 + SMatrix::identity() * floor
}

/// A general dense model, as issue 26 asks: a random stable 6-state transition (every entry
/// drawn, then scaled to spectral norm 0.95, so every eigenvalue is inside the unit circle),
/// a dense 3 x 6 observation matrix, random positive definite `Q`, `R` and input covariance
/// (seeded: the same problem every run). Nothing in it is structured for either filter.
pub fn dense_case() -> KfCase<U6, U3> {
    let mut rng = ChaCha8Rng::seed_from_u64(20261203);
    let a = uniform::<6, 6>(&mut rng);
    let norm = a.singular_values().max();
    let f = a * (0.95 / norm);
    let h = uniform::<3, 6>(&mut rng);
    let q = spd::<6>(&mut rng, 0.01);
    let r = spd::<3>(&mut rng, 0.1);
    let state = Gaussian {
        mean: SVector::<f64, 6>::from_fn(|_, _| rng.random_range(-1.0..1.0)),
        covariance: spd::<6>(&mut rng, 0.05),
    };
    let z = h * state.mean + Vector3::new(0.12, -0.07, 0.05);
    let tr = LinearTransition::new(f, q).expect("model");
    let ob = LinearObservation::new(h, r).expect("model");
    kf_case(tr, ob, state, z)
}

/// The UKF of the benchmark.
pub type CtUkf = Ukf<f64, CoordinatedTurn<f64>, RangeBearing<f64>>;

/// The UKF problem: the 5-state coordinated turn with a range-bearing observation, its input
/// state and observation.
pub fn ukf_case() -> (CtUkf, Gaussian<f64, nalgebra::U5>, Vector2<f64>) {
    let ct = CoordinatedTurn::new(0.5, 0.2, 1e-3).expect("model");
    let rb = RangeBearing::new(Vector2::new(-20.0, 15.0), 0, 2, 0.5, 1e-3).expect("model");
    let ukf = Ukf::new(ct, rb, MerweSigmaPoints::new(0.5, 2.0, -2.0)).expect("filter");
    let state = Gaussian {
        mean: Vector5::new(0.5, 7.0, -0.5, 2.5, 0.1),
        covariance: Matrix5::from_diagonal(&Vector5::new(2.0, 1.0, 2.0, 1.0, 0.01)),
    };
    (ukf, state, Vector2::new(27.4, -0.586))
}
