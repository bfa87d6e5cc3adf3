//! Scores method variants by cross-validation by user on the **training users only** of the
//! leaderboard's by-user split (`docs/accuracy.md`): the test users are dropped right after
//! the split, before anything is fitted or scored. This is how `aligned-ridge`'s settings
//! were chosen; its output is the "used to choose" table of `docs/accuracy.md`.
//!
//! ```sh
//! cargo run --release -p trajpred --example tune_by_user -- geolife ../shared/data/geolife 5 55
//! ```
//! (dataset, path, `--max-gap`, `--min-points`; a fifth argument `gbm` scores
//! `aligned-gbm`'s variants instead, with a sixth `1` to `13` for the first to thirteenth
//! round of them (8 to 11: `aligned-mlp`'s; 12: the mean of the two learners; 13, with a
//! seventh naming a method, default `cv-time`: that method with its own recent errors fed
//! back); the split is `--split by-user`,
//! `--train-fraction 0.3`, `--seed 0`, the evaluation `--history 20 --horizon 5`.)

use trajpred::dataset::{Dataset, Segmentation, load};
use trajpred::harness::{EvalConfig, Split, group_ids, split_segments};
use trajpred::predictors::{
    AlignedGbm, AlignedGbmParams, AlignedMlp, AlignedMlpParams, AlignedRidge, AlignedRidgeParams,
    cross_validate,
};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Predictor, Result, Trajectory};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let ds: Dataset = arg(1, "geolife").parse()?;
    let path = arg(2, "../shared/data/geolife");
    let max_gap: f64 = arg(3, "5").parse().unwrap_or(5.0);
    let min_points: usize = arg(4, "55").parse().unwrap_or(55);
    let seg = Segmentation {
        max_gap: Some(max_gap),
        min_points,
        ..Default::default()
    };
    let loaded = load(ds, path.as_ref(), &ds.options(), &seg, None)?;
    let split = Split::ByGroup {
        train_fraction: 0.3,
        seed: 0,
    };
    // the test users are dropped here: nothing below sees them
    let (train, _) = split_segments(&loaded.segments, split)?;
    let groups = group_ids(&train);
    let tracks: Vec<Trajectory> = train.iter().map(|s| s.trajectory.clone()).collect();
    let eval = EvalConfig {
        history: 20,
        horizon: 5,
        ..Default::default()
    };
    let opts = MethodOptions {
        eval,
        ..Default::default()
    };
    eprintln!(
        "{} training segments of {} users; 5 folds by user, seed 0",
        tracks.len(),
        groups.iter().max().map_or(0, |g| g + 1)
    );
    let ridge = |lags: usize, lambda: f64, robust: usize, bins: &[f64]| AlignedRidgeParams {
        lags,
        lambda: Some(lambda),
        robust_iterations: robust,
        speed_bins: bins.to_vec(),
        eval,
        ..Default::default()
    };
    eprintln!("| variant | CV mean error (m), pooled | per fold |\n|---|---|---|");
    let report = |name: &str, b: &dyn Fn() -> Result<Box<dyn Predictor>>| -> Result<()> {
        let s = cross_validate(name, b, &tracks, &groups, 5, 0, &eval)?;
        let f: Vec<String> = s.fold_errors.iter().map(|e| format!("{e:.3}")).collect();
        eprintln!("| {name} | {:.3} | {} |", s.pooled_error, f.join(", "));
        Ok(())
    };
    if arg(5, "ridge") == "gbm" {
        if arg(6, "1") == "1" {
            for name in ["cv-time", "aligned-ridge", "aligned-gbm"] {
                report(name, &|| build(name, &opts))?;
            }
        }
        let gbm = |name: &str, p: AlignedGbmParams| -> Result<()> {
            report(name, &|| {
                Ok(Box::new(AlignedGbm::new(p.clone())?) as Box<dyn Predictor>)
            })
        };
        // rounds 1 and 2 ran before the shape features: they are scored without them
        let base = || AlignedGbmParams {
            shape_features: false,
            robust_passes: 0,
            ..Default::default()
        };
        // round 3 ran before the reweighted passes
        let shape = || AlignedGbmParams {
            robust_passes: 0,
            ..Default::default()
        };
        if arg(6, "1") == "3" {
            gbm("gbm without shape features", base())?;
            gbm("gbm with shape features", shape())?;
        } else if arg(6, "1") == "4" {
            gbm(
                "gbm 1 reweighted pass, floor 1 m",
                AlignedGbmParams::default(),
            )?;
            gbm(
                "gbm 2 reweighted passes",
                AlignedGbmParams {
                    robust_passes: 2,
                    ..Default::default()
                },
            )?;
            gbm(
                "gbm 1 reweighted pass, floor 3 m",
                AlignedGbmParams {
                    robust_floor: 3.0,
                    ..Default::default()
                },
            )?;
            gbm(
                "gbm 1 reweighted pass, no shape features",
                AlignedGbmParams {
                    shape_features: false,
                    ..Default::default()
                },
            )?;
        } else if arg(6, "1") == "5" {
            gbm(
                "gbm mirrored origins",
                AlignedGbmParams {
                    mirror: true,
                    ..Default::default()
                },
            )?;
        } else if arg(6, "1") == "6" {
            let origins: usize = tracks.iter().map(|t| t.len().saturating_sub(9)).sum();
            eprintln!("training origins at step 1 (8 lags): {origins}");
            gbm(
                "gbm every origin (no cap)",
                AlignedGbmParams {
                    max_samples: usize::MAX,
                    ..Default::default()
                },
            )?;
            gbm(
                "gbm at most 50,000 origins a step",
                AlignedGbmParams {
                    max_samples: 50_000,
                    ..Default::default()
                },
            )?;
        } else if arg(6, "1") == "7" {
            gbm(
                "gbm every origin, mirrored, 2 reweighted passes",
                AlignedGbmParams {
                    max_samples: usize::MAX,
                    mirror: true,
                    robust_passes: 2,
                    ..Default::default()
                },
            )?;
        } else if arg(6, "1") == "8" {
            report("aligned-mlp", &|| build("aligned-mlp", &opts))?;
            let mlp = |name: &str, p: AlignedMlpParams| -> Result<()> {
                report(name, &|| {
                    Ok(Box::new(AlignedMlp::new(p.clone())?) as Box<dyn Predictor>)
                })
            };
            let mut p = AlignedMlpParams::default();
            p.network.epochs = 40;
            mlp("aligned-mlp 40 epochs", p)?;
            let mut p = AlignedMlpParams::default();
            p.network.hidden = vec![512, 512];
            mlp("aligned-mlp 2 x 512", p)?;
        } else if arg(6, "1") == "9" {
            let mlp = |name: &str, p: AlignedMlpParams| -> Result<()> {
                report(name, &|| {
                    Ok(Box::new(AlignedMlp::new(p.clone())?) as Box<dyn Predictor>)
                })
            };
            let mut p = AlignedMlpParams::default();
            p.network.epochs = 10;
            mlp("aligned-mlp 10 epochs", p)?;
            for members in [2, 4] {
                let p = AlignedMlpParams {
                    members,
                    ..Default::default()
                };
                mlp(&format!("aligned-mlp {members} members"), p)?;
            }
        } else if arg(6, "1") == "11" {
            // training tracks thinned to every other fix (both phases) as extra training
            // origins, split where the thinned fixes are more than `max_gap` apart
            let mlp = |name: &str, thin: bool| -> Result<()> {
                report(name, &|| {
                    let inner = AlignedMlp::new(AlignedMlpParams {
                        members: 1,
                        ..Default::default()
                    })?;
                    Ok(Box::new(Thinned {
                        inner,
                        thin,
                        max_gap,
                    }) as Box<dyn Predictor>)
                })
            };
            mlp("aligned-mlp one network (wrapper, no thinning)", false)?;
            mlp("aligned-mlp one network, thinned copies added", true)?;
        } else if arg(6, "1") == "12" {
            // the plain mean of the two learners' forecasts, every step weighing them equally
            report("mean of aligned-gbm and aligned-mlp", &|| {
                Ok(Box::new(MeanOf {
                    members: vec![build("aligned-gbm", &opts)?, build("aligned-mlp", &opts)?],
                }) as Box<dyn Predictor>)
            })?;
        } else if arg(6, "1") == "13" {
            // the inner method's own recent errors, read inside the history, fed back
            let inner = arg(7, "cv-time");
            for alpha in [0.0, 0.25, 0.5, 1.0] {
                report(&format!("{inner} with feedback {alpha}"), &|| {
                    Ok(Box::new(Feedback {
                        inner: build(&inner, &opts)?,
                        alpha,
                    }) as Box<dyn Predictor>)
                })?;
            }
        } else if arg(6, "1") == "10" {
            let one = |f: &dyn Fn(&mut AlignedMlpParams)| {
                let mut p = AlignedMlpParams {
                    members: 1,
                    ..Default::default()
                };
                f(&mut p);
                p
            };
            let mlp = |name: &str, p: AlignedMlpParams| -> Result<()> {
                report(name, &|| {
                    Ok(Box::new(AlignedMlp::new(p.clone())?) as Box<dyn Predictor>)
                })
            };
            mlp(
                "aligned-mlp one network, learning rate 1e-2",
                one(&|p| p.network.learning_rate = 1e-2),
            )?;
            mlp(
                "aligned-mlp one network, batches of 256",
                one(&|p| p.network.batch_size = 256),
            )?;
            mlp(
                "aligned-mlp one network, three hidden layers of 256",
                one(&|p| p.network.hidden = vec![256, 256, 256]),
            )?;
        } else if arg(6, "1") == "1" {
            gbm(
                "gbm 100 rounds",
                AlignedGbmParams {
                    iterations: 100,
                    ..base()
                },
            )?;
            gbm(
                "gbm 400 rounds lr 0.05",
                AlignedGbmParams {
                    iterations: 400,
                    learning_rate: 0.05,
                    ..base()
                },
            )?;
            gbm(
                "gbm no clipping",
                AlignedGbmParams {
                    clip_quantile: 1.0,
                    ..base()
                },
            )?;
            gbm(
                "gbm clip 0.9",
                AlignedGbmParams {
                    clip_quantile: 0.9,
                    ..base()
                },
            )?;
            gbm("gbm 4 lags", AlignedGbmParams { lags: 4, ..base() })?;
            gbm(
                "gbm 15 leaves",
                AlignedGbmParams {
                    max_leaves: 15,
                    ..base()
                },
            )?;
            gbm(
                "gbm leaf 400",
                AlignedGbmParams {
                    min_leaf_samples: 400.0,
                    ..base()
                },
            )?;
        } else {
            gbm(
                "gbm clip 0.8",
                AlignedGbmParams {
                    clip_quantile: 0.8,
                    ..base()
                },
            )?;
            gbm(
                "gbm clip 0.7",
                AlignedGbmParams {
                    clip_quantile: 0.7,
                    ..base()
                },
            )?;
            gbm(
                "gbm clip 0.8 100 rounds",
                AlignedGbmParams {
                    clip_quantile: 0.8,
                    iterations: 100,
                    ..base()
                },
            )?;
        }
        return Ok(());
    }
    let mut variants: Vec<(String, AlignedRidgeParams)> = Vec::new();
    for &lambda in &[1e-2, 1e-1, 1.0, 10.0] {
        variants.push((
            format!("ridge k=4 lambda={lambda}"),
            ridge(4, lambda, 0, &[]),
        ));
        variants.push((
            format!("robust k=4 lambda={lambda}"),
            ridge(4, lambda, 5, &[]),
        ));
    }
    for &lambda in &[1e-2, 1e-1, 1.0] {
        variants.push((
            format!("robust k=8 lambda={lambda}"),
            ridge(8, lambda, 5, &[]),
        ));
        variants.push((
            format!("robust k=2 lambda={lambda}"),
            ridge(2, lambda, 5, &[]),
        ));
        variants.push((
            format!("robust k=4 bins 2,7 m/s lambda={lambda}"),
            ridge(4, lambda, 5, &[2.0, 7.0]),
        ));
    }
    for name in ["cv-time", "gsc"] {
        report(name, &|| build(name, &opts))?;
    }
    for (name, p) in &variants {
        report(name, &|| {
            Ok(Box::new(AlignedRidge::new(p.clone())?) as Box<dyn Predictor>)
        })?;
    }
    Ok(())
}

