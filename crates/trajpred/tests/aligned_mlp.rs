//! `aligned-mlp`: its members are averaged, it is seeded, and its saved networks are read
//! strictly (typed errors naming the JSON path).
#![cfg(feature = "neural")]

use trajpred::predictors::{AlignedMlp, AlignedMlpParams};
use trajpred_core::{Error, Predictor, Trajectory};

/// A track that turns and brakes, a little different for every `k`.
fn track(k: usize) -> Trajectory {
    let t: Vec<f64> = (0..60)
        .map(|i| i as f64 + 0.2 * ((i * 3 + k) % 4) as f64)
        .collect();
    let v = 8.0 + 0.3 * k as f64;
    let x = t
        .iter()
        .map(|t| v * t - 0.04 * t * t + (0.1 * t).sin())
        .collect();
    let y = t.iter().map(|t| 0.02 * k as f64 * t * t).collect();
    Trajectory::from_axes(t, vec![x, y]).unwrap()
}

fn params(members: usize, seed: u64) -> AlignedMlpParams {
    let mut p = AlignedMlpParams {
        members,
        horizons: 3,
        ..Default::default()
    };
    p.network.hidden = vec![16];
    p.network.epochs = 5;
    p.network.batch_size = 64;
    p.network.seed = seed;
    p
}

fn fitted(p: AlignedMlpParams) -> AlignedMlp {
    let train: Vec<Trajectory> = (0..8).map(track).collect();
    let mut m = AlignedMlp::new(p).unwrap();
    m.fit(&train).unwrap();
    m
}

#[test]
fn two_members_forecast_the_mean_of_the_two_networks_and_a_seed_repeats() {
    let whole = track(11);
    let hist = whole.prefix(30).unwrap();
    let times = &whole.times()[30..33];
    let both = fitted(params(2, 7)).forecast_times(&hist, times).unwrap();
    let first = fitted(params(1, 7)).forecast_times(&hist, times).unwrap();
    let second = fitted(params(1, 8)).forecast_times(&hist, times).unwrap();
    let again = fitted(params(2, 7)).forecast_times(&hist, times).unwrap();
    assert_eq!(both, again);
    assert_ne!(first, second);
    for k in 1..=3 {
        for a in 0..2 {
            let mean = 0.5 * (first.step(k)[a] + second.step(k)[a]);
            assert!(
                (both.step(k)[a] - mean).abs() < 1e-9 * (1.0 + mean.abs()),
                "step {k} axis {a}: {} against {mean}",
                both.step(k)[a]
            );
        }
    }
}

#[test]
fn saved_networks_load_back_and_damaged_ones_are_typed_errors_naming_the_path() {
    let m = fitted(params(2, 1));
    let saved = m.fitted_params().unwrap();
    assert_eq!(saved["networks"].as_array().unwrap().len(), 2);
    let mut loaded = AlignedMlp::new(params(2, 1)).unwrap();
    loaded.load_fitted_params(&saved).unwrap();
    let hist = track(3).prefix(40).unwrap();
    assert_eq!(
        m.forecast(&hist, 3).unwrap(),
        loaded.forecast(&hist, 3).unwrap()
    );
    // the fitted one counts its training origins; the loaded one says where it came from
    assert!(m.fitted_summary().unwrap().contains(" training origins"));
    assert!(
        loaded
            .fitted_summary()
            .unwrap()
            .contains("; loaded from saved parameters")
    );

    let mut short = saved.clone();
    short["networks"][1]["layers"][0]["weights"]
        .as_array_mut()
        .unwrap()
        .pop();
    let e = AlignedMlp::new(params(2, 1))
        .unwrap()
        .load_fitted_params(&short)
        .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("aligned-mlp") && text.contains("networks[1].layers[0].weights"),
        "{text}"
    );

    // a network for another number of steps
    let mut other = AlignedMlp::new(params(1, 1)).unwrap();
    let mut p = params(1, 1);
    p.horizons = 2;
    let wrong = fitted(p).fitted_params().unwrap();
    let e = other.load_fitted_params(&wrong).unwrap_err();
    assert!(e.to_string().contains("horizons"), "{e}");

    // not fitted, and too short to fit
    assert!(matches!(
        AlignedMlp::new(params(1, 1)).unwrap().forecast(&hist, 3),
        Err(Error::NotFitted { .. })
    ));
    let tiny = vec![track(0).prefix(10).unwrap()];
    assert!(matches!(
        AlignedMlp::new(params(1, 1)).unwrap().fit(&tiny),
        Err(Error::TooShort { .. })
    ));
    assert!(matches!(
        AlignedMlp::new(params(0, 1)),
        Err(Error::InvalidParameter { .. })
    ));
}
