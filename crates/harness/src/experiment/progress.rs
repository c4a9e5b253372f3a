//! Sweep progress: a bar with ETA on a terminal, one line per measured round otherwise. Case
//! keys and messages (which may quote an external program's output) are shown with their
//! control characters escaped.

use super::runner::Observer;
use crate::units::Duration;
use indicatif::{ProgressBar, ProgressStyle};
use nbody_engine::output::neutral::control::{visible, visible_lines};
use nbody_records::results::CaseRecord;

/// Chooses the bar on a terminal and plain lines elsewhere (CI logs, pipes).
pub fn for_stderr() -> Box<dyn Observer> {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        Box::new(Bar::default())
    } else {
        Box::new(Lines::default())
    }
}

#[derive(Default)]
pub(crate) struct Bar {
    bar: Option<ProgressBar>,
}

impl Observer for Bar {
    fn start(&mut self, total: usize, done: usize) {
        let bar = ProgressBar::new(total as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} rounds  eta {eta}  {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_position(done as u64);
        self.bar = Some(bar);
    }

    fn round_done(&mut self, record: &CaseRecord, _round: usize) {
        if let Some(bar) = &self.bar {
            bar.inc(1);
            bar.set_message(visible(&record.key).into_owned());
        }
    }

    fn message(&mut self, text: &str) {
        match &self.bar {
            Some(bar) => bar.println(visible_lines(text)),
            None => eprintln!("{}", visible_lines(text)),
        }
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

#[derive(Default)]
pub(crate) struct Lines {
    total: usize,
    done: usize,
}

impl Observer for Lines {
    fn start(&mut self, total: usize, done: usize) {
        self.total = total;
        self.done = done;
    }

    fn round_done(&mut self, record: &CaseRecord, round: usize) {
        self.done += 1;
        let result = match &record.summary {
            Some(s) => format!("{} per step", Duration(s.median_s)),
            None => "no successful sample so far".to_string(),
        };
        eprintln!(
            "[{}/{}] {} round {}: {result}",
            self.done,
            self.total,
            visible(&record.key),
            round + 1,
        );
    }

    fn message(&mut self, text: &str) {
        eprintln!("{}", visible_lines(text));
    }
}