/// A throwaway wrapper for round 11: fits `inner` on the tracks plus, with `thin`, each track
/// thinned to every other fix (both phases), split where those fixes are more than
/// `max_gap` apart.
struct Thinned {
    inner: AlignedMlp,
    thin: bool,
    max_gap: f64,
}

impl Predictor for Thinned {
    fn name(&self) -> &str {
        "thinned"
    }
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        let mut all = train.to_vec();
        if self.thin {
            for tr in train {
                for phase in 0..2 {
                    let idx: Vec<usize> = (phase..tr.len()).step_by(2).collect();
                    let mut start = 0;
                    for k in 1..=idx.len() {
                        let cut = k == idx.len()
                            || tr.times()[idx[k]] - tr.times()[idx[k - 1]] > self.max_gap;
                        if cut {
                            if k - start >= 25 {
                                let times = idx[start..k].iter().map(|&i| tr.times()[i]).collect();
                                let axes = tr
                                    .axes()
                                    .map(|a| idx[start..k].iter().map(|&i| a[i]).collect())
                                    .collect();
                                all.push(Trajectory::from_axes(times, axes)?);
                            }
                            start = k;
                        }
                    }
                }
            }
        }
        self.inner.fit(&all)
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<trajpred_core::Forecast> {
        self.inner.forecast(history, horizon)
    }
    fn forecast_times(
        &self,
        history: &Trajectory,
        times: &[f64],
    ) -> Result<trajpred_core::Forecast> {
        self.inner.forecast_times(history, times)
    }
    fn min_history(&self) -> usize {
        self.inner.min_history()
    }
}

