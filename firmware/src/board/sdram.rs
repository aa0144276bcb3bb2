//! The F429I-DISC1's SDRAM: an IS42S16400J (1 M × 16 bits × 4 banks =
//! 8 MB) on the FMC's SDRAM bank 2, started and checked before the weight
//! table is touched.
//!
//! The power-up sequence and the controller's set-up are the `stm32-fmc`
//! crate's (`Sdram::init`: clock enable, 100 µs, precharge all, eight auto
//! refreshes, the mode register, the refresh counter), with its
//! `is42s16400j_7` timings (speed grade -7: CAS latency 2, tRCD = tRP =
//! 2 cycles, tRC 7, tRAS 4, tXSR 7, a 64 ms / 4096 rows refresh; burst
//! length 1, read burst on, no read pipe delay) and embassy-stm32's FMC as
//! the peripheral. The FMC runs on HCLK (180 MHz) and clocks the SDRAM at
//! HCLK / 2 = 90 MHz, under the chip's 100 MHz at CAS latency 2.
//!
//! Then a short check of the wiring, before any weight is written: the
//! data lines and both byte lanes on the first word, and every address
//! line (the column, row and bank bits of a 23-bit byte address) by the
//! powers of two — a stuck or shorted line makes two addresses alias. It
//! takes about 500 accesses, so it runs at every boot; what it does not
//! test (every cell) the table's per-weight checksum would show later.

use super::MemoryFault;
use embassy_stm32::fmc::Fmc;
use embassy_stm32::peripherals::FMC;
use stm32_fmc::devices::is42s16400j_7::Is42s16400j;

/// The SDRAM as embassy-stm32 constructs it (pins set, not started).
pub type DiscSdram = stm32_fmc::Sdram<Fmc<'static, FMC>, Is42s16400j>;

// `Sdram::init` asserts that the FMC clock divides to at most the chip's
// 100 MHz in 2 or 3 and that the refresh count fits its 13-bit register
// (it would panic otherwise). Both follow from the fixed clocks, so they
// are checked here at compile time and the assertions cannot fire.
/// The FMC's clock, HCLK: the F429's 180 MHz with AHB prescaler 1
/// (`f429.rs` checks that it is its `CPU_HZ`).
pub const FMC_HZ: u32 = 180_000_000;
const SD_DIVIDE: u32 = {
    let d = FMC_HZ.div_ceil(100_000_000);
    if d < 2 {
        2
    } else {
        d
    }
};
const _: () = assert!(SD_DIVIDE <= 3, "the FMC cannot clock the SDRAM below 100 MHz");
const REFRESH_COUNT: u64 = 15_625 * (FMC_HZ / SD_DIVIDE) as u64 / 1_000_000_000 - 20;
const _: () = assert!(REFRESH_COUNT >= 41 && REFRESH_COUNT < (1 << 13), "refresh count out of range");

unsafe extern "C" {
    /// `ORIGIN(SDRAM)` of `memory-f429.x`: where the table is linked.
    static __sdram_start: u32;
    /// `LENGTH(SDRAM)`: only the symbol's address is used.
    static __sdram_size: u8;
}

/// Runs the SDRAM's power-up sequence and checks the wiring.
pub fn start(mut sdram: DiscSdram) -> Result<(), MemoryFault> {
    // The returned pointer is bank 2's base, 0xD000_0000, which is also
    // ORIGIN(SDRAM) in memory-f429.x; the check runs over the linker's
    // region, where the table is.
    let _ = sdram.init(&mut embassy_time::Delay);
    let base = core::ptr::addr_of!(__sdram_start) as *mut u32;
    let bytes = core::ptr::addr_of!(__sdram_size) as usize;
    // SAFETY: the SDRAM is started; nothing else uses it before
    // `crate::table::take`, which needs this check to have passed; every
    // access below is aligned and inside the 8 MiB region.
    unsafe {
        check_data_lines(base)?;
        check_address_lines(base, bytes / 4)
    }
}

/// Reads a word back and compares.
///
/// # Safety
/// `at` is a valid, aligned address of the started SDRAM.
unsafe fn expect(at: *mut u32, want: u32) -> Result<(), MemoryFault> {
    // SAFETY: the caller's.
    let read = unsafe { at.read_volatile() };
    if read == want {
        Ok(())
    } else {
        Err(MemoryFault { address: at as u32, wrote: want, read })
    }
}

/// Walking ones over the 32 bits of the first word (both 16-bit beats of
/// the bus), then a byte and a half-word write (the byte masks NBL0/NBL1).
///
/// # Safety
/// `base` is the started SDRAM's first word.
unsafe fn check_data_lines(base: *mut u32) -> Result<(), MemoryFault> {
    // SAFETY: the caller's; byte and half-word offsets stay in the word.
    unsafe {
        for bit in 0..32 {
            base.write_volatile(1 << bit);
            expect(base, 1 << bit)?;
        }
        base.write_volatile(0);
        base.cast::<u8>().add(1).write_volatile(0xA5);
        expect(base, 0x0000_A500)?;
        base.cast::<u16>().add(1).write_volatile(0x5AC3);
        expect(base, 0x5AC3_A500)
    }
}

/// Every address line: the word at each power-of-two offset must keep its
/// own value while the word at offset 0 and every other power of two
/// change.
///
/// # Safety
/// `base` is the started SDRAM's first word and `words` its size.
unsafe fn check_address_lines(base: *mut u32, words: usize) -> Result<(), MemoryFault> {
    const PATTERN: u32 = 0xAAAA_AAAA;
    const ANTI: u32 = !PATTERN;
    let offsets = || (0..usize::BITS).map(|k| 1usize << k).take_while(move |&o| o < words);
    // SAFETY: the caller's; every offset is below `words`.
    unsafe {
        for o in offsets() {
            base.add(o).write_volatile(PATTERN);
        }
        // A line stuck high: the write at 0 lands on a power of two.
        base.write_volatile(ANTI);
        for o in offsets() {
            expect(base.add(o), PATTERN)?;
        }
        base.write_volatile(PATTERN);
        // A line stuck low or two lines shorted: the write at one power
        // of two lands on 0 or on another.
        for t in offsets() {
            base.add(t).write_volatile(ANTI);
            expect(base, PATTERN)?;
            for o in offsets().filter(|&o| o != t) {
                expect(base.add(o), PATTERN)?;
            }
            base.add(t).write_volatile(PATTERN);
        }
    }
    Ok(())
}
