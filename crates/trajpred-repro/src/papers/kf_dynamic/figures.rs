//! The KF-dynamic paper's figures (like its Figs. 1-6), drawn from the protocol runs.

use super::grid::Grid;
use super::{Ds, Params};
use crate::report::Figure;
use crate::spec::Spec;
use trajpred::plot::{Chart, Series};

fn series(label: &str, points: Vec<(f64, f64)>) -> Series {
    Series {
        label: label.to_string(),
        points,
        markers: true,
    }
}

fn figure(
    id: String,
    caption: String,
    title: String,
    x: &str,
    y: String,
    series: Vec<Series>,
) -> Figure {
    Figure {
        id,
        caption,
        chart: Chart {
            title,
            x_label: x.into(),
            y_label: y,
            series,
            log_y: true,
        },
    }
}

/// The figures of one dataset: error and accuracy against history, error against step, run
/// time against the number of test trajectories.
pub(super) fn figures(spec: &Spec, ds: Ds, p: &Params, g: &Grid) -> Vec<Figure> {
    let (slug, name) = (ds.key(), ds.label());
    let accuracy_kind = "accuracy (error < 25 m)";
    let mut out = Vec::new();
    for (kind, unit, id, fig) in [
        ("mean Euclidean error", "m", "error_history", ds.fig(1)),
        (accuracy_kind, "%", "accuracy_history", ds.fig(2)),
    ] {
        let is_err = id == "error_history";
        let lines = spec
            .methods
            .iter()
            .zip(&g.run.reports)
            .map(|(m, reports)| {
                let points = p
                    .histories
                    .iter()
                    .zip(reports)
                    .map(|(&h, r)| {
                        let y = if is_err {
                            r.mean_euclidean_all
                        } else {
                            100.0 * r.hit_rate_all
                        };
                        (h as f64, y)
                    })
                    .collect();
                series(m.short(), points)
            })
            .collect();
        let mut f = figure(
            format!("{slug}_{id}"),
            format!("{name}: {kind} against history length (like the paper's Fig. {fig})"),
            format!("{name}: {kind} against history length"),
            "history length (points)",
            format!("{kind} ({unit})"),
            lines,
        );
        f.chart.log_y = is_err;
        out.push(f);
    }
    let kind = "mean Euclidean error";
    let lines = spec
        .methods
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let points = (0..p.horizon)
                .map(|k| ((k + 1) as f64, g.run.step_error(i, k)))
                .collect();
            series(m.short(), points)
        })
        .collect();
    out.push(figure(
        format!("{slug}_error_step"),
        format!("{name}: {kind} against forecast step"),
        format!("{name}: {kind} against forecast step"),
        "forecast step",
        format!("{kind} (m)"),
        lines,
    ));
    let lines = spec
        .methods
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let points = g
                .timing
                .iter()
                .map(|(n, per)| (*n as f64, per[i].forecast_seconds))
                .collect();
            series(m.short(), points)
        })
        .collect();
    out.push(figure(
        format!("{slug}_runtime"),
        format!(
            "{name}: forecast wall time against the number of test trajectories (like the \
             paper's Fig. {})",
            ds.fig(3)
        ),
        format!("{name}: run time against test trajectories"),
        "test trajectories",
        "forecast wall time (s)".into(),
        lines,
    ));
    out
}
