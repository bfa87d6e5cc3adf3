//! A writer killed in the middle of [`write_atomic_with`] leaves the old file whole.
//!
//! This test binary has no test harness: run plainly it is the parent, which starts itself
//! again as the writer (`TRAJPRED_WRITER_TARGET` set), waits until the writer has put part
//! of the new content on disk, kills it (SIGKILL on Unix) and checks the destination still
//! holds the old content byte for byte. It then lets a writer finish and checks the new
//! content is there whole. A writer that wrote straight into the destination fails the
//! first check (tried: the destination then held a torn mix of new bytes).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::{Duration, Instant};
use trajpred_core::io::write_atomic_with;

const TARGET: &str = "TRAJPRED_WRITER_TARGET";
const CHUNKS: &str = "TRAJPRED_WRITER_CHUNKS";
const CHUNK: usize = 4096;

/// The writer: `chunks` chunks of `n`, pausing between them so the parent can catch it.
fn writer(target: &Path, chunks: usize) -> std::io::Result<()> {
    write_atomic_with(target, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        for i in 0..chunks {
            f.write_all(&[b'n'; CHUNK])?;
            f.flush()?;
            if i == 8 {
                // tell the parent that part of the new content is on disk
                std::fs::write(progress_file(target), b"8")?;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        Ok(())
    })
}

fn progress_file(target: &Path) -> PathBuf {
    target.with_file_name("progress")
}

fn temporary_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .is_some_and(|n| n.to_string_lossy().contains(".tmp"))
                })
                .collect()
        })
        .unwrap_or_default()
}

fn spawn(target: &Path, chunks: usize) -> Result<std::process::Child, String> {
    let exe = std::env::current_exe().map_err(|e| format!("current_exe: {e}"))?;
    Command::new(exe)
        .env(TARGET, target)
        .env(CHUNKS, chunks.to_string())
        .spawn()
        .map_err(|e| format!("spawn writer: {e}"))
}

fn parent() -> Result<(), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let target = dir.path().join("model.json");
    let old: Vec<u8> = b"old content\n".repeat(1000);
    std::fs::write(&target, &old).map_err(|e| e.to_string())?;

    // 1. kill the writer once part of the new content is on disk
    let mut child = spawn(&target, 5000)?;
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if progress_file(&target).exists() {
            break;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            return Err("the writer put nothing on disk within 60 s".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().map_err(|e| format!("kill: {e}"))?;
    let status = child.wait().map_err(|e| e.to_string())?;
    if status.success() {
        return Err("the writer finished before it was killed".into());
    }
    let now = std::fs::read(&target).map_err(|e| e.to_string())?;
    if now != old {
        return Err(format!(
            "after the kill the destination holds {} bytes, not the old {} bytes",
            now.len(),
            old.len()
        ));
    }
    let leftovers = temporary_files(dir.path());
    if leftovers.len() != 1 {
        return Err(format!(
            "expected the killed writer's temporary file, found {leftovers:?}"
        ));
    }

    // 2. a writer left alone replaces the file whole
    let status = spawn(&target, 20)?.wait().map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!("the finishing writer failed: {status}"));
    }
    let now = std::fs::read(&target).map_err(|e| e.to_string())?;
    if now != vec![b'n'; 20 * CHUNK] {
        return Err(format!(
            "after a full write the destination holds {} bytes",
            now.len()
        ));
    }
    Ok(())
}

fn main() -> ExitCode {
    if let Some(target) = std::env::var_os(TARGET) {
        let chunks = std::env::var(CHUNKS)
            .ok()
            .and_then(|c| c.parse().ok())
            .unwrap_or(1);
        return match writer(Path::new(&target), chunks) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("writer: {e}");
                ExitCode::FAILURE
            }
        };
    }
    match parent() {
        Ok(()) => {
            eprintln!(
                "killed_writer: ok (old file whole after SIGKILL; new file whole after a full write)"
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("killed_writer: FAILED: {e}");
            ExitCode::FAILURE
        }
    }
}
