//! Saved parameters (`trajpred::params`): fit, save, load, and the loaded predictors forecast
//! bit for bit as the fitted ones; evaluating with loaded parameters gives the table of
//! evaluating with fitting; every kind of bad file is its typed error, naming the JSON path.

use serde_json::{Value, json};
use trajpred::dataset::{Dataset, Segment, Segmentation};
use trajpred::harness::{self, Split};
use trajpred::params::{
    self, MAX_GSC_SIZE, MAX_METHODS, MAX_PARAMS_BYTES, ParamsError, ParamsFile,
};
use trajpred::protocol::{self, MethodSpec, Protocol, Silent};
use trajpred::registry::{MethodOptions, build};
use trajpred_core::{Error, Forecast, Predictor, Trajectory};

/// Every method but the papers' networks: the learners and those that learn nothing.
const METHODS: &[&str] = &[
    "kf-cv",
    "kf-ca",
    "gsc",
    "gskf",
    "hmm",
    "imm",
    "kf-dynamic",
    "kf-dynamic-4d-literal",
    "naive-kf",
    "cv-time",
    "poly2",
    "pf",
    "mkpf",
    "aligned-ridge",
    "aligned-gbm",
    "aligned-mlp",
    "auto",
    "blend",
    "last-position",
];

/// Segment `i`: 60 points at irregular times, a curve of its own.
fn segment(i: usize) -> Segment {
    let f = i as f64;
    let t: Vec<f64> = (0..60)
        .map(|k| k as f64 + 0.3 * ((k * 7 + i) % 5) as f64)
        .collect();
    let x = t
        .iter()
        .map(|t| (2.0 + 0.1 * f) * t + 3.0 * (0.2 * t + f).sin())
        .collect();
    let y = t
        .iter()
        .map(|t| 0.5 * t + 2.0 * (0.15 * t + 0.5 * f).cos())
        .collect();
    Segment {
        group: format!("g{}", i % 4),
        id: i.to_string(),
        frame: trajpred_data::Frame::Cartesian,
        trajectory: Trajectory::from_axes(t, vec![x, y]).expect("valid segment"),
    }
}

fn segments() -> Vec<Segment> {
    (0..10).map(segment).collect()
}

fn options() -> MethodOptions {
    MethodOptions {
        window: 4,
        horizons: 3,
        seed: 5,
        // the held-out scoring of the methods that choose by cross-validation
        eval: harness::EvalConfig {
            history: 10,
            horizon: 3,
            ..harness::EvalConfig::default()
        },
        ..MethodOptions::default()
    }
}

fn protocol_of(methods: &[&str]) -> Protocol {
    let segmentation = Segmentation {
        min_points: 13,
        ..Segmentation::default()
    };
    let split = Split::ByTrajectory {
        train_fraction: 0.4,
        seed: 3,
    };
    Protocol {
        stride: 4,
        ..protocol::custom(
            Dataset::Csv,
            methods,
            &options(),
            segmentation,
            split,
            10,
            3,
        )
    }
}

