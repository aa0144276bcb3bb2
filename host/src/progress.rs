//! Progress on stderr counting environment steps: a bar on a terminal, and
//! where stderr is not one (a log file, a pipe, a batch job) a plain line a
//! minute, so a run of an hour is not silent for an hour.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// How often a line is written when stderr is not a terminal.
const LOG_EVERY: Duration = Duration::from_secs(60);

/// A bar of `total` environment steps with a message.
pub fn steps_bar(total: u64, message: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{msg} [{bar:30}] {percent:>3}% {human_pos}/{human_len} steps, {per_sec}, eta {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(message.to_string());
    if !std::io::stderr().is_terminal() {
        log_lines(&bar, LOG_EVERY);
    }
    bar
}

/// Writes `bar`'s state as one line every `every` until the bar is
/// finished or dropped (the thread holds it weakly, so an error that drops
/// the bar ends the lines too).
fn log_lines(bar: &ProgressBar, every: Duration) {
    let weak = bar.downgrade();
    std::thread::spawn(move || loop {
        std::thread::sleep(every);
        let Some(bar) = weak.upgrade() else { return };
        if bar.is_finished() {
            return;
        }
        eprintln!("{}", line(&bar.message(), bar.position(), bar.length().unwrap_or(0), bar.elapsed(), bar.per_sec()));
    });
}

/// One progress line: `label: 52 % (36.1 M of 69.5 M steps), 17 900 steps/s,
/// 33 min elapsed, about 31 min left`.
fn line(label: &str, pos: u64, total: u64, elapsed: Duration, per_sec: f64) -> String {
    let percent = if total > 0 { 100.0 * pos as f64 / total as f64 } else { 0.0 };
    let left = (per_sec > 0.0 && total > pos).then(|| Duration::from_secs_f64((total - pos) as f64 / per_sec));
    format!(
        "{label}: {percent:.0} % ({} of {} steps), {per_sec:.0} steps/s, {} elapsed{}",
        count(pos),
        count(total),
        minutes(elapsed),
        left.map_or(String::new(), |l| format!(", about {} left", minutes(l)))
    )
}

/// A count in millions above ten million.
fn count(n: u64) -> String {
    if n >= 10_000_000 {
        format!("{:.1} M", n as f64 * 1e-6)
    } else {
        n.to_string()
    }
}

/// A duration in whole seconds under two minutes, else in minutes.
fn minutes(d: Duration) -> String {
    let s = d.as_secs();
    if s < 120 {
        format!("{s} s")
    } else {
        format!("{} min", (s + 30) / 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_says_how_far_how_fast_and_how_long_is_left() {
        let l = line("leo sarsa", 36_100_000, 69_500_000, Duration::from_secs(1980), 17_900.0);
        assert_eq!(l, "leo sarsa: 52 % (36.1 M of 69.5 M steps), 17900 steps/s, 33 min elapsed, about 31 min left");
        // Nothing done yet: no guess of what is left.
        assert_eq!(line("x", 0, 100, Duration::from_secs(5), 0.0), "x: 0 % (0 of 100 steps), 0 steps/s, 5 s elapsed");
    }
}
