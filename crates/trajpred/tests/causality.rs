//! Causality, over every predictor of the registry: the forecast made at origin `o` depends
//! only on the points up to `o`.
//!
//! Each check hands a whole trajectory to a forecasting route (the evaluation harness, or a
//! predictor given `prefix(o + 1)`), so a route that reached past the origin could see the
//! future. The trajectory is then changed at every point after `o` (positions by at least
//! 1000 m, timestamps by 0.25 to 0.75 s) and the forecasts at `o` must stay the same. The
//! same check is shown to catch two deliberate leaks written here: a predictor that holds
//! the trajectory it is evaluated on and reads the point after its history, and a harness
//! that slices one point too far.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::Mutex;
use trajpred::harness::{EvalConfig, evaluate, history_at};
use trajpred::registry::{MethodOptions, all_methods, build};
use trajpred_core::{Forecast, Predictor, Result, Trajectory};

const HORIZON: usize = 5;

/// A curving 2-D track in metres, 1 s sampling, with a little seeded jitter.
fn track(n: usize, seed: u64) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x = (0..n)
        .map(|i| 50.0 * (i as f64 * 0.05).sin() + 3.0 * i as f64 + rng.random::<f64>())
        .collect();
    let y = (0..n)
        .map(|i| 40.0 * (i as f64 * 0.03).cos() + rng.random::<f64>())
        .collect();
    Trajectory::uniform(0.0, 1.0, vec![x, y]).unwrap()
}

/// The same track with every point after `origin` changed: each coordinate moved by 1000 to
/// 2000 m (either way) and, with `move_times`, each timestamp delayed by 0.25 to 0.75 s
/// (still strictly increasing, since the samples are 1 s apart).
fn perturb_after(tr: &Trajectory, origin: usize, seed: u64, move_times: bool) -> Trajectory {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut times = tr.times().to_vec();
    let mut axes: Vec<Vec<f64>> = tr.axes().map(<[f64]>::to_vec).collect();
    for i in origin + 1..tr.len() {
        let delay = 0.25 + 0.5 * rng.random::<f64>();
        if move_times {
            times[i] += delay;
        }
        for a in axes.iter_mut() {
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            a[i] += sign * (1000.0 + 1000.0 * rng.random::<f64>());
        }
    }
    let changed = Trajectory::from_axes(times, axes).unwrap();
    for i in origin + 1..tr.len() {
        assert_eq!(changed.times()[i] != tr.times()[i], move_times);
        for (a, b) in changed.point(i).iter().zip(tr.point(i).iter()) {
            assert!((a - b).abs() >= 1000.0);
        }
    }
    changed
}

/// Records every forecast the harness asks of `inner`, in the order asked.
struct Recorder<'a> {
    inner: &'a dyn Predictor,
    seen: Mutex<Vec<Forecast>>,
}

impl Predictor for Recorder<'_> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        let f = self.inner.forecast(history, horizon)?;
        self.seen.lock().unwrap().push(f.clone());
        Ok(f)
    }
    // the harness asks at the scored points' timestamps: forward that, so time-aware
    // methods are checked on the route they are evaluated by
    fn forecast_times(&self, history: &Trajectory, times: &[f64]) -> Result<Forecast> {
        let f = self.inner.forecast_times(history, times)?;
        self.seen.lock().unwrap().push(f.clone());
        Ok(f)
    }
    fn min_history(&self) -> usize {
        self.inner.min_history()
    }
}

/// The forecasts `trajpred::harness::evaluate` makes at `origins` of `tr` (histories of
/// `hist_len` points, stride 1), picked from all the forecasts it makes on the whole
/// trajectory. One trajectory is evaluated by one task, origin after origin, so the k-th
/// forecast asked is the one at origin `hist_len - 1 + k`.
fn through_harness(
    p: &dyn Predictor,
    tr: &Trajectory,
    origins: &[usize],
    hist_len: usize,
) -> Vec<Forecast> {
    let rec = Recorder {
        inner: p,
        seen: Mutex::new(Vec::new()),
    };
    let cfg = EvalConfig {
        history: hist_len,
        horizon: HORIZON,
        stride: 1,
        ..EvalConfig::default()
    };
    let report = evaluate(&rec, std::slice::from_ref(tr), &cfg, None).unwrap();
    assert_eq!(
        report.failures,
        0,
        "{}: {:?}",
        p.name(),
        report.first_failure
    );
    let seen = rec.seen.into_inner().unwrap();
    assert_eq!(seen.len(), tr.len() - HORIZON - (hist_len - 1));
    origins
        .iter()
        .map(|&o| seen[o - (hist_len - 1)].clone())
        .collect()
}

/// The forecasts of `p` at `origins` of `tr`, each from the whole past `prefix(o + 1)`.
fn through_prefix(p: &dyn Predictor, tr: &Trajectory, origins: &[usize]) -> Vec<Forecast> {
    origins
        .iter()
        .map(|&o| p.forecast(&tr.prefix(o + 1).unwrap(), HORIZON).unwrap())
        .collect()
}