/// The bits of every mean and covariance entry of a forecast.
fn bits(f: &Forecast) -> Vec<u64> {
    let mut v: Vec<u64> = f
        .points()
        .flat_map(|p| p.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
        .collect();
    for k in 1..=f.horizon() {
        if let Some(c) = f.covariance(k) {
            v.extend(c.iter().map(|x| x.to_bits()));
        }
    }
    v
}

fn fitted_file(methods: &[&str]) -> ParamsFile {
    params::fit(
        &protocol_of(methods),
        "data".as_ref(),
        &segments(),
        None,
        &Silent,
    )
    .expect("fit")
}

fn reload(file: &ParamsFile) -> ParamsFile {
    let bytes = file.to_json().expect("serialise");
    ParamsFile::from_slice(&bytes, "params.json").expect("the saved file loads")
}

#[test]
fn loaded_parameters_forecast_bit_for_bit_as_the_fitted_methods() {
    let p = protocol_of(METHODS);
    let segs = segments();
    let (train, test) = protocol::split(&p, &segs).expect("split");
    let groups = harness::group_ids(&train);
    let train: Vec<Trajectory> = train.into_iter().map(|s| s.trajectory).collect();
    let file = reload(&fitted_file(METHODS));
    assert_eq!(file.fitted_on.train_segments, train.len());
    assert_eq!(file.fitted_on.segments, 10);
    for name in METHODS {
        // the method fitted directly on the training part of the same split
        let mut fitted = build(name, &options()).expect("build");
        fitted.fit_grouped(&train, &groups).expect("fit");
        let loaded = file.predictor(name).expect("loads");
        let learns = !file.method(name).expect("saved").params.is_null();
        assert_eq!(
            learns,
            [
                "kf-cv",
                "kf-ca",
                "gsc",
                "gskf",
                "hmm",
                "imm",
                "aligned-ridge",
                "aligned-gbm",
                "aligned-mlp",
                "auto",
                "blend",
                "pf",
                "mkpf"
            ]
            .contains(name),
            "{name}"
        );
        let mut compared = 0;
        for s in &test {
            for end in [15, 31, 60] {
                let h = s.trajectory.prefix(end).expect("prefix");
                let times = &s.trajectory.times()[end..(end + 3).min(60)];
                let (a, b) = (fitted.forecast(&h, 3), loaded.forecast(&h, 3));
                assert_eq!(bits(&a.expect(name)), bits(&b.expect(name)), "{name}");
                if times.len() == 3 {
                    let a = fitted.forecast_times(&h, times).expect(name);
                    let b = loaded.forecast_times(&h, times).expect(name);
                    assert_eq!(bits(&a), bits(&b), "{name}");
                }
                compared += 1;
            }
        }
        assert!(compared >= 18, "{name}");
    }
}

#[test]
fn the_learned_values_are_written_as_exact_strings() {
    let file = fitted_file(&["kf-cv", "hmm", "gskf"]);
    let kf = &file.method("kf-cv").expect("kf-cv").params;
    let r: f64 = kf["r"]
        .as_str()
        .expect("a string")
        .parse()
        .expect("a number");
    let mut p = build("kf-cv", &options()).expect("build");
    let segs = segments();
    let (train, _) = protocol::split(&protocol_of(&["kf-cv"]), &segs).expect("split");
    let train: Vec<Trajectory> = train.into_iter().map(|s| s.trajectory).collect();
    p.fit(&train).expect("fit");
    assert_eq!(p.fitted_params().expect("export")["r"], kf["r"]);
    assert!(r > 0.0);
    // the HMM's rows are probabilities; the GSKF has one coder per axis, A is T x m
    let hmm = &file.method("hmm").expect("hmm").params;
    assert_eq!(
        hmm["transition"].as_array().expect("rows").len(),
        hmm["centroids"].as_array().expect("rows").len()
    );
    let gskf = &file.method("gskf").expect("gskf").params;
    assert_eq!(gskf["axes"].as_array().expect("axes").len(), 2);
    assert_eq!(gskf["axes"][0]["a"].as_array().expect("A").len(), 3);
    assert_eq!(gskf["axes"][0]["a"][0].as_array().expect("row").len(), 4);
}

/// Why the numbers are strings: serde_json's default parser (without its `float_roundtrip`
/// feature) is not correctly rounded, so some numbers it wrote come back changed; whether
/// that feature is on depends on every crate in the build (`forust-ml` turns it on), and a
/// file may be read by another program. Rust's `str::parse` is correctly rounded (IEEE 754
/// round to nearest), so the strings give every number back whatever the build.
#[test]
fn exact_strings_round_trip_every_number() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    for _ in 0..20_000 {
        let x: f64 = rng.random::<f64>() * 10f64.powi(rng.random_range(-30..30));
        let exact: f64 = format!("{x:?}").parse().expect("number");
        assert_eq!(exact.to_bits(), x.to_bits(), "{x:?}");
    }
}

