//! Fig. 4 of the paper, which only it computes: the error against the SNR of white noise
//! added to the test part (the paper's setup) or to the whole series with the models refitted
//! (our variant); and the noise amplification of the fitted recurrence that explains it.

use super::predict::{experiment, fit, gsc, gskf, gskf_default, predict_test, test_truth};
use super::{Budget, Setup};
use crate::report::Figure;
use crate::runner::Row;
use crate::{Context, Result};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trajpred::plot::{Chart, Series};
use trajpred::predictors::{Gsc, GskfParams};
use trajpred_core::{Predictor, Trajectory};
use trajpred_data::noise::add_noise_snr;
use trajpred_metrics::rmse_3d;

/// The series with white Gaussian noise at `snr_db` added to its test part (each axis's
/// noise power relative to that axis's power over the test part); the training part stays
/// clean.
fn noisy_test_series(
    clean: &Trajectory,
    snr_db: f64,
    seed: u64,
    test: usize,
) -> Result<Trajectory> {
    let n = clean.len();
    let start = n - test;
    let test = clean.slice(start..n)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noisy = add_noise_snr(&test, snr_db, &mut rng)?;
    let axes: Vec<Vec<f64>> = clean
        .axes()
        .zip(noisy.axes())
        .map(|(c, z)| c[..start].iter().chain(z).copied().collect())
        .collect();
    Ok(Trajectory::from_axes(clean.times().to_vec(), axes)?)
}

/// The series with white Gaussian noise at `snr_db` on every point (each axis's noise power
/// relative to that axis's power over the whole series).
fn noisy_series(clean: &Trajectory, snr_db: f64, seed: u64) -> Result<Trajectory> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok(add_noise_snr(clean, snr_db, &mut rng)?)
}

/// Mean, min and max.
pub(super) fn spread(v: &[f64]) -> (f64, f64, f64) {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (mean, min, max)
}

