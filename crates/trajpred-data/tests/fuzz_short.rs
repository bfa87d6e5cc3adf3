//! A short run of the mutation fuzzer (`examples/fuzz_parsers.rs`, included here): 20 000
//! executions over the fixture seeds, every family (text, JSON, gzip files), no panic and no
//! `Ok` whose report fails to add up. A parser that panics on some input is caught, counted
//! and its input saved (shown with a deliberately panicking stand-in).

#[allow(dead_code)]
#[path = "../examples/fuzz_parsers.rs"]
mod fuzz;

use fuzz::{Outcome, Target, corpus, findings_dir, fixture_root, fuzz, fuzz_with, run_one};

#[test]
fn twenty_thousand_mutated_inputs_never_panic() {
    let seeds = corpus(&fixture_root());
    // the fixtures are found: every format is seeded from files, not only the hand-made inputs
    for t in [
        Target::Plt,
        Target::Labels,
        Target::TDrive,
        Target::Adsb,
        Target::Csv,
        Target::GzAdsb,
        Target::GzCsv,
    ] {
        assert!(
            seeds
                .iter()
                .any(|s| s.target == t && !s.name.starts_with("hand:")),
            "no fixture seed for {t:?}"
        );
    }
    let stats = fuzz(&seeds, 20_000, 2024, "all");
    fuzz::print(&stats);
    assert_eq!(stats.executions, 20_000);
    assert_eq!(stats.panics, 0, "{:?}", stats.findings);
    assert_eq!(stats.violations, 0, "{:?}", stats.findings);
    // both outcomes are reached in every family: the mutations neither always break the
    // input nor never do
    for fam in ["text", "json", "gz"] {
        assert!(
            stats.outcomes.contains_key(&format!("{fam} Ok")),
            "{:?}",
            stats.outcomes
        );
        assert!(
            stats
                .outcomes
                .keys()
                .any(|k| k.starts_with(&format!("{fam} Err"))),
            "{:?}",
            stats.outcomes
        );
    }
}

#[test]
fn a_panicking_parser_is_caught_counted_and_saved() {
    let seeds = corpus(&fixture_root());
    // a stand-in parser that panics on the byte 0xff and otherwise runs the real one
    let flaky =
        |t: Target, input: &[u8], o: &trajpred_data::LoadOptions, scratch: &std::path::Path| {
            if matches!(t, Target::Csv | Target::TDrive) && input.contains(&0xff) {
                panic!("stand-in parser: byte 0xff");
            }
            run_one(t, input, o, scratch)
        };
    // not the real findings folder
    let dir = findings_dir().with_file_name("fuzz-findings-selftest");
    let stats = fuzz_with(&seeds, 3_000, 7, "text", &flaky, &dir);
    assert!(stats.panics > 0, "{:?}", stats.outcomes);
    assert_eq!(stats.outcomes["text PANIC"], stats.panics);
    let first = &stats.findings[0];
    assert!(first.contains("stand-in parser: byte 0xff"), "{first}");
    let saved = first
        .rsplit(", ")
        .next()
        .expect("path")
        .trim_end_matches(')');
    assert!(
        saved.starts_with(dir.to_str().expect("UTF-8 path")),
        "{saved}"
    );
    let bytes = std::fs::read(saved).expect("the input is saved");
    assert!(bytes.contains(&0xff));
    // a violation (an Ok whose report does not add up) is counted too
    let lying = |_: Target, _: &[u8], _: &trajpred_data::LoadOptions, _: &std::path::Path| {
        Outcome::Violation("stand-in".into())
    };
    let stats = fuzz_with(&seeds, 10, 8, "json", &lying, &dir);
    assert_eq!((stats.violations, stats.panics), (10, 0));
}
