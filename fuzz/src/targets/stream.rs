//! A checkpoint streamed back to a board (`pada_core::checkpoint::stream`):
//! the chunks of a restore, damaged on the way (bits flipped, bytes cut,
//! chunks dropped, repeated or spliced), fed to the board's assembler. The
//! chunks are untrusted input to the chip, as telemetry is to the host.
//!
//! An input is bytes 0–7, the seed of the image, then the stream: each
//! chunk as one length byte and its encoding (`Chunk::encode`). So a
//! failing input in `target/fuzz-failures/` replays exactly.
//!
//! Invariants: nothing panics; a chunk that does not decode or is refused
//! leaves the assembler as it was (the next chunk it expects is the same);
//! an image is only ever completed whole and exact, the seed's; and on the
//! sender's side the image read near and past its end, from the table or
//! from its bytes in memory, is its bytes and then zeros.

use super::{ensure, Outcome, Target};
use crate::gen::{below, mutate};
use pada_core::checkpoint::stream::{Assembler, Chunk, Chunker, Expect, ImageSource, Order, Progress, TableImage};
use pada_core::checkpoint::{slot_len, LearnerState, STATE_LEN};
use pada_core::fixed::Q16;
use rand_core::{RngCore, SeedableRng};

/// Weights of the table: a few windows, with a run of zero windows.
const WEIGHTS: usize = 300;
const LEN: usize = slot_len(WEIGHTS, 4);
const HASH: u32 = 0x5EED;

pub struct Stream {
    name: &'static str,
}

impl Stream {
    pub fn new(name: &'static str) -> Self {
        Stream { name }
    }
}

/// What the image of seed `seed` is made of: a learner record, a table
/// whose middle is zero (a run of zero windows) and whose other weights
/// are random, some words zero, and a generation.
fn parts(seed: u64) -> ([u8; STATE_LEN], Vec<Q16>, u32) {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut state = LearnerState::default();
    state.user = core::array::from_fn(|_| rng.next_u32());
    state.agent.stats.steps = rng.next_u64();
    let record = state.to_bytes();
    let weights: Vec<Q16> = (0..WEIGHTS)
        .map(|i| if (64..200).contains(&i) || rng.next_u32() % 4 == 0 { Q16::ZERO } else { Q16(rng.next_u32() as i32) })
        .collect();
    let generation = 1 + rng.next_u32() % 1000;
    (record, weights, generation)
}

/// The image of seed `seed` ([`parts`]).
fn image(seed: u64) -> Vec<u8> {
    let (record, weights, generation) = parts(seed);
    let source = TableImage::new(HASH, generation, &record, &weights[..]).expect("a valid table");
    let mut bytes = vec![0u8; source.image_len()];
    source.read(0, &mut bytes);
    bytes
}

/// The sender's side: reads of the image of `seed` near and past its end,
/// from the table it is made of and from its bytes in memory (a kept
/// image), each into a buffer that held other bytes. Both must give the
/// image's bytes, then zeros past the end (`ImageSource`'s promise).
fn reads_past_the_end(seed: u64, expected: &[u8]) -> Outcome {
    let (record, weights, generation) = parts(seed);
    let table = TableImage::new(HASH, generation, &record, &weights[..]).expect("a valid table");
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed ^ 0x0E0F);
    for _ in 0..4 {
        let offset = LEN - 64 + rng.next_u32() as usize % 128;
        let n = 1 + rng.next_u32() as usize % 64;
        let want: Vec<u8> = (offset..offset + n).map(|i| expected.get(i).copied().unwrap_or(0)).collect();
        let mut from_table = vec![0xA5u8; n];
        table.read(offset, &mut from_table);
        let mut from_slice = vec![0x5Au8; n];
        expected.read(offset, &mut from_slice);
        ensure!(from_table == want, "the table image read {n} bytes at {offset} of {LEN} as {from_table:02x?}");
        ensure!(from_slice == want, "the image in memory read {n} bytes at {offset} of {LEN} as {from_slice:02x?}");
    }
    Outcome::Ok
}

/// The chunks of `image` in a restore, each as a length byte and its
/// encoding.
fn stream(image: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = [0u8; pada_core::checkpoint::stream::MAX_ENCODED_LEN];
    for chunk in Chunker::new(image, Order::HeaderFirst).expect("a valid image") {
        let n = chunk.encode(&mut buf).expect("a chunk fits its largest encoding");
        out.push(n as u8);
        out.extend_from_slice(&buf[..n]);
    }
    out
}

impl Target for Stream {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let seed = rng.next_u64();
        let mut input = seed.to_le_bytes().to_vec();
        let mut chunks = stream(&image(seed));
        match below(rng, 8) {
            // Whole: must complete.
            0 => {}
            // Another seed's chunks spliced in.
            1 => {
                let other = stream(&image(rng.next_u64()));
                mutate(rng, &mut chunks, &other);
            }
            _ => mutate(rng, &mut chunks, &[]),
        }
        input.extend_from_slice(&chunks);
        input
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let Some((seed, mut rest)) = input.split_first_chunk::<8>() else { return Outcome::Ok };
        let expected = image(u64::from_le_bytes(*seed));
        if let Outcome::Failed(why) = reads_past_the_end(u64::from_le_bytes(*seed), &expected) {
            return Outcome::Failed(why);
        }
        let mut board = vec![0u8; LEN];
        let expect = Expect { config_hash: Some(HASH), image_len: Some(LEN as u32), newer_than: None };
        let mut assembler = Assembler::new(&mut board[..], Order::HeaderFirst, expect);
        let mut complete = false;
        while let Some((&n, after)) = rest.split_first() {
            let n = (n as usize).min(after.len());
            let (bytes, after) = after.split_at(n);
            rest = after;
            let Ok(chunk) = Chunk::decode(bytes) else { continue };
            let before = assembler.expected_offset();
            match assembler.accept(&chunk) {
                Ok(Progress::Complete(_)) => {
                    complete = true;
                    break;
                }
                Ok(_) => {}
                Err(_) => ensure!(
                    assembler.expected_offset() == before,
                    "a refused chunk at offset {} moved the stream from {before}",
                    chunk.offset
                ),
            }
        }
        drop(assembler);
        ensure!(!complete || board == expected, "an image completed that is not the one streamed");
        Outcome::Ok
    }
}
