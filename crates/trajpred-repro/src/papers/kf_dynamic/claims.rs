//! The KF-dynamic paper's claims, decided from the protocol runs.

use super::*;

fn fmt_m(x: f64) -> String {
    format!("{x:.2} m")
}

pub(super) fn claims(ds: Ds, g: &Grid, out: &mut PaperResult) {
    let name = ds.label();
    let kf = Method::KfDyn1;
    let others = [
        Method::Naive1,
        Method::Naive2,
        Method::Hmm,
        Method::Poly1,
        Method::Poly2,
    ];
    let evidence = |ms: &[Method]| -> String {
        ms.iter()
            .map(|&m| format!("{} {}", m.short(), fmt_m(g.error(m))))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let best_kf = g.error(Method::KfDyn1).min(g.error(Method::KfDyn2));
    let best_other = others
        .iter()
        .map(|&m| g.error(m))
        .fold(f64::INFINITY, f64::min);
    let mut all = vec![Method::KfDyn1, Method::KfDyn2];
    all.extend(others);
    out.claim(
        format!("{name}: KF dynamic (better of its two parameter sets) has the lowest mean error of the methods"),
        best_kf < best_other,
        format!("mean over histories and steps: {}", evidence(&all)),
    );
    let fit = g.fitting_error();
    out.claim(
        format!("{name}: KF dynamic (set 1) has a lower error than both fitting methods"),
        g.error(kf) < g.error(Method::Poly1) && g.error(kf) < g.error(Method::Poly2),
        evidence(&[kf, Method::Poly1, Method::Poly2]),
    );
    let hmm = g.error(Method::Hmm);
    out.claim(
        format!(
            "{name}: the HMM's error is above KF dynamic's (set 1) and below both fitting methods'"
        ),
        hmm > g.error(kf) && hmm < g.error(Method::Poly1) && hmm < g.error(Method::Poly2),
        evidence(&[kf, Method::Hmm, Method::Poly1, Method::Poly2]),
    );
    match ds {
        Ds::Geolife => {
            let e = g.error(kf);
            out.claim(
                format!(
                    "GeoLife: KF dynamic's average error is about {PAPER_GEOLIFE_ERROR_M} m \
                     (within {:.0}%)",
                    100.0 * ABOUT_ERROR_REL
                ),
                ((e - PAPER_GEOLIFE_ERROR_M) / PAPER_GEOLIFE_ERROR_M).abs() <= ABOUT_ERROR_REL,
                format!(
                    "set 1 {}, set 2 {}",
                    fmt_m(e),
                    fmt_m(g.error(Method::KfDyn2))
                ),
            );
            let a = g.accuracy(kf);
            out.claim(
                format!(
                    "GeoLife: KF dynamic's accuracy is about {PAPER_GEOLIFE_ACCURACY_PCT}% \
                     (within {ABOUT_ACCURACY_PTS} points)"
                ),
                (a - PAPER_GEOLIFE_ACCURACY_PCT).abs() <= ABOUT_ACCURACY_PTS,
                format!("set 1 {a:.2}%, set 2 {:.2}%", g.accuracy(Method::KfDyn2)),
            );
        }
        Ds::Tdrive => {
            let gain = fit - g.error(kf);
            out.claim(
                format!(
                    "T-Drive: KF dynamic's error is lower than the fitting methods' (the paper: \
                     by {PAPER_TDRIVE_ERROR_GAIN_M} m on average)"
                ),
                gain > 0.0,
                format!(
                    "fitting methods' mean {} minus KF dynamic (set 1) {} = {}",
                    fmt_m(fit),
                    fmt_m(g.error(kf)),
                    fmt_m(gain)
                ),
            );
            let acc_gain = g.accuracy(kf) - g.fitting_accuracy();
            out.claim(
                format!(
                    "T-Drive: KF dynamic's accuracy is higher than the fitting methods' (the \
                     paper: by {PAPER_TDRIVE_ACCURACY_GAIN_PTS} points)"
                ),
                acc_gain > 0.0,
                format!(
                    "KF dynamic (set 1) {:.2}% minus fitting methods' mean {:.2}% = {acc_gain:.2} \
                     points",
                    g.accuracy(kf),
                    g.fitting_accuracy()
                ),
            );
        }
    }
    if let Some((n, per)) = g.timing.last() {
        let time = |m: Method| {
            let i = METHODS.iter().position(|&x| x == m).unwrap_or(0);
            per[i].forecast_seconds
                + if m == Method::Hmm {
                    g.hmm_fit_seconds
                } else {
                    0.0
                }
        };
        let slowest_fit = time(Method::Poly1).max(time(Method::Poly2));
        out.claim(
            format!(
                "{name}: KF dynamic and naive KF take longer than the fitting methods (wall time, \
                 {n} test trajectories)"
            ),
            time(Method::KfDyn1) > slowest_fit && time(Method::Naive1) > slowest_fit,
            format!(
                "KF dynamic {:.3} s, naive KF {:.3} s, linear {:.3} s, quadratic {:.3} s \
                 (set 1; this machine's wall times)",
                time(Method::KfDyn1),
                time(Method::Naive1),
                time(Method::Poly1),
                time(Method::Poly2)
            ),
        );
        let hmm_t = time(Method::Hmm);
        out.claim(
            format!("{name}: the HMM takes the longest (fit and forecasts, wall time)"),
            METHODS
                .iter()
                .filter(|&&m| m != Method::Hmm)
                .all(|&m| time(m) < hmm_t),
            format!(
                "HMM {hmm_t:.3} s (fit {:.3} s); slowest other {:.3} s",
                g.hmm_fit_seconds,
                METHODS
                    .iter()
                    .filter(|&&m| m != Method::Hmm)
                    .map(|&m| time(m))
                    .fold(0.0, f64::max)
            ),
        );
    }
}
