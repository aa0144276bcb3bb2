//! MCAP recordings of telemetry (`--mcap FILE`), and the channel list they
//! share with the live Foxglove server (`--foxglove`).
//!
//! - [`channels`]: which record goes on which topic, as what JSON, with
//!   the board's clock as log time;
//! - [`schemas`]: each channel's JSON Schema;
//! - [`scene`]: the robot drawn from its joint angles (`/scene`);
//! - [`writer`]: the MCAP file, with pada's version and the configuration
//!   hash in its metadata;
//! - [`read`]: a recording read back into `pada capture`'s summary.
//!
//! (The `pada` command adds two of its own: the scene strip drawn as a
//! PNG for the summary, and the `--mcap` tee of a host run.)
//!
//! A [`Tap`] sits in the capture path ([`crate::capture::Recorder`]): it
//! sees every decoded frame, every lost frame and every sequence gap, and
//! hands each channel message to its sinks (the file, the live server).

pub mod channels;
pub mod read;
pub mod scene;
pub mod schemas;
pub mod writer;

use channels::{ChannelMessage, Channelizer};
use pada_core::wire::{Decoded, FrameError, Hello, LinkStats, SeqGap, ToHost};

/// What a sink learns at the end of the stream.
#[derive(Debug, Clone)]
pub struct StreamEnd<'a> {
    /// The link's final counters.
    pub stats: LinkStats,
    /// Every `Hello` the stream carried.
    pub hellos: &'a [Hello],
}

/// Somewhere channel messages go.
pub trait ChannelSink: Send {
    /// One message.
    fn write(&mut self, msg: &ChannelMessage) -> std::io::Result<()>;
    /// The stream has ended (its last `/link` message was written).
    fn finish(&mut self, end: &StreamEnd<'_>) -> std::io::Result<()>;
}

/// The channel messages of a stream, to one or more sinks.
pub struct Tap {
    channels: Channelizer,
    sinks: Vec<Box<dyn ChannelSink>>,
    out: Vec<ChannelMessage>,
}

impl crate::capture::FrameTap for Tap {
    fn frame(&mut self, frame: &Decoded<ToHost>, stats: LinkStats) -> std::io::Result<()> {
        Tap::frame(self, frame, stats)
    }

    fn lost(&mut self, e: &FrameError, stats: LinkStats) -> std::io::Result<()> {
        Tap::lost(self, e, stats)
    }

    fn transfer(&mut self, t: &crate::capture::transfer::Transfer, _stats: LinkStats) -> std::io::Result<()> {
        let m = self.channels.transfer(t);
        self.out.push(m);
        self.flush()
    }

    fn finish(&mut self, stats: LinkStats) -> std::io::Result<()> {
        Tap::finish(self, stats)
    }
}

impl Tap {
    /// A tap feeding `sinks`.
    pub fn new(sinks: Vec<Box<dyn ChannelSink>>) -> Self {
        Tap { channels: Channelizer::new(), sinks, out: Vec::new() }
    }

    /// A decoded frame, with the link's counters after it.
    pub fn frame(&mut self, frame: &Decoded<ToHost>, stats: LinkStats) -> std::io::Result<()> {
        if let Some(gap) = &frame.gap {
            let m = self.channels.gap(gap, frame.seq, stats);
            self.out.push(m);
        }
        self.channels.frame(frame, &mut self.out);
        if matches!(frame.msg, ToHost::Health(_)) {
            let m = self.channels.counters("health", stats, frame.seq);
            self.out.push(m);
        }
        self.flush()
    }

    /// A sequence gap reported on its own (kept for callers that see gaps
    /// apart from frames).
    pub fn gap(&mut self, gap: &SeqGap, seq: u32, stats: LinkStats) -> std::io::Result<()> {
        let m = self.channels.gap(gap, seq, stats);
        self.out.push(m);
        self.flush()
    }

    /// A lost frame, with the link's counters after it.
    pub fn lost(&mut self, e: &FrameError, stats: LinkStats) -> std::io::Result<()> {
        let m = self.channels.lost(e, stats);
        self.out.push(m);
        self.flush()
    }

    /// The end of the stream: the final `/link` message, then every sink
    /// closes. Every sink is finished even when one fails; the first error
    /// is returned.
    pub fn finish(&mut self, stats: LinkStats) -> std::io::Result<()> {
        let m = self.channels.counters("end", stats, 0);
        self.out.push(m);
        let mut result = self.flush();
        let end = StreamEnd { stats, hellos: self.channels.hellos() };
        for s in &mut self.sinks {
            let r = s.finish(&end);
            if result.is_ok() {
                result = r;
            }
        }
        result
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let mut result = Ok(());
        for m in self.out.drain(..) {
            for s in &mut self.sinks {
                if let Err(e) = s.write(&m) {
                    if result.is_ok() {
                        result = Err(e);
                    }
                }
            }
        }
        result
    }
}
