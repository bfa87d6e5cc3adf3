//! Writing a run: every file atomically ([`write_atomic`]), a paper's folder
//! ([`write_paper`]), the index over every paper ([`write_index`]), and `--bless`
//! ([`replace_run`]).

use super::{PaperResult, RunInfo};
use crate::error::{ReproError, Result, io_err};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use trajpred::plot::write_chart;

static TEMP_SERIAL: AtomicU64 = AtomicU64::new(0);

/// The temporary file beside `path` that [`write_atomic_with`] writes first: hidden, in the same
/// folder (so the final rename stays on one file system), unique to this process and call, and
/// ending in the destination's extension (the plot writer chooses the format from it), e.g.
/// `.fig1.svg.tmp-4242-7.svg`. `.gitignore` ignores the pattern `.*.tmp-*`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| ReproError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"),
    })?;
    let ext = path
        .extension()
        .map_or_else(|| "tmp".into(), |e| e.to_string_lossy());
    let serial = TEMP_SERIAL.fetch_add(1, Ordering::Relaxed);
    Ok(path.with_file_name(format!(
        ".{}.tmp-{}-{serial}.{ext}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Writes `path` atomically: `write` is handed a temporary path in the same folder and must
/// write the whole file there; the temporary file is then flushed to disk and renamed over
/// `path`. Readers (and a later run) see either the old file or the new one, never a partial
/// one. When `write`, the flush or the rename fails, the temporary file is removed, `path` keeps
/// its old content and the error is returned.
pub fn write_atomic_with<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&Path) -> Result<()>,
{
    let tmp = temp_path(path)?;
    let outcome = write(&tmp)
        .and_then(|()| {
            std::fs::OpenOptions::new()
                .write(true)
                .open(&tmp)
                .and_then(|f| f.sync_all())
                .map_err(io_err(&tmp))
        })
        .and_then(|()| std::fs::rename(&tmp, path).map_err(io_err(path)));
    if outcome.is_err() {
        // best effort: the temporary file may not exist if `write` failed before creating it
        let _ = std::fs::remove_file(&tmp);
    }
    outcome
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |tmp| std::fs::write(tmp, bytes).map_err(io_err(tmp)))
}

impl RunInfo {
    /// The names of the files [`write_paper`] writes for this run, in the paper's folder:
    /// `README.md`, `run.json`, `<table>.md` and `<table>.csv` per table, `<figure>.svg` and
    /// `<figure>.png` per figure.
    pub fn files(&self) -> Vec<String> {
        let mut files = vec!["README.md".to_string(), "run.json".to_string()];
        for (id, _) in &self.tables {
            files.push(format!("{id}.md"));
            files.push(format!("{id}.csv"));
        }
        for (id, _) in &self.figures {
            files.push(format!("{id}.svg"));
            files.push(format!("{id}.png"));
        }
        files
    }
}

/// Removes every regular file of `dir` whose name is not in `keep` (files of an earlier run, or
/// temporary files a killed run left behind), so that the folder holds exactly one run.
fn prune(dir: &Path, keep: &[String]) -> Result<()> {
    for entry in std::fs::read_dir(dir).map_err(io_err(dir))? {
        let entry = entry.map_err(io_err(dir))?;
        let path = entry.path();
        let is_file = entry.file_type().map_err(io_err(&path))?.is_file();
        let kept = keep
            .iter()
            .any(|k| entry.file_name().to_str() == Some(k.as_str()));
        if is_file && !kept {
            std::fs::remove_file(&path).map_err(io_err(&path))?;
        }
    }
    Ok(())
}

fn json_err(path: &Path) -> impl FnOnce(serde_json::Error) -> ReproError + '_ {
    move |e| ReproError::Csv {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Reads the [`RunInfo`] of the run written in `dir` (its `run.json`).
pub fn read_run_info(dir: &Path) -> Result<RunInfo> {
    let path = dir.join("run.json");
    let text = std::fs::read_to_string(&path).map_err(io_err(&path))?;
    serde_json::from_str(&text).map_err(json_err(&path))
}

/// Replaces the run in `dest` with the run written in `fresh` (both a paper's folder): copies
/// every file the fresh run wrote (as listed by its `run.json`), each atomically, then removes
/// the files of `dest` the fresh run did not write. This is `--bless`.
pub fn replace_run(fresh: &Path, dest: &Path) -> Result<()> {
    let info = read_run_info(fresh)?;
    let files = info.files();
    std::fs::create_dir_all(dest).map_err(io_err(dest))?;
    for name in &files {
        let from = fresh.join(name);
        let bytes = std::fs::read(&from).map_err(io_err(&from))?;
        write_atomic(&dest.join(name), &bytes)?;
    }
    prune(dest, &files)
}

/// Writes one paper's results into `dir` (created if needed): `README.md` with every table,
/// figure, claim and note; `<table>.md` and `<table>.csv` per table; `<figure>.svg` and
/// `<figure>.png` per figure; `run.json` with the [`RunInfo`] (the list is
/// [`RunInfo::files`]). Every file is written atomically ([`write_atomic`]); files of `dir`
/// that this run did not write (an earlier run's) are removed afterwards.
pub fn write_paper(result: &PaperResult, info: &RunInfo, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let mut md = format!("# {}\n\n", info.title);
    let _ = writeln!(
        md,
        "Generated by `cargo xtask reproduce --paper {}{}` at revision `{}`, seed {}, in {:.1} s. \
         Every number in the tables comes from that run, except the columns headed \"paper\", \
         which are the figures the paper reports.\n",
        info.paper,
        if info.quick { " --quick" } else { "" },
        info.revision,
        info.seed,
        info.wall_seconds
    );
    if !result.data.is_empty() {
        md.push_str("Data:\n\n");
        for d in &result.data {
            let _ = writeln!(md, "- {d}");
        }
        md.push('\n');
    }
    if !result.missing.is_empty() {
        md.push_str("Not run (data missing):\n\n");
        for d in &result.missing {
            let _ = writeln!(md, "- {d}");
        }
        md.push('\n');
    }
    if !result.claims.is_empty() {
        md.push_str(
            "## The paper's claims in this run\n\n| claim | holds | evidence |\n|---|---|---|\n",
        );
        for c in &result.claims {
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                c.statement,
                if c.holds { "yes" } else { "no" },
                c.evidence
            );
        }
        md.push('\n');
    }
    if !result.notes.is_empty() {
        md.push_str("## Why our numbers differ, and what we decided\n\n");
        for n in &result.notes {
            let _ = writeln!(md, "- {n}");
        }
        md.push('\n');
    }
    md.push_str("## Tables\n\n");
    for t in &result.tables {
        let table_md = t.to_markdown();
        write_atomic(&dir.join(format!("{}.md", t.id)), table_md.as_bytes())?;
        write_atomic(&dir.join(format!("{}.csv", t.id)), t.to_csv()?.as_bytes())?;
        md.push_str(&table_md);
        let _ = writeln!(md, "\n([CSV]({}.csv))\n", t.id);
    }
    if !result.figures.is_empty() {
        md.push_str("## Figures\n\n");
    }
    for f in &result.figures {
        for ext in ["svg", "png"] {
            write_atomic_with(&dir.join(format!("{}.{ext}", f.id)), |tmp| {
                Ok(write_chart(&f.chart, tmp)?)
            })?;
        }
        let _ = writeln!(
            md,
            "![{}]({}.svg)\n\n{} ([PNG]({}.png))\n",
            f.caption, f.id, f.caption, f.id
        );
    }
    write_atomic(&dir.join("README.md"), md.as_bytes())?;
    let json_path = dir.join("run.json");
    let json = serde_json::to_string_pretty(info).map_err(json_err(&json_path))?;
    write_atomic(&json_path, json.as_bytes())?;
    prune(dir, &info.files())
}

/// Rewrites `<root>/README.md`, the index over every paper's `run.json` found under `root`.
pub fn write_index(root: &Path, explanations: &[(&str, &str)]) -> Result<()> {
    let mut md = String::from(
        "# Reproduced results\n\n\
         Written by `cargo xtask reproduce` (see the top-level README; the copy under \
         `docs/results/` changes only with `--bless`). Each paper's folder \
         holds its tables (Markdown and CSV), figures (SVG and PNG) and a README with the run's \
         seed, revision, data and wall time. Claims are decided from the run's own numbers.\n\n",
    );
    for (slug, why) in explanations {
        let path = root.join(slug).join("run.json");
        let Ok(text) = std::fs::read_to_string(&path) else {
            let _ = writeln!(
                md,
                "## {slug}\n\nNot run yet: `cargo xtask reproduce --paper {slug}`.\n"
            );
            continue;
        };
        let info: RunInfo = serde_json::from_str(&text).map_err(json_err(&path))?;
        let _ = writeln!(
            md,
            "## [{}]({slug}/README.md)\n\nRevision `{}`, seed {}, {:.1} s{}.\n",
            info.title,
            info.revision,
            info.seed,
            info.wall_seconds,
            if info.quick { ", quick run" } else { "" }
        );
        for (id, title) in &info.tables {
            let _ = writeln!(md, "- [{title}]({slug}/{id}.md)");
        }
        for (id, caption) in &info.figures {
            let _ = writeln!(md, "- [{caption}]({slug}/{id}.svg)");
        }
        md.push('\n');
        if !info.claims.is_empty() {
            md.push_str("| claim | holds in our run | evidence |\n|---|---|---|\n");
            for c in &info.claims {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} |",
                    c.statement,
                    if c.holds { "yes" } else { "no" },
                    c.evidence
                );
            }
            md.push('\n');
        }
        for m in &info.missing {
            let _ = writeln!(md, "- Not run: {m}");
        }
        let _ = writeln!(md, "{why}\n");
    }
    write_atomic(&root.join("README.md"), md.as_bytes())
}
