//! pada firmware: the pada-core learner on an STM32F4.
//!
//! For now it only boots and proves that pada-core links into the image;
//! the control loop, servos and telemetry come later.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
// Halts (spins) on panic; a later watchdog turns that into a reset.
use panic_halt as _;

#[entry]
fn main() -> ! {
    // Keep the call (and so pada-core) in the image; the optimiser may not
    // see through black_box.
    let marker = core::hint::black_box(pada_core::linked_marker());
    core::hint::black_box(marker);

    loop {
        // Busy-wait rather than `wfi`: on STM32 a sleeping core drops the
        // debug connection unless DBGMCU is configured, which would make
        // probe-rs attach flaky. The control loop replaces this.
        core::hint::spin_loop();
    }
}
