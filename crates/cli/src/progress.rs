//! Per-pass reporting on the command's own streams: a progress bar on a terminal, plain lines
//! otherwise, one JSON object per pass on request; and the outlook (share done, time left) that
//! the live views show too.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use ppm::{PassStats, Renderer};

use crate::duration;
use crate::settings::{Budget, Job};

/// How far a render is: the share of its budget spent and the time it still needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Outlook {
    /// In [0, 1]: the larger of the shares of the pass and time budgets spent.
    pub(crate) fraction: f64,
    /// Seconds left, at this run's mean time per pass (or the time budget left, if sooner).
    pub(crate) remaining: Option<f64>,
}

impl Outlook {
    /// After `passes` passes in total, `first_pass` of them done before this run, `elapsed`
    /// into this run.
    pub(crate) fn of(budget: Budget, first_pass: u32, passes: u32, elapsed: Duration) -> Self {
        let done_here = passes.saturating_sub(first_pass).max(1);
        let per_pass = elapsed.as_secs_f64() / f64::from(done_here);
        let mut fraction: f64 = 0.0;
        let mut remaining: Option<f64> = None;
        if let Some(n) = budget.passes {
            fraction = fraction.max(f64::from(passes) / f64::from(n.max(1)));
            remaining = Some(per_pass * f64::from(n.saturating_sub(passes)));
        }
        if let Some(t) = budget.time {
            let left = (t.as_secs_f64() - elapsed.as_secs_f64()).max(0.0);
            fraction = fraction.max(elapsed.as_secs_f64() / t.as_secs_f64());
            remaining = Some(remaining.map_or(left, |r| r.min(left)));
        }
        Outlook {
            fraction: fraction.min(1.0),
            remaining,
        }
    }
}

/// Per-pass reporting: a progress bar on a terminal, plain lines otherwise, JSON on request.
pub(crate) struct Progress {
    bar: Option<ProgressBar>,
    budget: Budget,
    quiet: bool,
    json: bool,
    first_pass: u32,
    /// NaN or infinite values dropped over the passes of this run.
    pub(crate) non_finite: u64,
    /// The latest error trend (`trend.rs`), shown until the next one.
    trend: Option<f64>,
    /// The passes after which it was measured.
    trend_pass: Option<u32>,
}