/// A throwaway wrapper for round 12: the plain mean of its members' forecasts.
struct MeanOf {
    members: Vec<Box<dyn Predictor>>,
}

impl MeanOf {
    fn mean(
        &self,
        f: &dyn Fn(&dyn Predictor) -> Result<trajpred_core::Forecast>,
    ) -> Result<trajpred_core::Forecast> {
        let got: Vec<_> = self
            .members
            .iter()
            .map(|m| f(m.as_ref()))
            .collect::<Result<_>>()?;
        let n = got.len() as f64;
        let steps: Vec<Vec<f64>> = (1..=got[0].horizon())
            .map(|k| {
                (0..got[0].dim())
                    .map(|a| got.iter().map(|g| g.step(k)[a]).sum::<f64>() / n)
                    .collect()
            })
            .collect();
        trajpred_core::Forecast::new(got[0].dim(), steps)
    }
}

impl Predictor for MeanOf {
    fn name(&self) -> &str {
        "mean-of"
    }
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.members.iter_mut().try_for_each(|m| m.fit(train))
    }
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        self.members
            .iter_mut()
            .try_for_each(|m| m.fit_grouped(train, groups))
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<trajpred_core::Forecast> {
        self.mean(&|m| m.forecast(history, horizon))
    }
    fn forecast_times(
        &self,
        history: &Trajectory,
        times: &[f64],
    ) -> Result<trajpred_core::Forecast> {
        self.mean(&|m| m.forecast_times(history, times))
    }
    fn min_history(&self) -> usize {
        self.members
            .iter()
            .map(|m| m.min_history())
            .max()
            .unwrap_or(1)
    }
}

