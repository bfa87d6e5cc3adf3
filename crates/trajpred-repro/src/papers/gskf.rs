//! MSTPM-GSKF (`docs/papers.md` A.5): group sparse coding + an improved Kalman filter on the eq. 20
//! trajectory.
//!
//! Setup: eq. 20, 1000 points, the first 800 train every model, the last 200 are the test
//! points. Each axis is predicted separately. Every test point `j` is predicted `k` steps
//! ahead from the origin `j - k` (the history ends at `j - k`; it may reach back into the
//! training part, which is known at that time), so every horizon is scored on the same 200
//! points. The error of horizon `T` is the 3-D RMSE of eq. 21 over the `T`-th step
//! predictions of the 200 test points; the "all steps" figure pools steps `1..=T`.
//!
//! Experiments: Table 1 (m = 2..8, T = 1), Table 2 (m = 6, T = 1..6, one model per T),
//! Table 3 (m = T = 6, per-axis and 3-D RMSE of BP, LSTM, GSC, MSTPM-GSKF, with wall times),
//! Table 4 (mean and variance of the per-point 3-D error), Fig. 4 (white Gaussian noise added
//! to the test part at SNR 1..100 dB, several seeds), Fig. 5 (per-point error), Fig. 6 (true
//! and predicted trajectories, x-y and x-z projections).
//!
//! The tables' layout, the paper's figures and its claims are in `papers/gskf.toml`; this module
//! computes the numbers ([`predict`]: predictions and errors; `snr`: the SNR sweep, which only
//! this paper computes).

use crate::report::{Figure, PaperResult};
use crate::runner::{Computed, Row, assemble};
use crate::{Context, Paper, Result};
use predict::{
    Fitted, TestPredictions, experiment, fit, fit_neural, gsc, gskf, predict_test, score,
    test_truth,
};
use serde::Deserialize;
use snr::{coefficient_norms, fmt_list, snr_sweep};
use trajpred::plot::{Chart, Series};
use trajpred_core::{Predictor, Trajectory};
use trajpred_data::synthetic::gskf_eq20;
use trajpred_neural::{LstmNet, Mlp};

pub mod predict;
mod snr;

/// The protocol (`[params]` of the spec).
#[derive(Debug, Clone, Deserialize)]
pub(crate) struct Setup {
    /// Points of the trajectory used for training.
    train_points: usize,
    /// Test points at the end of the trajectory.
    test_points: usize,
    /// Table 1: window lengths at T = 1.
    table1_windows: Vec<usize>,
    /// Table 2: horizons at m = `window`.
    table2_horizons: Vec<usize>,
    /// Tables 3, 4 and Fig. 4: the window m and the horizons T.
    window: usize,
    horizons: usize,
}

/// How much to run (`[budget]`): the full run or `--quick`.
#[derive(Debug, Clone, Deserialize)]
pub(crate) struct Budget {
    bp_epochs: usize,
    lstm_epochs: usize,
    snr_db: Vec<f64>,
    noise_seeds: usize,
}

