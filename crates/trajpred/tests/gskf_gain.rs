//! The GSKF gain fitted to the training series (`GskfParams::gain_lags`), through the public
//! API: chosen where the series is noisy, better there than the paper's gain, saved and
//! loaded to the bit, and its bad inputs refused with typed errors. The least-squares fit
//! itself is checked against numpy in the module's unit tests (`gskf/gain.rs`).

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use trajpred::predictors::{Gskf, GskfParams};
use trajpred_core::{Error, Predictor, Trajectory};

/// Eq. (20)'s `y` axis, 1000 points at `t_i = 0.01 pi i`, with white noise of standard
/// deviation `sd` (seeded); and the clean series.
fn noisy_sinusoid(sd: f64, seed: u64) -> (Trajectory, Vec<f64>) {
    let clean: Vec<f64> = (0..1000)
        .map(|i| {
            let t = 0.01 * std::f64::consts::PI * i as f64;
            t.sin() * (0.1 * t).cos()
        })
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = Normal::new(0.0, sd).unwrap();
    let x: Vec<f64> = clean.iter().map(|v| v + n.sample(&mut rng)).collect();
    (Trajectory::uniform(0.0, 1.0, vec![x]).unwrap(), clean)
}

/// RMSE of the 6th-step forecasts from every origin whose target is among the last 200
/// points, against the clean series.
fn sixth_step_rmse(p: &dyn Predictor, noisy: &Trajectory, clean: &[f64]) -> f64 {
    let sum: f64 = (800..1000)
        .zip(&clean[800..])
        .map(|(target, truth)| {
            let f = p.forecast(&noisy.prefix(target - 5).unwrap(), 6).unwrap();
            (f.step(6)[0] - truth).powi(2)
        })
        .sum();
    (sum / 200.0).sqrt()
}

fn params(gain_lags: Vec<usize>) -> GskfParams {
    GskfParams {
        gain_lags,
        ..Default::default()
    }
}

/// At an SNR of about 40 dB (noise 0.005 against a signal of RMS 0.5), the paper's gain does
/// worse than the GSC it corrects, and a gain fitted to the training series does better
/// than both: the default options choose it, on the last quarter of the training origins.
#[test]
fn a_noisy_series_chooses_a_fitted_gain_and_it_beats_the_papers() {
    let (noisy, clean) = noisy_sinusoid(0.005, 7);
    let train = noisy.prefix(800).unwrap();
    let mut paper = Gskf::new(params(Vec::new())).unwrap();
    paper.fit(std::slice::from_ref(&train)).unwrap();
    let mut ours = Gskf::new(GskfParams::default()).unwrap();
    ours.fit(std::slice::from_ref(&train)).unwrap();
    assert_eq!(paper.fitted_gain_lags(), vec![None]);
    let lags = ours.fitted_gain_lags()[0];
    assert!(lags.is_some(), "{:?}", ours.fitted_summary());
    assert_eq!(ours.process_noise(), vec![None]);
    let summary = ours.fitted_summary().unwrap();
    assert!(summary.contains("fitted gain"), "{summary}");
    let (e_paper, e_ours) = (
        sixth_step_rmse(&paper, &noisy, &clean),
        sixth_step_rmse(&ours, &noisy, &clean),
    );
    assert!(
        e_ours < 0.8 * e_paper,
        "ours {e_ours}, the paper's gain {e_paper}"
    );
}

#[test]
fn a_fitted_gain_is_saved_and_loaded_to_the_bit() {
    let (noisy, _) = noisy_sinusoid(0.005, 8);
    let mut ours = Gskf::new(GskfParams::default()).unwrap();
    ours.fit(&[noisy.prefix(800).unwrap()]).unwrap();
    assert!(ours.fitted_gain_lags()[0].is_some());
    let saved = ours.fitted_params().unwrap();
    assert!(saved["axes"][0]["gain"]["k"].is_array(), "{saved}");
    let mut loaded = Gskf::new(GskfParams::default()).unwrap();
    loaded.load_fitted_params(&saved).unwrap();
    assert_eq!(loaded.fitted_gain_lags(), ours.fitted_gain_lags());
    for end in [30, 500, 990] {
        let h = noisy.prefix(end).unwrap();
        let (a, b) = (
            ours.forecast(&h, 6).unwrap(),
            loaded.forecast(&h, 6).unwrap(),
        );
        for k in 1..=6 {
            assert_eq!(
                a.step(k)[0].to_bits(),
                b.step(k)[0].to_bits(),
                "end {end} step {k}"
            );
        }
    }

    // a gain of the wrong shape, or on an axis whose correction is off, is refused by name
    let mut bad = saved.clone();
    bad["axes"][0]["gain"]["k"][0][0]
        .as_array_mut()
        .unwrap()
        .pop();
    let e = Gskf::new(GskfParams::default())
        .unwrap()
        .load_fitted_params(&bad)
        .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidFitted { path, .. } if path == "axes[0].gain.k[0][0]"),
        "{e:?}"
    );
    let mut off = saved.clone();
    off["axes"][0]["correct"] = false.into();
    let e = Gskf::new(GskfParams::default())
        .unwrap()
        .load_fitted_params(&off)
        .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidFitted { path, .. } if path == "axes[0].gain"),
        "{e:?}"
    );
}

#[test]
fn too_many_lags_are_refused() {
    let e = Gskf::new(params(vec![0, 65])).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: "gain_lags",
                ..
            }
        ),
        "{e:?}"
    );
}

/// A history too short for the chosen lags is corrected with the gain of as many lags as it
/// has the points for: the same forecast as a model saved with only the gains up to those
/// lags. The shortest history stays `window + horizons`.
#[test]
fn a_short_history_uses_the_gain_of_fewer_lags() {
    let (noisy, _) = noisy_sinusoid(0.005, 7);
    let mut ours = Gskf::new(GskfParams::default()).unwrap();
    ours.fit(&[noisy.prefix(800).unwrap()]).unwrap();
    assert_eq!(ours.min_history(), 12);
    let lags = ours.fitted_gain_lags()[0].unwrap();
    assert!(lags >= 1, "{:?}", ours.fitted_summary());
    let saved = ours.fitted_params().unwrap();
    // a history of 12 + l points has the residuals of l earlier origins
    for l in 0..lags {
        let mut cut = saved.clone();
        let g = &mut cut["axes"][0]["gain"];
        g["lags"] = l.into();
        g["k"].as_array_mut().unwrap().truncate(l + 1);
        g["variances"].as_array_mut().unwrap().truncate(l + 1);
        let mut fewer = Gskf::new(GskfParams::default()).unwrap();
        fewer.load_fitted_params(&cut).unwrap();
        let h = noisy.prefix(12 + l).unwrap();
        let (a, b) = (
            ours.forecast(&h, 6).unwrap(),
            fewer.forecast(&h, 6).unwrap(),
        );
        for k in 1..=6 {
            assert_eq!(
                a.step(k)[0].to_bits(),
                b.step(k)[0].to_bits(),
                "{l} lags, step {k}"
            );
        }
        // and a longer history forecasts differently with all the lags
        let h = noisy.prefix(12 + lags).unwrap();
        assert_ne!(
            ours.forecast(&h, 6).unwrap().step(6),
            fewer.forecast(&h, 6).unwrap().step(6)
        );
    }
    let e = ours.forecast(&noisy.prefix(11).unwrap(), 6).unwrap_err();
    assert!(matches!(e, Error::TooShort { needed: 12, .. }), "{e:?}");
}
