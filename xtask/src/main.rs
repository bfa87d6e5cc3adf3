//! `cargo xtask`: project automation, kept thin (argument parsing and calls into
//! `trajpred-repro`).
//!
//! ```text
//! cargo xtask reproduce [--paper <slug>|all] [--quick] [--check | --bless]
//!                       [--data DIR] [--out DIR] [--seed N] [--jobs N]
//! cargo xtask perf [--runs N] [--out DIR] [--table-only]
//! ```
//!
//! The slugs are those of `trajpred_repro::Paper::ALL`. A run is written to `--out`
//! (`target/reproduce`, or `target/reproduce-quick` with `--quick`); `docs/results/` is only
//! read by `--check` and only written by `--bless`.
#![allow(clippy::print_stdout)]

use anyhow::{Context as _, Result, bail};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The reproduction's neural training allocates and frees a tensor per operation (burn's
/// ops return new tensors): mimalloc serves that churn with less work than glibc's malloc
/// (kfu-lstm alone, docs/performance.md: about 0.75x the time).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;
use trajpred_repro::{
    Context, Paper, ReproError, bless, check_paper, run_info, run_papers, write_run,
};

#[derive(Parser)]
#[command(name = "cargo xtask", about = "trajpred project automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The papers `--paper` selected.
#[derive(Clone)]
struct Selection(Vec<Paper>);

/// `--paper`: a slug of `Paper::ALL`, or `all`; clap lists these values in the help.
fn paper_parser() -> impl TypedValueParser<Value = Selection> {
    let values = Paper::ALL.iter().map(|p| p.slug()).chain(["all"]);
    PossibleValuesParser::new(values)
        .map(|s| Selection(Paper::from_slug(&s).map_or_else(|| Paper::ALL.to_vec(), |p| vec![p])))
}

#[derive(Subcommand)]
enum Command {
    /// Regenerate the tables and figures of the papers (under target/reproduce by default);
    /// --check compares them with docs/results/, --bless replaces docs/results/ with them.
    Reproduce {
        /// Which paper to reproduce (`all`: every paper, in order).
        #[arg(long, default_value = "all", value_parser = paper_parser())]
        paper: Selection,
        /// A reduced run (fewer seeds, epochs and trajectories) that finishes in under a
        /// minute; written to target/reproduce-quick unless --out is given. Cannot be blessed.
        #[arg(long)]
        quick: bool,
        /// Then compare the run with the one committed under docs/results/: fail, listing
        /// every difference, when a number is outside its column's tolerance, a label or paper
        /// figure changed, a claim's verdict changed, or a table, row, column, figure or claim
        /// is on one side only.
        #[arg(long, conflicts_with = "bless")]
        check: bool,
        /// Then copy the run into docs/results/ (replacing each reproduced paper's folder) and
        /// rewrite docs/results/README.md: the only way docs/results/ changes.
        #[arg(long, conflicts_with = "quick")]
        bless: bool,
        /// Folder holding the real datasets (geolife/, tdrive/, adsb-traffic/).
        #[arg(long, default_value = "../shared/data")]
        data: PathBuf,
        /// Where to write the run (default target/reproduce, or target/reproduce-quick with
        /// --quick); each paper in `OUT/SLUG/`, with an index `OUT/README.md`.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Base seed of every random choice.
        #[arg(long, default_value_t = Context::default().seed)]
        seed: u64,
        /// Papers run at once (default: the machine's cores). Each paper's numbers do not
        /// depend on it: every experiment is seeded from --seed alone.
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
        jobs: Option<u64>,
    },
    /// One sitting of every speed comparison (ours beside the peer: scikit-learn, adskalman,
    /// filterpy, PyTorch), then the table of docs/performance.md rewritten from it. Run it on
    /// an otherwise idle machine; it takes about 15 minutes.
    Perf {
        /// Rounds of the alternating comparisons (LAR, neural).
        #[arg(long, default_value_t = 5)]
        runs: u32,
        /// Where the sitting's raw outputs go.
        #[arg(long, default_value = "target/perf-sitting")]
        out: PathBuf,
        /// Only rewrite the table from the outputs already in --out.
        #[arg(long)]
        table_only: bool,
    },
}

/// The workspace root (xtask lives one level below it).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn revision(root: &Path) -> String {
    let out = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(root)
        .output();
    let dirty = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .current_dir(root)
        .output()
        .map(|o| !o.stdout.is_empty())
        .unwrap_or(false);
    match out {
        Ok(o) if o.status.success() => {
            let rev = String::from_utf8_lossy(&o.stdout).trim().to_string();
            if dirty {
                format!("{rev} (with uncommitted changes)")
            } else {
                rev
            }
        }
        _ => "unknown (not a git checkout)".to_string(),
    }
}

