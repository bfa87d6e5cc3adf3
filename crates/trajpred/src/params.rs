//! Fitted parameters in a JSON file: `trajpred fit --output params.json` writes one,
//! `trajpred evaluate --params` and `trajpred predict --params` use it instead of fitting.
//!
//! The file is one JSON document:
//!
//! ```text
//! {
//!   "format": "trajpred-params",
//!   "version": 1,
//!   "fitted_on": { protocol, dataset, path, segmentation, train_segmentation, split, seed,
//!                  max_units, max_train, segments, train_segments, train_points,
//!                  repeated_train_segments, train_fingerprints },
//!   "methods": [ { label, name, options, summary, fit_seconds, params }, ... ]
//! }
//! ```
//!
//! `params` is what [`Predictor::fitted_params`] exported (`null` for a method that learns
//! nothing). Loading is strict ([`ParamsFile::from_slice`]): the limits below, an unknown
//! format, version, field or method, a number out of range or a shape that disagrees with
//! the options is a [`ParamsError`] naming the file and the JSON path of the bad field
//! (syntax errors keep serde_json's line and column). See `docs/evaluation.md`, "Saved
//! parameters".
//!
//! ```
//! use trajpred::params::{fit, ParamsFile};
//! use trajpred::protocol::{Protocol, Silent};
//! # use trajpred::dataset::{Dataset, Segment, Segmentation};
//! # use trajpred::harness::Split;
//! # use trajpred::protocol::MethodSpec;
//! # use trajpred::registry::MethodOptions;
//! # use trajpred_core::{Predictor, Trajectory};
//! # let seg = |i: usize| Segment {
//! #     group: i.to_string(), id: i.to_string(), frame: trajpred_data::Frame::Cartesian,
//! #     trajectory: Trajectory::uniform(0.0, 1.0, vec![
//! #         (0..40).map(|k| (k * (i + 1)) as f64).collect(),
//! #         (0..40).map(|k| ((k as f64) * 0.1).sin()).collect()]).unwrap() };
//! # let segments: Vec<Segment> = (0..4).map(seg).collect();
//! # let protocol = Protocol {
//! #     name: "custom".into(), description: String::new(), dataset: Dataset::Csv,
//! #     load_options: Dataset::Csv.options(), max_units: None,
//! #     segmentation: Segmentation::default(), train_segmentation: None,
//! #     split: Split::ByTrajectory { train_fraction: 0.5, seed: 1 }, max_train: None,
//! #     max_test: None, histories: vec![10], horizon: 3, stride: 1, max_origins: None,
//! #     threshold: 25.0, same_origins: false,
//! #     methods: vec![MethodSpec { label: "kf-cv".into(), name: "kf-cv".into(),
//! #                                options: MethodOptions::default() }] };
//! // fit on the training part of the protocol's split, and save
//! let file = fit(&protocol, "data/".as_ref(), &segments, None, &Silent)?;
//! let bytes = file.to_json()?;
//! // load back (strictly) and forecast without fitting
//! let loaded = ParamsFile::from_slice(&bytes, "params.json")?;
//! let kf = loaded.predictor("kf-cv")?;
//! let f = kf.forecast(&segments[0].trajectory, 2)?;
//! assert_eq!(f.horizon(), 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::dataset::{Dataset, Segment, Segmentation};
use crate::harness::{self, Split};
use crate::protocol::{self, MethodSpec, Progress, Protocol};
use crate::registry::{MethodOptions, all_methods, build};
use serde::{Deserialize, Serialize};
use std::io::Read as _;
use std::path::Path;
use std::time::Instant;
use trajpred_core::{Error, Predictor, Trajectory};

/// The `format` field of every parameter file.
pub const FORMAT: &str = "trajpred-params";
/// The format version this build writes and reads.
pub const VERSION: u64 = 1;
/// Largest parameter file written or read, bytes (a GSKF of m = T = 64 over 3 axes is
/// ~0.3 MB; on GeoLife, `aligned-gbm` and `aligned-mlp` ~35 MB, `auto` and `blend` ~56 MB,
/// the learners saved again inside them).
pub const MAX_PARAMS_BYTES: u64 = 256 << 20;
/// Most methods in one file.
pub const MAX_METHODS: usize = 64;
/// Largest window m and number of horizons T of a loaded GSC/GSKF (the papers use m <= 8,
/// T <= 6; the GSKF's covariance recursion on loading costs T^3 per iteration).
pub const MAX_GSC_SIZE: usize = 256;

