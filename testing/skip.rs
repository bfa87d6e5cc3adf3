//! For integration tests that need what a clean checkout may lack (`../shared/data`): they
//! say on stderr that they skipped and why, and append one line to
//! `<target>/tmp/skipped-tests.log`, which `.ci/run` counts and prints after the tests, so a
//! run that silently tested less is visible. Included by path (`#[path]`) by each such test,
//! so there is one implementation.

use std::io::Write as _;

/// Reports that `test` skipped (part of) its work because of `reason`.
pub fn skipped(test: &str, reason: &str) {
    eprintln!("SKIPPED {test}: {reason}");
    let log = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("skipped-tests.log");
    let line = format!("{test}: {reason}\n");
    let appended = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log)
        .and_then(|mut f| f.write_all(line.as_bytes()));
    if let Err(e) = appended {
        eprintln!("(could not record the skip in {}: {e})", log.display());
    }
}
