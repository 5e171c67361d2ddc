//! A progress bar on stderr: redrawn in place on a terminal, a line every few percent in a log.

use std::io::{IsTerminal, Write};
use std::time::Instant;

/// Width of the bar in characters.
const BAR: usize = 30;
/// In a log, a line every this share of the work.
const LOG_STEP: f64 = 0.05;

/// Counts finished units of work and shows what runs now.
pub struct Progress {
    total: u64,
    done: u64,
    started: Instant,
    terminal: bool,
    last_logged: f64,
}

impl Progress {
    /// A bar for `total` units.
    pub fn new(total: u64) -> Self {
        Self {
            total: total.max(1),
            done: 0,
            started: Instant::now(),
            terminal: std::io::stderr().is_terminal(),
            last_logged: -1.0,
        }
    }

    /// Shows `what` as running (before the work).
    pub fn show(&mut self, what: &str) {
        let share = self.done as f64 / self.total as f64;
        let filled = (share * BAR as f64).round() as usize;
        let elapsed = self.started.elapsed().as_secs_f64();
        let eta = if self.done > 0 {
            format!("{:.0} s left", elapsed / share - elapsed)
        } else {
            String::new()
        };
        let line = format!(
            "[{}{}] {:>5}/{} {:>5.1} % {eta:>10}  {what}",
            "#".repeat(filled),
            ".".repeat(BAR - filled.min(BAR)),
            self.done,
            self.total,
            100.0 * share
        );
        let mut err = std::io::stderr().lock();
        if self.terminal {
            let _ = write!(err, "\r\x1b[2K{line}");
            let _ = err.flush();
        } else if share - self.last_logged >= LOG_STEP {
            self.last_logged = share;
            let _ = writeln!(err, "{line}");
        }
    }

    /// Marks `units` as done.
    pub fn advance(&mut self, units: u64) {
        self.done = (self.done + units).min(self.total);
    }

    /// A message on its own line, keeping the bar.
    pub fn note(&self, message: &str) {
        let mut err = std::io::stderr().lock();
        if self.terminal {
            let _ = write!(err, "\r\x1b[2K");
        }
        let _ = writeln!(err, "{message}");
    }

    /// Ends the bar.
    pub fn finish(&mut self) {
        self.done = self.total;
        self.last_logged = -1.0;
        self.show(&format!(
            "done in {:.1} s",
            self.started.elapsed().as_secs_f64()
        ));
        if self.terminal {
            eprintln!();
        }
    }
}
