//! Tidy checks over the whole repository (as rust-analyzer's xtask has): what a user who
//! picks up one crate expects, and the house rules that no compiler checks.
//!
//! - every library crate that can be published has a README that is also its crate-level
//!   documentation (so the README's examples run as doc tests), packaging metadata, and at
//!   least one example under `examples/` that a test runs (`#[path = "../examples/…"]`);
//! - no Rust source file over 800 lines;
//! - no `TODO` or `FIXME` without an issue number (`TODO(#27)`).
//!
//! That the code and docs cite `docs/papers.md` and nothing outside the repository is
//! `trajpred-repro/tests/tidy.rs`'s check.
//!
//! Every public item documented is the `missing_docs` lint's job (denied in CI through
//! `clippy -D warnings`).

use std::path::{Path, PathBuf};

const MAX_LINES: usize = 800;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every file below `dir`, skipping build output and hidden folders.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') || name == "target" {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_default()
}

/// The library crates that can be published (not `publish = false`).
fn library_crates() -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(root().join("crates"))
        .expect("crates/ folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.join("src/lib.rs").exists())
        .filter(|p| !read(&p.join("Cargo.toml")).contains("publish = false"))
        .collect();
    out.sort();
    out
}

#[test]
fn every_library_crate_has_a_readme_as_its_docs_metadata_and_a_tested_example() {
    let crates = library_crates();
    assert!(crates.len() >= 8, "found {crates:?}");
    let mut problems = Vec::new();
    for c in &crates {
        let name = c
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let readme = read(&c.join("README.md"));
        if readme.is_empty() {
            problems.push(format!("{name}: no README.md"));
        } else if !readme.lines().any(|l| l == "```" || l == "```rust") {
            problems.push(format!("{name}: README.md has no Rust example"));
        }
        if !read(&c.join("src/lib.rs")).contains("include_str!(\"../README.md\")") {
            problems.push(format!(
                "{name}: src/lib.rs does not include README.md as its docs"
            ));
        }
        let manifest = read(&c.join("Cargo.toml"));
        for key in [
            "description",
            "readme",
            "keywords",
            "categories",
            "license",
            "repository",
        ] {
            if !manifest.lines().any(|l| l.starts_with(key)) {
                problems.push(format!("{name}: Cargo.toml has no `{key}`"));
            }
        }
        let tests: String = files(&c.join("tests")).iter().map(|p| read(p)).collect();
        let examples: Vec<String> = files(&c.join("examples"))
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "rs"))
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        let tested = examples
            .iter()
            .filter(|e| tests.contains(&format!("#[path = \"../examples/{e}\"]")))
            .count();
        if tested == 0 {
            problems.push(format!("{name}: no example under examples/ run by a test"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn no_rust_file_is_over_800_lines() {
    let long: Vec<String> = [root().join("crates"), root().join("xtask")]
        .iter()
        .flat_map(|d| files(d))
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .filter_map(|p| {
            let n = read(&p).lines().count();
            (n > MAX_LINES).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

/// `word` as a whole word (not part of a longer identifier).
fn has_word(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(i, _)| {
        let before = line[..i].chars().next_back();
        let after = line[i + word.len()..].chars().next();
        let part = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !part(before) && !part(after)
    })
}

#[test]
fn no_todo_without_an_issue() {
    let mut problems = Vec::new();
    let this = Path::new(file!())
        .file_name()
        .map(|n| n.to_string_lossy().into_owned());
    for dir in ["crates", "xtask", "docs", "fixtures"] {
        for p in files(&root().join(dir)) {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().into_owned())
                .unwrap_or_default();
            if !["rs", "md", "toml", "py", "sh"].contains(&ext.as_str()) {
                continue;
            }
            if p.file_name().map(|n| n.to_string_lossy().into_owned()) == this {
                continue;
            }
            for (i, line) in read(&p).lines().enumerate() {
                let at = format!("{}:{}", p.display(), i + 1);
                for tag in ["TODO", "FIXME"] {
                    if has_word(line, tag) && !line.contains(&format!("{tag}(#")) {
                        problems.push(format!("{at}: {tag} without an issue, e.g. {tag}(#27)"));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_word_check_sees_whole_words_only() {
    assert!(has_word("TODO", "TODO"));
    assert!(!has_word("const TODOS: [&str; 4]", "TODO"));
    assert!(!has_word("a TODO_LIST", "TODO"));
    assert!(has_word("// TODO: later", "TODO"));
}
