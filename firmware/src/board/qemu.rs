//! QEMU's `netduinoplus2` machine (an STM32F405RG) under the emulated
//! board's lock-step layer ([`super::lockstep`]): the emulation of the
//! `f405` board profile for `pada sil` (cargo feature `qemu`).
//!
//! All it adds is its instruction counter: TIM2, free running at QEMU's
//! 1 GHz timer clock, which under `-icount shift=0` (one nanosecond of
//! virtual time per instruction) counts one per instruction. QEMU models
//! neither RCC nor PWR (`embassy_stm32::init` would never return), so TIM2
//! is driven through the PAC, without clock set-up. The F405 on
//! netduinoplus2 also has the real chip's CCM, where the table lives
//! (QEMU 10; 7.2 faults on it).

use stm32_metapac::TIM2;

/// The machine's name (QEMU's `-machine`).
pub const MACHINE: &str = "netduinoplus2";

/// The clock the cycle counts are converted with: the F405's 168 MHz, one
/// instruction taken as one cycle.
pub const CPU_HZ: u32 = 168_000_000;

/// Instructions per count of [`counter`].
pub const INSTRUCTIONS_PER_COUNT: u32 = 1;

/// Starts TIM2 free running from 0, no prescaler, full 32-bit range.
pub fn start_counter() {
    TIM2.psc().write_value(0);
    TIM2.arr().write_value(u32::MAX);
    TIM2.egr().write(|w| w.set_ug(true));
    TIM2.cr1().write(|w| w.set_cen(true));
}

/// The instruction counter (wraps).
pub fn counter() -> u32 {
    TIM2.cnt().read()
}
