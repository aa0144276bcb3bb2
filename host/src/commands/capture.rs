//! `pada capture`: telemetry from a board's serial port or a recorded
//! stream, decoded, recorded as CSV, with a live one-line status.
//!
//! Nothing stops a capture but the end of its input (end of file), Ctrl-C,
//! or `--seconds`. A serial port that goes away (an adapter pulled, a pty
//! closed) is waited for and opened again at the same path
//! (`crate::serial_link`): each disconnect is counted (`disconnects`), the
//! frame it cut short counts as lost, and what the board sent meanwhile
//! shows as a sequence gap. Otherwise a bad frame is counted and the
//! decoder picks up at the next frame. At the end of the input a frame cut
//! off is counted as lost too (a capture stopped by Ctrl-C or `--seconds`
//! cut it itself, so it is not). A read error ends the capture with its
//! summary and exit code 1.
//!
//! With `--checkpoint PATH` the board's streamed checkpoint is kept at
//! PATH and, with `--port`, sent back when the board asks
//! ([`crate::checkpoint_keeper::KeeperLink`]); a refused chunk or a failed
//! answer is a line on stderr, never the capture's end.

use crate::console::{errln, outln, status_line};
use crate::capture::Recorder;
use crate::serial_link::LinkEvent;
use super::stream_args::{Opened, StreamInput, StreamRecord};
use crate::error::{usage, CliError};
use anyhow::Context;
use clap::Args;
use serde::Serialize;
use std::io::{IsTerminal, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `pada capture`.
#[derive(Debug, Clone, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["port", "file"])))]
pub struct CaptureArgs {
    /// Where the telemetry comes from.
    #[command(flatten)]
    pub input: StreamInput,
    /// What is kept of it.
    #[command(flatten)]
    pub record: StreamRecord,
    /// With --file X.mcap: draw 8 frames over 3 s of its /scene (the robot
    /// from its joint angles; the start of the last test episode that
    /// long, else the end) side by side as a PNG, side view.
    #[arg(long, value_name = "FILE.png")]
    pub scene_png: Option<std::path::PathBuf>,
}

/// The end of a capture.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureSummary {
    /// What was read.
    pub source: String,
    /// Why the capture ended.
    pub ended: String,
    /// Wall-clock duration \[s\].
    pub wall_s: f64,
    /// Frames, bytes and every kind of loss.
    pub link: pada_core::wire::LinkStats,
    /// Frames that could not be used (all kinds).
    pub bad_frames: u32,
    /// Frames by message.
    pub messages: crate::capture::MessageCounts,
    /// The latest values (episodes, returns, fatigue, fault).
    pub latest: crate::capture::Latest,
    /// Times the serial port went away (and was waited for).
    pub disconnects: u32,
    /// What the `--foxglove` live server served, when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub foxglove: Option<crate::foxglove::server::LiveStats>,
}

impl CaptureSummary {
    /// The summary of what `rec` recorded from `source` since `started`.
    pub fn of(rec: &Recorder, source: String, ended: String, started: Instant, disconnects: u32) -> Self {
        let link = rec.stats();
        CaptureSummary {
            source,
            ended,
            wall_s: started.elapsed().as_secs_f64(),
            link,
            bad_frames: link.bad_frames(),
            messages: rec.counts(),
            latest: rec.latest().clone(),
            disconnects,
            foxglove: None,
        }
    }
}

/// `pada capture --file X.mcap`: the summary of a recording, rebuilt from
/// its channels ([`crate::mcap::read`]).
fn replay_mcap(args: &CaptureArgs, path: &std::path::Path) -> Result<(), CliError> {
    let r = &args.record;
    if r.out.is_some() || r.mcap.is_some() || r.foxglove.is_some() || r.seconds.is_some() || r.checkpoint.is_some() {
        return Err(usage(format!(
            "--file {}: an MCAP recording is read back for its summary only; \
             --out, --mcap, --foxglove, --seconds and --checkpoint take a telemetry stream",
            path.display()
        )));
    }
    let started = Instant::now();
    let bytes = std::fs::read(path).map_err(|e| usage(format!("--file {}: cannot read: {e}", path.display())))?;
    let rep = crate::mcap::read::replay(&bytes).map_err(|e| usage(format!("--file {}: {e}", path.display())))?;
    if let Some(png) = &args.scene_png {
        let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        let title = format!(
            "{name}: /scene (foxglove.SceneUpdate lines) drawn by pada, side view. Blue left leg, orange right leg, grey torso, purple arm, green floor"
        );
        // 90 messages: 3 s of LEO (30 Hz) or of the pendulum (33 Hz).
        let picture = crate::mcap::picture::scene_strip_png(&bytes, 8, 90, &title)
            .map_err(|e| usage(format!("--scene-png: {e}")))?;
        std::fs::write(png, picture).map_err(|e| usage(format!("--scene-png {}: cannot write: {e}", png.display())))?;
    }
    let summary = CaptureSummary {
        source: path.display().to_string(),
        ended: "end of file".to_string(),
        wall_s: started.elapsed().as_secs_f64(),
        link: rep.link,
        bad_frames: rep.link.bad_frames(),
        messages: rep.messages,
        latest: rep.latest,
        disconnects: 0,
        foxglove: None,
    };
    if r.json {
        outln!("{}", serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?)?;
    } else {
        let meta = rep.metadata.get(crate::mcap::writer::META_PADA);
        errln!(
            "recording {} (pada {}, configuration {}): {} frames, {} lost, {} sequence gaps ({} frames missing)",
            summary.source,
            meta.and_then(|m| m.get("version")).map_or("?", String::as_str),
            meta.and_then(|m| m.get("config_hash")).map_or("?", String::as_str),
            summary.link.frames,
            summary.bad_frames,
            summary.link.seq_gaps,
            summary.link.frames_missed
        );
        for (topic, n) in &rep.per_topic {
            errln!("  {topic}: {n} messages");
        }
    }
    Ok(())
}

