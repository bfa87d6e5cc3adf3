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
