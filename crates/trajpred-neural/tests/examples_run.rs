//! The crate's user example: train an LSTM, save it, load it back.

#[path = "../examples/train_save_lstm.rs"]
#[allow(dead_code)]
mod train_save_lstm;

#[test]
fn the_lstm_example_learns_the_circles_and_reloads_identically() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let s = train_save_lstm::run(&dir.path().join("lstm.model"), 30, 1).expect("the example runs");
    eprintln!("{s:?}");
    assert_eq!(s.losses.len(), 30);
    assert!(s.losses[29] < 0.5 * s.losses[0], "{:?}", s.losses);
    // 5 m/s: the last position is about 10 m off on average over 3 steps
    assert!(s.last_position_error > 8.0, "{s:?}");
    assert!(s.lstm_error < 0.5 * s.last_position_error, "{s:?}");
    assert!(s.reload_identical);
}