/// Whether `path` is a file that starts as an MCAP file does.
fn is_mcap_file(path: &std::path::Path) -> bool {
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| crate::mcap::read::is_mcap(&head))
}

/// Runs `pada capture`.
pub fn run(args: CaptureArgs) -> Result<(), CliError> {
    args.record.check()?;
    args.input.check()?;
    if args.scene_png.is_some() && !args.input.file.as_deref().is_some_and(is_mcap_file) {
        return Err(usage("--scene-png draws a recording: give --file X.mcap (an MCAP file written by --mcap)"));
    }
    if let Some(file) = args.input.file.as_deref().filter(|f| f.as_os_str() != "-" && is_mcap_file(f)) {
        return replay_mcap(&args, file);
    }
    let Some((mut source, name)) = args.input.open()? else {
        return Err(usage("give --port DEVICE or --file FILE"));
    };
    let mut keeper = args.record.keeper()?;
    if let Some(k) = &keeper {
        errln!("capture: {}", k.describe());
    }
    let csv = args.record.csv()?;
    let mut taps = args.record.taps("capture")?;
    let mut rec = Recorder::new(csv)
        .context("cannot write the CSV header")
        .map_err(CliError::Runtime)?;
    if let Some(tap) = taps.tap.take() {
        rec.set_tap(tap);
    }

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second handler cannot be installed (tests run several captures
        // in one process): then Ctrl-C simply ends the process.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let tty = std::io::stderr().is_terminal();
    let started = Instant::now();
    let mut last_status = Instant::now();
    let mut buf = vec![0u8; 4096];
    let mut frames = Vec::new();
    // Why the capture ended, and whether that was the end of the input
    // (which cuts off a frame in progress) or a read error.
    let (ended, input_ended, read_error) = loop {
        if stop.load(Ordering::SeqCst) {
            break ("interrupted".to_string(), false, false);
        }
        if args
            .record
            .seconds
            .is_some_and(|s| started.elapsed().as_secs_f64() >= s)
        {
            break ("time limit".to_string(), false, false);
        }
        let n = match &mut source {
            Opened::Port(p) => match p.read(&mut buf) {
                LinkEvent::Data(n) => n,
                LinkEvent::Nothing => 0,
                LinkEvent::Lost(why) => {
                    errln!("capture: {name}: {why}; waiting for it to come back (disconnect {})", p.disconnects());
                    // A frame in progress can never complete.
                    rec.finish(started.elapsed().as_secs_f64())
                        .context("cannot write the CSV")
                        .map_err(CliError::Runtime)?;
                    0
                }
                LinkEvent::Back => {
                    errln!("capture: {name} is back");
                    0
                }
            },
            Opened::Reader(r) => match r.read(&mut buf) {
                Ok(0) => break ("end of file".to_string(), true, false),
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => 0,
                Err(e) => break (format!("read error ({e})"), true, true),
            },
        };
        frames.clear();
        rec.feed(&buf[..n], started.elapsed().as_secs_f64(), &mut frames).map_err(|e| {
            if e.kind() == std::io::ErrorKind::InvalidData {
                // A stream of another pada's protocol: bad input, said once.
                usage(e.to_string())
            } else {
                CliError::Runtime(anyhow::Error::new(e).context("cannot write the CSV or the MCAP file"))
            }
        })?;
        if let Some(k) = keeper.as_mut().filter(|_| !frames.is_empty()) {
            let port = match &mut source {
                Opened::Port(p) => Some(p),
                Opened::Reader(_) => None,
            };
            for line in k.frames(&frames, port) {
                errln!("capture: {line}");
            }
            let (chunks, bytes) = k.take_answered();
            rec.answered(chunks, bytes);
        }
        let every = if tty {
            Duration::from_millis(100)
        } else {
            Duration::from_secs(1)
        };
        if last_status.elapsed() >= every {
            last_status = Instant::now();
            status_line(&rec.status_line(), tty, false);
        }
    };
    if input_ended {
        rec.finish(started.elapsed().as_secs_f64())
            .context("cannot write the CSV")
            .map_err(CliError::Runtime)?;
    }
    rec.end().context("cannot write the CSV").map_err(CliError::Runtime)?;
    rec.flush()
        .context("cannot write the CSV")
        .map_err(CliError::Runtime)?;
    for line in keeper.as_mut().map(|k| k.finish()).unwrap_or_default() {
        errln!("capture: {line}");
    }
    let closed = rec.close_tap();
    let live = taps.close("capture");
    closed
        .with_context(|| format!("cannot write the MCAP file {}", args.record.mcap.as_deref().unwrap_or(std::path::Path::new("")).display()))
        .map_err(CliError::Runtime)?;
    status_line(&rec.status_line(), tty, true);
    let disconnects = match &source {
        Opened::Port(p) => p.disconnects(),
        Opened::Reader(_) => 0,
    };
    let mut summary = CaptureSummary::of(&rec, name, ended, started, disconnects);
    summary.foxglove = live;
    if args.record.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?
        )?;
    } else {
        errln!(
            "capture of {} ended ({}): {} frames, {} lost, {} sequence gaps ({} frames missing), {} disconnects",
            summary.source,
            summary.ended,
            summary.link.frames,
            summary.bad_frames,
            summary.link.seq_gaps,
            summary.link.frames_missed,
            summary.disconnects
        );
    }
    if read_error {
        return Err(CliError::Runtime(anyhow::anyhow!(
            "capture of {} ended by a {}",
            summary.source,
            summary.ended
        )));
    }
    Ok(())
}
