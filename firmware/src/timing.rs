//! The control loop's own time: cycles of each period's work, overruns,
//! the longest period, and the agent step's cycles.

/// Loop-time statistics, from DWT cycle counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoopTiming {
    cpu_hz: u32,
    period_us: u32,
    /// Periods measured.
    pub periods: u32,
    /// Periods whose work took longer than the period.
    pub overruns: u32,
    /// Overrunning periods in a row, now.
    pub streak: u32,
    /// Longest period's work \[µs\].
    pub max_us: u32,
    /// Last period's work \[µs\].
    pub last_us: u32,
    /// Agent step: last, smallest and largest cycle count, and the sum and
    /// number of samples for the mean.
    pub agent_last: u32,
    /// Smallest agent step.
    pub agent_min: u32,
    /// Largest agent step.
    pub agent_max: u32,
    agent_sum: u64,
    agent_n: u32,
}

impl LoopTiming {
    /// Statistics for a CPU clock of `cpu_hz` and a period of `period_us`.
    pub fn new(cpu_hz: u32, period_us: u32) -> Self {
        LoopTiming {
            cpu_hz,
            period_us,
            periods: 0,
            overruns: 0,
            streak: 0,
            max_us: 0,
            last_us: 0,
            agent_last: 0,
            agent_min: u32::MAX,
            agent_max: 0,
            agent_sum: 0,
            agent_n: 0,
        }
    }

    /// Microseconds of `cycles`.
    pub fn us(&self, cycles: u32) -> u32 {
        (cycles as u64 * 1_000_000 / self.cpu_hz.max(1) as u64) as u32
    }

    /// Records one period whose work took `cycles` (wrapping difference of
    /// two DWT readings); returns whether it overran.
    pub fn period(&mut self, cycles: u32) -> bool {
        let us = self.us(cycles);
        self.periods = self.periods.wrapping_add(1);
        self.last_us = us;
        self.max_us = self.max_us.max(us);
        let overrun = us > self.period_us;
        if overrun {
            self.overruns = self.overruns.wrapping_add(1);
            self.streak = self.streak.saturating_add(1);
        } else {
            self.streak = 0;
        }
        overrun
    }

    /// Records one agent step of `cycles`.
    pub fn agent_step(&mut self, cycles: u32) {
        self.agent_last = cycles;
        self.agent_min = self.agent_min.min(cycles);
        self.agent_max = self.agent_max.max(cycles);
        self.agent_sum += cycles as u64;
        self.agent_n = self.agent_n.wrapping_add(1);
    }

    /// Mean agent step in cycles (0 before the first).
    pub fn agent_mean(&self) -> u32 {
        if self.agent_n == 0 {
            0
        } else {
            (self.agent_sum / self.agent_n as u64) as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overruns_and_streaks() {
        let mut t = LoopTiming::new(168_000_000, 33_333);
        assert!(!t.period(168_000)); // 1 ms
        assert_eq!(t.last_us, 1000);
        assert!(t.period(168 * 40_000)); // 40 ms
        assert!(t.period(168 * 34_000));
        assert_eq!((t.overruns, t.streak, t.max_us), (2, 2, 40_000));
        assert!(!t.period(168));
        assert_eq!(t.streak, 0);
    }

    #[test]
    fn agent_cycles() {
        let mut t = LoopTiming::new(168_000_000, 30_000);
        assert_eq!(t.agent_mean(), 0);
        t.agent_step(100);
        t.agent_step(300);
        assert_eq!((t.agent_min, t.agent_max, t.agent_mean(), t.agent_last), (100, 300, 200, 300));
    }
}
