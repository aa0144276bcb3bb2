//! The host's copy of a board's checkpoint, for a board whose weight table
//! fits no flash (LEO's 8 MiB claim table on the F429): the board streams
//! its checkpoints ([`pada_core::checkpoint::stream`]), the keeper writes
//! each one that arrives complete to one file, atomically, and reads it
//! back for the board at its next boot ([`CheckpointKeeper::restore_for`]).
//!
//! The file is exactly a format-4 flash slot's image, so the checkpoint
//! code reads it as it reads flash. It is replaced only by a complete,
//! checked, newer checkpoint: written to `PATH.partial`, fsynced, renamed
//! over `PATH`, the directory fsynced. A stream that stops, or that a new
//! generation interrupts, never touches `PATH`.

mod file_sink;
mod link;
mod restore;
mod serve;

pub use link::KeeperLink;
pub use restore::{read_kept, restore_for, Restore, RestoreRefusal};
pub use serve::{denial, Answer, RestoreServer};

use std::ffi::OsString;
use std::io;
use std::path::{Path, PathBuf};

use file_sink::FileSink;
use pada_core::checkpoint::stream::{AssembleError, Assembler, Chunk, Expect, Order, Progress};
use pada_core::checkpoint::HEADER_LEN;

/// One checkpoint kept: what a caller logs as one CSV row
/// ([`Kept::CSV_HEADER`], [`Kept::csv_row`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Kept {
    /// Its generation.
    pub generation: u32,
    /// Bytes of the image (the file's length).
    pub bytes: u64,
    /// Chunks it took.
    pub chunks: u32,
    /// Encoded bytes of those chunks (what the link carried, before
    /// framing).
    pub encoded_bytes: u64,
}

impl Kept {
    /// The CSV header of [`csv_row`](Self::csv_row).
    pub const CSV_HEADER: &'static str = "generation,bytes,chunks,encoded_bytes";

    /// The CSV row of this checkpoint.
    pub fn csv_row(&self) -> String {
        format!("{},{},{},{}", self.generation, self.bytes, self.chunks, self.encoded_bytes)
    }
}

/// Why a chunk did not go into a kept checkpoint.
#[derive(Debug, thiserror::Error)]
pub enum KeepError {
    /// The stream refused the chunk (out of order, corrupt, stale, …); the
    /// stream in flight is unchanged.
    #[error("{0}")]
    Refused(AssembleError<io::Error>),
    /// The checkpoint was complete but could not be made the file; the
    /// previous file is unchanged.
    #[error("checkpoint generation {generation} complete but not kept at {path}: {error}")]
    Commit {
        /// Its generation.
        generation: u32,
        /// The keeper's path.
        path: PathBuf,
        /// What the file system reported.
        error: io::Error,
    },
}

/// The stream being received.
#[derive(Debug)]
struct InFlight {
    assembler: Assembler<FileSink>,
    encoded_bytes: u64,
}

/// Keeps the last complete checkpoint a board streamed, at one path.
#[derive(Debug)]
pub struct CheckpointKeeper {
    path: PathBuf,
    partial: PathBuf,
    /// The generation of the file at `path`, if it holds a valid one.
    on_disk: Option<u32>,
    stream: Option<InFlight>,
    kept: Vec<Kept>,
}

impl CheckpointKeeper {
    /// A keeper of the checkpoint at `path`. A valid file there is the
    /// one to beat (an older generation is refused); a `PATH.partial` left
    /// by an interrupted run is removed.
    pub fn new(path: impl Into<PathBuf>) -> io::Result<Self> {
        let path = path.into();
        let mut partial = OsString::from(path.as_os_str());
        partial.push(".partial");
        let partial = PathBuf::from(partial);
        match std::fs::remove_file(&partial) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
        let on_disk = read_kept(&path).ok().map(|r| r.header().generation);
        Ok(CheckpointKeeper { path, partial, on_disk, stream: None, kept: Vec::new() })
    }

