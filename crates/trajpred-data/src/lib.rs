//! # trajpred-data
//!
//! Trajectory data for trajpred, in metres:
//!
//! - loaders, each returning [`Track`]s (a [`trajpred_core::Trajectory`] with its id, group
//!   (the user or vehicle, to split data by), source and [`Frame`]) and a [`LoadReport`]
//!   (files, records, points kept, every skip by [`SkipReason`] with file and line, the CSV
//!   time units):
//!   [`geolife`] (`.plt` and `labels.txt`), [`tdrive`] (taxi logs), [`adsb`] (the `traffic`
//!   package's JSON, both layouts, gzip) and [`csvfile`] (`t,x,y[,z]` or `t,lat,lon[,alt]`,
//!   optional track column, seconds, epoch milliseconds or ISO 8601 times);
//!   configured by [`LoadOptions`] (projection, altitude, bounding box, gap split, minimum
//!   length, strictness, and the limits on line length, decompressed bytes and points that
//!   stop a malicious or broken file with [`Error::LimitExceeded`]); each loads one file or
//!   folder at a time, streaming text, so memory stays bounded;
//! - [`segment`]: split on gaps, keep long trajectories, resample to a fixed step;
//! - [`geodesy`]: WGS84 latitude/longitude/altitude to a local east-north-up frame (via ECEF,
//!   exact) and back;
//! - [`synthetic`]: eq. (20) of the MSTPM-GSKF paper and the three curves of the KFU-LSTM-Net
//!   patent;
//! - [`noise`]: additive white Gaussian noise at a given SNR in dB, with an injected RNG.
//!
//! Every fallible function returns [`enum@Error`]; nothing panics on bad input. Decisions
//! (the repeated-timestamp rule, the T-Drive cleaning, units, the patent curves' equations)
//! are in `docs/data.md`.
//!
//! ```
//! use trajpred_data::{geolife, Frame, LoadOptions, Projection};
//! let f = concat!(env!("CARGO_MANIFEST_DIR"),
//!     "/../../fixtures/data/geolife/Data/000/Trajectory/20081023025304.plt");
//! let (tracks, report) = geolife::load_plt(f.as_ref(), &LoadOptions::geolife())?;
//! let tr = &tracks[0].trajectory;
//! assert!(matches!(tracks[0].frame, Frame::Enu(_)));
//! assert_eq!((tr.axis(0)[0], tr.axis(1)[0]), (0.0, 0.0)); // metres from the first point
//! assert_eq!(report.points_kept, tr.len());
//! # Ok::<(), trajpred_data::Error>(())
//! ```
#![forbid(unsafe_code)]

pub mod adsb;
pub mod csvfile;
pub mod error;
pub mod geodesy;
pub mod geolife;
mod io;
pub mod noise;
pub mod report;
pub mod segment;
pub mod synthetic;
pub mod tdrive;
pub mod time;
pub mod track;

pub use error::{Error, Result};
pub use report::{LoadReport, Skip, SkipReason};
pub use time::TimeUnit;
pub use track::{
    BoundingBox, Frame, LoadOptions, MAX_FILE_BYTES, MAX_JSON_BYTES, MAX_LINE_BYTES,
    MAX_TOTAL_POINTS, MAX_TRACK_POINTS, Projection, Track,
};
