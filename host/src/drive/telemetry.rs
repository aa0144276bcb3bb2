//! `pada drive`'s telemetry: the controller's messages framed as a board
//! frames them (`pada_core::wire`, numbered, CRC-32, COBS) on a thread of
//! their own, so that writing files never delays a period. Every frame
//! goes through `pada capture`'s recorder (the CSV, the MCAP file and the
//! live Foxglove view, each frame decoded and its losses counted) and, with
//! `--telemetry`, to a file or to `pada watch` over TCP. A message the
//! queue has no room for is dropped and counted, and its sequence number
//! skipped, so the recorder sees the gap as a board's link would show it.

use crate::capture::{Latest, MessageCounts, Recorder};
use crate::telemetry::{TelemetrySink, TelemetryTotals};
use pada_core::wire::{FrameEncoder, LinkStats, ToHost, MAX_FRAME_LEN};
use serde::Serialize;
use std::io::Write;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::Instant;

/// Messages the queue holds: minutes of a 33 Hz robot's steps.
const QUEUE: usize = 1 << 16;

struct Outgoing {
    msg: ToHost,
    skipped: u32,
}

/// What the telemetry carried.
#[derive(Debug, Clone, Serialize)]
pub struct TelemetryReport {
    /// The recorder's link counters: frames, bytes, every loss.
    pub link: LinkStats,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The latest values.
    pub latest: Latest,
    /// Messages dropped because the queue was full.
    pub dropped: u32,
    /// What `--telemetry` carried.
    #[serde(skip)]
    pub sink: Option<TelemetryTotals>,
}

/// The running pipeline.
pub struct TelemetryPipe {
    tx: SyncSender<Outgoing>,
    handle: JoinHandle<anyhow::Result<(LinkStats, MessageCounts, Latest, Option<TelemetryTotals>)>>,
    skipped: u32,
    dropped: u32,
}

impl TelemetryPipe {
    /// Starts the thread: frames into a recorder writing `csv` and feeding
    /// `tap` (MCAP, Foxglove), and to `sink`.
    pub fn start(
        csv: Option<Box<dyn Write + Send>>,
        tap: Option<crate::mcap::Tap>,
        sink: Option<TelemetrySink>,
    ) -> anyhow::Result<TelemetryPipe> {
        let mut rec = Recorder::new(csv)?;
        if let Some(tap) = tap {
            rec.set_tap(tap);
        }
        let (tx, rx) = sync_channel(QUEUE);
        let handle = std::thread::Builder::new().name("telemetry".into()).spawn(move || run(rx, rec, sink))?;
        Ok(TelemetryPipe { tx, handle, skipped: 0, dropped: 0 })
    }

    /// Queues a message; a full queue drops it (counted, and a gap in the
    /// sequence).
    pub fn send(&mut self, msg: ToHost) {
        match self.tx.try_send(Outgoing { msg, skipped: self.skipped }) {
            Ok(()) => self.skipped = 0,
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
                self.skipped += 1;
                self.dropped += 1;
            }
        }
    }

    /// Messages dropped so far.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Flushes and closes everything (the MCAP file's summary is written
    /// here); the report of what went through.
    pub fn finish(self) -> anyhow::Result<TelemetryReport> {
        drop(self.tx);
        let (link, messages, latest, sink) = self.handle.join().map_err(|_| anyhow::anyhow!("the telemetry thread panicked"))??;
        Ok(TelemetryReport { link, messages, latest, dropped: self.dropped, sink })
    }
}

fn run(
    rx: Receiver<Outgoing>,
    mut rec: Recorder,
    mut sink: Option<TelemetrySink>,
) -> anyhow::Result<(LinkStats, MessageCounts, Latest, Option<TelemetryTotals>)> {
    let started = Instant::now();
    let mut encoder = FrameEncoder::new();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut frames = Vec::new();
    for out in rx {
        for _ in 0..out.skipped {
            encoder.skip();
        }
        let Ok(frame) = encoder.encode(&out.msg, &mut buf) else { continue };
        frames.clear();
        rec.feed(frame, started.elapsed().as_secs_f64(), &mut frames)?;
        if let Some(s) = sink.as_mut() {
            s.forward(frame);
        }
    }
    rec.finish(started.elapsed().as_secs_f64())?;
    rec.flush()?;
    rec.close_tap()?;
    let totals = sink.map(TelemetrySink::finish).transpose()?;
    Ok((rec.stats(), rec.counts(), rec.latest().clone(), totals))
}
