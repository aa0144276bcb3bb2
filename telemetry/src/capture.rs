//! Telemetry capture: decoding `pada_core::wire` frames from any byte
//! stream (a board's serial port, a recorded file, a SIL run, a host
//! simulation's `--telemetry` stream), recording them as CSV, counting every
//! loss, and the live one-line status of `pada capture`.
//!
//! The decoder ([`pada_core::wire::FrameDecoder`]) resynchronises at the
//! next frame delimiter after garbage, so a bad frame costs that frame only;
//! nothing here stops on one. Losses are counted by kind (CRC, COBS,
//! oversize, too short, undecodable) and by sequence gap (frames missing).
//!
//! A checkpoint streamed to or from the host (LEO on the F429: up to
//! 65 543 chunks a save, a request per batch of a restore) is one CSV
//! row per save and per restore ([`transfer`]), not one per frame; the raw
//! stream keeps every frame.

pub mod digits;
pub mod transfer;

use pada_core::wire::{Decoded, FrameError, HostDecoder, LinkStats, RunMode, StepKind, ToHost};
use serde::Serialize;
use std::fmt::Write as _;
use std::io::Write;

/// The CSV header of [`Recorder`]'s rows: one row per frame, per lost frame
/// and per sequence gap, except the frames of a checkpoint transfer, which
/// make one row per save (`checkpoint-save`) and per restore
/// (`checkpoint-restore`) with its `generation`, image `bytes`, `chunks`,
/// `link_s` (seconds on the telemetry link) and `outcome`
/// ([`transfer::Transfer`]). Vectors (`state`, `output`, `damage`,
/// `reengagements`) are space-separated within their cell. Numbers are
/// written to the digits a person reads ([`digits`]): `state` and `output`
/// to three decimals, `reward`, `td_error` (as a real number, not the wire's
/// raw Q15.16) and `damage` to four significant digits; `telemetry.bin`
/// keeps them exactly.
pub const CSV_HEADER: &[&str] = &[
    "time_s",
    "seq",
    "kind",
    "step",
    "time_ms",
    "episode",
    "mode",
    "step_kind",
    "state",
    "action",
    "output",
    "reward",
    "td_error",
    "explored",
    "damage",
    "reengagements",
    "loop_us",
    "agent_cycles",
    "return",
    "length",
    "weights_checksum",
    "generation",
    "bytes",
    "chunks",
    "link_s",
    "outcome",
    "detail",
];

/// Column of [`CSV_HEADER`] named `name` (a const: a wrong name fails the
/// build).
const fn col(name: &str) -> usize {
    let mut i = 0;
    while i < CSV_HEADER.len() {
        if const_eq(CSV_HEADER[i], name) {
            return i;
        }
        i += 1;
    }
    panic!("no such CSV column");
}

const fn const_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const DETAIL: usize = col("detail");
const GENERATION: usize = col("generation");
const BYTES: usize = col("bytes");
const CHUNKS: usize = col("chunks");
const LINK_S: usize = col("link_s");
const OUTCOME: usize = col("outcome");

/// Frames decoded, by message.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct MessageCounts {
    /// `Hello`.
    pub hello: u64,
    /// `Step`.
    pub step: u64,
    /// `Episode`.
    pub episode: u64,
    /// `Health`.
    pub health: u64,
    /// `State`.
    pub state: u64,
    /// `Fault`.
    pub fault: u64,
    /// `CheckpointChunk`: the chunks of saves streamed to the host (one
    /// CSV row per save, not per chunk).
    pub checkpoint_chunk: u64,
    /// `RestoreWanted`: a restoring board's requests, one per batch of
    /// chunks (one CSV row per restore, not per request).
    pub restore_wanted: u64,
    /// Everything else (checkpoint report, restored, log, warning,
    /// weights, ack, nack, policy).
    pub other: u64,
}