/// Why a parameter file could not be written, read or used. Every variant names the file
/// and, for a bad field, its JSON path (`methods[2].params.axes[0].a[1][3]`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsError {
    /// Reading or writing the file failed.
    #[error("{file}: {error}")]
    Io {
        /// The file.
        file: String,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is larger than [`MAX_PARAMS_BYTES`].
    #[error("{file}: larger than the limit of {limit} bytes for a parameter file")]
    TooLarge {
        /// The file.
        file: String,
        /// The limit, bytes.
        limit: u64,
    },
    /// Not JSON, or JSON of the wrong shape (a missing or unknown field, a wrong type); the
    /// message carries serde_json's line and column.
    #[error("{file}: {error}")]
    Json {
        /// The file.
        file: String,
        /// serde_json's error (see its `line()` and `column()`).
        error: serde_json::Error,
    },
    /// The `format` field is not [`FORMAT`].
    #[error("{file}: not a trajpred parameter file (`format` is {found}, expected \"{FORMAT}\")")]
    Format {
        /// The file.
        file: String,
        /// What the field held (JSON), or `missing`.
        found: String,
    },
    /// The `version` field is not [`VERSION`].
    #[error("{file}: format version {found} is not supported (this build reads version {VERSION})")]
    Version {
        /// The file.
        file: String,
        /// What the field held (JSON), or `missing`.
        found: String,
    },
    /// A count above its limit.
    #[error("{file}: `{path}`: {got} exceeds the limit of {limit}")]
    Limit {
        /// The file.
        file: String,
        /// JSON path of the field.
        path: String,
        /// The count found.
        got: usize,
        /// The limit.
        limit: usize,
    },
    /// A method this build does not know.
    #[error("{file}: `{path}`: unknown method `{name}`")]
    UnknownMethod {
        /// The file.
        file: String,
        /// JSON path of the field.
        path: String,
        /// The name found.
        name: String,
    },
    /// Two methods with one label.
    #[error("{file}: `{path}`: a second method labelled `{label}`")]
    DuplicateMethod {
        /// The file.
        file: String,
        /// JSON path of the second one.
        path: String,
        /// The label.
        label: String,
    },
    /// A value out of range or inconsistent with the rest (shapes against the options,
    /// probabilities, variances, options a method refuses).
    #[error("{file}: `{path}`: {reason}")]
    Invalid {
        /// The file.
        file: String,
        /// JSON path of the bad field.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A method was asked for that the file does not hold.
    #[error("{file}: holds no parameters for method `{method}` (it holds: {available})")]
    Missing {
        /// The file.
        file: String,
        /// The label asked for.
        method: String,
        /// The labels it holds, comma-separated.
        available: String,
    },
    /// The method cannot save or load its fitted parameters (the neural networks: they save
    /// model files of their own).
    #[error("method `{method}` cannot save or load fitted parameters ({file}): {reason}")]
    Unsupported {
        /// The file.
        file: String,
        /// The method's label.
        method: String,
        /// Why.
        reason: String,
    },
    /// Fitting a method (or exporting what it learned) failed.
    #[error("fitting `{method}`: {error}")]
    Fit {
        /// The method's label.
        method: String,
        /// The method's error.
        error: Error,
    },
}

/// What the parameters were fitted on: enough to rebuild the same split.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedOn {
    /// The protocol's name (`custom` for options given on the command line).
    pub protocol: String,
    /// The dataset format.
    pub dataset: Dataset,
    /// The file or folder loaded.
    pub path: String,
    /// How tracks became segments.
    pub segmentation: Segmentation,
    /// How the training users' tracks became the segments fitted on, when not as
    /// `segmentation` ([`Protocol::train_segmentation`]; `None` in files written before it).
    #[serde(default)]
    pub train_segmentation: Option<Segmentation>,
    /// How segments were split; the training part was fitted on.
    pub split: Split,
    /// The split's seed (`None` for a split by time).
    pub seed: Option<u64>,
    /// Units read (`None`: all).
    pub max_units: Option<usize>,
    /// Cap on the training segments (`None`: all).
    pub max_train: Option<usize>,
    /// Segments loaded.
    pub segments: usize,
    /// Training segments fitted on.
    pub train_segments: usize,
    /// Points in them.
    pub train_points: usize,
    /// Training segments the split left out as exact repeats of others
    /// ([`harness::drop_repeats`]; 0 in files written before it).
    #[serde(default)]
    pub repeated_train_segments: usize,
    /// The training segments' fingerprints ([`harness::segment_fingerprint`], saved as 16
    /// hex digits each): `evaluate --params` leaves out of its test part every segment
    /// found here, even in another dataset or folder, because the saved methods have seen
    /// it. With a training segmentation, the training users' segments of both cuts are
    /// here. Empty in files written before it (nothing is then left out).
    #[serde(default, with = "hex_fingerprints")]
    pub train_fingerprints: Vec<u64>,
}

