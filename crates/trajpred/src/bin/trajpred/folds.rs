//! `evaluate --folds K` (cross-validation by user: mean and spread over folds) and
//! `evaluate --figure` (the per-step error curves).

use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;
use trajpred::plot::{Chart, Series, write_chart};
use trajpred::protocol::ProtocolRun;

/// Mean and sample standard deviation (0 for one value).
fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

/// Per method: the per-step mean error, averaged over the runs (folds), and the all-step
/// mean error and hit rate of each run.
pub struct Summary {
    pub labels: Vec<String>,
    pub steps: Vec<Vec<f64>>,
    pub errors: Vec<Vec<f64>>,
    pub hits: Vec<Vec<f64>>,
    pub forecasts: Vec<usize>,
    pub failures: Vec<usize>,
}

/// The runs' first history, per method (one run per fold; a single run is one fold).
pub fn summarise(runs: &[ProtocolRun]) -> Summary {
    let labels = runs.first().map(|r| r.labels.clone()).unwrap_or_default();
    let m = labels.len();
    let mut s = Summary {
        labels,
        steps: Vec::with_capacity(m),
        errors: vec![Vec::new(); m],
        hits: vec![Vec::new(); m],
        forecasts: vec![0; m],
        failures: vec![0; m],
    };
    for i in 0..m {
        let h = runs
            .first()
            .map_or(0, |r| r.reports[i][0].mean_euclidean.len());
        let mut steps = vec![0.0; h];
        for r in runs {
            let rep = &r.reports[i][0];
            for (k, e) in rep.mean_euclidean.iter().enumerate() {
                steps[k] += e / runs.len() as f64;
            }
            s.errors[i].push(rep.mean_euclidean_all);
            s.hits[i].push(rep.hit_rate_all);
            s.forecasts[i] += rep.forecasts;
            s.failures[i] += rep.failures;
        }
        s.steps.push(steps);
    }
    s
}

/// The cross-validation table: per method, the mean (and standard deviation over folds) of
/// the fold's mean error and hit rate, and the per-step error averaged over folds.
pub fn markdown(s: &Summary, folds: usize) -> String {
    let h = s.steps.first().map_or(0, Vec::len);
    let mut out = String::from("| method | folds | forecasts | failures |");
    for k in 1..=h {
        let _ = write!(out, " err step {k} (m) |");
    }
    out.push_str(" mean err all (m), mean ± sd over folds | hit rate all, mean ± sd |\n|---|");
    out.push_str(&"---|".repeat(h + 5));
    out.push('\n');
    for i in 0..s.labels.len() {
        let (e, es) = mean_sd(&s.errors[i]);
        let (r, rs) = mean_sd(&s.hits[i]);
        let _ = write!(
            out,
            "| {} | {folds} | {} | {} |",
            s.labels[i], s.forecasts[i], s.failures[i]
        );
        for v in &s.steps[i] {
            let _ = write!(out, " {v:.3} |");
        }
        let _ = writeln!(out, " {e:.3} ± {es:.3} | {r:.4} ± {rs:.4} |");
    }
    out
}

/// The per-step mean error of the methods within 1.5 times the best all-step error (at most
/// eight, best first), as a line chart.
pub fn figure(s: &Summary, title: &str, path: &Path) -> Result<()> {
    let overall: Vec<f64> = s.errors.iter().map(|v| mean_sd(v).0).collect();
    let best = overall
        .iter()
        .copied()
        .filter(|e| e.is_finite())
        .fold(f64::INFINITY, f64::min);
    let mut order: Vec<usize> = (0..s.labels.len())
        .filter(|&i| overall[i].is_finite() && overall[i] <= 1.5 * best)
        .collect();
    order.sort_by(|&a, &b| overall[a].total_cmp(&overall[b]));
    order.truncate(8);
    let chart = Chart {
        title: title.to_string(),
        x_label: "forecast step".into(),
        y_label: "mean Euclidean error (m)".into(),
        series: order
            .iter()
            .map(|&i| Series {
                label: format!("{} ({:.2} m)", s.labels[i], overall[i]),
                points: s.steps[i]
                    .iter()
                    .enumerate()
                    .map(|(k, &e)| ((k + 1) as f64, e))
                    .collect(),
                markers: true,
            })
            .collect(),
        log_y: false,
    };
    write_chart(&chart, path)?;
    Ok(())
}
