//! Progress of a long loop (the thickness bake, the benchmark's frames, the report's suite),
//! counted from any thread.
//!
//! With the `report` feature a [`Progress`] is an `indicatif` bar on stderr (drawn only when
//! stderr is a terminal). Without it there is no bar: the count is reported through the `log`
//! crate at info level, once per tenth of the total, so an embedding host that sets up a logger
//! still sees a long bake move, and one that does not pays one atomic add per step.

#[cfg(not(feature = "report"))]
use std::sync::atomic::{AtomicU64, Ordering};

/// A progress counter for `total` steps; [`Progress::hidden`] shows nothing.
#[derive(Debug)]
pub struct Progress {
    #[cfg(feature = "report")]
    bar: indicatif::ProgressBar,
    #[cfg(not(feature = "report"))]
    coarse: Option<Coarse>,
}

/// The count behind the log lines, without the `report` feature.
#[cfg(not(feature = "report"))]
#[derive(Debug)]
struct Coarse {
    what: String,
    total: u64,
    done: AtomicU64,
}

/// How many log lines a whole run gives, without the `report` feature.
#[cfg(not(feature = "report"))]
const LOG_STEPS: u64 = 10;

impl Progress {
    /// Shows nothing, whatever is counted.
    pub fn hidden() -> Progress {
        Progress {
            #[cfg(feature = "report")]
            bar: indicatif::ProgressBar::hidden(),
            #[cfg(not(feature = "report"))]
            coarse: None,
        }
    }

    /// A bar on stderr for `total` steps labelled `what`. With the `report` feature `template`
    /// is its indicatif template (`{msg}` is `what`) and `chars` its progress characters
    /// (indicatif's own when `None`); without it both are unused and the log lines say
    /// `what: done/total`.
    pub(crate) fn stderr(total: u64, what: &str, template: &str, chars: Option<&str>) -> Progress {
        #[cfg(feature = "report")]
        {
            let bar = indicatif::ProgressBar::with_draw_target(
                Some(total),
                indicatif::ProgressDrawTarget::stderr(),
            );
            let style = indicatif::ProgressStyle::with_template(template)
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(match chars {
                Some(chars) => style.progress_chars(chars),
                None => style,
            });
            bar.set_message(what.to_string());
            Progress { bar }
        }
        #[cfg(not(feature = "report"))]
        {
            let _ = (template, chars);
            Progress {
                coarse: Some(Coarse {
                    what: what.to_string(),
                    total,
                    done: AtomicU64::new(0),
                }),
            }
        }
    }

    /// Counts `n` more steps done.
    pub fn inc(&self, n: u64) {
        #[cfg(feature = "report")]
        self.bar.inc(n);
        #[cfg(not(feature = "report"))]
        if let Some(c) = &self.coarse {
            let before = c.done.fetch_add(n, Ordering::Relaxed);
            c.log_crossing(before, before.saturating_add(n));
        }
    }

    /// Sets the count of steps done to `done`.
    pub fn set_position(&self, done: u64) {
        #[cfg(feature = "report")]
        self.bar.set_position(done);
        #[cfg(not(feature = "report"))]
        if let Some(c) = &self.coarse {
            let before = c.done.swap(done, Ordering::Relaxed);
            c.log_crossing(before, done);
        }
    }

    /// Ends the run and removes the bar (without the `report` feature: nothing to remove).
    pub fn finish_and_clear(&self) {
        #[cfg(feature = "report")]
        self.bar.finish_and_clear();
    }
}

#[cfg(not(feature = "report"))]
impl Coarse {
    /// Logs `done` when going from `before` to `done` steps passed a tenth of the total; says
    /// whether it did.
    fn log_crossing(&self, before: u64, done: u64) -> bool {
        if self.total == 0 || done <= before {
            return false;
        }
        let tenth = |k: u64| {
            (u128::from(k.min(self.total)) * u128::from(LOG_STEPS)) / u128::from(self.total)
        };
        let crossed = tenth(done) > tenth(before);
        if crossed {
            log::info!("{}: {}/{}", self.what, done.min(self.total), self.total);
        }
        crossed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_from_many_threads_without_panicking() {
        let p = Progress::stderr(1000, "test", "{msg} {pos}/{len}", None);
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..250 {
                        p.inc(1);
                    }
                });
            }
        });
        p.set_position(1000);
        p.finish_and_clear();
        let h = Progress::hidden();
        h.inc(5);
        h.set_position(0);
        h.finish_and_clear();
    }

    #[cfg(not(feature = "report"))]
    #[test]
    fn coarse_count_logs_once_per_tenth() {
        let p = Progress::stderr(1000, "test", "", None);
        let c = p.coarse.as_ref().unwrap();
        let logged = (0..1000).filter(|&k| c.log_crossing(k, k + 1)).count();
        assert_eq!(logged, 10);
        assert!(!c.log_crossing(5, 5), "no step, no line");
        assert!(!c.log_crossing(900, 100), "going back, no line");
        assert!(c.log_crossing(0, 5000), "past the total");
        for _ in 0..7 {
            p.inc(1);
        }
        p.set_position(1000);
        assert_eq!(c.done.load(Ordering::Relaxed), 1000);
    }
}
