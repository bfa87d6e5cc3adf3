//! What the command line prints and writes: forecasts (CSV, Markdown, JSON with the local
//! frame's origin) and result tables, and atomic file writes.

use anyhow::{Context, Result};
use clap::ValueEnum;
use std::io::Write;
use trajpred::dataset::Segment;
use trajpred::harness::MethodReport;
use trajpred_core::{Forecast, Trajectory};
use trajpred_data::Frame;
use trajpred_data::geodesy::{Enu, LocalFrame};

/// An output format.
#[derive(Clone, Copy, ValueEnum)]
pub enum Format {
    /// A Markdown table.
    Markdown,
    /// Comma-separated values.
    Csv,
    /// JSON.
    Json,
}

/// The forecast's step in seconds: the mean interval of the history, as the methods take it.
pub fn mean_interval(tr: &Trajectory) -> f64 {
    let t = tr.times();
    if t.len() < 2 {
        return 1.0;
    }
    (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64
}

/// Latitude and longitude of a point of an ENU frame.
fn lat_lon(frame: Option<&LocalFrame>, p: &[f64]) -> Option<(f64, f64)> {
    let g = frame?.to_geodetic(&Enu {
        east: p[0],
        north: p.get(1).copied().unwrap_or(0.0),
        up: p.get(2).copied().unwrap_or(0.0),
    });
    Some((g.lat_deg, g.lon_deg))
}

pub fn write_forecast(
    f: &Forecast,
    seg: &Segment,
    history: &Trajectory,
    format: Format,
    out: &mut dyn Write,
) -> Result<()> {
    let dt = mean_interval(history);
    let t_last = history.times()[history.len() - 1];
    let times: Vec<f64> = (1..=f.horizon()).map(|k| t_last + dt * k as f64).collect();
    let axes = ["x", "y", "z"];
    let origin = match seg.frame {
        Frame::Enu(o) => Some(o),
        _ => None,
    };
    let local = origin.map(LocalFrame::new).transpose()?;
    let frame = match origin {
        Some(o) => format!(
            "local east/north metres around lat {:.7} lon {:.7}",
            o.lat_deg, o.lon_deg
        ),
        None => "the input's own metres".to_string(),
    };
    match format {
        Format::Json => {
            let steps: Vec<serde_json::Value> = f
                .points()
                .zip(&times)
                .enumerate()
                .map(|(k, (p, t))| {
                    let ll = lat_lon(local.as_ref(), &p);
                    serde_json::json!({
                        "step": k + 1,
                        "t": t,
                        "point": p.to_vec(),
                        "lat_deg": ll.map(|v| v.0),
                        "lon_deg": ll.map(|v| v.1),
                        "covariance": f.covariance(k + 1).map(|c| {
                            c.row_iter().map(|r| r.iter().copied().collect::<Vec<f64>>())
                                .collect::<Vec<_>>()
                        }),
                    })
                })
                .collect();
            let doc = serde_json::json!({
                "segment": seg.id,
                "origin_time": t_last,
                "step_seconds": dt,
                "dim": f.dim(),
                "frame": match origin {
                    Some(o) => serde_json::json!({
                        "kind": "enu",
                        "origin_lat_deg": o.lat_deg,
                        "origin_lon_deg": o.lon_deg,
                        "origin_alt_m": o.alt_m,
                    }),
                    None => serde_json::json!({ "kind": "cartesian" }),
                },
                "steps": steps,
            });
            writeln!(out, "{}", serde_json::to_string_pretty(&doc)?)?;
        }
        Format::Csv | Format::Markdown => {
            let md = matches!(format, Format::Markdown);
            let mut header: Vec<&str> = axes[..f.dim()].to_vec();
            if local.is_some() {
                header.extend(["lat", "lon"]);
            }
            if md {
                writeln!(
                    out,
                    "Forecast of {} from t = {t_last} s, steps of {dt:.3} s (the history's mean \
                     interval), in {frame}.\n",
                    seg.id
                )?;
                writeln!(out, "| step | t | {} |", header.join(" | "))?;
                writeln!(out, "|---|---|{}", "---|".repeat(header.len()))?;
            } else {
                eprintln!(
                    "note: the forecast is in {frame}; steps of {dt} s (the history's mean interval)"
                );
                writeln!(out, "step,t,{}", header.join(","))?;
            }
            for (k, (p, t)) in f.points().zip(&times).enumerate() {
                let mut vals: Vec<String> = p.iter().map(|v| format!("{v:.6}")).collect();
                if let Some((lat, lon)) = lat_lon(local.as_ref(), &p) {
                    vals.extend([format!("{lat:.8}"), format!("{lon:.8}")]);
                }
                if md {
                    writeln!(out, "| {} | {t} | {} |", k + 1, vals.join(" | "))?;
                } else {
                    writeln!(out, "{},{t},{}", k + 1, vals.join(","))?;
                }
            }
        }
    }
    Ok(())
}

pub fn table(reports: &[MethodReport], format: Format) -> Result<String> {
    if let Format::Json = format {
        return Ok(serde_json::to_string_pretty(reports)?);
    }
    let h = reports.first().map_or(0, |r| r.mean_euclidean.len());
    let mut head = vec![
        "method".to_string(),
        "trajectories".into(),
        "forecasts".into(),
        "failures".into(),
    ];
    for k in 1..=h {
        head.push(format!("mean err step {k} (m)"));
    }
    head.extend([
        "mean err all (m)".into(),
        "hit rate all".into(),
        "fit (s)".into(),
        "forecast (s)".into(),
    ]);
    let rows: Vec<Vec<String>> = reports
        .iter()
        .map(|r| {
            let mut row = vec![
                r.method.clone(),
                r.trajectories.to_string(),
                r.forecasts.to_string(),
                r.failures.to_string(),
            ];
            row.extend(r.mean_euclidean.iter().map(|v| format!("{v:.3}")));
            row.extend([
                format!("{:.3}", r.mean_euclidean_all),
                format!("{:.4}", r.hit_rate_all),
                format!("{:.3}", r.fit_seconds),
                format!("{:.3}", r.forecast_seconds),
            ]);
            row
        })
        .collect();
    let mut s = String::new();
    match format {
        Format::Csv => {
            s.push_str(&head.join(","));
            s.push('\n');
            for r in rows {
                s.push_str(&r.join(","));
                s.push('\n');
            }
        }
        _ => {
            s.push_str(&format!("| {} |\n", head.join(" | ")));
            s.push_str(&format!("|{}\n", "---|".repeat(head.len())));
            for r in rows {
                s.push_str(&format!("| {} |\n", r.join(" | ")));
            }
        }
    }
    Ok(s)
}

/// Writes `bytes` to `path` whole or not at all ([`trajpred_core::io::write_atomic`]).
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    trajpred_core::io::write_atomic(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}
