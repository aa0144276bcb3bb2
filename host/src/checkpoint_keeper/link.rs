//! The keeper and the restore server on a live link: what `pada capture
//! --checkpoint` and `pada watch --checkpoint` do with the frames they
//! decode. Every `CheckpointChunk` goes to the [`CheckpointKeeper`]; a
//! `RestoreWanted` is answered by the [`RestoreServer`] on the board's
//! serial port, framed with the link's own [`FrameEncoder`] (host → chip
//! sequence numbers 0, 1, 2, … for as long as the command runs). Nothing
//! here stops the command: each kept checkpoint, refusal, restore and
//! failed write is one line for the caller to print.

use std::io;
use std::path::{Path, PathBuf};

use pada_core::wire::{Decoded, FrameEncoder, ToHost, MAX_FRAME_LEN};

use super::{CheckpointKeeper, RestoreServer};
use crate::serial_link::SerialLink;

/// The board's streamed checkpoint kept at one path, and sent back when
/// the board asks.
#[derive(Debug)]
pub struct KeeperLink {
    keeper: CheckpointKeeper,
    server: RestoreServer,
    encoder: FrameEncoder,
    /// Whether a refusal was printed since the last chunk taken: a save
    /// cut short is refused chunk by chunk (up to 65 541 of them for LEO's
    /// table), so only the first refusal of a run is a line of its own.
    refusing: bool,
    /// Refusals after that first one, not printed yet.
    refused_quietly: u64,
    /// Restore chunks and frame bytes sent since [`KeeperLink::take_answered`].
    answered: (u32, u64),
}

impl KeeperLink {
    /// A link keeping the checkpoint at `path` (a valid file there is the
    /// one to beat).
    pub fn new(path: impl Into<PathBuf>) -> io::Result<Self> {
        let path = path.into();
        let keeper = CheckpointKeeper::new(&path)?;
        Ok(KeeperLink {
            keeper,
            server: RestoreServer::new(path),
            encoder: FrameEncoder::new(),
            refusing: false,
            refused_quietly: 0,
            answered: (0, 0),
        })
    }

    /// The kept checkpoint's path.
    pub fn path(&self) -> &Path {
        self.keeper.path()
    }

    /// What it keeps, one line: the path and the generation there now.
    pub fn describe(&self) -> String {
        match self.keeper.kept_generation() {
            Some(g) => format!("keeping the board's checkpoint at {} (generation {g} there)", self.path().display()),
            None => format!("keeping the board's checkpoint at {} (none there yet)", self.path().display()),
        }
    }

    /// The keeper.
    pub fn keeper(&self) -> &CheckpointKeeper {
        &self.keeper
    }

    /// The sequence number of the next frame to the board.
    pub fn next_seq(&self) -> u32 {
        self.encoder.next_seq()
    }

    /// Takes the frames just decoded: chunks to the keeper, restore
    /// requests answered on `port` (none: a recording, nobody to answer).
    /// Returns the lines to print, in order.
    pub fn frames(&mut self, frames: &[Decoded<ToHost>], mut port: Option<&mut SerialLink>) -> Vec<String> {
        let mut lines = Vec::new();
        for frame in frames {
            match &frame.msg {
                ToHost::CheckpointChunk(chunk) => self.chunk(chunk, &mut lines),
                ToHost::RestoreWanted(request) => {
                    if let Some(p) = port.as_deref_mut() {
                        self.answer(request, p, &mut lines);
                    }
                }
                _ => {}
            }
        }
        lines
    }

    /// One chunk of a save.
    fn chunk(&mut self, chunk: &pada_core::checkpoint::stream::Chunk, lines: &mut Vec<String>) {
        match self.keeper.feed(chunk) {
            Ok(kept) => {
                self.end_refusals(lines);
                if let Some(k) = kept {
                    lines.push(format!(
                        "checkpoint generation {} kept at {}: {} bytes, {} chunks",
                        k.generation,
                        self.keeper.path().display(),
                        k.bytes,
                        k.chunks
                    ));
                }
            }
            Err(_) if self.refusing => self.refused_quietly += 1,
            Err(e) => {
                self.refusing = true;
                lines.push(format!("{e} (generation {} offset {})", chunk.generation, chunk.offset));
            }
        }
    }

    /// A chunk was taken: the refusals before it, counted, end.
    fn end_refusals(&mut self, lines: &mut Vec<String>) {
        if self.refused_quietly > 0 {
            lines.push(format!("{} more checkpoint chunks refused after that one", self.refused_quietly));
        }
        self.refusing = false;
        self.refused_quietly = 0;
    }

    /// Answers one restore request on `port`.
    fn answer(&mut self, request: &pada_core::wire::RestoreRequest, port: &mut SerialLink, lines: &mut Vec<String>) {
        let answer = self.server.answer(request);
        if let Some(note) = answer.note {
            lines.push(note);
        }
        let mut bytes = Vec::with_capacity(answer.messages.len() * MAX_FRAME_LEN);
        let mut buf = [0u8; MAX_FRAME_LEN];
        for msg in &answer.messages {
            match self.encoder.encode(msg, &mut buf) {
                Ok(frame) => bytes.extend_from_slice(frame),
                Err(e) => {
                    lines.push(format!("cannot frame the answer to the board's restore request: {e:?}"));
                    return;
                }
            }
        }
        match port.write_all(&bytes) {
            Ok(()) => {
                let chunks = answer.messages.iter().filter(|m| matches!(m, pada_core::wire::ToChip::RestoreChunk(_))).count();
                self.answered.0 += chunks as u32;
                self.answered.1 += bytes.len() as u64;
            }
            Err(e) => lines.push(format!("cannot answer the board's restore request (offset {}): {e}", request.offset)),
        }
    }

    /// The restore chunks and frame bytes sent to the board since the last
    /// call: the host's half of a restore's link time, for
    /// [`crate::capture::Recorder::answered`].
    pub fn take_answered(&mut self) -> (u32, u64) {
        std::mem::take(&mut self.answered)
    }

    /// The refusals not printed yet, as a last line (at the end of the
    /// command).
    pub fn finish(&mut self) -> Vec<String> {
        let mut lines = Vec::new();
        self.end_refusals(&mut lines);
        lines
    }
}
