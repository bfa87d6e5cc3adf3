//! The real flight of the KFU-LSTM experiment, and the figures of each series.

use super::Params;
use super::train::{Case, MethodRun, points, train_len};
use crate::{Figure, ReproError, Result};
use std::path::Path;
use trajpred::plot::{Chart, Series as Line};
use trajpred_core::Trajectory;
use trajpred_data::geodesy::{Geodetic, LocalFrame};
use trajpred_data::{LoadOptions, Projection, adsb};

/// Loads the flight window in local ENU metres; returns it with a description of the data.
pub(super) fn load_flight(dir: &Path, p: &Params) -> Result<(Trajectory, String)> {
    let exp = |reason: String| ReproError::Experiment {
        experiment: "kfu-lstm/flight".into(),
        reason,
    };
    let path = dir.join(&p.flight_file);
    let opts = LoadOptions {
        projection: Projection::Geodetic,
        ..LoadOptions::adsb()
    };
    let (tracks, _) = adsb::load_file(&path, &opts)?;
    let track = tracks
        .iter()
        .find(|t| t.id == p.flight_id)
        .ok_or_else(|| exp(format!("no flight {} in {}", p.flight_id, path.display())))?;
    let tr = &track.trajectory;
    let start = tr
        .times()
        .iter()
        .position(|&t| t >= p.flight_start)
        .ok_or_else(|| exp("the flight ends before the window's start".into()))?;
    let points = p.flight_points;
    if start + points > tr.len() || tr.dim() != 3 {
        return Err(exp(format!(
            "the window needs {points} 3-D points from index {start}, the flight has {} \
             of {} axes",
            tr.len(),
            tr.dim()
        )));
    }
    let w = tr.slice(start..start + points)?;
    let (lat, lon, alt) = (w.axis(0), w.axis(1), w.axis(2));
    let frame = LocalFrame::new(Geodetic::new(lat[0], lon[0], alt[0])?)?;
    let mut axes: Vec<Vec<f64>> = (0..3).map(|_| Vec::with_capacity(points)).collect();
    for i in 0..points {
        let e = frame.to_enu(&Geodetic::new(lat[i], lon[i], alt[i])?);
        axes[0].push(e.east);
        axes[1].push(e.north);
        axes[2].push(e.up);
    }
    let t0 = w.times()[0];
    let times: Vec<f64> = w.times().iter().map(|t| t - t0).collect();
    let span = times.last().copied().unwrap_or(0.0);
    let alt_lo = alt.iter().copied().fold(f64::INFINITY, f64::min);
    let alt_hi = alt.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let desc = format!(
        "flight: {} (OpenSky ADS-B via the traffic package; not redistributed), track {}, \
         {points} consecutive points from index {start} of the cleaned track (first at or \
         after 2021-10-07 13:34:57 UTC), spanning {span:.0} s, barometric altitude \
         {alt_lo:.0}–{alt_hi:.0} m; local east-north-up metres around the window's first point; \
         the recorded positions are the truth, Gaussian noise σ = ({}, {}, {}) m (east, north, \
         up) is added",
        path.display(),
        p.flight_id,
        p.flight_sigma[0],
        p.flight_sigma[1],
        p.flight_sigma[2]
    );
    Ok((Trajectory::from_axes(times, axes)?, desc))
}

fn xy(p: &[Vec<f64>]) -> Vec<(f64, f64)> {
    p.iter()
        .map(|q| {
            (
                q.first().copied().unwrap_or(f64::NAN),
                q.get(1).copied().unwrap_or(f64::NAN),
            )
        })
        .collect()
}

/// The two figures of one series (first seed): the test part in the horizontal plane, and
/// the training losses.
pub(super) fn figures(
    methods: &[&str],
    out: &mut Vec<Figure>,
    case: &Case,
    noisy: &Trajectory,
    runs: &[MethodRun],
) -> Result<()> {
    let n_train = train_len(case.truth.len());
    let truth = points(&case.truth);
    let mut series = vec![
        Line {
            label: "truth".into(),
            points: xy(&truth[n_train..]),
            markers: false,
        },
        Line {
            label: "noisy observation".into(),
            points: xy(&points(noisy)[n_train..]),
            markers: true,
        },
    ];
    for (mi, name) in methods.iter().enumerate().skip(2) {
        if let Some(r) = runs.get(mi) {
            series.push(Line {
                label: (*name).into(),
                points: xy(&r.pred),
                markers: false,
            });
        }
    }
    out.push(Figure {
        id: format!("fig_{}_test", case.name),
        caption: format!(
            "{}: the test part (last 20%) seen from above ({} vs {}): truth, noisy \
             observation and the one-step-ahead predictions of RNN, LSTM and KFU-LSTM-Net \
             (first seed)",
            case.name, case.axes[1], case.axes[0]
        ),
        chart: Chart {
            title: format!("{}: one-step-ahead predictions on the test part", case.name),
            x_label: format!("{} (m)", case.axes[0]),
            y_label: format!("{} (m)", case.axes[1]),
            series,
            log_y: false,
        },
    });
    let loss_line = |label: &str, mi: usize| Line {
        label: label.into(),
        points: runs
            .get(mi)
            .map(|r| {
                r.losses
                    .iter()
                    .enumerate()
                    .map(|(e, l)| ((e + 1) as f64, *l))
                    .collect()
            })
            .unwrap_or_default(),
        markers: true,
    };
    out.push(Figure {
        id: format!("fig_{}_loss", case.name),
        caption: format!(
            "{}: training loss per epoch (z-scored units, first seed). RNN and LSTM: MSE of the \
             next noisy point; KFU-LSTM-Net: MSE(y(t|t), truth) + 0.5 MSE(y(t|t-1), truth), so \
             the curves are not on the same footing",
            case.name
        ),
        chart: Chart {
            title: format!("{}: training loss", case.name),
            x_label: "epoch".into(),
            y_label: "training loss (z-scored units)".into(),
            series: vec![
                loss_line("RNN", 2),
                loss_line("LSTM", 3),
                loss_line("KFU-LSTM-Net", 4),
            ],
            log_y: true,
        },
    });
    Ok(())
}