/// A throwaway wrapper for round 13: the inner forecast plus `alpha` times the mean of the
/// inner method's errors on the earlier origins of the same history (each error at step `k`
/// measured in the frame of its origin's last leg, turned into the frame of the history's
/// last leg).
struct Feedback {
    inner: Box<dyn Predictor>,
    alpha: f64,
}

/// The unit vector along the leg ending at `o`, if it has a length.
fn heading(tr: &Trajectory, o: usize) -> Option<[f64; 2]> {
    let (a, b) = (tr.point(o), tr.point(o - 1));
    let (dx, dy) = (a.as_ref()[0] - b.as_ref()[0], a.as_ref()[1] - b.as_ref()[1]);
    let n = dx.hypot(dy);
    (n > 1e-9).then(|| [dx / n, dy / n])
}

impl Feedback {
    fn corrected(&self, history: &Trajectory, times: &[f64]) -> Result<trajpred_core::Forecast> {
        let f = self.inner.forecast_times(history, times)?;
        let n = history.len();
        if n < 2 {
            return Ok(f);
        }
        let last = n - 1;
        let Some(u) = heading(history, last) else {
            return Ok(f);
        };
        let mut steps = Vec::with_capacity(times.len());
        for k in 1..=times.len() {
            // along and across errors at step k, summed over the earlier origins
            let (mut sa, mut sc, mut m) = (0.0, 0.0, 0usize);
            if self.alpha > 0.0 {
                let lo = self.inner.min_history().max(2) - 1;
                for o in lo..last.saturating_sub(k - 1) {
                    if o + k > last {
                        break;
                    }
                    let Some(v) = heading(history, o) else {
                        continue;
                    };
                    let sub = history.prefix(o + 1)?;
                    let ts: Vec<f64> = (1..=k).map(|j| history.times()[o + j]).collect();
                    let Ok(g) = self.inner.forecast_times(&sub, &ts) else {
                        continue;
                    };
                    let p = g.step(k);
                    let t = history.point(o + k);
                    let (ex, ey) = (t.as_ref()[0] - p[0], t.as_ref()[1] - p[1]);
                    sa += ex * v[0] + ey * v[1];
                    sc += -ex * v[1] + ey * v[0];
                    m += 1;
                }
            }
            let p = f.step(k);
            if m == 0 {
                steps.push(p.to_vec());
                continue;
            }
            let (a, c) = (self.alpha * sa / m as f64, self.alpha * sc / m as f64);
            let mut q = p.to_vec();
            q[0] += a * u[0] - c * u[1];
            q[1] += a * u[1] + c * u[0];
            steps.push(q);
        }
        trajpred_core::Forecast::new(f.dim(), steps)
    }
}

impl Predictor for Feedback {
    fn name(&self) -> &str {
        "feedback"
    }
    fn fit(&mut self, train: &[Trajectory]) -> Result<()> {
        self.inner.fit(train)
    }
    fn fit_grouped(&mut self, train: &[Trajectory], groups: &[usize]) -> Result<()> {
        self.inner.fit_grouped(train, groups)
    }
    fn forecast(&self, history: &Trajectory, horizon: usize) -> Result<trajpred_core::Forecast> {
        if history.len() < 2 {
            return self.inner.forecast(history, horizon);
        }
        let dt = history.times()[history.len() - 1] - history.times()[history.len() - 2];
        let t0 = history.times()[history.len() - 1];
        let ts: Vec<f64> = (1..=horizon).map(|k| t0 + k as f64 * dt).collect();
        self.corrected(history, &ts)
    }
    fn forecast_times(
        &self,
        history: &Trajectory,
        times: &[f64],
    ) -> Result<trajpred_core::Forecast> {
        self.corrected(history, times)
    }
    fn min_history(&self) -> usize {
        self.inner.min_history()
    }
}
