// The crate documentation is the README (its examples are compiled and run as doc tests).
#![doc = include_str!("../README.md")]
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
