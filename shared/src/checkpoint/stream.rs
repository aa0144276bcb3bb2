//! A checkpoint streamed as chunks, for a board whose weight table fits no
//! flash (LEO's 8 MiB claim table on the F429): the board sends its
//! checkpoint to the host over the telemetry link, and the host keeps the
//! last complete one and sends it back at boot.
//!
//! # The image
//!
//! The streamed **image is exactly a format-4 flash slot** ([`super`]): the
//! 32-byte header, the learner-state record, the entries and their padding,
//! the same bytes [`super::save`] writes into a slot. So a kept image is
//! read by the existing checkpoint code, and there is one format, not two.
//!
//! # Windows
//!
//! The image is cut into fixed windows: window 0 is the header
//! (`[0, 32)`), and the body is cut into [`WINDOW`]-byte windows from byte
//! 32 on (the last may be shorter). The header has a window of its own so
//! that it can be sent last (a save: the header commits the checkpoint, as
//! in flash) or first (a restore: the receiver checks configuration, size
//! and generation before it writes any table entry), while the body always
//! arrives in ascending order and its CRC is computed on the fly.
//!
//! # Chunks
//!
//! A [`Chunk`] is one window, or a run of all-zero body windows. It carries
//! the checkpoint's generation, the image's length, its offset and a CRC-32
//! of all that and its bytes; a window's zero 4-byte words are left out
//! (a bitmask says which are sent). A fresh claim table is mostly zeros, so
//! an empty 8 MiB table streams in a handful of chunks.
//!
//! # Modules
//!
//! [`chunk`] (the chunk and its byte encoding), [`source`] (the image's
//! bytes at any offset without materialising it), [`chunker`] (the
//! sender), [`assembler`] (the receiver and its refusals).

pub mod assembler;
pub mod chunk;
pub mod chunker;
pub mod source;

pub use assembler::{AssembleError, Assembler, Expect, ImageSink, OutsideSlice, Progress};
pub use chunk::{Body, Chunk, ChunkError, MAX_ENCODED_LEN};
pub use chunker::{Chunker, ChunkerError, Order};
pub use source::{ImageError, ImageSource, TableImage};

use super::slots::HEADER_LEN;

/// Bytes of a body window: 32 words, so a window's word mask is a `u32`.
/// Small enough that an encoded chunk ([`MAX_ENCODED_LEN`]) fits one
/// telemetry frame.
pub const WINDOW: usize = 128;

/// Whether `image_len` can be a streamed image's length: a header at least,
/// a whole number of 4-byte words (as every flash slot), and a `u32`.
pub const fn valid_image_len(image_len: u64) -> bool {
    image_len >= HEADER_LEN as u64 && image_len % 4 == 0 && image_len <= u32::MAX as u64
}

/// Whether `offset` starts a window of an image of `image_len` bytes: 0
/// (the header) or `32 + k·WINDOW` inside the image.
pub const fn is_window_start(offset: u64, image_len: u64) -> bool {
    offset == 0
        || (offset >= HEADER_LEN as u64 && offset < image_len && (offset - HEADER_LEN as u64) % WINDOW as u64 == 0)
}

/// Bytes of the window at `offset` (a window start) of an image of
/// `image_len` bytes: 32 for the header, else up to [`WINDOW`].
pub const fn window_len(offset: u64, image_len: u64) -> usize {
    if offset == 0 {
        HEADER_LEN
    } else if offset >= image_len {
        0
    } else {
        let rest = image_len - offset;
        if rest < WINDOW as u64 {
            rest as usize
        } else {
            WINDOW
        }
    }
}

#[cfg(test)]
mod tests;