/// The latest of what the status line shows.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Latest {
    /// Control step of the last `Step`.
    pub step: Option<u32>,
    /// Learning episodes finished.
    pub learning_episodes: u64,
    /// Test episodes finished.
    pub test_episodes: u64,
    /// Return of the last learning episode.
    pub learning_return: Option<f32>,
    /// Return of the last test episode.
    pub test_return: Option<f32>,
    /// Accumulated damage J per learned joint (last `Step`).
    pub damage: Vec<f64>,
    /// Backlash re-engagements per learned joint (last `Step`).
    pub reengagements: Vec<u32>,
    /// The last fault's cause.
    pub fault: Option<String>,
    /// The last state.
    pub state: Option<String>,
    /// The claim table's occupancy in the last `Health` (a board whose
    /// table is a claim table).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table: Option<TableOccupancy>,
}

/// What a [`Recorder`] hands every frame to besides its own counters
/// (`pada::mcap`: MCAP and the Foxglove server). A trait here, so
/// that the capture path need not import what it feeds.
pub trait FrameTap {
    /// A decoded frame, with the link's counters after it.
    fn frame(&mut self, frame: &Decoded<ToHost>, stats: LinkStats) -> std::io::Result<()>;
    /// A lost frame, with the link's counters after it.
    fn lost(&mut self, e: &FrameError, stats: LinkStats) -> std::io::Result<()>;
    /// A checkpoint save or restore ended (its frames went to
    /// [`FrameTap::frame`] too), with the link's counters.
    fn transfer(&mut self, t: &transfer::Transfer, stats: LinkStats) -> std::io::Result<()>;
    /// The end of the stream, with the final counters.
    fn finish(&mut self, stats: LinkStats) -> std::io::Result<()>;
}

/// A claim table's occupancy as the board's `Health` reports it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TableOccupancy {
    /// Slots claimed.
    pub claimed: u32,
    /// Slots in the table.
    pub slots: u32,
    /// The claimed fraction, 0–1.
    pub fraction: f64,
    /// Claims refused (updates dropped because the table was full).
    pub claims_refused: u32,
}

impl TableOccupancy {
    /// The occupancy a `Health` reports, `None` for a plain table.
    pub fn of(h: &pada_core::wire::Health) -> Option<TableOccupancy> {
        (h.table_slots > 0).then(|| TableOccupancy {
            claimed: h.table_claimed,
            slots: h.table_slots,
            fraction: h.table_claimed as f64 / h.table_slots as f64,
            claims_refused: h.claims_refused,
        })
    }
}

/// The error for a stream of another telemetry protocol (a recording or a
/// board of another pada): one line that says why it is refused.
fn foreign_protocol(found: u16) -> std::io::Error {
    let this = pada_core::wire::PROTOCOL_VERSION;
    let why = if found < this {
        "an older pada wrote it (protocol 10 reports a servo's hardware alert); read it with that version"
    } else {
        "a newer pada wrote it; update this one"
    };
    std::io::Error::new(
        std::io::ErrorKind::InvalidData,
        format!("the stream speaks telemetry protocol {found}, this pada reads protocol {this}: {why}"),
    )
}

/// Decodes a telemetry stream, writes CSV, keeps counts.
pub struct Recorder {
    decoder: HostDecoder,
    csv: Option<csv::Writer<Box<dyn Write + Send>>>,
    counts: MessageCounts,
    latest: Latest,
    /// The channels of an MCAP file or a live Foxglove view, when asked for.
    tap: Option<Box<dyn FrameTap + Send>>,
    /// Saves and restores of a checkpoint the host keeps, gathered from
    /// their frames.
    transfers: transfer::Transfers,
    /// Link bytes counted when the last frame ended (decoded or lost): a
    /// frame's bytes are the difference.
    bytes_at_frame_end: u64,
}

impl Recorder {
    /// A recorder writing CSV to `csv` (header first), or none.
    pub fn new(csv: Option<Box<dyn Write + Send>>) -> std::io::Result<Self> {
        let csv = match csv {
            Some(w) => {
                let mut w = csv::Writer::from_writer(w);
                w.write_record(CSV_HEADER)?;
                Some(w)
            }
            None => None,
        };
        Ok(Recorder {
            decoder: HostDecoder::new(),
            csv,
            counts: MessageCounts::default(),
            latest: Latest::default(),
            tap: None,
            transfers: transfer::Transfers::default(),
            bytes_at_frame_end: 0,
        })
    }

