//! Loading GeoLife as a user would: every `.plt` file of a `Data/` folder (or one user's
//! folder), projected to metres around each track's first fix, with the loader's report of
//! everything it skipped and why; then each track split where two fixes are more than 5 s
//! apart.
//!
//! ```text
//! cargo run --release -p trajpred-data --example load_geolife -- [path/to/Geolife/Data]
//! ```
//!
//! Without an argument it reads the small GeoLife-format fixture in the repository
//! (`fixtures/data/geolife/Data`). `tests/examples_run.rs` runs it on that fixture.
#![allow(clippy::print_stdout)]

use std::path::{Path, PathBuf};
use trajpred_data::{LoadOptions, LoadReport, geolife, segment};

/// What the example found.
#[derive(Debug)]
pub struct Summary {
    /// The loader's report.
    pub report: LoadReport,
    /// Tracks loaded (one per `.plt` file that kept at least one point).
    pub tracks: usize,
    /// Points in those tracks.
    pub points: usize,
    /// Segments after splitting at gaps over 5 s.
    pub segments: usize,
}

/// The repository's GeoLife-format fixture.
pub fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/data/geolife/Data")
}

/// Loads `data_dir` and splits its tracks at 5 s gaps.
pub fn run(data_dir: &Path) -> Result<Summary, trajpred_data::Error> {
    let (tracks, report) = geolife::load_data_dir(data_dir, &LoadOptions::geolife())?;
    let mut segments = 0;
    for t in &tracks {
        segments += segment::split_on_gaps(&t.trajectory, 5.0)?.len();
    }
    Ok(Summary {
        tracks: tracks.len(),
        points: tracks.iter().map(|t| t.trajectory.len()).sum(),
        segments,
        report,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).map_or_else(fixture, PathBuf::from);
    let s = run(&dir)?;
    println!(
        "{}: {} tracks, {} points, {} segments at 5 s gaps",
        dir.display(),
        s.tracks,
        s.points,
        s.segments
    );
    println!("{}", s.report);
    for (reason, n) in s.report.skipped_by_reason() {
        println!("skipped {n}: {reason}");
    }
    Ok(())
}
