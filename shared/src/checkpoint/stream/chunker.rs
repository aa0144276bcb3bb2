//! The sender: walks an image window by window and yields its chunks, the
//! header last (a save) or first (a restore).

use crate::checkpoint::slots::{Header, HeaderError, HEADER_LEN};

use super::chunk::Chunk;
use super::source::ImageSource;
use super::{valid_image_len, WINDOW};

/// Where the header goes in a stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Order {
    /// Body first, header last: a save. As in flash, the header commits
    /// the checkpoint, so a stream cut anywhere holds no header and is
    /// never taken for a checkpoint.
    HeaderLast,
    /// Header first, then the body: a restore. The receiver checks the
    /// configuration, size and generation before it writes any entry.
    HeaderFirst,
}

/// Why an image cannot be streamed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChunkerError {
    /// The image's first 32 bytes are not a valid format-4 header.
    BadHeader(HeaderError),
    /// The image's length is not the one its header describes.
    Length {
        /// The source's bytes.
        source: usize,
        /// The header's slot length (0 if it describes none).
        header: usize,
    },
}

impl core::fmt::Display for ChunkerError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ChunkerError::BadHeader(e) => write!(f, "checkpoint image not streamed: {}", e),
            ChunkerError::Length { source, header } => {
                write!(f, "checkpoint image of {source} bytes not streamed: its header describes {header} bytes")
            }
        }
    }
}

/// Yields the chunks of an image ([`super`]): each body window with its
/// zero words left out, each run of all-zero body windows as one chunk,
/// and the header's window first or last ([`Order`]).
#[derive(Debug, Clone)]
pub struct Chunker<'a, S: ?Sized> {
    source: &'a S,
    header: Header,
    len: usize,
    order: Order,
    /// The next body window's offset (`len` when the body is done).
    next: usize,
    header_sent: bool,
}

impl<'a, S: ImageSource + ?Sized> Chunker<'a, S> {
    /// A chunker over `source`, whose first 32 bytes must be a valid
    /// header describing exactly `source.image_len()` bytes (the chunks
    /// carry its generation).
    pub fn new(source: &'a S, order: Order) -> Result<Self, ChunkerError> {
        let mut hb = [0u8; HEADER_LEN];
        source.read(0, &mut hb);
        let header = Header::parse(&hb).map_err(ChunkerError::BadHeader)?;
        let len = source.image_len();
        let described = header.slot_bytes().unwrap_or(0);
        if described != len || !valid_image_len(len as u64) {
            return Err(ChunkerError::Length { source: len, header: described });
        }
        Ok(Chunker { source, header, len, order, next: HEADER_LEN, header_sent: false })
    }

    /// The header of the image being streamed.
    pub fn header(&self) -> Header {
        self.header
    }

    fn header_chunk(&mut self) -> Chunk {
        self.header_sent = true;
        let mut hb = [0u8; HEADER_LEN];
        self.source.read(0, &mut hb);
        Chunk::words(self.header.generation, self.len as u32, 0, &hb)
    }

    /// The window at `offset` into `buf`; its length.
    fn window(&self, offset: usize, buf: &mut [u8; WINDOW]) -> usize {
        let n = (self.len - offset).min(WINDOW);
        self.source.read(offset, &mut buf[..n]);
        n
    }

    fn body_chunk(&mut self) -> Chunk {
        let (generation, len) = (self.header.generation, self.len as u32);
        let start = self.next;
        let mut buf = [0u8; WINDOW];
        let n = self.window(start, &mut buf);
        if buf[..n].iter().any(|&b| b != 0) {
            self.next = start + n;
            return Chunk::words(generation, len, start as u32, &buf[..n]);
        }
        // A run of zero windows: extend it while the next window is zero
        // too (a nonzero one is read again as the next chunk).
        let mut windows = 1u32;
        let mut at = start + n;
        while at < self.len && windows < u32::MAX {
            let n = self.window(at, &mut buf);
            if buf[..n].iter().any(|&b| b != 0) {
                break;
            }
            windows += 1;
            at += n;
        }
        self.next = at;
        Chunk::zeros(generation, len, start as u32, windows)
    }
}

impl<S: ImageSource + ?Sized> Iterator for Chunker<'_, S> {
    type Item = Chunk;

    fn next(&mut self) -> Option<Chunk> {
        let body_left = self.next < self.len;
        match (self.order, self.header_sent, body_left) {
            (_, true, false) => None,
            (Order::HeaderFirst, false, _) | (Order::HeaderLast, false, false) => Some(self.header_chunk()),
            (_, _, true) => Some(self.body_chunk()),
        }
    }
}