/// [`FittedOn::train_fingerprints`] as hex strings (exact in every JSON reader, unlike
/// numbers above 2^53).
mod hex_fingerprints {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub(super) fn serialize<S: Serializer>(v: &[u64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|x| format!("{x:016x}")))
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u64>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|h| {
                u64::from_str_radix(h, 16).map_err(|e| {
                    D::Error::custom(format!("a training fingerprint `{h}` is not hex: {e}"))
                })
            })
            .collect()
    }
}

/// One method's saved parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MethodParams {
    /// Its label (the name asked for on the command line); unique in a file.
    pub label: String,
    /// Its name in the registry ([`crate::registry::build`]).
    pub name: String,
    /// The options it was built with (and is rebuilt with on loading).
    pub options: MethodOptions,
    /// What fitting chose, in words ([`Predictor::fitted_summary`]).
    pub summary: Option<String>,
    /// Wall time of the fit, seconds.
    pub fit_seconds: f64,
    /// What fitting learned ([`Predictor::fitted_params`]); `null` for nothing.
    pub params: serde_json::Value,
}

/// A parameter file, in memory. Built by [`fit`], written by [`ParamsFile::save`], read
/// (and checked) by [`ParamsFile::load`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamsFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u64,
    /// What the methods were fitted on.
    pub fitted_on: FittedOn,
    /// The methods, in the order they were asked for.
    pub methods: Vec<MethodParams>,
    /// The file it was read from (for errors), or `<unsaved>`.
    #[serde(skip, default = "unsaved")]
    source: String,
}

fn unsaved() -> String {
    "<unsaved>".into()
}

/// The header read before the rest, so that a file of another format or version is named as
/// such rather than as a shape error.
#[derive(Deserialize)]
struct Header {
    format: Option<serde_json::Value>,
    version: Option<serde_json::Value>,
}

/// The reason a method cannot save its parameters, with what to do for the neural ones.
fn unsupported(name: &str, reason: String) -> String {
    let neural = all_methods()
        .iter()
        .any(|m| m.name == name && !crate::registry::METHODS.contains(m));
    if neural {
        format!(
            "{reason}; a neural network keeps its weights in a model file of its own \
             (`save` and `load` of trajpred-neural)"
        )
    } else {
        reason
    }
}

fn shown(v: Option<&serde_json::Value>) -> String {
    v.map_or_else(|| "missing".into(), |v| v.to_string())
}

/// Refuses, before any fitting, a method that cannot save what it learns.
pub fn check_exportable(methods: &[MethodSpec]) -> Result<(), ParamsError> {
    for m in methods {
        let p = build(&m.name, &m.options).map_err(|error| ParamsError::Fit {
            method: m.label.clone(),
            error,
        })?;
        if let Err(Error::ParamsUnsupported { reason, .. }) = p.fitted_params() {
            return Err(ParamsError::Unsupported {
                file: unsaved(),
                method: m.label.clone(),
                reason: unsupported(&m.name, reason),
            });
        }
    }
    Ok(())
}

