//! The watchdog of QEMU's `mps2-an386`: the CMSDK APB watchdog (ARM DDI
//! 0479, "APB watchdog") at 0x4000_8000, clocked like the machine's
//! timers at its 25 MHz SYSCLK (`hw/arm/mps2.c`), so under `-icount
//! shift=0` it counts emulated nanoseconds: the instructions the firmware
//! executes. It stands in for the real boards' IWDG (`hw.rs`), with the
//! same periods: 250 ms, 8 s while a checkpoint sector is erased or a
//! fresh learner is built.
//!
//! The CMSDK watchdog counts LOAD down to zero, raises its interrupt (NMI
//! on the MPS2) and reloads; if the interrupt is still pending at the
//! second zero, it resets the chip. So a period is two LOADs; a feed
//! (INTCLR) clears the interrupt and reloads the counter.
//!
//! On the lock-step clock a feed costs no time, and a hung loop — one that
//! spins without returning to the executor — executes instructions at one
//! emulated nanosecond each until the watchdog resets the chip, 250 ms of
//! emulated time after its last feed. (A loop that waited forever without
//! spinning would execute nothing, and QEMU's clock would not move: the
//! host's `--hang-timeout` catches that one.)
//!
//! The reset cause: the MPS2 has no reset-cause register that QEMU models,
//! so the board keeps a small record in `.uninit` RAM, which QEMU's system
//! reset leaves as it was and a fresh emulator (power on) starts zeroed: a
//! boot that finds the record armed was reset by the watchdog (nothing
//! else resets this machine). While the loop hangs it writes the
//! instruction counter into the record, so the next boot knows how long
//! after the last feed the reset came.

use super::machine;
use core::mem::MaybeUninit;
use pada_firmware::sil::ResetCause;

/// The watchdog's period \[ms\], as the real boards' IWDG (`hw.rs`).
pub const PERIOD_MS: u32 = 250;
/// Its period while flash is erased or a fresh learner is built \[ms\].
pub const LONG_PERIOD_MS: u32 = 8_000;

const BASE: usize = 0x4000_8000;
const LOAD: usize = BASE;
const CONTROL: usize = BASE + 0x08;
const INTCLR: usize = BASE + 0x0C;
const LOCK: usize = BASE + 0xC00;
/// WDOGLOCK's unlock key.
const UNLOCK: u32 = 0x1ACC_E551;
/// WDOGCONTROL: interrupt enable, reset enable.
const INTEN_RESEN: u32 = 0b11;
/// WDOGCLK \[Hz\].
const CLOCK_HZ: u32 = 25_000_000;

/// "The watchdog is armed" in [`Record::magic`].
const ARMED: u32 = 0x5744_4f47;

/// What survives a watchdog reset (not a power cut).
#[repr(C)]
struct Record {
    magic: u32,
    fed_at_us: u64,
    fed_count: u32,
    hung_at_us: u64,
    alive_count: u32,
}

#[link_section = ".uninit.pada_reset_record"]
static mut RECORD: MaybeUninit<Record> = MaybeUninit::uninit();

fn record() -> *mut Record {
    // A pointer to the static, not a reference; every access below is
    // volatile and single-threaded (thread mode, or the NMI while thread
    // mode spins).
    (&raw mut RECORD).cast::<Record>()
}

fn write(addr: usize, v: u32) {
    // SAFETY: the CMSDK watchdog's registers on this machine; nothing
    // else uses it.
    unsafe { core::ptr::write_volatile(addr as *mut u32, v) }
}

/// Why this boot happened; clears the record.
pub fn reset_cause() -> ResetCause {
    let r = record();
    // SAFETY: see `record`; the fields are plain integers, any bit pattern
    // is valid, and RAM is zero on a fresh emulator.
    unsafe {
        let cause = if core::ptr::read_volatile(&raw const (*r).magic) == ARMED {
            let fed = core::ptr::read_volatile(&raw const (*r).fed_count);
            let alive = core::ptr::read_volatile(&raw const (*r).alive_count);
            ResetCause::Watchdog {
                fed_at_us: core::ptr::read_volatile(&raw const (*r).fed_at_us),
                hung_at_us: core::ptr::read_volatile(&raw const (*r).hung_at_us),
                since_feed_ns: alive.wrapping_sub(fed) as u64 * machine::INSTRUCTIONS_PER_COUNT as u64,
            }
        } else {
            ResetCause::PowerOn
        };
        core::ptr::write_volatile(&raw mut (*r).magic, 0);
        cause
    }
}

/// The watchdog (not started until [`Watchdog::start`]).
pub struct Watchdog(());

impl Watchdog {
    pub(super) fn new() -> Watchdog {
        Watchdog(())
    }

    /// Starts it at [`PERIOD_MS`].
    pub fn start(&mut self) {
        self.set(PERIOD_MS);
        write(LOCK, UNLOCK);
        write(CONTROL, INTEN_RESEN);
        write(LOCK, 0);
        let r = record();
        // SAFETY: see `record`.
        unsafe { core::ptr::write_volatile(&raw mut (*r).magic, ARMED) };
        self.feed();
    }

    /// Reloads the counter.
    pub fn feed(&mut self) {
        write(LOCK, UNLOCK);
        write(INTCLR, 1);
        write(LOCK, 0);
        let r = record();
        // SAFETY: see `record`.
        unsafe {
            core::ptr::write_volatile(&raw mut (*r).fed_count, machine::counter());
            core::ptr::write_volatile(&raw mut (*r).fed_at_us, super::lockstep_now_us());
        }
    }

    /// Switches to [`LONG_PERIOD_MS`] (`true`) or back, and feeds.
    pub fn extend(&mut self, long: bool) {
        self.set(if long { LONG_PERIOD_MS } else { PERIOD_MS });
        self.feed();
    }

    fn set(&mut self, period_ms: u32) {
        // Two LOADs to the reset (interrupt, then reset).
        write(LOCK, UNLOCK);
        write(LOAD, CLOCK_HZ / 1000 * period_ms / 2);
        write(LOCK, 0);
    }
}

/// The injected hang: spins, writing the instruction counter into the
/// record, until the watchdog resets the chip.
pub fn hang(now_us: u64) -> ! {
    let r = record();
    // SAFETY: see `record`.
    unsafe { core::ptr::write_volatile(&raw mut (*r).hung_at_us, now_us) };
    spin()
}

fn spin() -> ! {
    let r = record();
    loop {
        // SAFETY: see `record`.
        unsafe { core::ptr::write_volatile(&raw mut (*r).alive_count, machine::counter()) };
        // Between readings, a register-only loop of 2 × 5000 instructions
        // (10 µs of emulated time): under -icount every peripheral access
        // ends a translation block, and a loop of nothing but readings
        // would emulate a hundred times slower.
        // SAFETY: a register-only countdown loop.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, {n}, #1",
                "bne 2b",
                n = inout(reg) 5000u32 => _,
                options(nomem, nostack),
            );
        }
    }
}

/// The watchdog's first zero (its interrupt is the NMI here) while the
/// loop hangs: keep counting until the reset.
#[cortex_m_rt::exception]
unsafe fn NonMaskableInt() {
    spin()
}
