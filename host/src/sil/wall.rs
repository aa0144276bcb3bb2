//! Where a SIL run's wall-clock time goes: waiting for the emulated board
//! (QEMU running the firmware and moving its bytes), the plant (the bus
//! emulator and the robot behind it), the telemetry (decoding, recording,
//! the operator's reactions), and the rest of the host's loop.
//!
//! The shares depend on the machine's load; the exchange and instruction
//! counts of the summary do not.

use serde::Serialize;
use std::time::{Duration, Instant};

/// Accumulated wall-clock time by where it went.
#[derive(Debug, Clone, Copy, Default)]
pub struct WallClock {
    board: Duration,
    plant: Duration,
    telemetry: Duration,
}

/// What [`WallClock`] measured, in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct WallTime {
    /// Waiting for the board: QEMU executing the firmware, and the clock
    /// channel between the two \[s\].
    pub board_s: f64,
    /// The bus emulator and the robot's simulation \[s\].
    pub plant_s: f64,
    /// Decoding and recording telemetry, and reacting to it \[s\].
    pub telemetry_s: f64,
    /// Everything else of the host's loop (scheduling, encoding clock
    /// frames, the summary's replay is not included) \[s\].
    pub host_other_s: f64,
}

/// Which account a measured stretch goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Account {
    /// Waiting for the board.
    Board,
    /// The plant.
    Plant,
    /// Telemetry.
    Telemetry,
}

impl WallClock {
    /// Runs `f`, adding its wall-clock time to `account`.
    pub fn time<R>(&mut self, account: Account, f: impl FnOnce() -> R) -> R {
        let t0 = Instant::now();
        let r = f();
        self.add(account, t0.elapsed());
        r
    }

    /// Adds `d` to `account`.
    pub fn add(&mut self, account: Account, d: Duration) {
        match account {
            Account::Board => self.board += d,
            Account::Plant => self.plant += d,
            Account::Telemetry => self.telemetry += d,
        }
    }

    /// The totals, with the rest of `loop_s` (the loop's whole wall time)
    /// as the host's other work.
    pub fn report(&self, loop_s: f64) -> WallTime {
        let (b, p, t) = (self.board.as_secs_f64(), self.plant.as_secs_f64(), self.telemetry.as_secs_f64());
        WallTime { board_s: b, plant_s: p, telemetry_s: t, host_other_s: (loop_s - b - p - t).max(0.0) }
    }
}