#[test]
fn evaluating_loaded_parameters_gives_the_table_of_evaluating_with_fitting() {
    let methods = ["kf-cv", "gsc", "gskf", "hmm", "poly1"];
    let p = protocol_of(&methods);
    let segs = segments();
    let fitted = protocol::run(&p, &segs, &Silent).expect("run");
    let file = reload(&fitted_file(&methods));
    let loaded = protocol::run_with(&p, &segs, &Silent, &|m, _, _| {
        file.predictor(&m.label)
            .map_err(|e| Error::method(m.label.clone(), e))
    })
    .expect("run with loaded parameters");
    for (a, b) in fitted.reports.iter().zip(&loaded.reports) {
        let (a, b) = (&a[0], &b[0]);
        assert!(a.forecasts > 0, "{}", a.method);
        assert_eq!(
            (a.forecasts, a.failures, a.trajectories),
            (b.forecasts, b.failures, b.trajectories)
        );
        assert_eq!(a.mean_euclidean, b.mean_euclidean, "{}", a.method);
        assert_eq!(a.rms_euclidean, b.rms_euclidean, "{}", a.method);
        assert_eq!(a.hit_rate, b.hit_rate, "{}", a.method);
    }
    assert!(file.differences(&p).is_empty());
    let other = Protocol {
        split: Split::ByTrajectory {
            train_fraction: 0.4,
            seed: 4,
        },
        ..p
    };
    assert_eq!(file.differences(&other).len(), 1);
}

/// A saved file with `edit` applied to its JSON, loaded.
fn load_edited(edit: impl FnOnce(&mut Value)) -> Result<ParamsFile, ParamsError> {
    let file = fitted_file(&["kf-cv", "gsc", "hmm", "poly1"]);
    let mut v: Value = serde_json::from_slice(&file.to_json().expect("json")).expect("json");
    edit(&mut v);
    ParamsFile::from_slice(&serde_json::to_vec(&v).expect("json"), "bad.json")
}

fn invalid_at(r: Result<ParamsFile, ParamsError>) -> (String, String) {
    match r {
        Err(ParamsError::Invalid { file, path, reason }) => {
            assert_eq!(file, "bad.json");
            (path, reason)
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
}

/// An edit of a saved file's JSON.
type Edit = Box<dyn FnOnce(&mut Value)>;

#[test]
fn bad_values_are_invalid_errors_naming_the_json_path() {
    // method order in the file: kf-cv, gsc, hmm, poly1
    let cases: Vec<(Edit, &str, &str)> = vec![
        (
            Box::new(|v| v["methods"][0]["params"]["r"] = json!("NaN")),
            "methods[0].params.r",
            "not finite",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["r"] = json!(-1)),
            "methods[0].params.r",
            "must be > 0",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["r"] = json!(0)),
            "methods[0].params.r",
            "must be > 0",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["spectral_density"] = json!("1e999")),
            "methods[0].params.spectral_density",
            "not finite",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["r"] = json!("ten")),
            "methods[0].params.r",
            "not a number",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["r"] = json!([1])),
            "methods[0].params.r",
            "expected a number",
        ),
        (
            Box::new(|v| v["methods"][0]["params"]["extra"] = json!(1)),
            "methods[0].params",
            "unknown field `extra`",
        ),
        (
            Box::new(|v| {
                v["methods"][0]["params"]
                    .as_object_mut()
                    .expect("object")
                    .remove("r");
            }),
            "methods[0].params",
            "missing field `r`",
        ),
        // a coefficient matrix of the wrong shape for m = 4, T = 3
        (
            Box::new(|v| {
                v["methods"][1]["params"]["axes"][0]["a"][1]
                    .as_array_mut()
                    .expect("row")
                    .pop();
            }),
            "methods[1].params.axes[0].a[1]",
            "expected 4 entries, got 3",
        ),
        (
            Box::new(|v| {
                v["methods"][1]["params"]["axes"][1]["b"]
                    .as_array_mut()
                    .expect("b")
                    .push(json!(1));
            }),
            "methods[1].params.axes[1].b",
            "expected 3 entries, got 4",
        ),
        (
            Box::new(|v| {
                v["methods"][1]["params"]["axes"][0]["residual_variances"][2] = json!(-0.5)
            }),
            "methods[1].params.axes[0].residual_variances[2]",
            "must be >= 0",
        ),
        (
            Box::new(|v| v["methods"][1]["params"]["axes"] = json!([])),
            "methods[1].params.axes",
            "expected 1 to 3 entries, got 0",
        ),
        (
            Box::new(|v| {
                let ax = v["methods"][1]["params"]["axes"][0].clone();
                v["methods"][1]["params"]["axes"] = json!([ax, ax, ax, ax]);
            }),
            "methods[1].params.axes",
            "expected 1 to 3 entries, got 4",
        ),
        // HMM: probabilities in [0, 1], rows summing to 1, K x K, positive variance
        (
            Box::new(|v| v["methods"][2]["params"]["initial"][0] = json!(1.5)),
            "methods[2].params.initial[0]",
            "in [0, 1]",
        ),
        (
            Box::new(|v| v["methods"][2]["params"]["transition"][1][0] = json!(0)),
            "methods[2].params.transition[1]",
            "sum to 1",
        ),
        (
            Box::new(|v| {
                v["methods"][2]["params"]["transition"]
                    .as_array_mut()
                    .expect("rows")
                    .pop();
            }),
            "methods[2].params.transition",
            "entries",
        ),
        (
            Box::new(|v| v["methods"][2]["params"]["emission_variance"] = json!(0.0)),
            "methods[2].params.emission_variance",
            "must be > 0",
        ),
        (
            Box::new(|v| v["methods"][2]["params"]["centroids"][0] = json!([1, 2, 3, 4])),
            "methods[2].params.centroids[0]",
            "expected 1 to 3 entries, got 4",
        ),
        (
            Box::new(|v| v["methods"][2]["params"]["centroids"][1] = json!([1])),
            "methods[2].params.centroids[1]",
            "expected 2 entries, got 1",
        ),
        // a method that learns nothing takes null only
        (
            Box::new(|v| v["methods"][3]["params"] = json!({"q": 1})),
            "methods[3].params",
            "learns nothing",
        ),
        // options a method refuses; the fit time
        (
            Box::new(|v| v["methods"][3]["options"]["poly_points"] = json!(1)),
            "methods[3].options",
            "points",
        ),
        (
            Box::new(|v| v["methods"][0]["fit_seconds"] = json!(-1.0)),
            "methods[0].fit_seconds",
            ">= 0",
        ),
        (
            Box::new(|v| v["fitted_on"]["segmentation"]["min_points"] = json!(0)),
            "fitted_on.segmentation",
            "min_points",
        ),
        (
            Box::new(|v| v["methods"] = json!([])),
            "methods",
            "no method",
        ),
    ];
    for (edit, path, needle) in cases {
        let (p, reason) = invalid_at(load_edited(edit));
        assert_eq!(p, path, "{reason}");
        assert!(reason.contains(needle), "{path}: {reason}");
    }
}