/// Fits every method of `protocol` on the training part of its split of `segments` (exactly
/// the part [`protocol::run`] fits on, so evaluating the loaded file with the same protocol
/// tests on the held-out part only) and collects what they learned. `data_path` is recorded.
/// `train_pool`: the tracks cut by the protocol's [training
/// segmentation](Protocol::train_segmentation) (`None` without one;
/// [`protocol::split_with_pool`]).
pub fn fit(
    protocol: &Protocol,
    data_path: &Path,
    segments: &[Segment],
    train_pool: Option<&[Segment]>,
    progress: &dyn Progress,
) -> Result<ParamsFile, ParamsError> {
    let whole = |error| ParamsError::Fit {
        method: protocol.name.clone(),
        error,
    };
    protocol.validate().map_err(whole)?;
    check_exportable(&protocol.methods)?;
    let (train, _, repeats) =
        protocol::split_with_pool(protocol, segments, train_pool).map_err(whole)?;
    // what the saved methods have seen: the training part of both cuts
    let mut train_fingerprints: Vec<u64> = train.iter().map(harness::segment_fingerprint).collect();
    if train_pool.is_some() {
        let plain = Protocol {
            train_segmentation: None,
            ..protocol.clone()
        };
        let (main_cut, _, _) = protocol::split_counted(&plain, segments).map_err(whole)?;
        train_fingerprints.extend(main_cut.iter().map(harness::segment_fingerprint));
        train_fingerprints.sort_unstable();
        train_fingerprints.dedup();
    }
    let train_tr: Vec<Trajectory> = train.iter().map(|s| s.trajectory.clone()).collect();
    let groups = harness::group_ids(&train);
    let mut methods = Vec::with_capacity(protocol.methods.len());
    for m in &protocol.methods {
        let fail = |error| ParamsError::Fit {
            method: m.label.clone(),
            error,
        };
        progress.start(&format!("fit {}", m.label), 1);
        let t0 = Instant::now();
        // as `protocol::run` fits: told the training segments' groups (users, vehicles)
        let p = protocol::build_and_fit(m, &train_tr, &groups).map_err(fail)?;
        let fit_seconds = t0.elapsed().as_secs_f64();
        progress.finish();
        methods.push(MethodParams {
            label: m.label.clone(),
            name: m.name.clone(),
            options: m.options.clone(),
            summary: p.fitted_summary(),
            fit_seconds,
            params: p.fitted_params().map_err(fail)?,
        });
    }
    let seed = protocol.split.seed();
    Ok(ParamsFile {
        format: FORMAT.into(),
        version: VERSION,
        fitted_on: FittedOn {
            protocol: protocol.name.clone(),
            dataset: protocol.dataset,
            path: data_path.display().to_string(),
            segmentation: protocol.segmentation,
            train_segmentation: protocol.train_segmentation,
            split: protocol.split,
            seed,
            max_units: protocol.max_units,
            max_train: protocol.max_train,
            segments: segments.len(),
            train_segments: train.len(),
            train_points: train_tr.iter().map(Trajectory::len).sum(),
            repeated_train_segments: repeats.train,
            train_fingerprints,
        },
        methods,
        source: unsaved(),
    })
}

impl ParamsFile {
    /// The file as pretty-printed JSON.
    pub fn to_json(&self) -> Result<Vec<u8>, ParamsError> {
        serde_json::to_vec_pretty(self).map_err(|error| ParamsError::Json {
            file: self.source.clone(),
            error,
        })
    }

    /// Writes the file whole or not at all ([`trajpred_core::io::write_atomic`]).
    /// A file over [`MAX_PARAMS_BYTES`] is refused ([`ParamsError::TooLarge`]) and nothing
    /// is written: [`ParamsFile::load`] would refuse it.
    pub fn save(&self, path: &Path) -> Result<(), ParamsError> {
        let mut bytes = self.to_json()?;
        bytes.push(b'\n');
        write_within(path, &bytes, MAX_PARAMS_BYTES)
    }