/// A forecasting route: the forecasts at `origins`, given the whole trajectory.
type Route<'a> = dyn Fn(&Trajectory, &[usize]) -> Vec<Forecast> + 'a;

/// Whether the forecast at some origin changes when every point after it changes. Through the
/// harness the future timestamps are the question asked (where at those times), so there only
/// the positions move (`move_times` false); through a prefix the times move too.
fn leaks(route: &Route, tr: &Trajectory, origins: &[usize], move_times: bool) -> bool {
    let before = route(tr, origins);
    origins.iter().zip(&before).any(|(&o, a)| {
        let changed = perturb_after(tr, o, 1000 + o as u64, move_times);
        route(&changed, &[o])[0] != *a
    })
}

/// A leaky predictor: it holds the trajectory it is evaluated on (as a predictor sharing
/// memory with the data source might) and predicts the points that follow its history's
/// last timestamp there.
struct Peeker {
    full: Trajectory,
}

impl Predictor for Peeker {
    fn name(&self) -> &str {
        "peeker"
    }
    fn fit(&mut self, _train: &[Trajectory]) -> Result<()> {
        Ok(())
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<Forecast> {
        let t = history.times().last().unwrap();
        let i = self.full.times().iter().position(|s| s == t).unwrap();
        let last = self.full.len() - 1;
        let steps: Vec<_> = (1..=horizon)
            .map(|k| self.full.point((i + k).min(last)))
            .collect();
        Forecast::new(history.dim(), steps)
    }
}

/// A harness that slices one point too far: the "history" at `origin` ends at `origin + 1`.
fn off_by_one_history(tr: &Trajectory, origin: usize, history: usize) -> Trajectory {
    tr.slice(origin + 2 - history..origin + 2).unwrap()
}

#[test]
fn every_predictor_is_causal_and_the_check_catches_leaks() {
    let train = vec![track(200, 1), track(150, 2)];
    let test = track(120, 3);
    // two epochs keep the networks' training short; causality does not depend on it
    let opts = MethodOptions {
        epochs: Some(2),
        ..Default::default()
    };
    let methods = all_methods();
    assert!(methods.len() >= 10);
    for info in &methods {
        let mut p = build(info.name, &opts).unwrap();
        p.fit(&train).unwrap();
        let p = p.as_ref();
        let hist_len = 30.max(p.min_history());
        let origins = [hist_len - 1, 60, 100];
        let harness = |tr: &Trajectory, os: &[usize]| through_harness(p, tr, os, hist_len);
        let prefix = |tr: &Trajectory, os: &[usize]| through_prefix(p, tr, os);
        assert!(
            !leaks(&harness, &test, &origins, false),
            "{} (harness)",
            info.name
        );
        assert!(
            !leaks(&prefix, &test, &origins, true),
            "{} (prefix)",
            info.name
        );

        // the check has power on this method: one point too many in the history is caught
        let off_by_one = |tr: &Trajectory, os: &[usize]| {
            os.iter()
                .map(|&o| {
                    p.forecast(&off_by_one_history(tr, o, hist_len), HORIZON)
                        .unwrap()
                })
                .collect()
        };
        assert!(
            leaks(&off_by_one, &test, &origins, true),
            "{}: a history holding the point after the origin went unnoticed",
            info.name
        );
        // and the forecast is not trivially constant: it does depend on the past
        let moved = perturb_after(&test, 5, 99, true);
        let a = through_prefix(p, &test, &origins);
        let c = through_prefix(p, &moved, &origins);
        for ((a, c), o) in a.iter().zip(&c).zip(origins) {
            assert_ne!(a, c, "{} ignores its history at origin {o}", info.name);
        }
    }
}

#[test]
fn a_predictor_holding_the_trajectory_is_caught() {
    let test = track(120, 3);
    let origins = [29, 60, 100];
    let harness =
        |tr: &Trajectory, os: &[usize]| through_harness(&Peeker { full: tr.clone() }, tr, os, 30);
    let prefix =
        |tr: &Trajectory, os: &[usize]| through_prefix(&Peeker { full: tr.clone() }, tr, os);
    assert!(leaks(&harness, &test, &origins, false));
    assert!(leaks(&prefix, &test, &origins, true));
    // the peeker does read the future: its one-step forecast is the next true point
    let f = &through_prefix(&Peeker { full: test.clone() }, &test, &[60])[0];
    assert_eq!(f.step(1), &test.point(61)[..]);
}

#[test]
fn history_at_holds_nothing_after_the_origin() {
    let tr = track(50, 4);
    let h = history_at(&tr, 20, 10).unwrap();
    assert_eq!(h.len(), 10);
    assert_eq!(h.times()[0], tr.times()[11]);
    assert_eq!(h.times().last(), Some(&tr.times()[20]));
    assert_eq!(&h.last_point()[..], &tr.point(20)[..]);
    assert!(history_at(&tr, 5, 10).is_err());
}
