//! For integration tests that need what a clean checkout may lack (`../shared/data`): they
//! say on stderr that they skipped and why, and append one line to
//! `<target>/tmp/skipped-tests.log`, which `.ci/run` counts and prints after the tests, so a
//! run that silently tested less is visible. Included by path (`#[path]`) by each such test,
//! so there is one implementation.

#![allow(dead_code)]

use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Reports that `test` skipped (part of) its work because of `reason`.
pub fn skipped(test: &str, reason: &str) {
    eprintln!("SKIPPED {test}: {reason}");
    let log = Path::new(env!("CARGO_TARGET_TMPDIR")).join("skipped-tests.log");
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

/// The shared data folder (`../shared/data` beside the repository) when it holds the folder
/// `needs`, or `None` after reporting that `test` skips its real-data parts.
pub fn shared_data(test: &str, needs: &str) -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    if d.join(needs).is_dir() {
        return Some(d);
    }
    let reason = format!(
        "the real-data parts need {} (see docs/data.md)",
        d.join(needs).display()
    );
    skipped(test, &reason);
    None
}
