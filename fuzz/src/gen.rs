//! Inputs: the recorded corpus, random values of the message types, and
//! the byte mutations applied to valid inputs.

use rand_core::RngCore;
use serde::de::DeserializeOwned;

/// A uniform number in `0..n` (`n ≥ 1`).
pub fn below(rng: &mut impl RngCore, n: usize) -> usize {
    (rng.next_u64() % n.max(1) as u64) as usize
}

/// Random bytes, `len` of them, a quarter of them biased towards the values
/// the formats treat specially (0x00 delimiters, 0xFF headers, small
/// lengths and varint continuation bits).
pub fn bytes(rng: &mut impl RngCore, len: usize) -> Vec<u8> {
    (0..len)
        .map(|_| {
            let r = rng.next_u32();
            if r % 4 == 0 {
                [0x00, 0xFF, 0x01, 0x02, 0x80, 0x7F, 0xFE, 0xFD][(r >> 8) as usize % 8]
            } else {
                (r >> 16) as u8
            }
        })
        .collect()
}

/// A random value of `M`: postcard's decoder run on random bytes is a
/// generator of valid values of any type it can decode. `None` if no
/// attempt decoded.
pub fn value<M: DeserializeOwned>(rng: &mut impl RngCore, variants: u8) -> Option<M> {
    for _ in 0..64 {
        let len = 1 + below(rng, 120);
        let mut b = bytes(rng, len);
        // A variant index in range, so most attempts get past the first byte.
        b[0] = below(rng, variants as usize) as u8;
        if let Ok((v, _)) = postcard::take_from_bytes::<M>(&b) {
            return Some(v);
        }
    }
    None
}

/// Damages `input` in place with 1–4 random mutations: flip a bit, set a
/// byte, insert or delete bytes, splice in a piece of `other`, truncate,
/// duplicate a piece.
pub fn mutate(rng: &mut impl RngCore, input: &mut Vec<u8>, other: &[u8]) {
    for _ in 0..1 + below(rng, 4) {
        if input.is_empty() {
            input.push(rng.next_u32() as u8);
            continue;
        }
        let at = below(rng, input.len());
        match below(rng, 7) {
            0 => input[at] ^= 1 << below(rng, 8),
            1 => input[at] = bytes(rng, 1)[0],
            2 => {
                let n = 1 + below(rng, 8);
                let b = bytes(rng, n);
                input.splice(at..at, b);
            }
            3 => {
                let n = (1 + below(rng, 8)).min(input.len() - at);
                input.drain(at..at + n);
            }
            4 if !other.is_empty() => {
                let from = below(rng, other.len());
                let n = (1 + below(rng, 64)).min(other.len() - from);
                input.splice(at..at, other[from..from + n].iter().copied());
            }
            5 => input.truncate(at),
            _ => {
                let n = (1 + below(rng, 32)).min(input.len() - at);
                let piece: Vec<u8> = input[at..at + n].to_vec();
                input.splice(at..at, piece);
            }
        }
    }
}

/// The frames of the recorded SIL stream (`tests/data/sil-pendulum-3s.bin`),
/// each with its delimiter: real telemetry as a corpus.
pub struct Corpus {
    /// One frame per entry.
    pub frames: Vec<Vec<u8>>,
}

impl Corpus {
    /// Reads the recording; an empty corpus if it is missing.
    pub fn load() -> Corpus {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/sil-pendulum-3s.bin");
        let stream = std::fs::read(path).unwrap_or_default();
        let frames = stream
            .split_inclusive(|&b| b == 0)
            .map(<[u8]>::to_vec)
            .collect();
        Corpus { frames }
    }
}
