//! QEMU's `mps2-an386` machine (ARM's MPS2+ board with the AN386 FPGA
//! image: a Cortex-M4 with an FPU) under the emulated board's lock-step
//! layer ([`super::lockstep`]): the emulation of the `f429-sdram` board
//! profile for `pada sil` (cargo feature `mps2`).
//!
//! The STM32F429I-DISC1 keeps LEO's 8 MiB weight table in its SDRAM; QEMU
//! emulates no STM32 with external memory, and this machine's memory map
//! (`info mtree` in QEMU 10) has room for it:
//!
//! | address | memory | here (`memory-mps2.x`) |
//! |---|---|---|
//! | 0x0000_0000 | 4 MB SSRAM1 (QEMU loads the ELF here) | program, 1 MiB as the F429's bank 1 |
//! | 0x2000_0000 | 4 MB SSRAM2/3 | RAM, 192 KiB as the F429's SRAM |
//! | 0x2100_0000 | 16 MB PSRAM | the DISC1's 8 MB SDRAM (`.sdram`) |
//!
//! It has no CCM; the `f429-sdram` profile keeps nothing there. Unlike the
//! F429's SDRAM, QEMU's PSRAM works from reset: nothing to start.
//!
//! Its instruction counter is CMSDK APB timer 0 (ARM DDI 0479, CMSDK
//! technical reference: CTRL at 0x00 with bit 0 enable, VALUE at 0x04
//! counting down, RELOAD at 0x08), clocked at the machine's 25 MHz
//! SYSCLK: under `-icount shift=0` one count per 40 instructions. A
//! count's 40 instructions are the resolution of the cycle counts on this
//! board (an agent step of LEO is about 10⁵ instructions).

/// The machine's name (QEMU's `-machine`).
pub const MACHINE: &str = "mps2-an386";

/// The clock the cycle counts are converted with: the F429's 180 MHz, one
/// instruction taken as one cycle.
pub const CPU_HZ: u32 = 180_000_000;

/// Instructions per count of [`counter`]: QEMU's mps2 timers run at its
/// 25 MHz SYSCLK (`hw/arm/mps2.c`), 40 ns per count, one instruction per
/// nanosecond under `-icount shift=0`.
pub const INSTRUCTIONS_PER_COUNT: u32 = 40;

/// CMSDK APB timer 0.
const TIMER0: usize = 0x4000_0000;
const CTRL: usize = TIMER0;
const VALUE: usize = TIMER0 + 0x04;
const RELOAD: usize = TIMER0 + 0x08;

/// Starts timer 0 counting down from 2³² − 1, reloading there.
pub fn start_counter() {
    // SAFETY: the CMSDK timer's registers on this machine; nothing else
    // uses timer 0.
    unsafe {
        core::ptr::write_volatile(RELOAD as *mut u32, u32::MAX);
        core::ptr::write_volatile(VALUE as *mut u32, u32::MAX);
        core::ptr::write_volatile(CTRL as *mut u32, 1);
    }
}

/// The instruction counter, counting up (wraps).
pub fn counter() -> u32 {
    // SAFETY: a read of the timer's current value.
    !unsafe { core::ptr::read_volatile(VALUE as *const u32) }
}
