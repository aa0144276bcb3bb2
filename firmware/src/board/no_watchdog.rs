//! QEMU's `netduinoplus2` models no watchdog (no IWDG, no WWDG: `info
//! qtree` shows none), so the `f405` emulation runs without one; a hung
//! board there is noticed only by the host (`--hang-timeout`). The
//! watchdog is tested on `mps2-an386` ([`super::cmsdk_watchdog`]); the real
//! F405 has its IWDG (`hw.rs`).

use pada_firmware::sil::ResetCause;

/// No watchdog: period 0.
pub const PERIOD_MS: u32 = 0;

/// Always power on: nothing else resets this machine.
pub fn reset_cause() -> ResetCause {
    ResetCause::PowerOn
}

/// No watchdog.
pub struct Watchdog(());

impl Watchdog {
    pub(super) fn new() -> Watchdog {
        Watchdog(())
    }
    /// Nothing to start.
    pub fn start(&mut self) {}
    /// Nothing to feed.
    pub fn feed(&mut self) {}
    /// Nothing to extend.
    pub fn extend(&mut self, _long: bool) {}
}

/// The injected hang: spins forever (`pada sil` refuses `--fault hang` on
/// this machine).
pub fn hang(_now_us: u64) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