/// Table 1 (m = 2..8, T = 1) and Table 2 (m = 6, T = 1..6, one model per T).
fn tables_1_2(ctx: &Context, s: &Setup, series: &Trajectory, out: &mut Computed) -> Result<()> {
    let train = series.prefix(s.train_points)?;
    let truth = test_truth(series, s.test_points);
    let bar = ctx.bar(
        s.table1_windows.len() as u64,
        "gskf: table 1 (m = 2..8, T = 1)",
    );
    for &m in &s.table1_windows {
        let g = fit(gsc(m, 1)?, &train)?;
        let gp = predict_test(g.predictor.as_ref(), series, 1, s.test_points)?;
        let gs = score(&gp, &truth, 1)?;
        let k = fit(Box::new(gskf(m, 1)?), &train)?;
        let kp = predict_test(k.predictor.as_ref(), series, 1, s.test_points)?;
        let ks = score(&kp, &truth, 1)?;
        out.table("table1").rows.push(
            Row::new(format!("m{m}"))
                .set("gsc", gs.rmse_3d * 1e3)
                .set("gskf", ks.rmse_3d * 1e3)
                .set("seconds", k.fit_seconds + kp.seconds),
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    let bar = ctx.bar(
        s.table2_horizons.len() as u64,
        "gskf: table 2 (m = 6, T = 1..6)",
    );
    let mut chosen_q = Vec::new();
    for &t in &s.table2_horizons {
        let g = fit(gsc(s.window, t)?, &train)?;
        let gp = predict_test(g.predictor.as_ref(), series, t, s.test_points)?;
        let gs = score(&gp, &truth, t)?;
        let mut k = gskf(s.window, t)?;
        k.fit(std::slice::from_ref(&train))?;
        // one training series: q is chosen in sample and the correction is always on
        let q: Vec<f64> = k.process_noise().into_iter().flatten().collect();
        chosen_q.push(format!("T = {t}: {}", fmt_list(&q)));
        let ks = score(&predict_test(&k, series, t, s.test_points)?, &truth, t)?;
        out.table("table2").rows.push(
            Row::new(format!("T{t}"))
                .set("gsc", gs.rmse_3d * 1e3)
                .set("gskf", ks.rmse_3d * 1e3)
                .set("pooled", ks.pooled_3d * 1e3),
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    out.var("chosen_q", chosen_q.join("; "));
    Ok(())
}

/// Figs. 5 and 6: per-point error, and the true and predicted test trajectories.
fn figures_5_6(
    methods: &[&str],
    truth: &[[f64; 3]],
    per_point: &[Vec<f64>],
    preds: &[TestPredictions],
    t: usize,
) -> Vec<Figure> {
    let mut out = vec![Figure {
        id: "fig5_per_point".into(),
        caption: "Fig. 5: per-point 3-D error (m, log scale) of the 6th-step predictions over \
                  the 200 test points, m = T = 6 (points with zero error are not drawn)"
            .into(),
        chart: Chart {
            title: "Per-point 3-D error (m = T = 6)".into(),
            x_label: "test point".into(),
            y_label: "3-D error (m)".into(),
            series: methods
                .iter()
                .zip(per_point)
                .map(|(name, e)| Series {
                    label: (*name).into(),
                    points: e
                        .iter()
                        .enumerate()
                        .map(|(j, e)| ((j + 1) as f64, *e))
                        .collect(),
                    markers: false,
                })
                .collect(),
            log_y: true,
        },
    }];
    for (id, axis, name) in [("fig6_xy", 1, "y"), ("fig6_xz", 2, "z")] {
        let mut s = vec![Series {
            label: "true".into(),
            points: truth.iter().map(|p| (p[0], p[axis])).collect(),
            markers: false,
        }];
        for (name, p) in methods.iter().zip(preds) {
            s.push(Series {
                label: format!("{name} (6-step)"),
                points: p.steps[t - 1].iter().map(|q| (q[0], q[axis])).collect(),
                markers: false,
            });
        }
        out.push(Figure {
            id: id.into(),
            caption: format!(
                "Fig. 6: true test trajectory and the 6th-step predictions of the four methods, \
                 x-{name} projection (m)"
            ),
            chart: Chart {
                title: format!("True and predicted trajectory, x-{name} (m = T = 6)"),
                x_label: "x (m)".into(),
                y_label: format!("{name} (m)"),
                series: s,
                log_y: false,
            },
        });
    }
    out
}

/// Runs the paper's experiments and builds its report from the spec.
pub fn run(ctx: &Context) -> Result<PaperResult> {
    let spec = Paper::Gskf.spec()?;
    let s: Setup = spec.params()?;
    let budget: Budget = spec.budget_as(ctx.quick)?;
    let series = gskf_eq20();
    if series.len() != s.train_points + s.test_points {
        return Err(experiment(
            "data",
            format!(
                "eq. 20 has {} points, expected {}",
                series.len(),
                s.train_points + s.test_points
            ),
        ));
    }
    let train = series.prefix(s.train_points)?;
    let truth = test_truth(&series, s.test_points);
    let mut out = Computed::default();
    out.data.push(format!(
        "Eq. 20 (trajpred_data::synthetic::gskf_eq20): {} points, t_i = i * 0.01 pi; the first \
         {} train every model, the last {} are the test points.",
        series.len(),
        s.train_points,
        s.test_points
    ));
    out.var("seed", ctx.seed.to_string());
    tables_1_2(ctx, &s, &series, &mut out)?;

    // Tables 3 and 4: m = T = 6, the four methods in the spec's order
    let (m, t) = (s.window, s.horizons);
    let fitted: Vec<Fitted> = vec![
        fit_neural(
            ctx,
            Mlp::gskf_bp(m, t)?,
            budget.bp_epochs,
            ctx.seed,
            &train,
            "gskf: BP training",
        )?,
        fit_neural(
            ctx,
            LstmNet::gskf_lstm(m, t)?,
            budget.lstm_epochs,
            ctx.seed,
            &train,
            "gskf: LSTM training",
        )?,
        fit(gsc(m, t)?, &train)?,
        fit(Box::new(gskf(m, t)?), &train)?,
    ];
    let bar = ctx.bar(4, "gskf: table 3 forecasts");
    let mut preds = Vec::new();
    let mut per_point = Vec::new();
    for (f, method) in fitted.iter().zip(&spec.methods) {
        let p = predict_test(f.predictor.as_ref(), &series, t, s.test_points)?;
        let sc = score(&p, &truth, t)?;
        let axis = |k: usize| sc.axes.get(k).copied().unwrap_or(f64::NAN);
        out.table("table3").rows.push(
            Row::new(&method.key)
                .set("x", axis(0))
                .set("y", axis(1))
                .set("z", axis(2))
                .set("3d", sc.rmse_3d)
                .set("pooled", sc.pooled_3d)
                .set("fit_s", f.fit_seconds)
                .set("forecast_s", p.seconds),
        );
        out.table("table4").rows.push(
            Row::new(&method.key)
                .set("mean", sc.mean)
                .set("variance", sc.variance),
        );
        per_point.push(sc.per_point);
        preds.push(p);
        bar.inc(1);
    }
    bar.finish_and_clear();

    // Fig. 4: noise on the test part (the paper), and on the whole series (our addition)
    let mut paper: Vec<(f64, f64)> = spec
        .paper
        .iter()
        .filter(|p| p.table == "fig4")
        .flat_map(|p| p.values.iter())
        .filter_map(|(k, v)| Some((k.parse::<f64>().ok()?, *v)))
        .collect();
    paper.sort_by(|a, b| a.0.total_cmp(&b.0));
    let fixed: [&dyn Predictor; 2] = [fitted[2].predictor.as_ref(), fitted[3].predictor.as_ref()];
    let (rows, fig4) = snr_sweep(ctx, &s, &budget, &series, Some(fixed), &paper)?;
    out.table("fig4").rows = rows;
    out.figures.push(fig4);
    let (rows, fig4b) = snr_sweep(ctx, &s, &budget, &series, None, &paper)?;
    out.table("fig4_noisy_train").rows = rows;
    out.figures.push(fig4b);

    let labels: Vec<&str> = spec.methods.iter().map(|m| m.label.as_str()).collect();
    out.figures
        .extend(figures_5_6(&labels, &truth, &per_point, &preds, t));
    let norms = coefficient_norms(&s, &train)?;
    out.var("coefficient_norms", fmt_list(&norms));
    assemble(spec, ctx, out)
}
