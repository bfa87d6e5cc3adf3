//! A short run of the model-file fuzzer (`examples/fuzz_models.rs`, included here): mutated
//! LSTM and KFU-LSTM-Net files never panic the loader or the forecast, both outcomes (loaded,
//! refused) are reached, and the unmutated files load.

#[allow(dead_code)]
#[path = "../examples/fuzz_models.rs"]
mod fuzz;

use trajpred_neural::{KfuLstmNet, LstmArch, WindowNet};

#[test]
fn mutated_model_files_load_or_give_typed_errors() {
    let seeds = fuzz::seeds();
    assert!(WindowNet::<LstmArch>::load_bytes(&seeds[0].1).is_ok());
    assert!(KfuLstmNet::load_bytes(&seeds[1].1).is_ok());
    let stats = fuzz::fuzz(&seeds, 1_500, 7);
    assert_eq!(stats.executions, 1_500);
    assert_eq!(stats.panics, 0, "{:?}", stats.findings);
    assert!(stats.loaded > 0 && stats.refused > 0, "{stats:?}");
}

/// The inputs a long run found panicking (a record of element type `u32`), replayed.
#[test]
fn the_fuzzers_findings_load_or_give_typed_errors() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fuzz-models");
    let history = trajpred_core::Trajectory::uniform(
        0.0,
        0.1,
        vec![(0..20).map(|i| f64::from(i).sin()).collect(), vec![0.5; 20]],
    )
    .expect("valid history");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).expect("fixtures/fuzz-models") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "tpnn") {
            continue;
        }
        let bytes = std::fs::read(&path).expect("readable");
        let name = path.display().to_string();
        let outcome = std::panic::catch_unwind(|| {
            use trajpred_core::Predictor;
            if name.contains("Kfu") {
                if let Ok(m) = KfuLstmNet::load_bytes(&bytes) {
                    let _ = m.forecast(&history, 3);
                }
            } else if let Ok(m) = WindowNet::<LstmArch>::load_bytes(&bytes) {
                let _ = m.forecast(&history, 3);
            }
        });
        assert!(outcome.is_ok(), "{name} panicked");
        seen += 1;
    }
    assert_eq!(seen, 3);
}