/// The SNR sweep of Fig. 4 at m = T = `s.window`. With `fixed` (GSC and GSKF fitted on the
/// clean training part), noise is added to the test part only (the paper's experiment);
/// without, noise is added to the whole series and the models are refitted on its noisy
/// training part at every SNR and seed: GSC, the paper's MSTPM-GSKF and our default GSKF
/// (whose gain may be fitted to the training series). Errors are against the true test
/// points. Returns the table's rows (one per SNR, keyed by it) and the figure; `paper` holds
/// the paper's points.
pub(super) fn snr_sweep(
    ctx: &Context,
    s: &Setup,
    budget: &Budget,
    series: &Trajectory,
    fixed: Option<[&dyn Predictor; 2]>,
    paper: &[(f64, f64)],
) -> Result<(Vec<Row>, Figure)> {
    let (m, t) = (s.window, s.horizons);
    let truth = test_truth(series, s.test_points);
    let n_snr = budget.snr_db.len();
    let (id, what) = match fixed {
        Some(_) => ("fig4", "noise on the test data (the paper's setup)"),
        None => (
            "fig4_noisy_train",
            "noise on the training and test data, models refitted (our addition)",
        ),
    };
    let bar = ctx.bar((n_snr * budget.noise_seeds) as u64, format!("gskf: {id}"));
    // errors[method][snr][seed] (mm) against the truth; observed[snr][seed]: GSKF against the
    // noisy test values
    let names: &[(&str, &str)] = match fixed {
        Some(_) => &[("gsc", "GSC"), ("gskf", "MSTPM-GSKF")],
        None => &[
            ("gsc", "GSC"),
            ("gskf", "MSTPM-GSKF"),
            (
                "gskf_fit",
                "GSKF, gain chosen on the training series (ours)",
            ),
        ],
    };
    let mut errors = vec![vec![Vec::new(); n_snr]; names.len()];
    let mut observed = vec![Vec::new(); n_snr];
    for k in 0..budget.noise_seeds {
        // the same draws at every SNR (common random numbers), scaled to it
        let noise_seed = ctx.seed.wrapping_add(1 + k as u64);
        for (si, &snr) in budget.snr_db.iter().enumerate() {
            let (noisy, refitted) = match fixed {
                Some(_) => (
                    noisy_test_series(series, snr, noise_seed, s.test_points)?,
                    None,
                ),
                None => {
                    let noisy = noisy_series(series, snr, noise_seed)?;
                    let train = noisy.prefix(s.train_points)?;
                    let g = fit(gsc(m, t)?, &train)?.predictor;
                    let k = fit(Box::new(gskf(m, t)?), &train)?.predictor;
                    let d = fit(Box::new(gskf_default(m, t)?), &train)?.predictor;
                    (noisy, Some([g, k, d]))
                }
            };
            let models: Vec<&dyn Predictor> = match (&fixed, &refitted) {
                (Some(f), _) => f.to_vec(),
                (None, Some(r)) => r.iter().map(|p| p.as_ref()).collect(),
                (None, None) => return Err(experiment(id, "no models")),
            };
            let noisy_truth = test_truth(&noisy, s.test_points);
            for (mi, p) in models.into_iter().enumerate() {
                let pred = predict_test(p, &noisy, t, s.test_points)?;
                errors[mi][si].push(rmse_3d(pred.step(t)?, &truth)? * 1e3);
                if mi == 1 {
                    observed[si].push(rmse_3d(pred.step(t)?, &noisy_truth)? * 1e3);
                }
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    let mut rows = Vec::with_capacity(n_snr);
    let mut curves: Vec<Vec<(f64, f64, f64, f64)>> = vec![Vec::new(); names.len()];
    for (si, &snr) in budget.snr_db.iter().enumerate() {
        let mut row = Row::new(format!("{snr}")).set("snr", snr);
        for (mi, (curve, (name, _))) in curves.iter_mut().zip(names).enumerate() {
            let (mean, min, max) = spread(&errors[mi][si]);
            curve.push((snr, mean, min, max));
            row = row
                .set(&format!("{name}_mean"), mean)
                .set(&format!("{name}_min"), min)
                .set(&format!("{name}_max"), max);
        }
        rows.push(row.set("observed", spread(&observed[si]).0));
    }

    let mut lines = Vec::new();
    for (mi, (_, name)) in names.iter().enumerate() {
        for (what, pick, markers) in [
            ("mean", 1usize, true),
            ("min over seeds", 2, false),
            ("max over seeds", 3, false),
        ] {
            lines.push(Series {
                label: format!("{name} ({what})"),
                points: curves[mi]
                    .iter()
                    .map(|c| (c.0, [c.1, c.2, c.3][pick - 1]))
                    .collect(),
                markers,
            });
        }
    }
    lines.push(Series {
        label: "paper (MSTPM-GSKF)".into(),
        points: paper.to_vec(),
        markers: true,
    });
    let figure = Figure {
        id: format!("{id}_snr"),
        caption: format!(
            "Fig. 4{}: 3-D RMSE (mm, log scale) of the 6th-step predictions against the SNR, \
             m = T = 6, {what}; mean and spread over the noise seeds",
            if fixed.is_some() { "" } else { " (variant)" }
        ),
        chart: Chart {
            title: format!("Error against SNR (m = T = 6), {what}"),
            x_label: "SNR (dB)".into(),
            y_label: "3-D RMSE (mm)".into(),
            series: lines,
            log_y: true,
        },
    };
    Ok((rows, figure))
}

/// The L2 norm of the last coefficient row (the T-th horizon) of the GSC fitted at
/// m = T = 6 on `train`, per axis: the factor by which it amplifies white noise in the window.
pub(super) fn coefficient_norms(s: &Setup, train: &Trajectory) -> Result<Vec<f64>> {
    let mut g = Gsc::new(GskfParams {
        window: s.window,
        horizons: s.horizons,
        ..Default::default()
    })?;
    g.fit(std::slice::from_ref(train))?;
    Ok(g.coders()
        .iter()
        .map(|c| {
            let a = c.coefficients();
            a.row(a.nrows().saturating_sub(1)).norm()
        })
        .collect())
}

pub(super) fn fmt(x: f64) -> String {
    crate::report::format_number(x, 4)
}

pub(super) fn fmt_list(xs: &[f64]) -> String {
    xs.iter().map(|x| fmt(*x)).collect::<Vec<_>>().join(", ")
}
