//! Progress bars on stderr for the command line.

use anyhow::{Result, anyhow};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use trajpred::protocol::Progress;

/// Progress bars on stderr (none when stderr is not a terminal, or with `--quiet`).
pub struct Bars {
    multi: MultiProgress,
    current: std::sync::Mutex<Option<ProgressBar>>,
    style: ProgressStyle,
}

impl Bars {
    pub fn new(quiet: bool) -> Result<Self> {
        let target = if quiet || !std::io::stderr().is_terminal() {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        Ok(Bars {
            multi: MultiProgress::with_draw_target(target),
            current: std::sync::Mutex::new(None),
            style: ProgressStyle::with_template("{prefix:>24} {bar:30} {pos}/{len} {elapsed}")
                .map_err(|e| anyhow!("{e}"))?,
        })
    }

    pub fn spinner(&self, message: String) -> ProgressBar {
        let s = self
            .multi
            .add(ProgressBar::new_spinner().with_message(message));
        s.enable_steady_tick(std::time::Duration::from_millis(120));
        s
    }
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: u64) {
        let bar = self.multi.add(ProgressBar::new(total));
        bar.set_style(self.style.clone());
        bar.set_prefix(stage.to_string());
        if let Ok(mut c) = self.current.lock() {
            *c = Some(bar);
        }
    }
    fn advance(&self, n: u64) {
        if let Ok(c) = self.current.lock()
            && let Some(b) = c.as_ref()
        {
            b.inc(n);
        }
    }
    fn finish(&self) {
        if let Ok(mut c) = self.current.lock()
            && let Some(b) = c.take()
        {
            b.finish();
        }
    }
}
