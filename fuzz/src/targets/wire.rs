//! Frame decoders ([`pada_core::wire::FrameDecoder`]) for both directions.

use super::{ensure, Outcome, Target};
use crate::gen::{below, bytes, mutate, value};
use pada_core::wire::{encode_frame, FrameDecoder, FrameError, MAX_FRAME_LEN, MAX_SEQ_GAP};
use rand_core::RngCore;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::marker::PhantomData;

/// Streams of frames of messages `M` into a decoder of `N` bytes.
pub struct Frames<M, const N: usize> {
    name: &'static str,
    /// Variants of `M` (to aim the value generator).
    variants: u8,
    /// Recorded frames of `M` to start from.
    corpus: Vec<Vec<u8>>,
    _m: PhantomData<fn() -> M>,
}

impl<M, const N: usize> Frames<M, N> {
    pub fn new(name: &'static str, variants: u8, corpus: Vec<Vec<u8>>) -> Self {
        Frames {
            name,
            variants,
            corpus,
            _m: PhantomData,
        }
    }
}

impl<M: DeserializeOwned + Serialize, const N: usize> Frames<M, N> {
    /// 1–8 valid frames with consecutive sequence numbers (sometimes about
    /// to wrap, sometimes with a jump).
    fn valid_stream(&self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let mut seq = match below(rng, 4) {
            0 => u32::MAX - below(rng, 4) as u32,
            1 => rng.next_u32(),
            _ => below(rng, 1000) as u32,
        };
        let mut out = Vec::new();
        let mut buf = [0u8; MAX_FRAME_LEN];
        for _ in 0..1 + below(rng, 8) {
            if !self.corpus.is_empty() && below(rng, 2) == 0 {
                out.extend_from_slice(&self.corpus[below(rng, self.corpus.len())]);
                continue;
            }
            if let Some(msg) = value::<M>(rng, self.variants) {
                if let Ok(f) = encode_frame(&msg, seq, &mut buf) {
                    out.extend_from_slice(f);
                }
            }
            seq = match below(rng, 16) {
                0 => seq.wrapping_add(2 + below(rng, 5) as u32),
                1 => seq.wrapping_add(MAX_SEQ_GAP + below(rng, 3) as u32),
                2 => seq.wrapping_sub(1 + below(rng, 3) as u32),
                _ => seq.wrapping_add(1),
            };
        }
        out
    }
}

impl<M: DeserializeOwned + Serialize, const N: usize> Target for Frames<M, N> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        match below(rng, 8) {
            0 => {
                let n = below(rng, 700);
                bytes(rng, n)
            }
            1 => self.valid_stream(rng),
            _ => {
                let mut s = self.valid_stream(rng);
                let other = self.valid_stream(rng);
                mutate(rng, &mut s, &other);
                s
            }
        }
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let mut dec = FrameDecoder::<M, N>::new();
        let (mut oks, mut errs) = (0u32, [0u32; 6]);
        // The model of the sequence-number ledger.
        let (mut expected, mut gaps, mut missed, mut resyncs) = (None::<u32>, 0u32, 0u64, 0u32);
        let mut segments = 0usize;
        let mut start = 0usize;
        let mut buf = [0u8; MAX_FRAME_LEN];
        for (i, &b) in input.iter().enumerate() {
            let result = dec.push(b);
            if b != 0 {
                ensure!(result.is_none(), "a result at a non-delimiter byte {i}");
                continue;
            }
            let segment = &input[start..=i];
            start = i + 1;
            if segment.len() == 1 {
                ensure!(result.is_none(), "an empty frame gave a result at byte {i}");
                continue;
            }
            segments += 1;
            // Invariant 3: each delimited frame gives exactly one outcome.
            let Some(result) = result else {
                return Outcome::Failed(format!("frame ending at byte {i} gave no outcome"));
            };
            match result {
                Ok(d) => {
                    oks += 1;
                    // Invariant 2: an accepted frame re-encodes to its bytes.
                    let again = encode_frame(&d.msg, d.seq, &mut buf);
                    ensure!(
                        again.is_ok_and(|f| f == segment),
                        "accepted frame at byte {i} re-encodes differently"
                    );
                    let model_gap = match expected {
                        Some(e) if e != d.seq => {
                            gaps += 1;
                            let ahead = d.seq.wrapping_sub(e);
                            if ahead > MAX_SEQ_GAP {
                                resyncs += 1;
                            } else {
                                missed += ahead as u64;
                            }
                            true
                        }
                        _ => false,
                    };
                    ensure!(
                        d.gap.is_some() == model_gap,
                        "gap of frame seq {} not as modelled",
                        d.seq
                    );
                    expected = Some(d.seq.wrapping_add(1));
                }
                Err(e) => {
                    let k = match e {
                        FrameError::Oversize => 0,
                        FrameError::Cobs => 1,
                        FrameError::TooShort => 2,
                        FrameError::Crc { .. } => 3,
                        FrameError::Decode => 4,
                        FrameError::NonCanonical => 5,
                        FrameError::Truncated => {
                            return Outcome::Failed("Truncated before the end".into())
                        }
                    };
                    errs[k] += 1;
                }
            }
        }
        let s = dec.stats();
        ensure!(
            s.bytes == input.len() as u64,
            "bytes {} of {}",
            s.bytes,
            input.len()
        );
        ensure!(
            s.frames == oks,
            "frames {} counted, {oks} returned",
            s.frames
        );
        let counted = [
            s.oversize,
            s.cobs_errors,
            s.too_short,
            s.crc_errors,
            s.decode_errors,
            s.noncanonical,
        ];
        ensure!(
            counted == errs,
            "losses counted {counted:?}, returned {errs:?}"
        );
        ensure!(
            (s.frames + s.bad_frames()) as usize == segments,
            "{segments} frames, {} outcomes",
            s.frames + s.bad_frames()
        );
        ensure!(
            (s.seq_gaps, s.frames_missed, s.seq_resyncs) == (gaps, missed, resyncs),
            "ledger {:?}, model {:?}",
            (s.seq_gaps, s.frames_missed, s.seq_resyncs),
            (gaps, missed, resyncs)
        );
        // The end of the input: a frame in progress is lost, once.
        let cut = start < input.len();
        ensure!(
            dec.finish().is_some() == cut,
            "finish with {} bytes pending",
            input.len() - start
        );
        ensure!(
            dec.stats().truncated == cut as u32,
            "truncated counted {}",
            dec.stats().truncated
        );
        ensure!(dec.finish().is_none(), "a second finish counted again");
        Outcome::Ok
    }
}