impl Progress {
    pub(crate) fn new(job: &Job, first_pass: u32) -> Self {
        let quiet = job.run.quiet;
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(1000);
            let style =
                ProgressStyle::with_template("{spinner} [{bar:30}] {elapsed_precise} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> ");
            bar.set_style(style);
            bar.set_message("first pass…");
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        });
        Progress {
            bar,
            budget: job.budget,
            quiet,
            json: job.run.json,
            first_pass,
            non_finite: 0,
            trend: None,
            trend_pass: None,
        }
    }

    /// The outlook after `passes` passes, `elapsed` into this run.
    pub(crate) fn outlook(&self, passes: u32, elapsed: Duration) -> Outlook {
        Outlook::of(self.budget, self.first_pass, passes, elapsed)
    }

    /// Reports a pass; `trend` is the error trend measured after it, if it was.
    pub(crate) fn pass(
        &mut self,
        renderer: &Renderer,
        stats: &PassStats,
        elapsed: Duration,
        trend: Option<f64>,
    ) {
        let passes = renderer.passes();
        self.non_finite += stats.non_finite;
        if trend.is_some() {
            self.trend = trend;
            self.trend_pass = Some(passes);
        }
        if self.json {
            let line = serde_json::json!({
                "event": "pass",
                "pass": stats.pass,
                "passes": passes,
                "camera_paths": stats.camera_paths,
                "photons_traced": stats.photons_traced,
                "frequency_photons": stats.frequency_photons,
                "photons_deposited": stats.photons_deposited,
                "hitpoints_hit": stats.hitpoints_hit,
                "hitpoints_valid": stats.hitpoints_valid,
                "mean_radius": finite_or_null(stats.mean_radius),
                "min_radius": finite_or_null(stats.min_radius),
                "max_radius": finite_or_null(stats.max_radius),
                "frequency_held": finite_or_null(stats.frequency_held),
                "photons_stored": stats.photons_stored,
                "light_connections": stats.light_connections,
                "volume_photons": stats.volume_photons,
                "non_finite": stats.non_finite,
                "timings": {
                    "camera": stats.timings.camera,
                    "index": stats.timings.index,
                    "trace": stats.timings.trace,
                    "gather": stats.timings.gather,
                    "update": stats.timings.update,
                    "frequency": stats.timings.frequency,
                    "volume": stats.timings.volume,
                },
                "photons_emitted": renderer.photons_emitted(),
                "elapsed_seconds": elapsed.as_secs_f64(),
                // The latest trend and the passes it was measured after: measuring it reads
                // the image, which costs too much to do after every pass (`Watch::after_pass`).
                "error_trend": self.trend,
                "error_trend_pass": self.trend_pass,
            });
            // A closed stdout is not worth stopping the render for.
            let _ = crate::print_stdout(&format!("{line}\n"));
        }
        if self.quiet {
            return;
        }
        let outlook = self.outlook(passes, elapsed);
        let of = self
            .budget
            .passes
            .map(|n| format!("/{n}"))
            .unwrap_or_default();
        let left = outlook.remaining.map_or(String::new(), |r| {
            format!(", ~{} left", duration::format(Duration::from_secs_f64(r)))
        });
        let photons = if renderer.params().method.traces_light_paths() {
            format!(", {} photons", human_count(renderer.photons_emitted()))
        } else {
            String::new()
        };
        let trend = self
            .trend
            .map_or(String::new(), |t| format!(", error trend {}", percent(t)));
        match &self.bar {
            Some(bar) => {
                bar.set_position((outlook.fraction * 1000.0) as u64);
                bar.set_message(format!("pass {passes}{of}{photons}{trend}{left}"));
            }
            None => eprintln!(
                "pass {passes}{of}{photons}{trend}, {} elapsed{left}",
                duration::format(elapsed)
            ),
        }
    }

    /// The latest error trend.
    pub(crate) fn trend(&self) -> Option<f64> {
        self.trend
    }

    /// A remark between progress updates.
    pub(crate) fn note(&self, message: &str) {
        if self.quiet {
            return;
        }
        match &self.bar {
            Some(bar) => bar.println(message),
            None => eprintln!("{message}"),
        }
    }

    pub(crate) fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// `3.2%`, `0.41%`, `0.052%`: two significant digits.
pub(crate) fn percent(fraction: f64) -> String {
    let p = fraction * 100.0;
    if p.is_nan() || p <= 0.0 {
        "0%".to_owned()
    } else if p >= 10.0 {
        format!("{p:.0}%")
    } else if p >= 1.0 {
        format!("{p:.1}%")
    } else {
        let digits = (1.0 - p.log10().floor()).clamp(2.0, 6.0) as usize;
        format!("{p:.digits$}%")
    }
}

/// `1.2M`, `350k`, `999`.
pub(crate) fn human_count(n: u64) -> String {
    if n >= 10_000_000 {
        format!("{:.0}M", n as f64 / 1e6)
    } else if n >= 1_000_000 {
        format!("{:.1}M", n as f64 / 1e6)
    } else if n >= 10_000 {
        format!("{:.0}k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

fn finite_or_null(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentages_keep_two_significant_digits() {
        assert_eq!(percent(0.5), "50%");
        assert_eq!(percent(0.032), "3.2%");
        assert_eq!(percent(0.0041), "0.41%");
        assert_eq!(percent(0.000_52), "0.052%");
        assert_eq!(percent(0.0), "0%");
        assert_eq!(percent(1e-12), "0.000000%");
    }

    #[test]
    fn the_outlook_takes_the_nearer_budget() {
        let both = Budget {
            passes: Some(10),
            time: Some(Duration::from_secs(100)),
        };
        let o = Outlook::of(both, 0, 5, Duration::from_secs(10));
        assert_eq!(o.fraction, 0.5);
        assert_eq!(o.remaining, Some(10.0));
        let o = Outlook::of(both, 0, 1, Duration::from_secs(90));
        assert_eq!(o.fraction, 0.9);
        assert_eq!(o.remaining, Some(10.0));
    }
}
