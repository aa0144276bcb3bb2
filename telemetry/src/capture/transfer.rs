//! Checkpoint transfers in a telemetry stream, one record each.
//!
//! A board whose checkpoint fits no flash (LEO's 8 MiB table on the F429)
//! streams each save to the host as up to 65 543 `CheckpointChunk` frames
//! and, at every boot, asks for the kept one back with a `RestoreWanted`
//! per batch of chunks. Written one CSV row per frame, they buried the
//! learning (`pada sil --task leo --board f429-sdram --seconds 1800
//! --checkpoint-every 300`: 454 753 chunk rows, 50 of the CSV's 71 MB,
//! against 60 552 steps). The raw stream keeps every frame; the CSV, the
//! MCAP file and
//! `pada.read_telemetry` get one [`Transfer`] per save and per restore
//! instead: its generation, image bytes, chunks, the time it holds the
//! telemetry link and how it ended.
//!
//! A save runs from its first chunk to the board's `Checkpoint(Streamed)`
//! report; a restore from the `RestoreWanted` at offset 0 to the board's
//! `Restored` report. A transfer that never reaches its report is
//! `cut-off` (the board restarted, or began another) or `unfinished` (the
//! input ended).

use pada_core::checkpoint::stream::Chunk;
use pada_core::checkpoint::HEADER_LEN;
use pada_core::wire::{CheckpointReport, RestoreDenied, RestoreOutcome, RestoreRequest, ToHost};
use serde::{Deserialize, Serialize};

/// The telemetry link's rate \[baud\]: the board's USART at 921 600 baud,
/// 8N1, ten bit times per byte (`pada_firmware`'s `TELEMETRY_BAUD`).
pub const LINK_BAUD: u32 = 921_600;

/// Seconds `bytes` take on the telemetry link ([`LINK_BAUD`], 8N1).
pub fn link_s(bytes: u64) -> f64 {
    bytes as f64 * 10.0 / LINK_BAUD as f64
}

/// Seconds a save of an `image_len`-byte image holds the telemetry link
/// when every word of it is nonzero (a full table, the longest save; a
/// restore carries the same chunks the other way): the header's chunk, one
/// chunk per body window, each as the largest frame it can be, and the
/// `Streamed` report. An upper bound the host can compute before a run.
pub fn full_save_link_s(image_len: u32) -> f64 {
    use pada_core::checkpoint::stream::WINDOW;
    use pada_core::wire::{encode_frame, MAX_FRAME_LEN};
    let frame_len = |msg: &ToHost| {
        let mut buf = [0u8; MAX_FRAME_LEN];
        // The longest sequence number and fields: the largest frame.
        encode_frame(msg, u32::MAX, &mut buf).map_or(MAX_FRAME_LEN, |f| f.len()) as u64
    };
    let body = (image_len as u64).saturating_sub(HEADER_LEN as u64);
    let windows = body.div_ceil(WINDOW as u64);
    // The last window's offset: the largest, so the longest varint.
    let last = (HEADER_LEN as u64 + windows.saturating_sub(1) * WINDOW as u64) as u32;
    let window = Chunk::words(u32::MAX, image_len, last, &[0xFF; WINDOW]);
    let header = Chunk::words(u32::MAX, image_len, 0, &[0xFF; HEADER_LEN]);
    let report = ToHost::Checkpoint(CheckpointReport::Streamed { generation: u32::MAX, chunks: u32::MAX, image_len });
    let bytes = windows * frame_len(&ToHost::CheckpointChunk(window))
        + frame_len(&ToHost::CheckpointChunk(header))
        + frame_len(&report);
    link_s(bytes)
}

/// Which way a checkpoint went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// Board to host: a save (`CheckpointChunk`s, body first, header last).
    Save,
    /// Host to board: a restore at boot (`RestoreWanted` per batch).
    Restore,
}

impl Direction {
    /// The CSV kind of its row.
    pub fn row_kind(self) -> &'static str {
        match self {
            Direction::Save => "checkpoint-save",
            Direction::Restore => "checkpoint-restore",
        }
    }
}

