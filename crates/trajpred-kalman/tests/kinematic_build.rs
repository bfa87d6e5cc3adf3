//! The kinematic models are built without searching `F` for its pattern and with `Q`
//! checked on one axis's block (so a filter can build one for every time step of an
//! irregular track): the result must be the very value the general, validating constructor
//! `LinearTransition::new(F, Q)` gives, for every layout, static and run-time sizes, time
//! steps from milliseconds to hours, and both noise models.

use nalgebra::{Dim, Dyn, U2, U3, U4, U6, U9};
use trajpred_kalman::LinearTransition;
use trajpred_kalman::motion::{
    KinematicLayout, StateOrder, damped_velocity, kinematic, kinematic_continuous,
};

const STEPS: [f64; 8] = [1e-3, 0.1, 0.5, 1.0, 2.9, 5.0, 300.0, 1e4];

fn layouts() -> Vec<KinematicLayout> {
    let mut out = Vec::new();
    for axes in 1..=3 {
        for derivatives in 2..=3 {
            for order in [StateOrder::AxisBlocks, StateOrder::PositionsFirst] {
                out.push(KinematicLayout::new(axes, derivatives, order).expect("layout"));
            }
        }
    }
    out
}

/// Both builders of `layout` at every step, at size `D`, against `LinearTransition::new`.
fn same_as_general<D: Dim>(layout: KinematicLayout)
where
    nalgebra::DefaultAllocator:
        nalgebra::allocator::Allocator<D> + nalgebra::allocator::Allocator<D, D>,
{
    for dt in STEPS {
        for level in [0.0, 1e-3, 0.7, 10.0] {
            let built = [
                kinematic_continuous::<f64, D>(layout, dt, level).expect("continuous"),
                kinematic::<f64, D>(layout, dt, level).expect("discrete"),
            ];
            for tr in built {
                let general =
                    LinearTransition::new(tr.f().clone(), tr.q().clone()).expect("validates");
                assert_eq!(tr, general, "{layout:?}, dt = {dt}, level = {level}");
            }
        }
    }
}

#[test]
fn kinematic_models_equal_the_validated_general_transition() {
    for layout in layouts() {
        same_as_general::<Dyn>(layout);
        match layout.state_dim() {
            2 => same_as_general::<U2>(layout),
            3 => same_as_general::<U3>(layout),
            4 => same_as_general::<U4>(layout),
            6 => same_as_general::<U6>(layout),
            9 => same_as_general::<U9>(layout),
            n => panic!("unexpected state size {n}"),
        }
    }
}

#[test]
fn the_damped_velocity_is_not_taken_for_the_kinematic_pattern() {
    // F = [[1, (1 - e) / beta], [0, e]]: not unit triangular, so the general constructor
    // decides (no kinematic pattern), and the value is the validated one
    for order in [StateOrder::AxisBlocks, StateOrder::PositionsFirst] {
        let layout = KinematicLayout::new(2, 2, order).expect("layout");
        for dt in STEPS {
            let tr = damped_velocity::<f64, U4>(layout, dt, 0.5, 30.0).expect("damped");
            let general = LinearTransition::new(*tr.f(), *tr.q()).expect("valid");
            assert_eq!(tr, general, "dt = {dt}");
        }
    }
}

#[test]
fn a_bad_step_or_noise_is_still_a_typed_error() {
    let layout = KinematicLayout::new(2, 3, StateOrder::PositionsFirst).expect("layout");
    for (dt, q) in [
        (f64::NAN, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (1.0, -1.0),
        (1.0, f64::NAN),
    ] {
        let e = kinematic_continuous::<f64, U6>(layout, dt, q).expect_err("rejected");
        assert!(
            matches!(
                e,
                trajpred_kalman::KalmanError::Core(trajpred_core::Error::InvalidParameter { .. })
            ),
            "dt = {dt}, q = {q}: {e:?}"
        );
    }
    // a step so long that dt^5 overflows: Q is not finite, the general constructor says so
    let e = kinematic_continuous::<f64, U6>(layout, 1e80, 1.0).expect_err("overflow");
    assert!(
        matches!(
            e,
            trajpred_kalman::KalmanError::Core(trajpred_core::Error::NotPositiveDefinite { .. })
                | trajpred_kalman::KalmanError::Core(trajpred_core::Error::NonFinite { .. })
        ),
        "{e:?}"
    );
}

#[test]
fn the_in_place_rebuild_equals_a_new_transition_at_every_step() {
    use trajpred_kalman::motion::kinematic_continuous_in_place;
    for layout in layouts() {
        // run-time sizes, starting from another layout's transition (replaced, not rewritten)
        let other = KinematicLayout::new(1, 2, StateOrder::AxisBlocks).expect("layout");
        let mut tr = kinematic_continuous::<f64, Dyn>(other, 1.0, 1.0).expect("start");
        for (k, dt) in STEPS.iter().enumerate() {
            let q = 0.1 * (k + 1) as f64;
            kinematic_continuous_in_place(&mut tr, layout, *dt, q).expect("in place");
            let fresh = kinematic_continuous::<f64, Dyn>(layout, *dt, q).expect("fresh");
            assert_eq!(tr, fresh, "{layout:?}, dt = {dt}");
        }
        // a bad step is an error and leaves the transition as it was
        let before = tr.clone();
        let e = kinematic_continuous_in_place(&mut tr, layout, -1.0, 1.0).expect_err("bad dt");
        assert!(matches!(
            e,
            trajpred_kalman::KalmanError::Core(trajpred_core::Error::InvalidParameter { .. })
        ));
        assert_eq!(tr, before);
    }
    // a damped velocity (no kinematic pattern) is replaced by the kinematic transition
    let layout = KinematicLayout::new(2, 2, StateOrder::PositionsFirst).expect("layout");
    let mut tr = damped_velocity::<f64, U4>(layout, 2.0, 0.5, 30.0).expect("damped");
    kinematic_continuous_in_place(&mut tr, layout, 2.0, 0.5).expect("in place");
    assert_eq!(
        tr,
        kinematic_continuous::<f64, U4>(layout, 2.0, 0.5).expect("cv")
    );
}

#[test]
fn a_kf_whose_transition_changes_size_in_place_is_a_typed_error() {
    use trajpred_kalman::motion::{kinematic_continuous_in_place, position_observation};
    use trajpred_kalman::{Kf, LinearObservation};
    let cv = KinematicLayout::new(2, 2, StateOrder::PositionsFirst).expect("layout");
    let ca = KinematicLayout::new(2, 3, StateOrder::PositionsFirst).expect("layout");
    let obs: LinearObservation<f64, Dyn, Dyn> = position_observation(cv, 4.0).expect("obs");
    let mut kf = Kf::new(
        kinematic_continuous::<f64, Dyn>(cv, 1.0, 1.0).expect("cv"),
        obs,
    )
    .expect("kf");
    kf.update_transition(|tr| kinematic_continuous_in_place(tr, cv, 3.0, 1.0))
        .expect("same size");
    assert_eq!(
        kf.transition(),
        &kinematic_continuous::<f64, Dyn>(cv, 3.0, 1.0).expect("cv")
    );
    // the constant-acceleration state has 6 components, H reads 4
    let e = kf
        .update_transition(|tr| kinematic_continuous_in_place(tr, ca, 3.0, 1.0))
        .expect_err("size");
    assert!(
        matches!(
            e,
            trajpred_kalman::KalmanError::Core(trajpred_core::Error::DimensionMismatch { .. })
        ),
        "{e:?}"
    );
}
