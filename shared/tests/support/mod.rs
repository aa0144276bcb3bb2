//! Helpers shared by the integration tests (each test file that needs them
//! says `mod support;`).

use pada_core::checkpoint::CheckpointStore;

/// A store that loses power after `budget` more bytes have been written:
/// the write in progress is cut at that byte and every later operation fails.
pub struct TornStore<S> {
    /// The medium underneath, as the power cut left it.
    pub inner: S,
    budget: usize,
    dead: bool,
}

impl<S> TornStore<S> {
    /// `inner`, which will lose power after `budget` written bytes.
    pub fn new(inner: S, budget: usize) -> Self {
        TornStore { inner, budget, dead: false }
    }
}

/// The only error of a [`TornStore`].
#[derive(Debug, PartialEq)]
pub struct PowerLost;

impl<S: CheckpointStore> CheckpointStore for TornStore<S> {
    type Error = PowerLost;
    fn capacity(&self) -> usize {
        self.inner.capacity()
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), PowerLost> {
        self.inner.read(slot, offset, buf).map_err(|_| PowerLost)
    }
    fn erase(&mut self, slot: u8) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        self.inner.erase(slot).map_err(|_| PowerLost)
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        let n = data.len().min(self.budget);
        self.inner.write(slot, offset, &data[..n]).map_err(|_| PowerLost)?;
        self.budget -= n;
        if n < data.len() || self.budget == 0 {
            self.dead = true;
            if n < data.len() {
                return Err(PowerLost);
            }
        }
        Ok(())
    }
}
