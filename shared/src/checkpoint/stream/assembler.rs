//! The receiver: takes a stream's chunks in order into a sink and refuses
//! every one that would make the image wrong, each refusal with its cause.
//!
//! A refused chunk changes nothing (neither the sink nor the assembler), so
//! a sender that resends it, or the chunk it skipped, continues the stream.
//! The image is complete only when every byte arrived and both CRCs (the
//! header's own, the payload's) check; the last chunk is checked before it
//! is written, so in a save (header last) a sink never receives a header
//! whose payload does not match it, as in flash.

use crate::checkpoint::slots::{is_newer, Header, HeaderError, HEADER_LEN};
use crate::crc::CRC32;

use super::chunk::{Body, Chunk, ChunkError};
use super::chunker::Order;
use super::WINDOW;

/// Where an assembled image goes: bytes written at offsets. Each byte is
/// written once, the body in ascending order.
pub trait ImageSink {
    /// What the sink reports when a write fails.
    type Error;
    /// Writes `bytes` at image offset `offset`.
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), Self::Error>;
    /// Writes `len` zero bytes at `offset` (a run of zero windows). A sink
    /// that starts zeroed (a fresh sparse file) may skip them.
    fn write_zeros(&mut self, offset: usize, len: usize) -> Result<(), Self::Error> {
        let zeros = [0u8; WINDOW];
        let mut done = 0;
        while done < len {
            let n = (len - done).min(WINDOW);
            self.write(offset + done, &zeros[..n])?;
            done += n;
        }
        Ok(())
    }
}

/// A write outside an [`ImageSink`] slice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutsideSlice {
    /// The first byte's offset.
    pub offset: usize,
    /// The bytes.
    pub len: usize,
}

impl core::fmt::Display for OutsideSlice {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "write of {} bytes at offset {} outside the buffer", self.len, self.offset)
    }
}

/// A buffer as long as the image at least (a slot's bytes, a test's
/// vector).
impl ImageSink for [u8] {
    type Error = OutsideSlice;
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), OutsideSlice> {
        let dst = offset.checked_add(bytes.len()).and_then(|end| self.get_mut(offset..end));
        match dst {
            Some(dst) => {
                dst.copy_from_slice(bytes);
                Ok(())
            }
            None => Err(OutsideSlice { offset, len: bytes.len() }),
        }
    }
}

impl<K: ImageSink + ?Sized> ImageSink for &mut K {
    type Error = K::Error;
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), K::Error> {
        (**self).write(offset, bytes)
    }
    fn write_zeros(&mut self, offset: usize, len: usize) -> Result<(), K::Error> {
        (**self).write_zeros(offset, len)
    }
}

/// What the receiver knows beforehand; `None` checks nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Expect {
    /// The running configuration's hash: a header of another is refused.
    pub config_hash: Option<u32>,
    /// The image's length (from the table's size): a stream of another is
    /// refused at its first chunk.
    pub image_len: Option<u32>,
    /// The generation the receiver already has: a stream not newer
    /// ([`is_newer`]) is refused at its first chunk.
    pub newer_than: Option<u32>,
}

/// Why a chunk was refused. The assembler and the sink are unchanged,
/// except after [`AssembleError::Sink`] (the sink may hold part of the
/// chunk).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AssembleError<E> {
    /// The chunk's fields are not a chunk's ([`Chunk::check`]).
    Malformed(ChunkError),
    /// The chunk's CRC does not match its contents.
    Corrupt {
        /// The chunk's offset.
        offset: u32,
        /// The CRC it carries.
        carried: u32,
        /// The CRC of its contents.
        computed: u32,
    },
    /// Not the chunk that comes next.
    OutOfOrder {
        /// The offset that comes next.
        expected: u32,
        /// The chunk's.
        found: u32,
    },
    /// A chunk of another checkpoint in the middle of this one's stream.
    GenerationChanged {
        /// This stream's generation.
        expected: u32,
        /// The chunk's.
        found: u32,
    },
    /// An image length other than the stream's (its first chunk's) or the
    /// expected one ([`Expect::image_len`]).
    WrongLength {
        /// The valid length.
        expected: u32,
        /// The chunk's.
        found: u32,
    },
    /// A generation not newer than the one the receiver has
    /// ([`Expect::newer_than`]).
    Stale {
        /// The receiver's generation.
        have: u32,
        /// The stream's.
        found: u32,
    },
    /// The header window is not a valid format-4 header (magic, version,
    /// header CRC).
    BadHeader(HeaderError),
    /// The header's generation is not the stream's.
    HeaderGeneration {
        /// The header's.
        header: u32,
        /// The stream's.
        stream: u32,
    },
    /// The header describes an image of another length than the stream's.
    HeaderLength {
        /// Bytes the header describes (0: none it can).
        header: u32,
        /// The stream's image length.
        stream: u32,
    },
    /// The header is of another configuration ([`Expect::config_hash`]).
    ConfigMismatch {
        /// The running configuration's hash.
        expected: u32,
        /// The header's.
        found: u32,
    },
    /// The payload (state record and entries) does not have the CRC the
    /// header states: refused with the last chunk, before it is written.
    PayloadCrc {
        /// The header's payload CRC.
        header: u32,
        /// The CRC of the bytes received.
        computed: u32,
    },
    /// The image is complete; no chunk follows.
    AlreadyComplete {
        /// Its generation.
        generation: u32,
    },
    /// The sink failed.
    Sink(E),
}

