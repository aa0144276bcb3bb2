//! Answering a board's restore requests ([`ToHost::RestoreWanted`]) from
//! the kept file: the host's side of a restore at boot, the same for
//! `pada sil`, `pada capture` and `pada watch`.
//!
//! [`ToHost::RestoreWanted`]: pada_core::wire::ToHost::RestoreWanted

use std::path::{Path, PathBuf};

use pada_core::checkpoint::stream::Chunk;
use pada_core::wire::{RestoreDenied, RestoreRequest, ToChip, RESTORE_BATCH};

use super::restore::{restore_for, RestoreRefusal};

/// The wire's reason for a refusal (the line itself stays on the host).
pub fn denial(refusal: &RestoreRefusal) -> RestoreDenied {
    match refusal {
        RestoreRefusal::NoFile { .. } => RestoreDenied::NoCheckpoint,
        RestoreRefusal::Unreadable { .. } => RestoreDenied::Unreadable,
        RestoreRefusal::Truncated { .. } => RestoreDenied::Truncated,
        RestoreRefusal::Corrupted { .. } => RestoreDenied::Corrupted,
        RestoreRefusal::OtherConfiguration { .. } => RestoreDenied::OtherConfiguration,
        RestoreRefusal::WrongSize { .. } => RestoreDenied::WrongSize,
        RestoreRefusal::Older { .. } => RestoreDenied::Older,
    }
}

/// The answer to one request: the messages for the board, and a line for
/// the host's log when the request starts a restore or is refused.
#[derive(Debug, Clone, PartialEq)]
pub struct Answer {
    /// What to send the board, in order.
    pub messages: Vec<ToChip>,
    /// What to tell the user (`None` in the middle of a restore).
    pub note: Option<String>,
}

/// Serves restores of the checkpoint kept at one path. A request from
/// offset 0 reads and checks the file afresh (it may have been replaced
/// since the last restore); the following requests are served from that
/// reading, so a file replaced in the middle of a restore cannot mix two
/// checkpoints.
#[derive(Debug)]
pub struct RestoreServer {
    path: PathBuf,
    /// The restore in progress: its request's configuration and length,
    /// and its chunks in stream order.
    current: Option<(RestoreRequest, Vec<Chunk>)>,
}

impl RestoreServer {
    /// A server of the checkpoint kept at `path`.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        RestoreServer { path: path.into(), current: None }
    }

    /// The path it serves.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The answer to `request`: up to [`RESTORE_BATCH`] chunks from its
    /// offset, header first, or [`ToChip::RestoreNone`] with the reason.
    pub fn answer(&mut self, request: &RestoreRequest) -> Answer {
        let mut note = None;
        if request.offset == 0 {
            self.current = None;
            match restore_for(&self.path, request.config_hash, request.image_len as u64, None) {
                Ok(restore) => {
                    let chunks: Vec<Chunk> = restore.chunks().collect();
                    note = Some(format!(
                        "restoring checkpoint generation {} ({} bytes, {} chunks) from {}",
                        restore.header().generation,
                        restore.image().len(),
                        chunks.len(),
                        self.path.display()
                    ));
                    self.current = Some((*request, chunks));
                }
                Err(refusal) => {
                    return Answer {
                        messages: vec![ToChip::RestoreNone(denial(&refusal))],
                        note: Some(format!("no checkpoint sent to the board: {refusal}")),
                    }
                }
            }
        }
        let batch = self.current.as_ref().and_then(|(first, chunks)| {
            let same = first.config_hash == request.config_hash && first.image_len == request.image_len;
            let at = chunks.iter().position(|c| c.offset == request.offset)?;
            same.then(|| chunks[at..].iter().take(RESTORE_BATCH).cloned().map(ToChip::RestoreChunk).collect())
        });
        match batch {
            Some(messages) => Answer { messages, note },
            None => Answer {
                messages: vec![ToChip::RestoreNone(RestoreDenied::NotAChunk)],
                note: Some(format!(
                    "no checkpoint sent to the board: it asked for offset {} of a restore that {}",
                    request.offset,
                    if self.current.is_some() {
                        "has no chunk there"
                    } else {
                        "has not started (valid: offset 0 first)"
                    }
                )),
            },
        }
    }
}
