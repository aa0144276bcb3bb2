//! A checkpoint image in memory: the two slots a board keeps its
//! checkpoints in, of any size, and loading one image into a controller
//! as the firmware loads its checkpoint at boot (for a board trial that
//! starts from exported weights, [`super::trial::BoardStart::Checkpoint`]).

use anyhow::{anyhow, bail};
use pada_core::checkpoint::{CheckpointStore, LoadOutcome};
use pada_core::robot::RobotRules;
use pada_core::weights::WeightStore;
use pada_firmware::control::Controller;

/// Two checkpoint slots in memory, of any size (a board's table may be
/// megabytes), erased to `0xFF` as flash is.
pub struct VecStore {
    slots: [Vec<u8>; 2],
}

/// An access outside a [`VecStore`]'s slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutOfSlot;

impl VecStore {
    /// Two erased slots of `len` bytes.
    pub fn erased(len: usize) -> VecStore {
        VecStore { slots: [vec![0xFF; len], vec![0xFF; len]] }
    }

    /// Slot `slot`'s bytes (0 or 1), taken out (left empty).
    pub fn take_slot(&mut self, slot: u8) -> Vec<u8> {
        std::mem::take(&mut self.slots[slot as usize & 1])
    }

    /// Slot 0 holding `image`, slot 1 erased.
    pub fn holding(image: &[u8]) -> VecStore {
        VecStore { slots: [image.to_vec(), vec![0xFF; image.len()]] }
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, core::ops::Range<usize>), OutOfSlot> {
        let end = offset.checked_add(len).ok_or(OutOfSlot)?;
        let s = slot as usize;
        if s < 2 && end <= self.slots[s].len() {
            Ok((s, offset..end))
        } else {
            Err(OutOfSlot)
        }
    }
}

impl CheckpointStore for VecStore {
    type Error = OutOfSlot;
    fn capacity(&self) -> usize {
        self.slots[0].len()
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfSlot> {
        let (s, r) = self.range(slot, offset, buf.len())?;
        buf.copy_from_slice(&self.slots[s][r]);
        Ok(())
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfSlot> {
        self.slots.get_mut(slot as usize).ok_or(OutOfSlot)?.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfSlot> {
        let (s, r) = self.range(slot, offset, data.len())?;
        for (dst, src) in self.slots[s][r].iter_mut().zip(data) {
            *dst &= *src;
        }
        Ok(())
    }
}

/// Loads `image` into `ctl` as the firmware loads its checkpoint at boot;
/// anything but a loaded checkpoint is an error naming the outcome.
pub fn load_image<W: WeightStore, R: RobotRules>(ctl: &mut Controller<W, R>, image: &[u8]) -> anyhow::Result<()> {
    let store = VecStore::holding(image);
    match ctl.load_checkpoint(&store).map_err(|e| anyhow!("the checkpoint image: {e:?}"))? {
        LoadOutcome::Loaded { .. } => Ok(()),
        other => bail!(
            "the checkpoint image was not loaded: {other:?}{}",
            ctl.last_refusal().map(|e| format!(" ({e})")).unwrap_or_default()
        ),
    }
}