    /// The path of the kept checkpoint.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path a stream is received into before it is complete.
    pub fn partial_path(&self) -> &Path {
        &self.partial
    }

    /// The generation of the kept checkpoint, if there is a valid one.
    pub fn kept_generation(&self) -> Option<u32> {
        self.on_disk
    }

    /// Every checkpoint kept by this keeper, oldest first.
    pub fn kept(&self) -> &[Kept] {
        &self.kept
    }

    /// Takes one chunk of a board's stream. A chunk at a stream's start
    /// (offset 32: a save, header last; offset 0: header first) that the
    /// stream in flight does not expect begins a new stream and abandons
    /// the one in flight (of another generation, or of the same one: a
    /// board cut off in mid-save, restored from the kept checkpoint, saves
    /// the generation it was saving again); any other chunk continues the
    /// stream in flight. Returns the checkpoint when this chunk completed
    /// it and it was kept.
    pub fn feed(&mut self, chunk: &Chunk) -> Result<Option<Kept>, KeepError> {
        let continues = self.stream.as_ref().is_some_and(|s| {
            !s.assembler.is_complete()
                && s.assembler.generation() == Some(chunk.generation)
                && s.assembler.expected_offset() == chunk.offset
        });
        let starts = chunk.offset == 0 || chunk.offset == HEADER_LEN as u32;
        let progress = if continues || !starts { self.continue_stream(chunk)? } else { self.start_stream(chunk)? };
        let Progress::Complete(header) = progress else {
            return Ok(None);
        };
        let Some(done) = self.stream.take() else {
            return Ok(None);
        };
        let kept = Kept {
            generation: header.generation,
            bytes: chunk.image_len as u64,
            chunks: done.assembler.accepted(),
            encoded_bytes: done.encoded_bytes,
        };
        done.assembler.into_sink().commit(&self.path).map_err(|error| KeepError::Commit {
            generation: header.generation,
            path: self.path.clone(),
            error,
        })?;
        self.on_disk = Some(header.generation);
        self.kept.push(kept);
        Ok(Some(kept))
    }

    /// A chunk for the stream in flight (or, with none, a refusal: the
    /// first chunk that comes is not a stream's start).
    fn continue_stream(&mut self, chunk: &Chunk) -> Result<Progress, KeepError> {
        let Some(s) = self.stream.as_mut() else {
            let expected = HEADER_LEN as u32;
            return Err(KeepError::Refused(AssembleError::OutOfOrder { expected, found: chunk.offset }));
        };
        let progress = s.assembler.accept(chunk).map_err(KeepError::Refused)?;
        s.encoded_bytes += chunk.encoded_len() as u64;
        Ok(progress)
    }

    /// A new stream from `chunk`, refused if it is not newer than the kept
    /// file. The stream in flight is replaced only if the chunk is taken.
    fn start_stream(&mut self, chunk: &Chunk) -> Result<Progress, KeepError> {
        let order = if chunk.offset == 0 { Order::HeaderFirst } else { Order::HeaderLast };
        let expect = Expect { newer_than: self.on_disk, ..Expect::default() };
        let sink = FileSink::new(self.partial.clone(), chunk.image_len as u64);
        let mut assembler = Assembler::new(sink, order, expect);
        // A refused first chunk writes nothing, so the file of the stream
        // in flight is untouched; a taken one replaces it (a new file).
        let progress = assembler.accept(chunk).map_err(KeepError::Refused)?;
        self.stream = Some(InFlight { assembler, encoded_bytes: chunk.encoded_len() as u64 });
        Ok(progress)
    }

    /// The kept checkpoint for a board running `config_hash` whose image
    /// is `image_len` bytes and whose own checkpoint is `board_generation`
    /// (`None`: none), to stream back to it header first
    /// ([`Restore::chunks`]); or the refusal, one line.
    pub fn restore_for(
        &self,
        config_hash: u32,
        image_len: u64,
        board_generation: Option<u32>,
    ) -> Result<Restore, RestoreRefusal> {
        restore_for(&self.path, config_hash, image_len, board_generation)
    }
}
