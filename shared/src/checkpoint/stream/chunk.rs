//! One chunk of a streamed checkpoint: plain data, a CRC over where its
//! bytes go and what they are, and a compact byte encoding bounded by
//! [`MAX_ENCODED_LEN`] so that it can ride in one telemetry frame.
//!
//! # Encoding (little endian)
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 1 | kind: 0 a window's words, 1 a run of zero windows |
//! | 1 | 4 | generation |
//! | 5 | 4 | image length |
//! | 9 | 4 | offset (a window start) |
//! | 13 | 4 | CRC-32 ([`Chunk::expected_crc`]) |
//! | 17 | 4 | words: the mask of sent words (bit `i`: word `i` of the window); run: the number of windows |
//! | 21 | 4·k | words only: the `k` sent words, in window order |

use super::{is_window_start, valid_image_len, window_len, WINDOW};
use crate::crc::CRC32;

/// Bytes before a chunk's payload.
const FIXED_LEN: usize = 21;

/// The longest encoded chunk: the fixed fields and a whole window.
pub const MAX_ENCODED_LEN: usize = FIXED_LEN + WINDOW;

/// Kind byte of [`Body::Words`].
const KIND_WORDS: u8 = 0;
/// Kind byte of [`Body::Zeros`].
const KIND_ZEROS: u8 = 1;

/// What a chunk holds.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Body {
    /// One window: its nonzero 4-byte words, the others known to be zero.
    Words {
        /// Bit `i` set: word `i` (bytes `4i..4i+4` of the window) is sent.
        mask: u32,
        /// The sent words' bytes, in window order (4 per set bit).
        words: heapless::Vec<u8, WINDOW>,
    },
    /// `windows` consecutive body windows, every byte zero (a fresh claim
    /// table's empty stretches cost one chunk).
    Zeros {
        /// Number of windows (at least 1; the last may be the image's short
        /// last window).
        windows: u32,
    },
}

/// A piece of a streamed checkpoint image ([`super`]).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Chunk {
    /// The checkpoint's generation (the header's), so a receiver tells one
    /// stream from the next before the header arrives.
    pub generation: u32,
    /// Bytes of the whole image.
    pub image_len: u32,
    /// The image offset of the first byte covered (a window start).
    pub offset: u32,
    /// CRC-32 over the fields above, the kind, and the covered bytes (a
    /// window) or the run's length (zeros): [`Chunk::expected_crc`].
    pub crc: u32,
    /// The bytes.
    pub body: Body,
}

/// In the firmware's logs a chunk is where it goes, not its bytes.
#[cfg(feature = "defmt")]
impl defmt::Format for Chunk {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "Chunk {{ generation: {=u32}, image_len: {=u32}, offset: {=u32}, covered: {=u64} }}",
            self.generation,
            self.image_len,
            self.offset,
            self.covered_len()
        )
    }
}

/// Why a chunk's bytes or fields do not form a chunk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChunkError {
    /// Fewer bytes than the fields need.
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// A kind byte other than 0 (words) or 1 (zeros).
    UnknownKind {
        /// The byte found.
        found: u8,
    },
    /// An image length that is no image's: under 32 bytes or not a
    /// multiple of 4.
    BadImageLength {
        /// The length found.
        image_len: u32,
    },
    /// An offset that is not a window start inside the image.
    NotAWindow {
        /// The offset found.
        offset: u32,
        /// The image's length.
        image_len: u32,
    },
    /// Mask bits beyond the window's words.
    MaskBeyondWindow {
        /// The mask found.
        mask: u32,
        /// Words in the window.
        words: u32,
    },
    /// Payload bytes that are not 4 per mask bit.
    PayloadLength {
        /// Bytes the mask calls for.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// A zero run that is empty, covers the header, or ends past the image.
    BadRun {
        /// Its offset.
        offset: u32,
        /// Its windows.
        windows: u32,
    },
    /// The output buffer is too small for the encoding.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
}

