//! LAR and the lasso on the diabetes data as scikit-learn ships it (`load_diabetes()`: 442
//! patients, 10 baseline variables centred and scaled, a disease-progression target), the
//! data of the LAR paper, computed as `sklearn.linear_model.lars_path` does, with the lasso
//! path drawn as an SVG (coefficients against `sum |beta| / max sum |beta|`, as scikit-learn's
//! "Lasso path using LARS" example plots it).
//!
//! ```text
//! cargo run -p trajpred-sparse --example diabetes_path -- [lasso_path.svg] [diabetes.json]
//! ```
//!
//! The data default to the repository's copy (`fixtures/sparse/lars_sklearn.json`, written by
//! `fixtures/sparse/make_fixtures.py` from scikit-learn); the SVG to `lasso_path.svg`.
#![allow(clippy::print_stdout)]

use nalgebra::DMatrix;
use std::fmt::Write as _;
use trajpred_sparse::{LarsPath, LarsPathOptions, Method, PathEvent, lars_path};

/// The variables of `load_diabetes()`, in column order.
pub const NAMES: [&str; 10] = [
    "age", "sex", "bmi", "bp", "s1", "s2", "s3", "s4", "s5", "s6",
];

/// Where the repository keeps the data.
pub fn default_data() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sparse/lars_sklearn.json")
}

/// Reads `X` (442 x 10, scaled as `load_diabetes()` returns it) and `y` from the fixture file.
pub fn load(
    path: &std::path::Path,
) -> Result<(DMatrix<f64>, Vec<f64>), Box<dyn std::error::Error>> {
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path)?)?;
    let rows: Vec<Vec<f64>> = serde_json::from_value(json["diabetes"]["x_scaled"].clone())?;
    let y: Vec<f64> = serde_json::from_value(json["diabetes"]["target"].clone())?;
    let p = rows.first().map_or(0, Vec::len);
    if rows.iter().any(|r| r.len() != p) {
        return Err("ragged design rows".into());
    }
    Ok((DMatrix::from_fn(rows.len(), p, |i, j| rows[i][j]), y))
}

/// The lasso path as an SVG: one polyline per variable, `sum |beta|` (relative to its final
/// value) on the horizontal axis, the coefficient on the vertical one.
pub fn svg(path: &LarsPath) -> String {
    let (p, k) = path.coefs.shape();
    let l1: Vec<f64> = (0..k).map(|j| path.coefs.column(j).abs().sum()).collect();
    let l1_max = l1
        .iter()
        .copied()
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let c_max = path.coefs.amax().max(f64::MIN_POSITIVE);
    let (w, h, m) = (640.0, 420.0, 40.0);
    let sx = |v: f64| m + (w - 2.0 * m) * v / l1_max;
    let sy = |v: f64| h / 2.0 - (h / 2.0 - m) * v / c_max;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <line x1=\"{m}\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"gray\"/>\n",
        h / 2.0,
        w - m
    );
    for var in 0..p {
        let hue = 36 * var;
        let points: Vec<String> = (0..k)
            .map(|j| format!("{:.1},{:.1}", sx(l1[j]), sy(path.coefs[(var, j)])))
            .collect();
        let _ = writeln!(
            out,
            "<polyline fill=\"none\" stroke=\"hsl({hue},70%,40%)\" stroke-width=\"1.5\" points=\"{}\"/>",
            points.join(" ")
        );
        let _ = writeln!(
            out,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"hsl({hue},70%,40%)\">{}</text>",
            w - m + 3.0,
            sy(path.coefs[(var, k - 1)]) + 4.0,
            NAMES.get(var).copied().unwrap_or("?")
        );
    }
    for &x in &l1 {
        let _ = writeln!(
            out,
            "<line x1=\"{0:.1}\" y1=\"{m}\" x2=\"{0:.1}\" y2=\"{1}\" stroke=\"#ddd\"/>",
            sx(x),
            h - m
        );
    }
    out.push_str("<text x=\"40\" y=\"20\" font-size=\"13\">Lasso path, diabetes (|coef| / max |coef| across)</text>\n</svg>\n");
    out
}

/// Computes both paths, prints them, writes the SVG; returns (LAR, lasso).
pub fn run(
    data: &std::path::Path,
    svg_out: &std::path::Path,
) -> Result<(LarsPath, LarsPath), Box<dyn std::error::Error>> {
    let (x, y) = load(data)?;
    let opts = LarsPathOptions::default();
    let lar = lars_path(&x, &y, Method::Lar, &opts)?;
    let lasso = lars_path(&x, &y, Method::Lasso, &opts)?;
    for (name, path) in [("LAR", &lar), ("lasso", &lasso)] {
        println!("{name}: {} steps", path.n_iter);
        for ev in path.fit.events() {
            match *ev {
                PathEvent::Added { feature, step } => {
                    println!(
                        "  step {step:2}: + {} (alpha {:.3})",
                        NAMES[feature],
                        path.alphas[step - 1]
                    );
                }
                PathEvent::Dropped { feature, step } => {
                    println!(
                        "  step {step:2}: - {} (alpha {:.3})",
                        NAMES[feature], path.alphas[step]
                    );
                }
            }
        }
    }
    std::fs::write(svg_out, svg(&lasso))?;
    println!("lasso path drawn in {}", svg_out.display());
    Ok((lar, lasso))
}

#[allow(dead_code)] // the tests call `run` and never `main`
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let svg_out = args.next().unwrap_or_else(|| "lasso_path.svg".into());
    let data = args.next().map_or_else(default_data, Into::into);
    run(&data, std::path::Path::new(&svg_out))?;
    Ok(())
}
