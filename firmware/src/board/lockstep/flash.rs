//! Checkpoints in a file on the host, through semihosting: two slots of
//! one flash sector each, written up to an armed power cut (`injection.rs`).

use super::link::link;
use super::panic::exit_failure;
use super::semi;
use pada_core::checkpoint::{self, CheckpointStore};
use pada_firmware::sil::{self, FromBoard};

/// The checkpoint file in QEMU's working directory: slot A, then slot B,
/// each [`sil::CHECKPOINT_SLOT_LEN`] bytes (one flash sector, as on the
/// real boards). Persists across boots of the same run directory, as flash
/// persists across resets.
const CHECKPOINT_FILE: &[u8] = b"pada-checkpoint.bin\0";
const _: () = assert!(CHECKPOINT_FILE.len() == sil::CHECKPOINT_FILE.len() + 1);
/// Bytes of each slot.
const SLOT_LEN: usize = sil::CHECKPOINT_SLOT_LEN;

/// Errors of the checkpoint file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// Offset or length outside the slot, or a slot number other than 0/1.
    OutOfRange,
    /// The host refused to open, read or write the file.
    Host,
}

/// The two checkpoint slots in a host file.
pub struct FlashStore {
    handle: Option<usize>,
}

impl FlashStore {
    pub(super) fn open() -> FlashStore {
        let existing = semi::open(CHECKPOINT_FILE, semi::READ_WRITE)
            .filter(|&h| semi::len(h).is_some_and(|n| n >= 2 * SLOT_LEN));
        let handle = existing.or_else(|| {
            let h = semi::open(CHECKPOINT_FILE, semi::CREATE)?;
            let mut store = FlashStore { handle: Some(h) };
            (store.erase(0).is_ok() && store.erase(1).is_ok()).then_some(h)
        });
        if handle.is_none() {
            defmt::warn!("checkpoint file unavailable (semihosting); saves will fail");
        }
        FlashStore { handle }
    }

    fn at(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, usize), FlashError> {
        let h = self.handle.ok_or(FlashError::Host)?;
        if slot >= checkpoint::SLOTS || offset.checked_add(len).is_none_or(|end| end > SLOT_LEN) {
            return Err(FlashError::OutOfRange);
        }
        Ok((h, slot as usize * SLOT_LEN + offset))
    }
}

/// An erased kilobyte, written in one semihosting call.
static ERASED: [u8; 1024] = [0xFF; 1024];

impl CheckpointStore for FlashStore {
    type Error = FlashError;

    fn capacity(&self) -> usize {
        SLOT_LEN
    }

    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, offset, buf.len())?;
        (semi::seek(h, pos) && semi::read(h, buf)).then_some(()).ok_or(FlashError::Host)
    }

    fn erase(&mut self, slot: u8) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, 0, SLOT_LEN)?;
        let mut done = 0;
        while done < SLOT_LEN {
            let n = (SLOT_LEN - done).min(ERASED.len());
            if !flash_put(h, pos + done, &ERASED[..n]) {
                return Err(FlashError::Host);
            }
            done += n;
        }
        Ok(())
    }

    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, offset, data.len())?;
        flash_put(h, pos, data).then_some(()).ok_or(FlashError::Host)
    }
}

/// The armed power cut is here (`injection.rs`): report everything, say
/// so, and wait for the host to kill the emulator.
fn power_cut_now() -> ! {
    let from_host = link(|l| {
        l.report_output();
        let cut = FromBoard::PowerCut { now_us: l.now_us };
        l.queue(&cut);
        l.flush_writes();
        l.from_host
    });
    let mut buf = [0u8; 64];
    // The host ends QEMU on reading PowerCut; whatever comes meanwhile is
    // dropped, as the power is off.
    while semi::read_some(from_host, &mut buf) > 0 {}
    exit_failure()
}

/// Writes `data` at `pos` of the checkpoint file, up to an armed power cut.
fn flash_put(h: usize, pos: usize, data: &[u8]) -> bool {
    match crate::board::injection::before_cut(data.len()) {
        Ok(_) => semi::seek(h, pos) && semi::write(h, data),
        Err(n) => {
            if n > 0 {
                let _ = semi::seek(h, pos) && semi::write(h, &data[..n]);
            }
            power_cut_now()
        }
    }
}