impl core::fmt::Display for ChunkError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ChunkError::Truncated { needed, got } => write!(f, "chunk truncated: {got} bytes, needs {needed}"),
            ChunkError::UnknownKind { found } => write!(f, "chunk kind {found} unknown: valid are 0 (words) and 1 (zeros)"),
            ChunkError::BadImageLength { image_len } => {
                write!(f, "chunk's image length {image_len} invalid: valid is a multiple of 4, at least 32")
            }
            ChunkError::NotAWindow { offset, image_len } => write!(
                f,
                "chunk offset {offset} is no window start: valid are 0 and 32 + k*{WINDOW} below the image length {image_len}"
            ),
            ChunkError::MaskBeyondWindow { mask, words } => {
                write!(f, "chunk word mask {mask:#010x} beyond its window: valid are bits 0..{words}")
            }
            ChunkError::PayloadLength { expected, found } => {
                write!(f, "chunk payload of {found} bytes: its mask calls for {expected}")
            }
            ChunkError::BadRun { offset, windows } => write!(
                f,
                "zero run of {windows} windows at offset {offset}: valid is at least 1 body window inside the image"
            ),
            ChunkError::BufferTooSmall { needed, got } => {
                write!(f, "chunk needs {needed} bytes to encode, buffer has {got}")
            }
        }
    }
}

/// Little-endian `u32` at `i` of `b` (which the caller checked is long
/// enough; 0 otherwise, never a panic).
fn u32_at(b: &[u8], i: usize) -> u32 {
    match b.get(i..i + 4) {
        Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]),
        _ => 0,
    }
}

impl Chunk {
    /// The chunk of the window at `offset` holding `window` (its bytes, of
    /// [`window_len`]); zero words are left out, the CRC is filled in.
    /// Bytes beyond [`WINDOW`] and a trailing partial word are ignored.
    pub fn words(generation: u32, image_len: u32, offset: u32, window: &[u8]) -> Chunk {
        let mut mask = 0u32;
        let mut words = heapless::Vec::new();
        for (i, w) in window.chunks_exact(4).take(WINDOW / 4).enumerate() {
            if w.iter().any(|&b| b != 0) {
                mask |= 1 << i;
                // Capacity is WINDOW bytes, 4 per word: never full here.
                let _ = words.extend_from_slice(w);
            }
        }
        let mut chunk = Chunk { generation, image_len, offset, crc: 0, body: Body::Words { mask, words } };
        chunk.crc = chunk.expected_crc();
        chunk
    }

    /// The chunk standing for `windows` all-zero body windows from
    /// `offset`, its CRC filled in.
    pub fn zeros(generation: u32, image_len: u32, offset: u32, windows: u32) -> Chunk {
        let mut chunk = Chunk { generation, image_len, offset, crc: 0, body: Body::Zeros { windows } };
        chunk.crc = chunk.expected_crc();
        chunk
    }

    /// Bytes of the image this chunk covers: its window's, or its run's
    /// (the last window may be short).
    pub fn covered_len(&self) -> u64 {
        let (offset, image_len) = (self.offset as u64, self.image_len as u64);
        match self.body {
            Body::Words { .. } => window_len(offset, image_len) as u64,
            Body::Zeros { windows } => (windows as u64 * WINDOW as u64).min(image_len.saturating_sub(offset)),
        }
    }

    /// The window's bytes into `out` (zero words filled in); returns the
    /// window's length. A zero run writes nothing and returns 0.
    pub fn expand(&self, out: &mut [u8; WINDOW]) -> usize {
        let Body::Words { mask, words } = &self.body else {
            return 0;
        };
        let len = window_len(self.offset as u64, self.image_len as u64);
        out.fill(0);
        let mut sent = words.chunks_exact(4);
        for (i, dst) in out[..len].chunks_exact_mut(4).enumerate() {
            if mask & (1 << i) != 0 {
                if let Some(w) = sent.next() {
                    dst.copy_from_slice(w);
                }
            }
        }
        len
    }

    /// The CRC-32 this chunk should carry: over generation, image length,
    /// offset (little endian), the kind byte, and then the window's
    /// expanded bytes or the run's window count. So a flipped bit in any
    /// field or payload byte, or a payload put at the wrong place, fails
    /// the check.
    pub fn expected_crc(&self) -> u32 {
        let mut d = CRC32.digest();
        d.update(&self.generation.to_le_bytes());
        d.update(&self.image_len.to_le_bytes());
        d.update(&self.offset.to_le_bytes());
        match self.body {
            Body::Words { .. } => {
                let mut w = [0u8; WINDOW];
                let n = self.expand(&mut w);
                d.update(&[KIND_WORDS]);
                d.update(&w[..n]);
            }
            Body::Zeros { windows } => {
                d.update(&[KIND_ZEROS]);
                d.update(&windows.to_le_bytes());
            }
        }
        d.finalize()
    }

