//! Figures with plotters: a trajectory with forecasts (the CLI's `plot`), and line charts for
//! the reproduction. SVG or PNG by the file extension; text uses an embedded DejaVu font, so
//! no system font is needed.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;
use trajpred_core::{Error, Result};

/// One polyline of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// The points `(x, y)`.
    pub points: Vec<(f64, f64)>,
    /// Draw markers at the points as well as the line.
    pub markers: bool,
}

/// A 2-D line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Logarithmic y axis.
    pub log_y: bool,
}

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // registering the same static bytes cannot fail in practice; if it did, text would be
        // missing and plotters would report FontUnavailable at draw time
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::InvalidParameter {
        name: "figure",
        reason: e.to_string(),
    }
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

fn bounds(chart: &Chart) -> Result<(f64, f64, f64, f64)> {
    let pts = chart.series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        if !(x.is_finite() && y.is_finite()) || (chart.log_y && y <= 0.0) {
            continue;
        }
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(Error::Empty {
            what: "figure (no finite point to draw)",
        });
    }
    let pad = |a: f64, b: f64| {
        let d = (b - a).abs().max(1e-12 * a.abs().max(1.0));
        (a - 0.05 * d, b + 0.05 * d)
    };
    let (x0, x1) = pad(x0, x1);
    let (y0, y1) = if chart.log_y {
        (y0 / 1.5, y1 * 1.5)
    } else {
        pad(y0, y1)
    };
    Ok((x0, x1, y0, y1))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, chart: &Chart) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_error)?;
    let (x0, x1, y0, y1) = bounds(chart)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&chart.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70);
    macro_rules! body {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            ctx.configure_mesh()
                .x_desc(chart.x_label.as_str())
                .y_desc(chart.y_label.as_str())
                .draw()
                .map_err(plot_error)?;
            for (i, s) in chart.series.iter().enumerate() {
                let color = PALETTE[i % PALETTE.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| x.is_finite() && y.is_finite() && (!chart.log_y || *y > 0.0))
                    .collect();
                ctx.draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                    .map_err(plot_error)?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                    });
                if s.markers {
                    ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(plot_error)?;
                }
            }
            ctx.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(plot_error)?;
        }};
    }
    if chart.log_y {
        body!(
            builder
                .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                .map_err(plot_error)?
        );
    } else {
        body!(
            builder
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(plot_error)?
        );
    }
    root.present().map_err(plot_error)?;
    Ok(())
}

/// Writes `chart` to `path`: SVG for `.svg`, PNG for `.png` (800 x 600). The chart is drawn
/// into a temporary file in the same folder, then renamed over `path`, so an interrupted
/// write leaves the old file (or none), never a torn one.
pub fn write_chart(chart: &Chart, path: &Path) -> Result<()> {
    register_font();
    let size = (800, 600);
    let ext = path.extension().and_then(|e| e.to_str());
    if !matches!(ext, Some("svg") | Some("png")) {
        return Err(Error::InvalidParameter {
            name: "output",
            reason: format!("{}: the file name must end in .svg or .png", path.display()),
        });
    }
    trajpred_core::io::write_atomic_with(path, |tmp: &Path| match ext {
        Some("svg") => draw(SVGBackend::new(tmp, size).into_drawing_area(), chart),
        _ => draw(BitMapBackend::new(tmp, size).into_drawing_area(), chart),
    })
}
