//! The fuzz targets, one per decoder, each with its generator and its
//! invariants.

mod checkpoint;
mod claim_table;
mod dynamixel;
mod wire;

use crate::gen::Corpus;
use pada_core::wire::{ToChip, ToHost};

/// Whether an input kept every invariant.
pub enum Outcome {
    /// It did.
    Ok,
    /// It broke one: which, and how.
    Failed(String),
}

/// Returns `Outcome::Failed` with the message if the condition is false.
macro_rules! ensure {
    ($cond:expr, $($why:tt)*) => {
        if !$cond {
            return $crate::targets::Outcome::Failed(format!($($why)*));
        }
    };
}
pub(crate) use ensure;

/// One decoder under test.
pub trait Target {
    /// Its name in the report.
    fn name(&self) -> &'static str;
    /// The next input (random, or valid and then damaged).
    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8>;
    /// Runs the decoder on `input` and checks the invariants.
    fn check(&self, input: &[u8]) -> Outcome;
}

/// Every target: the host's and the chip's frame decoders, the status and
/// instruction packet decoders, checkpoint loading and torn saves, and the
/// claim table's reads, claims and writes.
pub fn all(corpus: &Corpus) -> Vec<Box<dyn Target>> {
    vec![
        Box::new(
            wire::Frames::<ToHost, { pada_core::wire::MAX_FRAME_LEN }>::new(
                "wire-host",
                12,
                corpus.frames.clone(),
            ),
        ),
        Box::new(wire::Frames::<ToChip, 64>::new("wire-chip", 11, Vec::new())),
        Box::new(dynamixel::Status::<32>::new("dynamixel-status")),
        Box::new(dynamixel::Instructions::<64>::new("dynamixel-instr")),
        Box::new(checkpoint::Checkpoints::new("checkpoint")),
        Box::new(claim_table::Claims::new("claim-table")),
    ]
}