#[test]
fn bad_files_are_typed_errors() {
    let good = fitted_file(&["kf-cv", "poly1"]).to_json().expect("json");
    let text = String::from_utf8(good.clone()).expect("utf-8");
    // not JSON: serde_json's line and column are kept
    match ParamsFile::from_slice(&good[..good.len() / 2], "cut.json") {
        Err(ParamsError::Json {
            file,
            error: source,
        }) => {
            assert_eq!(file, "cut.json");
            assert!(source.line() > 1 && source.column() > 0, "{source}");
        }
        other => panic!("{other:?}"),
    }
    // deep nesting stops at serde_json's recursion limit
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    assert!(matches!(
        ParamsFile::from_slice(deep.as_bytes(), "deep.json"),
        Err(ParamsError::Json { .. })
    ));
    // an unknown field anywhere in the structure
    let extra = text.replacen("\"fitted_on\": {", "\"fitted_on\": {\"colour\": 1,", 1);
    assert!(matches!(
        ParamsFile::from_slice(extra.as_bytes(), "x"),
        Err(ParamsError::Json { .. })
    ));
    // format, version
    let other = text.replacen("\"trajpred-params\"", "\"something-else\"", 1);
    assert!(
        matches!(ParamsFile::from_slice(other.as_bytes(), "x"), Err(ParamsError::Format { found, .. }) if found == "\"something-else\"")
    );
    let v2 = text.replacen("\"version\": 1", "\"version\": 2", 1);
    assert!(
        matches!(ParamsFile::from_slice(v2.as_bytes(), "x"), Err(ParamsError::Version { found, .. }) if found == "2")
    );
    let no_version = text.replacen("\"version\": 1,", "", 1);
    assert!(
        matches!(ParamsFile::from_slice(no_version.as_bytes(), "x"), Err(ParamsError::Version { found, .. }) if found == "missing")
    );
    // unknown, duplicated and neural methods
    let unknown = text.replacen("\"name\": \"poly1\"", "\"name\": \"poly9\"", 1);
    assert!(
        matches!(ParamsFile::from_slice(unknown.as_bytes(), "x"), Err(ParamsError::UnknownMethod { path, name, .. }) if path == "methods[1].name" && name == "poly9")
    );
    let twice = text.replacen("\"label\": \"poly1\"", "\"label\": \"kf-cv\"", 1);
    assert!(
        matches!(ParamsFile::from_slice(twice.as_bytes(), "x"), Err(ParamsError::DuplicateMethod { path, .. }) if path == "methods[1].label")
    );
    #[cfg(feature = "neural")]
    {
        let neural = text.replacen("\"name\": \"poly1\"", "\"name\": \"lstm\"", 1);
        assert!(
            matches!(ParamsFile::from_slice(neural.as_bytes(), "x"), Err(ParamsError::Unsupported { method, .. }) if method == "poly1")
        );
        let spec = MethodSpec {
            label: "bp".into(),
            name: "bp".into(),
            options: options(),
        };
        assert!(
            matches!(params::check_exportable(&[spec]), Err(ParamsError::Unsupported { method, .. }) if method == "bp")
        );
    }
    // limits: the number of methods, the GSC sizes, the file size
    let mut v: Value = serde_json::from_slice(&good).expect("json");
    let one = v["methods"][1].clone();
    v["methods"] = Value::Array(
        (0..=MAX_METHODS)
            .map(|i| {
                let mut m = one.clone();
                m["label"] = json!(format!("m{i}"));
                m
            })
            .collect(),
    );
    assert!(
        matches!(ParamsFile::from_slice(&serde_json::to_vec(&v).expect("json"), "x"), Err(ParamsError::Limit { path, got, .. }) if path == "methods" && got == MAX_METHODS + 1)
    );
    let mut v: Value = serde_json::from_slice(&good).expect("json");
    v["methods"][1]["options"]["horizons"] = json!(MAX_GSC_SIZE + 1);
    assert!(
        matches!(ParamsFile::from_slice(&serde_json::to_vec(&v).expect("json"), "x"), Err(ParamsError::Limit { path, .. }) if path == "methods[1].options.horizons")
    );
    let mut huge = good.clone();
    huge.resize(MAX_PARAMS_BYTES as usize + 1, b' ');
    assert!(matches!(
        ParamsFile::from_slice(&huge, "x"),
        Err(ParamsError::TooLarge { .. })
    ));
    // a file that is not there; a method the file lacks
    assert!(
        matches!(ParamsFile::load("/no/such/params.json".as_ref()), Err(ParamsError::Io { file, .. }) if file == "/no/such/params.json")
    );
    let loaded = ParamsFile::from_slice(&good, "good.json").expect("loads");
    assert!(
        matches!(loaded.predictor("gsc"), Err(ParamsError::Missing { method, available, .. }) if method == "gsc" && available == "kf-cv, poly1")
    );
}