/// One save or restore of a checkpoint the host keeps. Its JSON is a
/// recording's `/checkpoint` message, without the recorder's clock (which
/// stays out of a recording: it reads back as 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Transfer {
    /// A save or a restore.
    pub direction: Direction,
    /// The checkpoint's generation (a save: its chunks'; a restore: the
    /// one loaded; unknown for a restore that loaded nothing).
    pub generation: Option<u32>,
    /// Bytes of the image (the flash slot's bytes it stands for).
    pub bytes: u32,
    /// Chunks: a save's chunks received by the host; a restore's chunks
    /// the board took (its `Restored` report), else the chunks the host
    /// was seen to send.
    pub chunks: u32,
    /// A restore's requests (`RestoreWanted` frames); 0 for a save.
    pub requests: u32,
    /// Frame bytes of this transfer from the board (its chunks or requests
    /// and its closing report, delimiters included).
    pub board_bytes: u64,
    /// Frame bytes of the host's answers to a restore, as the host that
    /// answered reported them (0 in a recording: the answers go the other
    /// way and are not in the stream).
    pub host_bytes: u64,
    /// Seconds the transfer holds the telemetry link: its bytes at
    /// [`LINK_BAUD`]. A restore's requests and answers alternate, so both
    /// directions add; the round trip of each request comes on top (none
    /// in QEMU). Learning waits meanwhile: a save streams with the control
    /// loop stopped, a restore runs at boot before it starts.
    pub link_s: f64,
    /// How it ended: a save `streamed` (the board's report came and every
    /// chunk it counted arrived) or `incomplete` (the report came, some
    /// chunks did not); a restore as the board's `Restored` report says
    /// ([`restore_outcome_name`]: `loaded`, `no-checkpoint`,
    /// `denied-<reason>`, `no-answer`, `chunk-refused`, `invalid-state`);
    /// either `cut-off` (the board restarted, or began another, before its
    /// report) or `unfinished` (the capture ended first).
    pub outcome: String,
    /// Whether the board's closing report (`Checkpoint(Streamed)`,
    /// `Restored`) came: it is one of the transfer's frames.
    pub reported: bool,
    /// Chunks the board said it sent (a save's `Streamed` report).
    pub reported_chunks: Option<u32>,
    /// When its first frame came \[s\] (the recorder's clock).
    #[serde(skip)]
    pub started_s: f64,
    /// When its last frame came \[s\].
    #[serde(skip)]
    pub ended_s: f64,
}

impl Transfer {
    fn new(direction: Direction, bytes: u32, time_s: f64) -> Transfer {
        Transfer {
            direction,
            generation: None,
            bytes,
            chunks: 0,
            requests: 0,
            board_bytes: 0,
            host_bytes: 0,
            link_s: 0.0,
            outcome: String::new(),
            reported: false,
            reported_chunks: None,
            started_s: time_s,
            ended_s: time_s,
        }
    }

    fn close(mut self, outcome: impl Into<String>) -> Transfer {
        self.outcome = outcome.into();
        self.link_s = link_s(self.board_bytes + self.host_bytes);
        self
    }

    /// The rest of its CSV row, one line: requests, bytes each way, chunks
    /// missing. (Nothing of the recorder's clock but the row's time, its
    /// end: the same stream gives the same rows but for that column.)
    pub fn detail(&self) -> String {
        let mut d = match self.direction {
            Direction::Save => format!("{} bytes from the board", self.board_bytes),
            Direction::Restore => format!(
                "{} requests, {} bytes from the board, {} bytes of answers",
                self.requests, self.board_bytes, self.host_bytes
            ),
        };
        if let Some(n) = self.reported_chunks.filter(|&n| n != self.chunks) {
            d.push_str(&format!("; the board sent {n} chunks, {} arrived", self.chunks));
        }
        d
    }
}

/// A restore's outcome as the CSV's `outcome` names it.
pub fn restore_outcome_name(o: &RestoreOutcome) -> String {
    match o {
        RestoreOutcome::Loaded { .. } => "loaded".into(),
        RestoreOutcome::Denied(RestoreDenied::NoCheckpoint) => "no-checkpoint".into(),
        RestoreOutcome::Denied(d) => format!("denied-{}", denied_name(d)),
        RestoreOutcome::NoAnswer { .. } => "no-answer".into(),
        RestoreOutcome::ChunkRefused { .. } => "chunk-refused".into(),
        RestoreOutcome::InvalidState => "invalid-state".into(),
    }
}

fn denied_name(d: &RestoreDenied) -> &'static str {
    match d {
        RestoreDenied::NoCheckpoint => "no-checkpoint",
        RestoreDenied::Unreadable => "unreadable",
        RestoreDenied::Truncated => "truncated",
        RestoreDenied::Corrupted => "corrupted",
        RestoreDenied::OtherConfiguration => "other-configuration",
        RestoreDenied::WrongSize => "wrong-size",
        RestoreDenied::Older => "older",
        RestoreDenied::NotAChunk => "not-a-chunk",
    }
}

/// Gathers the frames of saves and restores into [`Transfer`]s.
#[derive(Debug, Default)]
pub struct Transfers {
    save: Option<Transfer>,
    restore: Option<Transfer>,
    /// Every transfer closed, in the order closed.
    done: Vec<Transfer>,
    /// Index in `done` of the first not yet taken by [`Transfers::take_new`].
    taken: usize,
}

impl Transfers {
    /// Whether `msg` is a frame of a transfer: it goes into a [`Transfer`]
    /// rather than a row of its own.
    pub fn is_transfer_frame(msg: &ToHost) -> bool {
        matches!(
            msg,
            ToHost::CheckpointChunk(_)
                | ToHost::RestoreWanted(_)
                | ToHost::Restored(_)
                | ToHost::Checkpoint(CheckpointReport::Streamed { .. })
        )
    }

