//! Loading a dataset by name for the harness and the CLI: the loaders of `trajpred-data`,
//! then the cleaning the KF-dynamic experiments need (a uniform step, a minimum length).

use serde::{Deserialize, Serialize};
use std::path::Path;
use trajpred_core::{Error, Result, Trajectory};
use trajpred_data::{LoadOptions, LoadReport, adsb, csvfile, geolife, segment, tdrive};

/// A dataset format the loaders read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dataset {
    /// GeoLife 1.3: a `Data/` folder, one user's folder, or one `.plt` file.
    Geolife,
    /// T-Drive: a folder of taxi files or one file.
    Tdrive,
    /// ADS-B flights as the `traffic` package ships them (`.json`/`.json.gz`): a folder or a file.
    Adsb,
    /// A CSV of `t,x,y[,z]` or `t,lat,lon[,alt]` with a header.
    Csv,
}

impl std::str::FromStr for Dataset {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s {
            "geolife" => Dataset::Geolife,
            "tdrive" | "t-drive" => Dataset::Tdrive,
            "adsb" | "ads-b" => Dataset::Adsb,
            "csv" => Dataset::Csv,
            _ => {
                return Err(Error::InvalidParameter {
                    name: "dataset",
                    reason: format!("unknown dataset `{s}`; known: geolife, tdrive, adsb, csv"),
                });
            }
        })
    }
}

impl Dataset {
    /// The loader options this dataset starts from.
    pub fn options(self) -> LoadOptions {
        match self {
            Dataset::Geolife | Dataset::Csv => LoadOptions::geolife(),
            Dataset::Tdrive => LoadOptions::tdrive(),
            Dataset::Adsb => LoadOptions::adsb(),
        }
    }
}

/// What to do after loading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Prepare {
    /// Resample every trajectory to this step in seconds (linear interpolation), if set.
    pub resample_dt: Option<f64>,
    /// Keep trajectories with at least this many points (after resampling).
    pub min_points: usize,
}

fn data_error(e: trajpred_data::Error) -> Error {
    Error::method("data", e)
}

/// Loads `path` as `dataset` with `opts`, then resamples and filters as `prep` says.
/// Returns the trajectories and the loaders' report (every skipped line or point, by reason).
pub fn load(
    dataset: Dataset,
    path: &Path,
    opts: &LoadOptions,
    prep: &Prepare,
) -> Result<(Vec<Trajectory>, LoadReport)> {
    let is_file = path.is_file();
    let (tracks, report) = match (dataset, is_file) {
        (Dataset::Geolife, true) => geolife::load_plt(path, opts),
        (Dataset::Geolife, false) => {
            if path.join("Trajectory").is_dir() {
                geolife::load_user(path, opts)
            } else {
                let data = if path.join("Data").is_dir() {
                    path.join("Data")
                } else {
                    path.to_path_buf()
                };
                geolife::load_data_dir(&data, opts)
            }
        }
        (Dataset::Tdrive, true) => tdrive::load_file(path, opts),
        (Dataset::Tdrive, false) => tdrive::load_dir(path, opts),
        (Dataset::Adsb, true) => adsb::load_file(path, opts),
        (Dataset::Adsb, false) => adsb::load_dir(path, opts),
        (Dataset::Csv, _) => csvfile::load_file(path, opts),
    }
    .map_err(data_error)?;
    let mut out = Vec::with_capacity(tracks.len());
    for t in tracks {
        let tr = match prep.resample_dt {
            Some(dt) if t.trajectory.len() >= 2 => {
                segment::resample(&t.trajectory, dt).map_err(data_error)?
            }
            _ => t.trajectory,
        };
        if tr.len() >= prep.min_points {
            out.push(tr);
        }
    }
    Ok((out, report))
}