#[test]
fn saving_writes_the_file_whole_and_loading_reads_it_back() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("params.json");
    let file = fitted_file(&["gskf", "cv-time"]);
    file.save(&path).expect("save");
    let back = ParamsFile::load(&path).expect("load");
    assert_eq!(back.source(), path.display().to_string());
    assert_eq!(back.methods, file.methods);
    assert_eq!(back.fitted_on, file.fitted_on);
    // a save into a folder that does not exist is an I/O error naming it
    let bad = dir.path().join("no/such/params.json");
    assert!(matches!(file.save(&bad), Err(ParamsError::Io { .. })));
}

#[test]
fn aligned_ridge_and_auto_name_what_does_not_fit_their_options() {
    let file = fitted_file(&["aligned-ridge", "auto"]);
    let mut v: Value = serde_json::from_slice(&file.to_json().expect("json")).expect("json");
    let saved = |v: &Value, i: usize| v["methods"][i]["params"].clone();
    // aligned-ridge: the shape it was fitted for must be this predictor's
    let mut ridge = build("aligned-ridge", &options()).expect("build");
    let mut edited = saved(&v, 0);
    edited["lags"] = json!(5);
    match ridge.load_fitted_params(&edited) {
        Err(Error::InvalidFitted { path, reason, .. }) => {
            assert_eq!(path, "lags");
            assert!(reason.contains("fitted with lags 5"), "{reason}");
        }
        other => panic!("expected InvalidFitted, got {other:?}"),
    }
    let mut edited = saved(&v, 0);
    edited["weights"][2][1][0] = json!("inf");
    match ridge.load_fitted_params(&edited) {
        Err(Error::InvalidFitted { path, .. }) => assert_eq!(path, "weights[2][1][0]"),
        other => panic!("expected InvalidFitted, got {other:?}"),
    }
    assert!(ridge.load_fitted_params(&saved(&v, 0)).is_ok());
    // auto: the method must be one of its candidates, and the inner path is prefixed
    let mut auto = build("auto", &options()).expect("build");
    let mut edited = saved(&v, 1);
    edited["method"] = json!("lstm");
    match auto.load_fitted_params(&edited) {
        Err(Error::InvalidFitted { path, reason, .. }) => {
            assert_eq!(path, "method");
            assert!(reason.contains("not among"), "{reason}");
        }
        other => panic!("expected InvalidFitted, got {other:?}"),
    }
    v["methods"][1]["params"]["method"] = json!("gsc");
    v["methods"][1]["params"]["params"] = json!({"axes": "x"});
    match auto.load_fitted_params(&saved(&v, 1)) {
        Err(Error::InvalidFitted { method, path, .. }) => {
            assert_eq!(method, "auto");
            assert_eq!(path, "params.axes");
        }
        other => panic!("expected InvalidFitted, got {other:?}"),
    }
}

