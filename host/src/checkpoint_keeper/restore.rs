//! Reading the kept checkpoint back for a board that asks, and refusing,
//! in one line each, a file that would not restore it.

use std::io;
use std::path::{Path, PathBuf};

use pada_core::checkpoint::stream::{Chunk, Chunker, Order};
use pada_core::checkpoint::{crc32, is_newer, Header, HEADER_LEN};

/// Why the kept checkpoint is not sent to a board.
#[derive(Debug, thiserror::Error)]
pub enum RestoreRefusal {
    /// No file at the path.
    #[error("no checkpoint kept at {path}")]
    NoFile {
        /// The keeper's path.
        path: PathBuf,
    },
    /// The file could not be read.
    #[error("checkpoint {path} unreadable: {error}")]
    Unreadable {
        /// The keeper's path.
        path: PathBuf,
        /// What reading it reported.
        error: io::Error,
    },
    /// The file is shorter than its header says (or than a header).
    #[error("checkpoint {path} truncated: {bytes} bytes, valid is {expected} bytes")]
    Truncated {
        /// The keeper's path.
        path: PathBuf,
        /// Bytes in the file.
        bytes: u64,
        /// Bytes its header describes (32 if it has no whole header).
        expected: u64,
    },
    /// The header or the payload fails its check.
    #[error("checkpoint {path} corrupted: {why}")]
    Corrupted {
        /// The keeper's path.
        path: PathBuf,
        /// What failed, with the valid value.
        why: String,
    },
    /// The file is of another configuration than the board's.
    #[error("checkpoint {path} is of configuration {kept:#010x}, the board runs configuration {board:#010x}")]
    OtherConfiguration {
        /// The keeper's path.
        path: PathBuf,
        /// The board's configuration hash.
        board: u32,
        /// The file's.
        kept: u32,
    },
    /// The file's image has another length than the board's table needs.
    #[error("checkpoint {path} holds a {kept}-byte image, the board's table needs {board} bytes")]
    WrongSize {
        /// The keeper's path.
        path: PathBuf,
        /// The board's image length.
        board: u64,
        /// The file's.
        kept: u64,
    },
    /// The board's own checkpoint is newer than the file's.
    #[error("checkpoint {path} is generation {kept}, older than the board's own generation {board}")]
    Older {
        /// The keeper's path.
        path: PathBuf,
        /// The board's generation.
        board: u32,
        /// The file's.
        kept: u32,
    },
}

/// A kept checkpoint, checked, ready to stream to a board.
#[derive(Debug, Clone)]
pub struct Restore {
    header: Header,
    image: Vec<u8>,
}

impl Restore {
    /// Its header.
    pub fn header(&self) -> Header {
        self.header
    }

    /// The image: a format-4 flash slot's bytes.
    pub fn image(&self) -> &[u8] {
        &self.image
    }

    /// Its chunks, header first, so the board checks configuration, size
    /// and generation before it writes any entry.
    pub fn chunks(&self) -> impl Iterator<Item = Chunk> + '_ {
        // The header and length were checked when the file was read, so
        // the chunker is always made; if not, nothing is sent.
        Chunker::new(&self.image[..], Order::HeaderFirst).into_iter().flatten()
    }
}

/// Reads and checks the file at `path`: a whole format-4 image whose
/// header and payload CRCs check.
pub fn read_kept(path: &Path) -> Result<Restore, RestoreRefusal> {
    let image = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Err(RestoreRefusal::NoFile { path: path.into() }),
        Err(error) => return Err(RestoreRefusal::Unreadable { path: path.into(), error }),
    };
    let bytes = image.len() as u64;
    let truncated = |expected: u64| RestoreRefusal::Truncated { path: path.into(), bytes, expected };
    let corrupted = |why: String| RestoreRefusal::Corrupted { path: path.into(), why };
    let Some(hb) = image.first_chunk::<HEADER_LEN>() else {
        return Err(truncated(HEADER_LEN as u64));
    };
    let header = Header::parse(hb).map_err(|e| corrupted(e.to_string()))?;
    let Some(described) = header.slot_bytes() else {
        return Err(corrupted(format!("header describes no image ({} bytes per entry)", header.weight_bytes)));
    };
    let described = described as u64;
    if bytes < described {
        return Err(truncated(described));
    }
    if bytes > described {
        return Err(corrupted(format!("{bytes} bytes, valid is {described} bytes as the header describes")));
    }
    let computed = crc32(&image[HEADER_LEN..]);
    if computed != header.payload_crc {
        return Err(corrupted(format!(
            "payload CRC {computed:#010x}, valid is {:#010x} as the header states",
            header.payload_crc
        )));
    }
    Ok(Restore { header, image })
}

/// The kept checkpoint at `path` for a board running `config_hash` with
/// an image of `image_len` bytes and its own checkpoint of
/// `board_generation` (`None`: it has none), or why not.
pub fn restore_for(
    path: &Path,
    config_hash: u32,
    image_len: u64,
    board_generation: Option<u32>,
) -> Result<Restore, RestoreRefusal> {
    let restore = read_kept(path)?;
    let h = restore.header;
    if h.config_hash != config_hash {
        return Err(RestoreRefusal::OtherConfiguration { path: path.into(), board: config_hash, kept: h.config_hash });
    }
    let kept = restore.image.len() as u64;
    if kept != image_len {
        return Err(RestoreRefusal::WrongSize { path: path.into(), board: image_len, kept });
    }
    if let Some(board) = board_generation {
        if is_newer(board, h.generation) {
            return Err(RestoreRefusal::Older { path: path.into(), board, kept: h.generation });
        }
    }
    Ok(restore)
}
