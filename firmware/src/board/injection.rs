//! Fault injection on the emulated boards (`pada sil --power-cut`,
//! `--fault hang`), armed by the host over the lock-step clock:
//!
//! - a power cut inside a checkpoint save ([`ToBoard::CutInSave`]): the
//!   checkpoint file takes the first `after_bytes` bytes the board writes
//!   to it (erases included) and nothing more; the board then tells the
//!   host ([`FromBoard::PowerCut`]) and waits to be killed, so the file is
//!   exactly as a cut at that byte leaves it;
//! - a hang ([`ToBoard::Hang`]): the control loop stops at its next
//!   period and spins without feeding the watchdog.
//!
//! The real boards have none of this (`hw.rs`: `injected_hang` does
//! nothing).
//!
//! [`ToBoard::CutInSave`]: pada_firmware::sil::ToBoard::CutInSave
//! [`ToBoard::Hang`]: pada_firmware::sil::ToBoard::Hang
//! [`FromBoard::PowerCut`]: pada_firmware::sil::FromBoard::PowerCut

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, Ordering};
use critical_section::Mutex;

/// Bytes the checkpoint file takes before the armed cut.
static CUT_AFTER: Mutex<Cell<Option<u32>>> = Mutex::new(Cell::new(None));
/// The host asked for a hang.
static HANG: AtomicBool = AtomicBool::new(false);

/// Arms a cut after `after_bytes` more bytes written to the checkpoint file.
pub fn arm_cut(after_bytes: u32) {
    critical_section::with(|cs| CUT_AFTER.borrow(cs).set(Some(after_bytes)));
}

/// How many of the next `len` bytes to write: `Ok(len)` when no cut comes
/// within them, `Err(n)` when the cut comes after `n` of them.
pub fn before_cut(len: usize) -> Result<usize, usize> {
    critical_section::with(|cs| {
        let cell = CUT_AFTER.borrow(cs);
        match cell.get() {
            None => Ok(len),
            Some(left) if (left as usize) < len => Err(left as usize),
            Some(left) => {
                cell.set(Some(left - len as u32));
                Ok(len)
            }
        }
    })
}

/// Asks the control loop to hang.
pub fn request_hang() {
    HANG.store(true, Ordering::SeqCst);
}

/// Called by the control loop every period: hangs if the host asked.
pub fn injected_hang() {
    if HANG.load(Ordering::SeqCst) {
        super::watchdog::hang(super::lockstep_now_us())
    }
}
