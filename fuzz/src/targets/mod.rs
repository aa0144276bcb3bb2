//! The fuzz targets, one per decoder, each with its generator and its
//! invariants.

mod checkpoint;
mod claim_table;
mod dynamixel;
mod dynamixel_v2;
mod stream;
mod tally;
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

/// Variants of [`ToHost`] (protocol 8: `Hello` … `Policy`, `CheckpointChunk`,
/// `RestoreWanted`, `Restored`), to aim the value generator.
const TO_HOST_VARIANTS: u8 = 16;
/// Variants of [`ToChip`] (protocol 8: `Ping` … `SetMtbfBudget`,
/// `RestoreChunk`, `RestoreNone`).
const TO_CHIP_VARIANTS: u8 = 14;

/// Every target: the host's and the chip's frame decoders, the status and
/// instruction packet decoders of Protocol 1.0, Feetech and 2.0, checkpoint loading
/// and torn saves, a checkpoint streamed back to a board and damaged on the
/// way, and the claim table's reads, claims and writes.
pub fn all(corpus: &Corpus) -> Vec<Box<dyn Target>> {
    vec![
        Box::new(
            wire::Frames::<ToHost, { pada_core::wire::MAX_FRAME_LEN }>::new(
                "wire-host",
                TO_HOST_VARIANTS,
                corpus.frames.clone(),
            ),
        ),
        // The chip's decoder holds a whole frame (a restore's chunks).
        Box::new(wire::Frames::<ToChip, { pada_core::wire::MAX_FRAME_LEN }>::new(
            "wire-chip",
            TO_CHIP_VARIANTS,
            Vec::new(),
        )),
        Box::new(dynamixel::Status::<32>::new("dynamixel-status")),
        Box::new(dynamixel::Instructions::<64>::new("dynamixel-instr", dynamixel::Dialect::Dynamixel)),
        // Feetech: Protocol 1.0's framing with its own instruction table;
        // its status side is Protocol 1.0's decoder at the SO-101's
        // buffer (a SYNC READ of six servos' present block).
        Box::new(dynamixel::Status::<64>::new("feetech-status")),
        Box::new(dynamixel::Instructions::<128>::new("feetech-instr", dynamixel::Dialect::Feetech)),
        // Protocol 2.0: the firmware's default buffer, and a small one so
        // that too-long packets are common.
        Box::new(dynamixel_v2::Status::<{ pada_core::dynamixel::v2::DEFAULT_PACKET_LEN }>::new("dxl2-status")),
        Box::new(dynamixel_v2::Instructions::<64>::new("dxl2-instr")),
        Box::new(checkpoint::Checkpoints::new("checkpoint")),
        Box::new(stream::Stream::new("checkpoint-stream")),
        Box::new(claim_table::Claims::new("claim-table")),
    ]
}