impl<E: core::fmt::Display> core::fmt::Display for AssembleError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("checkpoint chunk refused: ")?;
        match self {
            AssembleError::Malformed(e) => write!(f, "{e}"),
            AssembleError::Corrupt { offset, carried, computed } => write!(
                f,
                "corrupt chunk at offset {offset}: carries CRC {carried:#010x}, its contents have {computed:#010x}"
            ),
            AssembleError::OutOfOrder { expected, found } => {
                write!(f, "chunk at offset {found} out of order: expected offset {expected}")
            }
            AssembleError::GenerationChanged { expected, found } => {
                write!(f, "chunk of generation {found} mid-stream: expected generation {expected}")
            }
            AssembleError::WrongLength { expected, found } => {
                write!(f, "image length {found} bytes: expected {expected} bytes")
            }
            AssembleError::Stale { have, found } => {
                write!(f, "stale generation {found}: valid is newer than {have}, the one already kept")
            }
            AssembleError::BadHeader(e) => write!(f, "bad {e}"),
            AssembleError::HeaderGeneration { header, stream } => {
                write!(f, "header of generation {header} in the stream of generation {stream}")
            }
            AssembleError::HeaderLength { header, stream } => {
                write!(f, "header describes {header} bytes: the stream's image has {stream} bytes")
            }
            AssembleError::ConfigMismatch { expected, found } => {
                write!(f, "configuration hash {found:#010x}: expected {expected:#010x}")
            }
            AssembleError::PayloadCrc { header, computed } => {
                write!(f, "payload CRC {computed:#010x} of the bytes received: the header states {header:#010x}")
            }
            AssembleError::AlreadyComplete { generation } => {
                write!(f, "generation {generation} is complete: a new stream needs a new assembler")
            }
            AssembleError::Sink(e) => write!(f, "sink failed: {e}"),
        }
    }
}

/// What an accepted chunk did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Progress {
    /// Taken; more to come.
    More,
    /// Taken, and the image is complete and checked.
    Complete(Header),
}

/// The stream's identity, from its first chunk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stream {
    generation: u32,
    len: u32,
}

/// Reassembles a stream ([`super`]) of one [`Order`] into a sink.
pub struct Assembler<K> {
    sink: K,
    order: Order,
    expect: Expect,
    stream: Option<Stream>,
    /// The header, once received (in a restore, before the body).
    header: Option<Header>,
    /// The next body window's offset.
    next: u32,
    /// CRC of the body received so far.
    digest: crc::Digest<'static, u32>,
    accepted: u32,
    complete: bool,
}

impl<K: core::fmt::Debug> core::fmt::Debug for Assembler<K> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Assembler")
            .field("sink", &self.sink)
            .field("order", &self.order)
            .field("expect", &self.expect)
            .field("stream", &self.stream)
            .field("header", &self.header)
            .field("next", &self.next)
            .field("accepted", &self.accepted)
            .field("complete", &self.complete)
            .finish()
    }
}

impl<K: ImageSink> Assembler<K> {
    /// An assembler of a stream in `order` into `sink`, checking `expect`.
    pub fn new(sink: K, order: Order, expect: Expect) -> Self {
        Assembler {
            sink,
            order,
            expect,
            stream: None,
            header: None,
            next: HEADER_LEN as u32,
            digest: CRC32.digest(),
            accepted: 0,
            complete: false,
        }
    }

    /// The sink.
    pub fn sink(&self) -> &K {
        &self.sink
    }

    /// The sink, given back.
    pub fn into_sink(self) -> K {
        self.sink
    }

    /// Chunks accepted so far.
    pub fn accepted(&self) -> u32 {
        self.accepted
    }

    /// The stream's generation, once a chunk was accepted.
    pub fn generation(&self) -> Option<u32> {
        self.stream.map(|s| s.generation)
    }

    /// Whether the image is complete.
    pub fn is_complete(&self) -> bool {
        self.complete
    }

    /// The offset of the chunk that comes next.
    pub fn expected_offset(&self) -> u32 {
        self.expected_in(self.stream.map_or(u32::MAX, |s| s.len))
    }

    /// The offset that comes next in a stream of `len` bytes.
    fn expected_in(&self, len: u32) -> u32 {
        let body_done = self.next >= len;
        match (self.order, self.header.is_some()) {
            (Order::HeaderFirst, false) => 0,
            (Order::HeaderLast, _) if body_done => 0,
            _ => self.next,
        }
    }