    /// Whether the carried CRC matches the contents.
    pub fn is_intact(&self) -> bool {
        self.crc == self.expected_crc()
    }

    /// Checks the fields' shape (not the CRC): a valid image length, an
    /// offset at a window start, mask bits within the window and 4 payload
    /// bytes per bit, a zero run of body windows within the image.
    pub fn check(&self) -> Result<(), ChunkError> {
        let (offset, image_len) = (self.offset, self.image_len);
        if !valid_image_len(image_len as u64) {
            return Err(ChunkError::BadImageLength { image_len });
        }
        if !is_window_start(offset as u64, image_len as u64) {
            return Err(ChunkError::NotAWindow { offset, image_len });
        }
        match &self.body {
            Body::Words { mask, words } => {
                let n = (window_len(offset as u64, image_len as u64) / 4) as u32;
                let allowed = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
                if mask & !allowed != 0 {
                    return Err(ChunkError::MaskBeyondWindow { mask: *mask, words: n });
                }
                let expected = 4 * mask.count_ones() as usize;
                if words.len() != expected {
                    return Err(ChunkError::PayloadLength { expected, found: words.len() });
                }
            }
            Body::Zeros { windows } => {
                let start = offset as u64;
                // The run's last window must start inside the image.
                let last = start + (*windows as u64).saturating_sub(1) * WINDOW as u64;
                if *windows == 0 || start == 0 || last >= image_len as u64 {
                    return Err(ChunkError::BadRun { offset, windows: *windows });
                }
            }
        }
        Ok(())
    }

    /// Bytes of [`encode`](Self::encode)'s output.
    pub fn encoded_len(&self) -> usize {
        match &self.body {
            Body::Words { words, .. } => FIXED_LEN + words.len(),
            Body::Zeros { .. } => FIXED_LEN,
        }
    }

    /// Writes the encoding (module documentation) into `out`; returns its
    /// length. At most [`MAX_ENCODED_LEN`] bytes.
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, ChunkError> {
        let needed = self.encoded_len();
        let Some(out) = out.get_mut(..needed) else {
            return Err(ChunkError::BufferTooSmall { needed, got: out.len() });
        };
        let (kind, word, payload): (u8, u32, &[u8]) = match &self.body {
            Body::Words { mask, words } => (KIND_WORDS, *mask, words),
            Body::Zeros { windows } => (KIND_ZEROS, *windows, &[]),
        };
        out[0] = kind;
        out[1..5].copy_from_slice(&self.generation.to_le_bytes());
        out[5..9].copy_from_slice(&self.image_len.to_le_bytes());
        out[9..13].copy_from_slice(&self.offset.to_le_bytes());
        out[13..17].copy_from_slice(&self.crc.to_le_bytes());
        out[17..21].copy_from_slice(&word.to_le_bytes());
        out[FIXED_LEN..].copy_from_slice(payload);
        Ok(needed)
    }

    /// Reads a chunk written by [`encode`](Self::encode): exactly its
    /// bytes, its shape checked ([`check`](Self::check)); the CRC is left
    /// to the receiver ([`is_intact`](Self::is_intact)), which reports it
    /// with the chunk's place.
    pub fn decode(bytes: &[u8]) -> Result<Chunk, ChunkError> {
        if bytes.len() < FIXED_LEN {
            return Err(ChunkError::Truncated { needed: FIXED_LEN, got: bytes.len() });
        }
        let word = u32_at(bytes, 17);
        let payload = &bytes[FIXED_LEN..];
        let body = match bytes[0] {
            KIND_WORDS => {
                let expected = 4 * word.count_ones() as usize;
                if payload.len() != expected {
                    return Err(ChunkError::PayloadLength { expected, found: payload.len() });
                }
                let words = heapless::Vec::from_slice(payload)
                    .map_err(|_| ChunkError::PayloadLength { expected: WINDOW, found: payload.len() })?;
                Body::Words { mask: word, words }
            }
            KIND_ZEROS => {
                if !payload.is_empty() {
                    return Err(ChunkError::PayloadLength { expected: 0, found: payload.len() });
                }
                Body::Zeros { windows: word }
            }
            found => return Err(ChunkError::UnknownKind { found }),
        };
        let chunk = Chunk {
            generation: u32_at(bytes, 1),
            image_len: u32_at(bytes, 5),
            offset: u32_at(bytes, 9),
            crc: u32_at(bytes, 13),
            body,
        };
        chunk.check()?;
        Ok(chunk)
    }
}
