//! What a long run (`roam reproduce …`, `roam bench …`) shows while it works, on stderr
//! only, so stdout stays the report or the JSON a pipe reads.
//!
//! The runners report [`Done`] counts through a callback
//! (`roam_experiments::progress`); this is the one place that turns them into
//! something a person sees, so every command looks alike:
//!
//! - stderr a terminal: a bar per stage (indicatif: runs done, elapsed, time left),
//!   left on screen when its stage ends, so the terminal keeps how long each part took;
//! - stderr a pipe or a file: one plain line per finished stage (`paper 002 es3: 5/5
//!   runs in 41.2 s`), no carriage returns or redraws in a log;
//! - `--quiet`: nothing.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use roam_experiments::progress::Done;

/// How the reports are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Quiet,
    Lines,
    Bars,
}

/// The stage being counted.
#[derive(Debug)]
struct Stage {
    name: String,
    /// When its work began: the end of the stage before it, or the command's start
    /// (its first report comes only after its first unit is done).
    started: Instant,
    /// When its last unit was done.
    ended: Option<Instant>,
    bar: Option<ProgressBar>,
}

/// A long run's progress on stderr; `report` is its callback (from any thread).
#[derive(Debug)]
pub(crate) struct Progress {
    /// What the whole command is, e.g. `paper 002`: each stage's label starts with it.
    title: String,
    mode: Mode,
    /// When the command began, for its first stage's clock.
    created: Instant,
    stage: Mutex<Option<Stage>>,
}

impl Progress {
    /// Bars when stderr is a terminal, lines otherwise, nothing when `quiet`.
    pub(crate) fn new(title: &str, quiet: bool) -> Progress {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            Mode::Bars
        } else {
            Mode::Lines
        };
        Progress {
            title: title.to_owned(),
            mode,
            created: Instant::now(),
            stage: Mutex::new(None),
        }
    }

    /// Whether anything but errors may go to stderr (the commands' own closing lines,
    /// such as a batch's wall time, follow `--quiet` too).
    pub(crate) fn speaks(&self) -> bool {
        self.mode != Mode::Quiet
    }

    /// Shows `done`: starts a new stage when its name changes, moves the bar forward
    /// (reports from several threads may arrive out of order: the bar never goes back),
    /// and ends the stage at `total`.
    pub(crate) fn report(&self, done: Done<'_>) {
        if self.mode == Mode::Quiet {
            return;
        }
        let mut current = roam_runtime::lock(&self.stage);
        if current.as_ref().is_none_or(|s| s.name != done.stage) {
            if let Some(bar) = current.as_ref().and_then(|s| s.bar.as_ref()) {
                bar.finish();
            }
            let started = current
                .as_ref()
                .map_or(self.created, |s| s.ended.unwrap_or_else(Instant::now));
            *current = Some(Stage {
                name: done.stage.to_owned(),
                started,
                ended: None,
                bar: (self.mode == Mode::Bars).then(|| self.bar(&done, started)),
            });
        }
        let Some(stage) = current.as_mut() else {
            return;
        };
        if let Some(bar) = &stage.bar {
            if done.done > bar.position() {
                bar.set_position(done.done);
            }
        }
        if done.done >= done.total && stage.ended.is_none() {
            stage.ended = Some(Instant::now());
            match &stage.bar {
                Some(bar) => {
                    bar.set_style(style(FINISHED));
                    bar.finish();
                }
                None => eprintln!(
                    "{}: {}/{} {} in {:.1} s",
                    self.label(done.stage),
                    done.done,
                    done.total,
                    done.unit,
                    stage.started.elapsed().as_secs_f64()
                ),
            }
        }
    }

    /// The callback form of [`Progress::report`], for the runners' `Progress` argument.
    pub(crate) fn callback(&self) -> impl Fn(Done<'_>) + Sync + '_ {
        move |done| self.report(done)
    }

    fn label(&self, stage: &str) -> String {
        format!("{} {stage}", self.title)
    }

    fn bar(&self, done: &Done<'_>, started: Instant) -> ProgressBar {
        // Hidden until it is set up, so its first frame is whole; its clock from when
        // the stage's work began.
        let bar = ProgressBar::with_draw_target(Some(done.total), ProgressDrawTarget::hidden())
            .with_elapsed(started.elapsed());
        bar.set_style(style(RUNNING));
        bar.set_prefix(self.label(done.stage));
        bar.set_message(done.unit);
        bar.set_draw_target(ProgressDrawTarget::stderr());
        // A unit can take many seconds (a day of the executive's): the clock moves anyway.
        bar.enable_steady_tick(Duration::from_millis(500));
        bar
    }
}

/// A running stage's bar: done, elapsed, time left.
const RUNNING: &str = "{prefix} [{bar:30}] {pos}/{len} {msg}, {elapsed} elapsed, ~{eta} left";
/// A finished stage's line: how long it took.
const FINISHED: &str = "{prefix} [{bar:30}] {pos}/{len} {msg} in {elapsed}";

fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template)
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ")
}

impl Drop for Progress {
    /// A run that ends early (an error) leaves its bar where it stopped, not spinning.
    fn drop(&mut self) {
        if let Some(bar) = roam_runtime::lock(&self.stage)
            .as_ref()
            .and_then(|s| s.bar.as_ref())
        {
            bar.abandon();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_stage_name_starts_a_new_count_and_the_end_is_marked_once() {
        let progress = Progress {
            title: "test".into(),
            mode: Mode::Lines,
            created: Instant::now(),
            stage: Mutex::new(None),
        };
        progress.report(Done::of("es1", "runs", 1, 2));
        progress.report(Done::of("es1", "runs", 2, 2));
        let finished = |p: &Progress| {
            let stage = roam_runtime::lock(&p.stage);
            stage.as_ref().map(|s| (s.name.clone(), s.ended.is_some()))
        };
        assert_eq!(finished(&progress), Some(("es1".into(), true)));
        let es1_ended = roam_runtime::lock(&progress.stage)
            .as_ref()
            .and_then(|s| s.ended);
        progress.report(Done::of("es2", "runs", 1, 3));
        assert_eq!(finished(&progress), Some(("es2".into(), false)));
        // The second stage's clock starts where the first one ended, not at its first
        // report (after its first run).
        let es2_started = roam_runtime::lock(&progress.stage)
            .as_ref()
            .map(|s| s.started);
        assert!(es1_ended.is_some());
        assert_eq!(es2_started, es1_ended);
        assert_eq!(progress.label("es2"), "test es2");
    }

    #[test]
    fn quiet_keeps_no_stage() {
        let progress = Progress::new("test", true);
        progress.report(Done::of("es1", "runs", 1, 1));
        assert!(roam_runtime::lock(&progress.stage).is_none());
        assert!(!progress.speaks());
    }
}
