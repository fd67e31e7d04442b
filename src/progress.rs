//! Progress of a long loop (the thickness bake, the benchmark's frames, the report's suite),
//! counted from any thread.
//!
//! A [`Progress`] is an `indicatif` bar on stderr (drawn only when stderr is a terminal), behind
//! one type so that its callers do not name the crate.

/// A progress counter for `total` steps; [`Progress::hidden`] shows nothing.
#[derive(Debug)]
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    /// Shows nothing, whatever is counted.
    pub fn hidden() -> Progress {
        Progress {
            bar: indicatif::ProgressBar::hidden(),
        }
    }

    /// A bar on stderr for `total` steps labelled `what`: `template` is its indicatif template
    /// (`{msg}` is `what`) and `chars` its progress characters (indicatif's own when `None`).
    pub(crate) fn stderr(total: u64, what: &str, template: &str, chars: Option<&str>) -> Progress {
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

    /// Counts `n` more steps done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// Sets the count of steps done to `done`.
    pub fn set_position(&self, done: u64) {
        self.bar.set_position(done);
    }

    /// Ends the run and removes the bar.
    pub fn finish_and_clear(&self) {
        self.bar.finish_and_clear();
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
}