    /// Takes one decoded frame of `frame_bytes` bytes at `time_s`; true if
    /// it belongs to a transfer ([`Transfers::is_transfer_frame`]).
    pub fn frame(&mut self, msg: &ToHost, frame_bytes: u64, time_s: f64) -> bool {
        match msg {
            ToHost::CheckpointChunk(c) => self.chunk(c, frame_bytes, time_s),
            ToHost::Checkpoint(CheckpointReport::Streamed { generation, chunks, image_len }) => {
                let mut t = match self.save.take() {
                    Some(t) if t.generation == Some(*generation) => t,
                    other => {
                        // Every chunk of this save was lost (or the
                        // capture began after them): the report alone.
                        if let Some(t) = other {
                            self.close(t, "cut-off");
                        }
                        let mut t = Transfer::new(Direction::Save, *image_len, time_s);
                        t.generation = Some(*generation);
                        t
                    }
                };
                t.board_bytes += frame_bytes;
                t.ended_s = time_s;
                t.reported = true;
                t.reported_chunks = Some(*chunks);
                let outcome = if t.chunks == *chunks { "streamed" } else { "incomplete" };
                self.close(t, outcome);
            }
            ToHost::RestoreWanted(r) => self.request(r, frame_bytes, time_s),
            ToHost::Restored(outcome) => {
                let mut t = self.restore.take().unwrap_or_else(|| {
                    // The requests were lost, or the capture began after
                    // them: the report alone.
                    Transfer::new(Direction::Restore, 0, time_s)
                });
                t.board_bytes += frame_bytes;
                t.ended_s = time_s;
                t.reported = true;
                if let RestoreOutcome::Loaded { generation, chunks } = outcome {
                    t.generation = Some(*generation);
                    t.chunks = *chunks;
                }
                self.close(t, restore_outcome_name(outcome));
            }
            ToHost::Hello(_) => {
                // A board announces itself at boot: what it was sending
                // before never ends.
                self.interrupt("cut-off");
                return false;
            }
            _ => return false,
        }
        true
    }

    fn chunk(&mut self, c: &Chunk, frame_bytes: u64, time_s: f64) {
        // A save starts with its first body chunk (header last); a chunk of
        // another generation, or a first body chunk again (a board cut off
        // mid-save and restored saves the same generation again), starts
        // another.
        let starts = c.offset == HEADER_LEN as u32;
        let continues = self.save.as_ref().is_some_and(|t| t.generation == Some(c.generation) && !starts);
        if !continues {
            if let Some(t) = self.save.take() {
                self.close(t, "cut-off");
            }
            let mut t = Transfer::new(Direction::Save, c.image_len, time_s);
            t.generation = Some(c.generation);
            self.save = Some(t);
        }
        if let Some(t) = self.save.as_mut() {
            t.chunks += 1;
            t.board_bytes += frame_bytes;
            t.ended_s = time_s;
        }
    }

    fn request(&mut self, r: &RestoreRequest, frame_bytes: u64, time_s: f64) {
        if r.offset == 0 || self.restore.is_none() {
            if let Some(t) = self.restore.take() {
                self.close(t, "cut-off");
            }
            self.restore = Some(Transfer::new(Direction::Restore, r.image_len, time_s));
        }
        if let Some(t) = self.restore.as_mut() {
            t.requests += 1;
            t.board_bytes += frame_bytes;
            t.ended_s = time_s;
        }
    }

    /// The host answered the restore in progress with `chunks` chunks in
    /// `bytes` frame bytes (its side of the link, which the stream from
    /// the board does not hold).
    pub fn answered(&mut self, chunks: u32, bytes: u64) {
        if let Some(t) = self.restore.as_mut() {
            t.chunks += chunks;
            t.host_bytes += bytes;
        }
    }

    /// Ends the transfers in progress with `outcome`: `cut-off` (the
    /// board restarted: a power cut, a reset) or `unfinished` (the
    /// capture ended inside them).
    pub fn interrupt(&mut self, outcome: &str) {
        if let Some(t) = self.save.take() {
            self.close(t, outcome);
        }
        if let Some(t) = self.restore.take() {
            self.close(t, outcome);
        }
    }

    fn close(&mut self, t: Transfer, outcome: impl Into<String>) {
        let t = t.close(outcome);
        self.done.push(t);
    }

    /// The transfers closed since the last call, in order.
    pub fn take_new(&mut self) -> &[Transfer] {
        let from = self.taken;
        self.taken = self.done.len();
        &self.done[from..]
    }

    /// Every transfer closed so far.
    pub fn all(&self) -> &[Transfer] {
        &self.done
    }
}
