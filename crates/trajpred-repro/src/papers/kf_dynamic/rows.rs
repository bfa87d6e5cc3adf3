//! The numbers of the KF-dynamic tables and the quantities of its claims, from the protocol
//! runs (the tables' layout, the paper's figures and the claims are in `papers/kf-dynamic.toml`).

use super::grid::Grid;
use super::{Ds, Params};
use crate::Result;
use crate::report::Value;
use crate::runner::{Computed, Row};
use crate::spec::Spec;

/// Index of the method with key `key` in the spec (the protocol's order).
pub(super) fn index(spec: &Spec, key: &str) -> usize {
    spec.methods.iter().position(|m| m.key == key).unwrap_or(0)
}

impl Grid {
    /// Mean Euclidean error over every step and history.
    pub(super) fn error(&self, m: usize) -> f64 {
        self.run.error(m)
    }
    /// Accuracy (percent) over every step and history.
    pub(super) fn accuracy(&self, m: usize) -> f64 {
        self.run.accuracy(m)
    }
    /// The mean error of the two N-point fits.
    fn fitting_error(&self, spec: &Spec) -> f64 {
        (self.error(index(spec, "poly1")) + self.error(index(spec, "poly2"))) / 2.0
    }
    /// The mean accuracy of the two N-point fits.
    fn fitting_accuracy(&self, spec: &Spec) -> f64 {
        (self.accuracy(index(spec, "poly1")) + self.accuracy(index(spec, "poly2"))) / 2.0
    }
}

/// The per-dataset tables' numbers and the claims' quantities.
pub(super) fn dataset_rows(
    spec: &Spec,
    ds: Ds,
    p: &Params,
    g: &Grid,
    out: &mut Computed,
) -> Result<()> {
    let d = ds.key();
    for (i, m) in spec.methods.iter().enumerate() {
        let reports = &g.run.reports[i];
        let mut err = Row::new(&m.key);
        let mut acc = Row::new(&m.key);
        for (&h, r) in p.histories.iter().zip(reports) {
            err = err.set(&format!("h{h}"), r.mean_euclidean_all);
            acc = acc.set(&format!("h{h}"), 100.0 * r.hit_rate_all);
        }
        out.table(&format!("{d}_error_history"))
            .rows
            .push(err.set("mean", g.error(i)).set("rmse", g.run.rmse(i)));
        out.table(&format!("{d}_accuracy_history"))
            .rows
            .push(acc.set("mean", g.accuracy(i)));
        let mut err = Row::new(&m.key);
        let mut acc = Row::new(&m.key);
        for k in 0..p.horizon {
            err = err.set(&format!("s{}", k + 1), g.run.step_error(i, k));
            acc = acc.set(&format!("s{}", k + 1), g.run.step_accuracy(i, k));
        }
        out.table(&format!("{d}_error_step")).rows.push(err);
        out.table(&format!("{d}_accuracy_step")).rows.push(acc);
    }
    let hmm = index(spec, "hmm");
    let runtime = out.table(&format!("{d}_runtime"));
    for (n, per) in &g.timing {
        for (i, (m, r)) in spec.methods.iter().zip(per).enumerate() {
            runtime.rows.push(
                Row::new(format!("{n}:{}", m.key))
                    .set("n", n.to_string())
                    .set("method", m.label.as_str())
                    .set("forecasts", r.forecasts)
                    .set("error", r.mean_euclidean_all)
                    .set("accuracy", 100.0 * r.hit_rate_all)
                    .set("forecast_s", r.forecast_seconds)
                    .set(
                        "fit_s",
                        if i == hmm {
                            Value::Num(g.hmm_fit_seconds)
                        } else {
                            Value::Missing
                        },
                    ),
            );
        }
    }
    let hi = p
        .histories
        .iter()
        .position(|&h| h == p.timing_history)
        .unwrap_or(0);
    let at = |key: &str| &g.run.reports[index(spec, key)][hi];
    let mut pairs = vec![
        ("set1", at("kf1"), at("naive1")),
        ("set2", at("kf2"), at("naive2")),
    ];
    pairs.extend(g.combos.iter().map(|(key, a, b)| (*key, a, b)));
    let table = out.table(&format!("{d}_kf_parameters"));
    for (key, a, b) in pairs {
        table.rows.push(
            Row::new(key)
                .set("kf_error", a.mean_euclidean_all)
                .set("kf_accuracy", 100.0 * a.hit_rate_all)
                .set("naive_error", b.mean_euclidean_all)
                .set("naive_accuracy", 100.0 * b.hit_rate_all),
        );
    }
    // the claims' quantities
    let q = &mut out.quantities;
    q.insert(format!("{d}.fitting_error"), g.fitting_error(spec));
    q.insert(format!("{d}.fitting_accuracy"), g.fitting_accuracy(spec));
    q.insert(format!("{d}.hmm_fit"), g.hmm_fit_seconds);
    if let Some((n, per)) = g.timing.last() {
        let time =
            |i: usize| per[i].forecast_seconds + if i == hmm { g.hmm_fit_seconds } else { 0.0 };
        for key in ["kf1", "naive1", "hmm", "poly1", "poly2"] {
            q.insert(format!("{d}.time.{key}"), time(index(spec, key)));
        }
        let slowest_other = (0..per.len())
            .filter(|&i| i != hmm)
            .map(time)
            .fold(0.0, f64::max);
        q.insert(format!("{d}.time.slowest_other"), slowest_other);
        out.var(&format!("{d}.timing_n"), *n);
    }
    Ok(())
}

/// The headline table: the paper's four figures beside ours (missing where the dataset is).
pub(super) fn headline(spec: &Spec, grids: &[(Ds, Grid)], out: &mut Computed) {
    let find = |ds: Ds| grids.iter().find(|(d, _)| *d == ds).map(|(_, g)| g);
    let (geo, td) = (find(Ds::Geolife), find(Ds::Tdrive));
    let kf = index(spec, "kf1");
    let rows = [
        ("geolife_error", geo.map(|g| g.error(kf))),
        ("geolife_accuracy", geo.map(|g| g.accuracy(kf))),
        (
            "tdrive_error_gain",
            td.map(|g| g.fitting_error(spec) - g.error(kf)),
        ),
        (
            "tdrive_accuracy_gain",
            td.map(|g| g.accuracy(kf) - g.fitting_accuracy(spec)),
        ),
    ];
    let t = out.table("headline");
    for (key, v) in rows {
        t.rows.push(Row::new(key).set("ours", v));
    }
}