    /// Takes `chunk`, or refuses it and changes nothing.
    pub fn accept(&mut self, chunk: &Chunk) -> Result<Progress, AssembleError<K::Error>> {
        if self.complete {
            let generation = self.stream.map_or(chunk.generation, |s| s.generation);
            return Err(AssembleError::AlreadyComplete { generation });
        }
        chunk.check().map_err(AssembleError::Malformed)?;
        let computed = chunk.expected_crc();
        if computed != chunk.crc {
            return Err(AssembleError::Corrupt { offset: chunk.offset, carried: chunk.crc, computed });
        }
        let stream = self.check_stream(chunk)?;
        let expected = self.expected_in(stream.len);
        if chunk.offset != expected {
            return Err(AssembleError::OutOfOrder { expected, found: chunk.offset });
        }
        let progress =
            if chunk.offset == 0 { self.take_header(chunk, stream)? } else { self.take_body(chunk, stream)? };
        self.stream = Some(stream);
        self.accepted = self.accepted.saturating_add(1);
        if let Progress::Complete(_) = progress {
            self.complete = true;
        }
        Ok(progress)
    }

    /// The chunk's stream: this one's, or (the first chunk) a new one that
    /// passes [`Expect`].
    fn check_stream(&self, chunk: &Chunk) -> Result<Stream, AssembleError<K::Error>> {
        let found = Stream { generation: chunk.generation, len: chunk.image_len };
        if let Some(s) = self.stream {
            if found.generation != s.generation {
                return Err(AssembleError::GenerationChanged { expected: s.generation, found: found.generation });
            }
            if found.len != s.len {
                return Err(AssembleError::WrongLength { expected: s.len, found: found.len });
            }
            return Ok(s);
        }
        if let Some(expected) = self.expect.image_len {
            if found.len != expected {
                return Err(AssembleError::WrongLength { expected, found: found.len });
            }
        }
        if let Some(have) = self.expect.newer_than {
            if !is_newer(found.generation, have) {
                return Err(AssembleError::Stale { have, found: found.generation });
            }
        }
        Ok(found)
    }

    /// The header's window: checked against the stream and [`Expect`], and
    /// in a save (the last chunk) against the payload received.
    fn take_header(&mut self, chunk: &Chunk, stream: Stream) -> Result<Progress, AssembleError<K::Error>> {
        let mut window = [0u8; WINDOW];
        chunk.expand(&mut window);
        let mut hb = [0u8; HEADER_LEN];
        hb.copy_from_slice(&window[..HEADER_LEN]);
        let header = Header::parse(&hb).map_err(AssembleError::BadHeader)?;
        if header.generation != stream.generation {
            return Err(AssembleError::HeaderGeneration { header: header.generation, stream: stream.generation });
        }
        let described = header.slot_bytes().unwrap_or(0);
        if described != stream.len as usize {
            let header = u32::try_from(described).unwrap_or(u32::MAX);
            return Err(AssembleError::HeaderLength { header, stream: stream.len });
        }
        if let Some(expected) = self.expect.config_hash {
            if header.config_hash != expected {
                return Err(AssembleError::ConfigMismatch { expected, found: header.config_hash });
            }
        }
        let body_done = self.next >= stream.len;
        if body_done {
            check_payload(&header, self.digest.clone().finalize())?;
        }
        self.sink.write(0, &hb).map_err(AssembleError::Sink)?;
        self.header = Some(header);
        Ok(if body_done { Progress::Complete(header) } else { Progress::More })
    }

    /// A body window or zero run: the payload CRC runs on, and in a
    /// restore the last one is checked against the header's before it is
    /// written.
    fn take_body(&mut self, chunk: &Chunk, stream: Stream) -> Result<Progress, AssembleError<K::Error>> {
        let covered = chunk.covered_len() as u32;
        let mut digest = self.digest.clone();
        let mut window = [0u8; WINDOW];
        let n = chunk.expand(&mut window);
        match chunk.body {
            Body::Words { .. } => digest.update(&window[..n]),
            Body::Zeros { .. } => {
                let zeros = [0u8; WINDOW];
                let mut left = covered as usize;
                while left > 0 {
                    let k = left.min(WINDOW);
                    digest.update(&zeros[..k]);
                    left -= k;
                }
            }
        }
        let end = chunk.offset + covered;
        let last = end >= stream.len;
        let complete = match self.header {
            Some(header) if last => {
                check_payload(&header, digest.clone().finalize())?;
                Some(header)
            }
            _ => None,
        };
        let offset = chunk.offset as usize;
        match chunk.body {
            Body::Words { .. } => self.sink.write(offset, &window[..n]),
            Body::Zeros { .. } => self.sink.write_zeros(offset, covered as usize),
        }
        .map_err(AssembleError::Sink)?;
        self.digest = digest;
        self.next = end;
        Ok(match complete {
            Some(header) => Progress::Complete(header),
            None => Progress::More,
        })
    }
}

fn check_payload<E>(header: &Header, computed: u32) -> Result<(), AssembleError<E>> {
    if computed == header.payload_crc {
        Ok(())
    } else {
        Err(AssembleError::PayloadCrc { header: header.payload_crc, computed })
    }
}