/// Makes a relative path relative to the workspace root.
fn under(root: &Path, path: PathBuf) -> PathBuf {
    if path.is_relative() {
        root.join(path)
    } else {
        path
    }
}

/// Runs a program from the workspace root, failing when it does.
fn run(root: &Path, program: &str, args: &[&str]) -> Result<()> {
    let status = std::process::Command::new(program)
        .args(args)
        .current_dir(root)
        .status()
        .with_context(|| format!("starting {program}"))?;
    if !status.success() {
        bail!("{program} {} failed: {status}", args.join(" "));
    }
    Ok(())
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Perf {
            runs,
            out,
            table_only,
        } => {
            let root = root();
            let out = under(&root, out);
            let out = out.to_string_lossy();
            if !table_only {
                run(
                    &root,
                    "bash",
                    &["xtask/perf/sitting.sh", &out, &runs.to_string()],
                )?;
            }
            run(
                &root,
                "python3",
                &["xtask/perf/table.py", &out, "docs/performance.md"],
            )
        }
        Command::Reproduce {
            paper,
            quick,
            check,
            bless: blessing,
            data,
            out,
            seed,
            jobs,
        } => {
            let root = root();
            let data = under(&root, data);
            if !data.is_dir() {
                eprintln!(
                    "note: no data folder at {}; the real-data experiments will say what to \
                     download, the synthetic ones still run",
                    data.display()
                );
            }
            let ctx = Context {
                quick,
                seed,
                data_dir: data.is_dir().then_some(data),
                progress: true,
            };
            let committed = root.join("docs").join("results");
            let out = match out {
                Some(dir) => under(&root, dir),
                None => root.join("target").join(if quick {
                    "reproduce-quick"
                } else {
                    "reproduce"
                }),
            };
            let rev = revision(&root);
            let start = Instant::now();
            let mut failed = Vec::new();
            let papers = paper.0;
            let jobs = jobs.map_or_else(
                || std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
                |j| usize::try_from(j).unwrap_or(usize::MAX),
            );
            eprintln!(
                "reproducing {} paper(s), up to {jobs} at once",
                papers.len()
            );
            let results = run_papers(&papers, &ctx, jobs);
            for (&p, run) in papers.iter().zip(results) {
                eprintln!("== {}", p.title());
                let (result, wall) = run.with_context(|| format!("reproducing {}", p.slug()))?;
                let info = run_info(p, &ctx, &result, wall, &rev);
                write_run(p, &result, &info, &out)
                    .with_context(|| format!("writing {} under {}", p.slug(), out.display()))?;
                let readme = out.join(p.slug()).join("README.md");
                let text = std::fs::read_to_string(&readme)
                    .with_context(|| format!("reading {}", readme.display()))?;
                println!("{text}");
                for m in &info.missing {
                    eprintln!("not run: {m}");
                }
                eprintln!(
                    "{}: {:.1} s, written to {}",
                    p.slug(),
                    wall,
                    out.join(p.slug()).display()
                );
                if check {
                    match check_paper(p, &result, &committed) {
                        Ok(()) => println!(
                            "check {}: {} tables, {} figures and {} claims agree with \
                             docs/results/{} within their tolerances",
                            p.slug(),
                            result.tables.len(),
                            result.figures.len(),
                            result.claims.len(),
                            p.slug()
                        ),
                        Err(ReproError::CheckFailed { differences, .. }) => {
                            println!(
                                "check {}: {} difference(s) from docs/results/{}:",
                                p.slug(),
                                differences.len(),
                                p.slug()
                            );
                            for d in &differences {
                                println!("  - {d}");
                            }
                            failed.push((p.slug(), differences.len()));
                        }
                        Err(e) => {
                            return Err(e).with_context(|| format!("checking {}", p.slug()));
                        }
                    }
                }
                if blessing {
                    bless(p, &out, &committed).with_context(|| {
                        format!("blessing {} into {}", p.slug(), committed.display())
                    })?;
                    eprintln!(
                        "{}: blessed into {}",
                        p.slug(),
                        committed.join(p.slug()).display()
                    );
                }
            }
            eprintln!("total: {:.1} s", start.elapsed().as_secs_f64());
            if !failed.is_empty() {
                let which: Vec<String> = failed
                    .iter()
                    .map(|(slug, n)| format!("{slug} ({n})"))
                    .collect();
                bail!(
                    "--check failed: differences from docs/results in {}",
                    which.join(", ")
                );
            }
            Ok(())
        }
    }
}