    /// Also hands every frame, lost frame and gap to `tap` (`--mcap`,
    /// `--foxglove`); [`Recorder::close_tap`] ends it.
    pub fn set_tap(&mut self, tap: impl FrameTap + Send + 'static) {
        self.tap = Some(Box::new(tap));
    }

    /// Ends the tap, if any: the final link counters, then its sinks close
    /// (the MCAP file's summary and metadata are written).
    pub fn close_tap(&mut self) -> std::io::Result<()> {
        let stats = self.stats();
        match self.tap.take() {
            Some(mut tap) => tap.finish(stats),
            None => Ok(()),
        }
    }

    /// Feeds received bytes at `time_s` (the caller's clock); every decoded
    /// frame is recorded and pushed to `frames`.
    pub fn feed(
        &mut self,
        bytes: &[u8],
        time_s: f64,
        frames: &mut Vec<Decoded<ToHost>>,
    ) -> std::io::Result<()> {
        for &byte in bytes {
            let Some(result) = self.decoder.push(byte) else {
                continue;
            };
            match result {
                Ok(frame) => {
                    if let ToHost::Hello(h) = &frame.msg {
                        if h.protocol != pada_core::wire::PROTOCOL_VERSION {
                            return Err(foreign_protocol(h.protocol));
                        }
                    }
                    let frame_bytes = self.decoder.stats().bytes - self.bytes_at_frame_end;
                    self.bytes_at_frame_end = self.decoder.stats().bytes;
                    if let Some(gap) = frame.gap {
                        let detail = if gap.is_resync() {
                            format!(
                                "expected seq {} got {} (resynchronised: too far to count frames)",
                                gap.expected, gap.got
                            )
                        } else {
                            format!(
                                "expected seq {} got {} ({} missed)",
                                gap.expected,
                                gap.got,
                                gap.missed()
                            )
                        };
                        self.row_other(time_s, Some(frame.seq), "gap", &detail)?;
                    }
                    self.note(&frame.msg);
                    // A transfer's frames make its one row when it ends (a
                    // Hello ends the one in progress first).
                    let in_transfer = self.transfers.frame(&frame.msg, frame_bytes, time_s);
                    self.write_transfers()?;
                    if !in_transfer {
                        self.row(time_s, &frame)?;
                    }
                    if let Some(tap) = self.tap.as_mut() {
                        tap.frame(&frame, self.decoder.stats())?;
                    }
                    frames.push(frame);
                }
                Err(e) => {
                    if let Some(found) = self.decoder.foreign_protocol() {
                        return Err(foreign_protocol(found));
                    }
                    self.bytes_at_frame_end = self.decoder.stats().bytes;
                    self.row_other(time_s, None, "lost", &loss_name(&e))?;
                    if let Some(tap) = self.tap.as_mut() {
                        tap.lost(&e, self.decoder.stats())?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The input has ended (end of file, the port closed): a frame still in
    /// progress can never complete, so it is counted as lost
    /// ([`FrameError::Truncated`]) and recorded as a `lost` row at
    /// `time_s`. Returns whether there was one.
    pub fn finish(&mut self, time_s: f64) -> std::io::Result<bool> {
        match self.decoder.finish() {
            Some(e) => {
                self.row_other(time_s, None, "lost", &loss_name(&e))?;
                if let Some(tap) = self.tap.as_mut() {
                    tap.lost(&e, self.decoder.stats())?;
                }
                Ok(true)
            }
            None => Ok(false),
        }
    }

    /// The sender restarted on purpose (a board booted again after a
    /// power cut or a reset): its sequence numbers start over, so the next
    /// frame is not a gap; a frame cut short by the restart counts as lost;
    /// a checkpoint transfer in progress is recorded as `cut-off`.
    /// Returns whether a frame was cut short.
    pub fn restarted(&mut self) -> std::io::Result<bool> {
        let cut = match self.decoder.finish() {
            Some(e) => {
                self.bytes_at_frame_end = self.decoder.stats().bytes;
                if let Some(tap) = self.tap.as_mut() {
                    // A sink's write error shows again at close_tap.
                    let _ = tap.lost(&e, self.decoder.stats());
                }
                true
            }
            None => false,
        };
        self.decoder.resync_seq();
        self.transfers.interrupt("cut-off");
        self.write_transfers()?;
        Ok(cut)
    }

    /// The capture is over (after [`Recorder::finish`] when the input
    /// ended): a checkpoint save or restore still in progress is recorded
    /// as `unfinished`, so that every transfer begun has its row.
    pub fn end(&mut self) -> std::io::Result<()> {
        self.transfers.interrupt("unfinished");
        self.write_transfers()
    }

    /// The host answered the board's restore request in progress with
    /// `chunks` chunks in `bytes` frame bytes: the host-to-board half of the
    /// restore's link time, which the board's stream does not carry.
    pub fn answered(&mut self, chunks: u32, bytes: u64) {
        self.transfers.answered(chunks, bytes);
    }

    /// Every checkpoint save and restore recorded so far, in order.
    pub fn transfers(&self) -> &[transfer::Transfer] {
        self.transfers.all()
    }

    /// Writes the rows of the transfers that ended since the last call and
    /// hands them to the tap.
    fn write_transfers(&mut self) -> std::io::Result<()> {
        let stats = self.decoder.stats();
        for t in self.transfers.take_new() {
            if let Some(w) = self.csv.as_mut() {
                w.write_record(transfer_row(t)).map_err(std::io::Error::other)?;
            }
            if let Some(tap) = self.tap.as_mut() {
                tap.transfer(t, stats)?;
            }
        }
        Ok(())
    }

    /// Link counters: frames, bytes, every kind of loss.
    pub fn stats(&self) -> LinkStats {
        self.decoder.stats()
    }

    /// Frames by message.
    pub fn counts(&self) -> MessageCounts {
        self.counts
    }

    /// The latest values.
    pub fn latest(&self) -> &Latest {
        &self.latest
    }

    /// Flushes the CSV.
    pub fn flush(&mut self) -> std::io::Result<()> {
        if let Some(w) = self.csv.as_mut() {
            w.flush()?;
        }
        Ok(())
    }

    /// The live status: steps, episodes and returns, fatigue, losses.
    pub fn status_line(&self) -> String {
        let s = self.stats();
        let l = &self.latest;
        let mut line = String::new();
        let _ = write!(line, "frames {}", s.frames);
        if let Some(step) = l.step {
            let _ = write!(line, "  step {step}");
        }
        let _ = write!(
            line,
            "  episodes {}+{} test",
            l.learning_episodes, l.test_episodes
        );
        if let Some(r) = l.learning_return {
            let _ = write!(line, "  return {r:.1}");
        }
        if let Some(r) = l.test_return {
            let _ = write!(line, "  test {r:.1}");
        }
        if !l.damage.is_empty() {
            let j: f64 = l.damage.iter().sum();
            let n: u64 = l.reengagements.iter().map(|&r| r as u64).sum();
            let _ = write!(line, "  J {j:.3e}  re-engagements {n}");
        }
        if let Some(f) = &l.fault {
            let _ = write!(line, "  FAULT {f}");
        }
        let _ = write!(
            line,
            "  lost: gaps {} ({} frames) crc {} cobs {} other {}",
            s.seq_gaps,
            s.frames_missed,
            s.crc_errors,
            s.cobs_errors,
            s.oversize + s.too_short + s.decode_errors + s.noncanonical + s.truncated
        );
        line
    }

    fn note(&mut self, msg: &ToHost) {
        let c = &mut self.counts;
        let l = &mut self.latest;
        match msg {
            ToHost::Hello(_) => c.hello += 1,
            ToHost::Step(s) => {
                c.step += 1;
                l.step = Some(s.step);
                l.damage = s.joints.iter().map(|j| j.damage).collect();
                l.reengagements = s.joints.iter().map(|j| j.reengagements).collect();
            }
            ToHost::Episode(e) => {
                c.episode += 1;
                match e.mode {
                    RunMode::Learning => {
                        l.learning_episodes += 1;
                        l.learning_return = Some(e.total_reward);
                    }
                    RunMode::Testing => {
                        l.test_episodes += 1;
                        l.test_return = Some(e.total_reward);
                    }
                }
            }
            ToHost::Health(h) => {
                c.health += 1;
                l.table = TableOccupancy::of(h);
            }
            ToHost::State(s) => {
                c.state += 1;
                l.state = Some(format!("{:?}", s.to));
                if s.to.fault().is_none() {
                    l.fault = None;
                }
            }
            ToHost::Fault(f) => {
                c.fault += 1;
                l.fault = Some(f.cause.name().to_string());
            }
            ToHost::CheckpointChunk(_) => c.checkpoint_chunk += 1,
            ToHost::RestoreWanted(_) => c.restore_wanted += 1,
            _ => c.other += 1,
        }
    }

    fn row(&mut self, time_s: f64, frame: &Decoded<ToHost>) -> std::io::Result<()> {
        let Some(w) = self.csv.as_mut() else {
            return Ok(());
        };
        let mut r: Vec<String> = vec![String::new(); CSV_HEADER.len()];
        r[0] = format!("{time_s:.6}");
        r[1] = frame.seq.to_string();
        let join = |v: &mut dyn Iterator<Item = String>| v.collect::<Vec<_>>().join(" ");
        match &frame.msg {
            ToHost::Step(s) => {
                r[2] = "step".into();
                r[3] = s.step.to_string();
                r[4] = s.time_ms.to_string();
                r[5] = s.episode.to_string();
                r[6] = mode_name(s.mode).into();
                r[7] = step_kind_name(s.kind).into();
                r[8] = join(&mut s.state.iter().map(|&x| digits::fixed3(x as f64)));
                r[9] = s.action.to_string();
                r[10] = join(&mut s.output.iter().map(|&x| digits::fixed3(x as f64)));
                r[11] = digits::sig4(s.reward as f64);
                r[12] = digits::sig4(s.td_error as f64 / (1u64 << pada_core::fixed::Q16_FRAC_BITS) as f64);
                r[13] = (s.explored as u8).to_string();
                r[14] = join(&mut s.joints.iter().map(|j| digits::sig4(j.damage)));
                r[15] = join(&mut s.joints.iter().map(|j| j.reengagements.to_string()));
                r[16] = s.loop_us.to_string();
                r[17] = s.agent_cycles.to_string();
            }
            ToHost::Episode(e) => {
                r[2] = "episode".into();
                r[5] = e.index.to_string();
                r[6] = mode_name(e.mode).into();
                r[18] = e.total_reward.to_string();
                r[19] = e.length.to_string();
                r[20] = format!("{:08x}", e.weights_checksum);
            }
            other => {
                let (kind, detail) = describe(other);
                r[2] = kind.into();
                r[DETAIL] = detail;
            }
        }
        w.write_record(&r).map_err(std::io::Error::other)
    }

    fn row_other(
        &mut self,
        time_s: f64,
        seq: Option<u32>,
        kind: &str,
        detail: &str,
    ) -> std::io::Result<()> {
        let Some(w) = self.csv.as_mut() else {
            return Ok(());
        };
        let mut r: Vec<String> = vec![String::new(); CSV_HEADER.len()];
        r[0] = format!("{time_s:.6}");
        r[1] = seq.map(|s| s.to_string()).unwrap_or_default();
        r[2] = kind.into();
        r[DETAIL] = detail.into();
        w.write_record(&r).map_err(std::io::Error::other)
    }
}

/// The CSV row of one checkpoint save or restore: its end's time, no
/// sequence number (it stands for many frames), its kind and columns.
fn transfer_row(t: &transfer::Transfer) -> Vec<String> {
    let mut r: Vec<String> = vec![String::new(); CSV_HEADER.len()];
    r[0] = format!("{:.6}", t.ended_s);
    r[2] = t.direction.row_kind().into();
    r[GENERATION] = t.generation.map(|g| g.to_string()).unwrap_or_default();
    r[BYTES] = t.bytes.to_string();
    r[CHUNKS] = t.chunks.to_string();
    r[LINK_S] = format!("{:.3}", t.link_s);
    r[OUTCOME] = t.outcome.clone();
    r[DETAIL] = t.detail();
    r
}

/// The CSV name of a run mode.
pub fn mode_name(m: RunMode) -> &'static str {
    match m {
        RunMode::Learning => "learning",
        RunMode::Testing => "testing",
    }
}

/// The CSV name of a step kind.
pub fn step_kind_name(k: StepKind) -> &'static str {
    match k {
        StepKind::Start => "start",
        StepKind::Step => "step",
        StepKind::Absorbing => "absorbing",
        StepKind::Timeout => "timeout",
    }
}

/// The CSV name of a lost frame.
pub fn loss_name(e: &FrameError) -> String {
    match e {
        FrameError::Oversize => "oversize".into(),
        FrameError::Cobs => "cobs".into(),
        FrameError::TooShort => "too-short".into(),
        FrameError::Crc { computed, received } => {
            format!("crc (computed {computed:08x}, received {received:08x})")
        }
        FrameError::Decode => "undecodable".into(),
        FrameError::NonCanonical => "non-canonical".into(),
        FrameError::Truncated => "truncated (the input ended inside a frame)".into(),
    }
}

/// A message other than Step and Episode: its CSV kind and a one-line
/// description.
pub fn describe(msg: &ToHost) -> (&'static str, String) {
    match msg {
        ToHost::Hello(h) => (
            "hello",
            format!(
                "protocol {} config {:08x} weights {} period {} us state dims {} joints {}",
                h.protocol, h.config_hash, h.weight_count, h.period_us, h.state_dims, h.joints
            ),
        ),
        ToHost::Health(h) => (
            "health",
            format!(
                "uptime {} ms temps {:?} min voltage {} dV bus errors {} checksum errors {} timeouts {} overruns {} max loop {} us telemetry drops {} table claimed {} of {} refused {}",
                h.uptime_ms,
                h.servo_temps_c.as_slice(),
                h.min_voltage_dv,
                h.bus_errors,
                h.checksum_errors,
                h.timeouts,
                h.overruns,
                h.max_loop_us,
                h.telemetry_drops,
                h.table_claimed,
                h.table_slots,
                h.claims_refused
            ),
        ),
        ToHost::State(s) => ("state", format!("{:?} -> {:?} at step {}", s.from, s.to, s.step)),
        ToHost::Fault(f) => ("fault", format!("{} {:?} at step {} ({} ms)", f.cause.name(), f.cause, f.step, f.time_ms)),
        ToHost::Checkpoint(c) => ("checkpoint", format!("{c:?}")),
        ToHost::Log(l) => ("log", format!("{:?} {}", l.level, l.text.as_str())),
        ToHost::Warning(w) => ("warning", format!("{w:?}")),
        ToHost::Weights(w) => ("weights", format!("offset {} of {} ({} weights)", w.offset, w.total, w.weights.len())),
        ToHost::Ack(a) => ("ack", format!("seq {}", a.seq)),
        ToHost::Nack(n) => ("nack", format!("seq {} {:?}", n.seq, n.reason)),
        ToHost::Policy(p) => (
            "policy",
            match &p.governor {
                // The wear governor's move or status: the Δ or α in force and
                // the damage rate it measured.
                Some(g) => format!(
                    "{:?} switched {} at step {}; wear governor: budget {} s, {:?} {} (rung {} of {}), damage rate {:e} per s, window MTBF {} s over {} actions, {} moves, {} actions over budget",
                    p.built,
                    p.switched_to_sarsa,
                    p.step,
                    g.budget_s,
                    g.restricts,
                    g.parameter,
                    g.rung + 1,
                    g.rungs,
                    g.damage_rate,
                    g.window_mtbf_s,
                    g.window_steps,
                    g.moves,
                    g.over_budget_steps
                ),
                None => format!("{:?} switched {} at step {}", p.built, p.switched_to_sarsa, p.step),
            },
        ),
        ToHost::CheckpointChunk(c) => (
            "checkpoint-chunk",
            format!("generation {} offset {} covers {} of {} bytes", c.generation, c.offset, c.covered_len(), c.image_len),
        ),
        ToHost::RestoreWanted(r) => (
            "restore-wanted",
            format!("config {:08x} image {} bytes from offset {}", r.config_hash, r.image_len, r.offset),
        ),
        ToHost::Restored(o) => ("restored", format!("{o:?}")),
        ToHost::Step(_) => ("step", String::new()),
        ToHost::Episode(_) => ("episode", String::new()),
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod transfer_tests;
