//! Where checkpoints live: the medium's interface and a RAM medium for
//! tests and host-side runs.

/// Where checkpoints live: two slots of equal size, read and written at byte
/// offsets. On the chip, two flash sectors; in tests, RAM ([`RamStore`]).
pub trait CheckpointStore {
    /// What the medium reports when an operation fails.
    type Error;
    /// Bytes in each slot.
    fn capacity(&self) -> usize;
    /// Reads `buf.len()` bytes of `slot` from `offset`.
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), Self::Error>;
    /// Erases `slot` (to `0xFF`, as flash).
    fn erase(&mut self, slot: u8) -> Result<(), Self::Error>;
    /// Writes `data` into `slot` at `offset` (only erased bytes are written).
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), Self::Error>;
}

/// A [`CheckpointStore`] in RAM: two slots of `SLOT` bytes, erased to
/// `0xFF`. For tests and host-side runs.
#[derive(Debug, Clone)]
pub struct RamStore<const SLOT: usize> {
    slots: [[u8; SLOT]; 2],
}

/// An access outside a [`RamStore`]'s slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutOfRange;

impl<const SLOT: usize> Default for RamStore<SLOT> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SLOT: usize> RamStore<SLOT> {
    /// Two erased slots.
    pub const fn new() -> Self {
        RamStore { slots: [[0xFF; SLOT]; 2] }
    }

    /// The raw bytes of a slot (for tests that corrupt them).
    pub fn slot_mut(&mut self, slot: u8) -> Option<&mut [u8; SLOT]> {
        self.slots.get_mut(slot as usize)
    }

    /// The raw bytes of a slot.
    pub fn slot(&self, slot: u8) -> Option<&[u8; SLOT]> {
        self.slots.get(slot as usize)
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, core::ops::Range<usize>), OutOfRange> {
        let end = offset.checked_add(len).ok_or(OutOfRange)?;
        if (slot as usize) < self.slots.len() && end <= SLOT {
            Ok((slot as usize, offset..end))
        } else {
            Err(OutOfRange)
        }
    }
}

impl<const SLOT: usize> CheckpointStore for RamStore<SLOT> {
    type Error = OutOfRange;
    fn capacity(&self) -> usize {
        SLOT
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, buf.len())?;
        buf.copy_from_slice(&self.slots[s][r]);
        Ok(())
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfRange> {
        let s = self.slots.get_mut(slot as usize).ok_or(OutOfRange)?;
        s.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, data.len())?;
        // As flash: programming can only clear bits of erased bytes.
        for (dst, src) in self.slots[s][r].iter_mut().zip(data) {
            *dst &= *src;
        }
        Ok(())
    }
}
