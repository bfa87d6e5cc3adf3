//! `cargo xtask`: project automation, kept thin (argument parsing and calls into
//! `trajpred-repro`).
//!
//! ```text
//! cargo xtask reproduce [--paper gskf|kf-dynamic|mkpf|kfu-lstm|all] [--quick] [--check]
//!                       [--data DIR] [--out DIR] [--seed N]
//! ```
#![allow(clippy::print_stdout)]

use anyhow::{Context as _, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use trajpred_repro::{Context, Paper, check_paper, reproduce_into};

#[derive(Parser)]
#[command(name = "cargo xtask", about = "trajpred project automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Regenerate the tables and figures of the four papers under docs/results/.
    Reproduce {
        /// Which paper to reproduce.
        #[arg(long, value_enum, default_value_t = Which::All)]
        paper: Which,
        /// A reduced run (fewer seeds, epochs and trajectories) that finishes in under a
        /// minute; written to target/reproduce-quick unless --out is given.
        #[arg(long)]
        quick: bool,
        /// Run, then compare the tables with the committed ones under docs/results/ within
        /// each column's stated tolerance, instead of overwriting them.
        #[arg(long)]
        check: bool,
        /// Folder holding the real datasets (geolife/, tdrive/, adsb-traffic/).
        #[arg(long, default_value = "../shared/data")]
        data: PathBuf,
        /// Where to write the results (default docs/results, or target/reproduce-quick with
        /// --quick).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Base seed of every random choice.
        #[arg(long, default_value_t = Context::default().seed)]
        seed: u64,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Which {
    /// MSTPM-GSKF: group sparse coding + improved Kalman filter (SPEC A).
    Gskf,
    /// Dynamic trajectory prediction with a Kalman filter (SPEC B).
    KfDynamic,
    /// MKPF: particle filter with a UKF+EKF proposal (SPEC C).
    Mkpf,
    /// KFU-LSTM-Net: Kalman-filter-unfolded LSTM (SPEC D).
    KfuLstm,
    /// All four.
    All,
}

impl Which {
    fn papers(self) -> Vec<Paper> {
        match self {
            Which::Gskf => vec![Paper::Gskf],
            Which::KfDynamic => vec![Paper::KfDynamic],
            Which::Mkpf => vec![Paper::Mkpf],
            Which::KfuLstm => vec![Paper::KfuLstm],
            Which::All => Paper::ALL.to_vec(),
        }
    }
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

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Reproduce {
            paper,
            quick,
            check,
            data,
            out,
            seed,
        } => {
            let root = root();
            let data = if data.is_relative() {
                root.join(data)
            } else {
                data
            };
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
            let out = out.unwrap_or_else(|| {
                if quick {
                    root.join("target").join("reproduce-quick")
                } else {
                    committed.clone()
                }
            });
            let rev = revision(&root);
            let mut failures = 0;
            for p in paper.papers() {
                eprintln!("== {}", p.title());
                if check {
                    let (result, diffs) = check_paper(p, &ctx, &committed)
                        .with_context(|| format!("reproducing {}", p.slug()))?;
                    for t in &result.tables {
                        println!("{}", t.to_markdown());
                    }
                    if diffs.is_empty() {
                        println!(
                            "check {}: {} tables agree with docs/results/{} within their tolerances",
                            p.slug(),
                            result.tables.len(),
                            p.slug()
                        );
                    } else {
                        failures += diffs.len();
                        for d in &diffs {
                            println!("check {}: {d}", p.slug());
                        }
                    }
                    continue;
                }
                let info = reproduce_into(p, &ctx, &out, &rev)
                    .with_context(|| format!("reproducing {}", p.slug()))?;
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
                    info.wall_seconds,
                    out.join(p.slug()).display()
                );
            }
            if failures > 0 {
                bail!("{failures} difference(s) from the committed results");
            }
            Ok(())
        }
    }
}