    /// Reads and checks the file at `path` (at most [`MAX_PARAMS_BYTES`]).
    pub fn load(path: &Path) -> Result<Self, ParamsError> {
        let file = path.display().to_string();
        let io = |error| ParamsError::Io {
            file: file.clone(),
            error,
        };
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .map_err(io)?
            // one byte past the limit tells a file over it, without reading all of it
            .take(MAX_PARAMS_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        Self::from_slice(&bytes, &file)
    }

    /// Parses and checks the bytes of a parameter file, named `file` in errors: the size
    /// limit, the format and version, the shape (no unknown field), then every method
    /// (known, unique, within the limits, rebuilt and its parameters loaded, which checks
    /// every value).
    pub fn from_slice(bytes: &[u8], file: &str) -> Result<Self, ParamsError> {
        if bytes.len() as u64 > MAX_PARAMS_BYTES {
            return Err(ParamsError::TooLarge {
                file: file.into(),
                limit: MAX_PARAMS_BYTES,
            });
        }
        let json = |error| ParamsError::Json {
            file: file.into(),
            error,
        };
        let header: Header = serde_json::from_slice(bytes).map_err(json)?;
        if header.format.as_ref().and_then(|f| f.as_str()) != Some(FORMAT) {
            return Err(ParamsError::Format {
                file: file.into(),
                found: shown(header.format.as_ref()),
            });
        }
        if header.version.as_ref().and_then(|v| v.as_u64()) != Some(VERSION) {
            return Err(ParamsError::Version {
                file: file.into(),
                found: shown(header.version.as_ref()),
            });
        }
        let mut out: ParamsFile = serde_json::from_slice(bytes).map_err(json)?;
        out.source = file.into();
        out.check()?;
        Ok(out)
    }

    fn invalid(&self, path: impl Into<String>, reason: impl Into<String>) -> ParamsError {
        ParamsError::Invalid {
            file: self.source.clone(),
            path: path.into(),
            reason: reason.into(),
        }
    }

    fn check(&self) -> Result<(), ParamsError> {
        let file = || self.source.clone();
        self.fitted_on
            .segmentation
            .validate()
            .map_err(|e| self.invalid("fitted_on.segmentation", e.to_string()))?;
        if let Some(t) = &self.fitted_on.train_segmentation {
            t.validate()
                .map_err(|e| self.invalid("fitted_on.train_segmentation", e.to_string()))?;
        }
        let n = self.methods.len();
        if n > MAX_METHODS {
            return Err(ParamsError::Limit {
                file: file(),
                path: "methods".into(),
                got: n,
                limit: MAX_METHODS,
            });
        }
        if n == 0 {
            return Err(self.invalid("methods", "holds no method"));
        }
        let known = all_methods();
        for (i, m) in self.methods.iter().enumerate() {
            let at = |field: &str| format!("methods[{i}].{field}");
            if !known.iter().any(|k| k.name == m.name) {
                return Err(ParamsError::UnknownMethod {
                    file: file(),
                    path: at("name"),
                    name: m.name.clone(),
                });
            }
            if self.methods[..i].iter().any(|o| o.label == m.label) {
                return Err(ParamsError::DuplicateMethod {
                    file: file(),
                    path: at("label"),
                    label: m.label.clone(),
                });
            }
            if !(m.fit_seconds.is_finite() && m.fit_seconds >= 0.0) {
                return Err(self.invalid(
                    at("fit_seconds"),
                    format!("must be finite and >= 0, got {}", m.fit_seconds),
                ));
            }
            for (field, v) in [
                ("window", m.options.window),
                ("horizons", m.options.horizons),
            ] {
                if v > MAX_GSC_SIZE {
                    return Err(ParamsError::Limit {
                        file: file(),
                        path: at(&format!("options.{field}")),
                        got: v,
                        limit: MAX_GSC_SIZE,
                    });
                }
            }
            self.rebuild(i)?;
        }
        Ok(())
    }

    /// Method `i` built from its options with its parameters loaded.
    fn rebuild(&self, i: usize) -> Result<Box<dyn Predictor>, ParamsError> {
        let m = &self.methods[i];
        let mut p = build(&m.name, &m.options)
            .map_err(|e| self.invalid(format!("methods[{i}].options"), e.to_string()))?;
        p.load_fitted_params(&m.params).map_err(|e| match e {
            Error::InvalidFitted { path, reason, .. } => {
                let sep = if path.is_empty() { "" } else { "." };
                self.invalid(format!("methods[{i}].params{sep}{path}"), reason)
            }
            Error::ParamsUnsupported { reason, .. } => ParamsError::Unsupported {
                file: self.source.clone(),
                method: m.label.clone(),
                reason: unsupported(&m.name, reason),
            },
            e => self.invalid(format!("methods[{i}].params"), e.to_string()),
        })?;
        Ok(p)
    }

    /// The saved parameters of the method labelled `label`.
    pub fn method(&self, label: &str) -> Option<&MethodParams> {
        self.methods.iter().find(|m| m.label == label)
    }

    /// The method labelled `label`, built and loaded (not fitted); [`ParamsError::Missing`]
    /// when the file does not hold it.
    pub fn predictor(&self, label: &str) -> Result<Box<dyn Predictor>, ParamsError> {
        let i = self
            .methods
            .iter()
            .position(|m| m.label == label)
            .ok_or_else(|| ParamsError::Missing {
                file: self.source.clone(),
                method: label.into(),
                available: self
                    .methods
                    .iter()
                    .map(|m| m.label.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        self.rebuild(i)
    }

    /// Where `protocol` would split differently from what the file was fitted on (dataset,
    /// segmentation, split, caps), one line each: evaluating on such a protocol may test on
    /// segments the methods were fitted on.
    pub fn differences(&self, protocol: &Protocol) -> Vec<String> {
        let f = &self.fitted_on;
        let mut out = Vec::new();
        let mut differ = |what: &str, saved: String, now: String| {
            if saved != now {
                out.push(format!("{what}: fitted with {saved}, now {now}"));
            }
        };
        differ(
            "dataset",
            format!("{:?}", f.dataset),
            format!("{:?}", protocol.dataset),
        );
        differ(
            "segmentation",
            format!("{:?}", f.segmentation),
            format!("{:?}", protocol.segmentation),
        );
        differ(
            "split",
            format!("{:?}", f.split),
            format!("{:?}", protocol.split),
        );
        differ(
            "max_units",
            format!("{:?}", f.max_units),
            format!("{:?}", protocol.max_units),
        );
        differ(
            "max_train",
            format!("{:?}", f.max_train),
            format!("{:?}", protocol.max_train),
        );
        out
    }

    /// Evaluates the saved methods as `protocol` says, without fitting: splits `segments`
    /// ([`protocol::split_counted`]), leaves out of the test part every segment these
    /// methods were fitted on ([`ParamsFile::drop_seen`], counted with the copies of
    /// training segments in the run's `repeats`) and evaluates on the rest. With
    /// [`Split::None`] every segment tests, and the training side's repeats are reported
    /// as 0 (these data train nothing here). Returns the run and how many test segments
    /// were left out as seen. What `trajpred evaluate --params` runs.
    pub fn evaluate(
        &self,
        protocol: &Protocol,
        segments: &[Segment],
        progress: &dyn Progress,
    ) -> Result<(protocol::ProtocolRun, usize), Error> {
        protocol.validate()?;
        // nothing is fitted here: how the protocol would cut its training tracks does not
        // matter, the test part is cut by its segmentation
        let protocol = &Protocol {
            train_segmentation: None,
            ..protocol.clone()
        };
        let (train, test, mut repeats) = protocol::split_counted(protocol, segments)?;
        let (test, seen) = self.drop_seen(test);
        repeats.test_of_train += seen;
        if protocol.split == Split::None {
            repeats.train = 0;
        }
        let run = protocol::run_split(
            protocol,
            segments.len(),
            (train, test, repeats),
            progress,
            &|m, _, _| {
                self.predictor(&m.label)
                    .map_err(|e| Error::method(m.label.clone(), e))
            },
        )?;
        Ok((run, seen))
    }

    /// Leaves out of `test` every segment the saved methods were fitted on
    /// ([`FittedOn::train_fingerprints`]; a fingerprint match, not compared point by
    /// point, since the training data are not at hand), returning the rest and how many
    /// were left out.
    pub fn drop_seen(&self, test: Vec<Segment>) -> (Vec<Segment>, usize) {
        let seen: std::collections::HashSet<u64> =
            self.fitted_on.train_fingerprints.iter().copied().collect();
        let before = test.len();
        let kept: Vec<Segment> = test
            .into_iter()
            .filter(|s| !seen.contains(&harness::segment_fingerprint(s)))
            .collect();
        let dropped = before - kept.len();
        (kept, dropped)
    }

    /// The file it was read from, or `<unsaved>`.
    pub fn source(&self) -> &str {
        &self.source
    }
}

/// Writes `bytes` to `path` whole, unless they are more than `limit`.
fn write_within(path: &Path, bytes: &[u8], limit: u64) -> Result<(), ParamsError> {
    let file = || path.display().to_string();
    if bytes.len() as u64 > limit {
        return Err(ParamsError::TooLarge {
            file: file(),
            limit,
        });
    }
    trajpred_core::io::write_atomic(path, bytes).map_err(|error| ParamsError::Io {
        file: file(),
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::{ParamsError, write_within};

    #[test]
    fn a_file_over_the_limit_is_refused_and_not_written() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("p.json");
        assert!(matches!(
            write_within(&path, &[b' '; 11], 10),
            Err(ParamsError::TooLarge { limit: 10, .. })
        ));
        assert!(!path.exists());
        write_within(&path, &[b' '; 10], 10).expect("at the limit");
        assert_eq!(std::fs::read(&path).expect("written").len(), 10);
    }
}