#[test]
fn a_fit_records_the_repeats_it_left_out_and_older_files_without_the_count_load() {
    // segments 0..10, then two copies of each under other groups and ids
    let mut segs = segments();
    for k in 0..2 {
        for i in 0..10 {
            let mut copy = segment(i);
            copy.group = format!("copy{k}-{i}");
            copy.id = format!("copy{k}-{i}");
            segs.push(copy);
        }
    }
    let p = protocol_of(&["cv-time"]);
    let (train, test, r) = protocol::split_counted(&p, &segs).expect("split");
    assert_eq!(train.len() + test.len(), 10, "{r:?}");
    assert_eq!(r.total(), 20, "{r:?}");
    assert!(r.train > 0, "{r:?}");
    let file = params::fit(&p, "data".as_ref(), &segs, None, &Silent).expect("fit");
    assert_eq!(file.fitted_on.repeated_train_segments, r.train);
    assert_eq!(file.fitted_on.train_segments, train.len());
    assert_eq!(reload(&file).fitted_on, file.fitted_on);
    // a file written before the count existed reads it as 0
    let old = load_edited(|v| {
        v["fitted_on"]
            .as_object_mut()
            .expect("object")
            .remove("repeated_train_segments")
            .expect("the field is written");
    })
    .expect("an older file loads");
    assert_eq!(old.fitted_on.repeated_train_segments, 0);
}

#[test]
fn evaluating_saved_parameters_leaves_out_what_they_were_fitted_on_from_any_data() {
    // fitted on segments 0-5 whole; evaluated on every segment of 4-9, of which 4 and 5
    // were fitted on
    let all = segments();
    let whole = |methods: &[&str]| Protocol {
        split: Split::None,
        ..protocol_of(methods)
    };
    let p = whole(&["kf-cv", "cv-time"]);
    let file = params::fit(&p, "ours".as_ref(), &all[..6], None, &Silent).expect("fit");
    assert_eq!(file.fitted_on.train_segments, 6);
    assert_eq!(file.fitted_on.train_fingerprints.len(), 6);
    let file = reload(&file);
    let (run, seen) = file.evaluate(&p, &all[4..], &Silent).expect("evaluate");
    assert_eq!(seen, 2);
    assert_eq!(run.repeats.test_of_train, 2);
    let ids: Vec<&str> = run.test.iter().map(|s| s.id.as_str()).collect();
    let expected: Vec<&str> = all[6..].iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, expected);
    // fitting on a split of none is refused; evaluating the data it was fitted on leaves
    // nothing to test
    assert!(matches!(
        protocol::run(&p, &all, &Silent),
        Err(Error::InvalidParameter { name: "split", .. })
    ));
    assert!(matches!(
        file.evaluate(&p, &all[..6], &Silent),
        Err(Error::InvalidParameter {
            name: "segments",
            ..
        })
    ));
}
