//! A short run of the parameter-file fuzzer (`examples/fuzz_params.rs`, included here): no
//! panic, both outcomes reached; and a panicking loader is caught, counted and its input
//! saved (shown with a deliberately panicking stand-in).

#[allow(dead_code)]
#[path = "../examples/fuzz_params.rs"]
mod fuzz;

#[test]
fn three_thousand_mutated_parameter_files_never_panic() {
    let seeds = fuzz::seeds();
    assert_eq!(seeds.len(), 6);
    let stats = fuzz::fuzz(&seeds, 3_000, 2024);
    eprintln!("{stats:?}");
    assert_eq!(stats.executions, 3_000);
    assert_eq!(stats.panics, 0, "{:?}", stats.findings);
    // the mutations neither always break the file nor never do, and reach the checks past
    // the JSON syntax
    assert!(stats.loaded > 100, "{stats:?}");
    assert!(stats.refused > 100, "{stats:?}");
    for v in ["Json", "Invalid"] {
        assert!(stats.by_error.get(v).is_some_and(|&n| n > 0), "{stats:?}");
    }
}

#[test]
fn a_panicking_loader_is_caught_counted_and_saved() {
    let seeds = fuzz::seeds();
    let history = trajpred_core::Trajectory::uniform(0.0, 1.0, vec![vec![0.0; 12], vec![1.0; 12]])
        .expect("valid");
    // a stand-in loader that panics on a NaN and otherwise runs the real one
    let flaky = |d: &[u8]| {
        if d.windows(3).any(|w| w == b"NaN") {
            panic!("stand-in loader: NaN");
        }
        fuzz::run_one(d, &history)
    };
    let dir = fuzz::findings_dir().with_file_name("fuzz-findings-params-selftest");
    let stats = fuzz::fuzz_with(&seeds, 2_000, 7, &flaky, &dir);
    assert!(stats.panics > 0, "{stats:?}");
    assert_eq!(stats.panics + stats.loaded + stats.refused, 2_000);
    let first = &stats.findings[0];
    assert!(first.contains("stand-in loader: NaN"), "{first}");
    let saved = first
        .rsplit("(saved: ")
        .next()
        .expect("path")
        .trim_end_matches(')');
    let bytes = std::fs::read(saved).expect("the input is saved");
    assert!(bytes.windows(3).any(|w| w == b"NaN"));
}
