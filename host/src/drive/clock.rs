//! The period clock of `pada drive`: a tick every control period on the
//! wall clock (real time) or at once (lock step, against virtual servos
//! whose time is the controller's), the jitter of every tick, and each
//! period's work with its overruns.
//!
//! Real time: tick `k` is due at `start + k·T`. The thread sleeps until a
//! little before it and spins the rest (a sleep alone wakes up to about a
//! millisecond late on a loaded machine), so the jitter measured is the
//! wake-up's lateness. A period whose work ran past the next tick makes
//! that tick late; one that ran past a whole period skips the ticks it
//! missed (each counted), as a board's ticker does not run periods twice.

use serde::Serialize;
use std::time::{Duration, Instant};

/// Sleeping stops this long before a tick; the rest is spun.
const SPIN: Duration = Duration::from_micros(300);

/// The clock.
pub struct PeriodClock {
    start: Instant,
    period_us: u64,
    real_time: bool,
    /// The next tick's index.
    next: u64,
    /// The current period's tick \[µs since start\].
    tick_us: u64,
    late_us: Vec<u32>,
    work_us: Vec<u32>,
    overruns: u32,
    skipped: u64,
}

/// What the clock measured.
#[derive(Debug, Clone, Serialize)]
pub struct ClockReport {
    /// Periods run.
    pub periods: u64,
    /// Ticks skipped because a period's work took more than a whole
    /// period.
    pub skipped_ticks: u64,
    /// Periods whose work took longer than the period.
    pub overruns: u32,
    /// Lateness of the ticks \[µs\]: median, 99th percentile, largest.
    pub jitter_us: Percentiles,
    /// Each period's work (read, decide, write) \[µs\].
    pub work_us: Percentiles,
}

/// Median, 99th percentile and largest of a sample.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct Percentiles {
    /// Median.
    pub p50: u32,
    /// 99th percentile.
    pub p99: u32,
    /// Largest.
    pub max: u32,
}

impl Percentiles {
    /// Of `sample` (sorted here; nearest rank).
    pub fn of(sample: &[u32]) -> Percentiles {
        if sample.is_empty() {
            return Percentiles::default();
        }
        let mut s = sample.to_vec();
        s.sort_unstable();
        let rank = |q: f64| s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
        Percentiles { p50: rank(0.5), p99: rank(0.99), max: s[s.len() - 1] }
    }
}

impl PeriodClock {
    /// A clock of `period_us`, starting now.
    pub fn new(period_us: u32, real_time: bool) -> Self {
        PeriodClock {
            start: Instant::now(),
            period_us: period_us as u64,
            real_time,
            next: 0,
            tick_us: 0,
            late_us: Vec::new(),
            work_us: Vec::new(),
            overruns: 0,
            skipped: 0,
        }
    }

    /// Waits for the next tick; returns the period's index and its time
    /// \[µs\]: the tick's schedule (lock step: `k·T`).
    pub fn tick(&mut self) -> (u64, u64) {
        let k = self.next;
        let due = k * self.period_us;
        if self.real_time {
            let mut now = self.start.elapsed();
            let due_at = Duration::from_micros(due);
            if now + SPIN < due_at {
                std::thread::sleep(due_at - now - SPIN);
            }
            while {
                now = self.start.elapsed();
                now < due_at
            } {
                std::hint::spin_loop();
            }
            self.late_us.push((now.as_micros() as u64).saturating_sub(due).min(u32::MAX as u64) as u32);
        }
        self.tick_us = due;
        (k, due)
    }

    /// The current period's work is done: whether it overran the period.
    /// The next tick is the next one after now (ticks missed are skipped).
    pub fn done(&mut self) -> bool {
        if !self.real_time {
            self.next += 1;
            return false;
        }
        let now = self.start.elapsed().as_micros() as u64;
        let work = now.saturating_sub(self.tick_us);
        self.work_us.push(work.min(u32::MAX as u64) as u32);
        let overran = work > self.period_us;
        self.overruns += overran as u32;
        let mut next = self.next + 1;
        let behind = now / self.period_us;
        if behind > next {
            self.skipped += behind - next;
            next = behind;
        }
        self.next = next;
        overran
    }

    /// Microseconds since the clock started.
    pub fn now_us(&self) -> u64 {
        self.start.elapsed().as_micros() as u64
    }

    /// The last period's work \[µs\].
    pub fn last_work_us(&self) -> u32 {
        self.work_us.last().copied().unwrap_or(0)
    }

    /// Overruns so far.
    pub fn overruns(&self) -> u32 {
        self.overruns
    }

    /// The longest period's work so far \[µs\].
    pub fn max_work_us(&self) -> u32 {
        self.work_us.iter().copied().max().unwrap_or(0)
    }

    /// What it measured.
    pub fn report(&self) -> ClockReport {
        ClockReport {
            periods: self.next,
            skipped_ticks: self.skipped,
            overruns: self.overruns,
            jitter_us: Percentiles::of(&self.late_us),
            work_us: Percentiles::of(&self.work_us),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_by_nearest_rank() {
        let s: Vec<u32> = (1..=100).collect();
        assert_eq!(Percentiles::of(&s), Percentiles { p50: 50, p99: 99, max: 100 });
        assert_eq!(Percentiles::of(&[]), Percentiles::default());
        assert_eq!(Percentiles::of(&[7]), Percentiles { p50: 7, p99: 7, max: 7 });
    }

    #[test]
    fn real_time_ticks_are_on_time_and_a_long_period_skips() {
        // A 50 ms period: long beside the few ms a loaded machine may take
        // to wake a sleeping thread (a 5 ms period failed under load: the
        // scheduler alone overran it).
        let mut c = PeriodClock::new(50_000, true);
        for _ in 0..5 {
            c.tick();
            assert!(!c.done());
        }
        c.tick();
        std::thread::sleep(Duration::from_millis(120));
        assert!(c.done(), "120 ms of work in a 50 ms period");
        let (k, _) = c.tick();
        assert!(k >= 7, "ticks missed are skipped: {k}");
        let r = c.report();
        assert_eq!(r.overruns, 1);
        assert!(r.skipped_ticks >= 1);
        assert!(r.jitter_us.p50 < 10_000, "{:?}", r.jitter_us);
    }

    #[test]
    fn lock_step_never_waits() {
        let mut c = PeriodClock::new(1_000_000, false);
        let t = Instant::now();
        for k in 0..3 {
            assert_eq!(c.tick(), (k, k * 1_000_000));
            c.done();
        }
        assert!(t.elapsed() < Duration::from_millis(100));
    }
}
