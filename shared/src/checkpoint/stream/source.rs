//! The image's bytes at any offset, without materialising it: on the chip
//! the image is a header, a state record in SRAM and a table of 8 MiB in
//! SDRAM, and there is no second 8 MiB to assemble it in.

use crate::checkpoint::record::STATE_LEN;
use crate::checkpoint::slots::{valid_entry_bytes, Header, FORMAT_VERSION, HEADER_LEN};
use crate::crc::CRC32;
use crate::weights::WeightStore;

use super::WINDOW;

/// A checkpoint image ([`super`]) read at byte offsets: the sender's side
/// of a stream ([`super::Chunker`]).
pub trait ImageSource {
    /// Bytes of the image.
    fn image_len(&self) -> usize;
    /// Fills `out` with the image's bytes from `offset`; bytes past the end
    /// read as zero (every read is total, so the chip never panics).
    fn read(&self, offset: usize, out: &mut [u8]);
}

/// A complete image in memory: a flash slot's bytes (cut to the slot's
/// length), a file the host kept.
impl ImageSource for [u8] {
    fn image_len(&self) -> usize {
        self.len()
    }

    fn read(&self, offset: usize, out: &mut [u8]) {
        // Past the end the trait promises zeros: clear what the copy will
        // not reach (bytes before the image start cannot occur, offsets
        // being unsigned).
        let inside = self.len().saturating_sub(offset).min(out.len());
        out[inside..].fill(0);
        copy_overlap(self, 0, offset, out);
    }
}

/// Copies into `out` (the image's bytes from `offset`) the part of `src`
/// (the image's bytes from `src_start`) they share; the rest of `out` is
/// left as it is.
fn copy_overlap(src: &[u8], src_start: usize, offset: usize, out: &mut [u8]) {
    let lo = offset.max(src_start);
    let hi = offset.saturating_add(out.len()).min(src_start.saturating_add(src.len()));
    if lo < hi {
        out[lo - offset..hi - offset].copy_from_slice(&src[lo - src_start..hi - src_start]);
    }
}

/// Why a table cannot form an image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImageError {
    /// The image would not fit the stream's `u32` lengths.
    TooLarge {
        /// Bytes it would need.
        bytes: usize,
    },
    /// An entry width a slot cannot describe.
    EntryBytes {
        /// The table's bytes per entry.
        found: usize,
    },
}

impl core::fmt::Display for ImageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ImageError::TooLarge { bytes } => {
                write!(f, "checkpoint image of {bytes} bytes too large: valid is at most {} bytes", u32::MAX)
            }
            ImageError::EntryBytes { found } => {
                write!(f, "table entry of {found} bytes cannot be checkpointed: valid are 2, 4 or 8")
            }
        }
    }
}

/// The image of a learner's record and table, the bytes [`super::super::save`]
/// would write into a slot, produced at any offset from the table itself
/// ([`WeightStore::stored_le`]).
///
/// The header, with the payload's CRC, is computed when the image is made
/// (one pass over the table), so it can be sent first or last. A table
/// that changes while it is streamed then fails the receiver's payload
/// check, and the stream is never kept: hold the table still while it is
/// sent.
#[derive(Debug, Clone)]
pub struct TableImage<'a, W: ?Sized> {
    header: Header,
    header_bytes: [u8; HEADER_LEN],
    record: &'a [u8; STATE_LEN],
    weights: &'a W,
    len: usize,
}

impl<'a, W: WeightStore + ?Sized> TableImage<'a, W> {
    /// The image of `record` (the learner state's bytes, wear included, as
    /// it should be restored) and `weights`, as checkpoint `generation` of
    /// configuration `config_hash`.
    pub fn new(
        config_hash: u32,
        generation: u32,
        record: &'a [u8; STATE_LEN],
        weights: &'a W,
    ) -> Result<Self, ImageError> {
        let entry = weights.entry_bytes();
        if !valid_entry_bytes(entry) {
            return Err(ImageError::EntryBytes { found: entry });
        }
        let n = weights.len();
        let len = n
            .checked_mul(entry)
            .and_then(|b| b.checked_next_multiple_of(4))
            .and_then(|b| b.checked_add(HEADER_LEN + STATE_LEN));
        let len = match len {
            Some(len) if len <= u32::MAX as usize && n <= u32::MAX as usize => len,
            _ => {
                return Err(ImageError::TooLarge {
                    bytes: n.saturating_mul(entry).saturating_add(HEADER_LEN + STATE_LEN),
                })
            }
        };
        let header = Header {
            version: FORMAT_VERSION,
            config_hash,
            weight_count: n as u32,
            generation,
            payload_crc: 0,
            state_len: STATE_LEN as u32,
            weight_bytes: entry as u16,
        };
        let mut image = TableImage { header, header_bytes: [0; HEADER_LEN], record, weights, len };
        let mut digest = CRC32.digest();
        let mut buf = [0u8; WINDOW];
        let mut offset = HEADER_LEN;
        while offset < len {
            let n = (len - offset).min(WINDOW);
            image.read(offset, &mut buf[..n]);
            digest.update(&buf[..n]);
            offset += n;
        }
        image.header.payload_crc = digest.finalize();
        image.header_bytes = image.header.to_bytes();
        Ok(image)
    }

    /// The image's header (payload CRC included).
    pub fn header(&self) -> Header {
        self.header
    }
}

impl<W: WeightStore + ?Sized> ImageSource for TableImage<'_, W> {
    fn image_len(&self) -> usize {
        self.len
    }

    fn read(&self, offset: usize, out: &mut [u8]) {
        out.fill(0);
        copy_overlap(&self.header_bytes, 0, offset, out);
        copy_overlap(self.record, HEADER_LEN, offset, out);
        let base = HEADER_LEN + STATE_LEN;
        let entry = self.weights.entry_bytes();
        if entry == 0 || entry > 8 {
            return;
        }
        let end = offset.saturating_add(out.len());
        let mut i = offset.saturating_sub(base) / entry;
        let mut tmp = [0u8; 8];
        // Entries past the table are the padding's zeros, already in `out`.
        while i < self.weights.len() {
            let at = base + i * entry;
            if at >= end {
                break;
            }
            self.weights.stored_le(i, &mut tmp[..entry]);
            copy_overlap(&tmp[..entry], at, offset, out);
            i += 1;
        }
    }
}
