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

use crate::console::{errln, outln};
use crate::capture::Recorder;
use crate::serial_link::LinkEvent;
use crate::error::{usage, CliError};
use anyhow::Context;
use clap::Args;
use serde::Serialize;
use std::io::{IsTerminal, Read, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `pada capture`.
#[derive(Debug, Clone, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["port", "file"])))]
pub struct CaptureArgs {
    /// A serial port with a board on it (e.g. /dev/ttyUSB0, /dev/ttyACM0).
    #[arg(long, value_name = "DEVICE")]
    pub port: Option<PathBuf>,
    /// A recorded byte stream (a board's raw output, or `pada run
    /// --telemetry FILE`); `-` reads standard input.
    #[arg(long, value_name = "FILE")]
    pub file: Option<PathBuf>,
    /// The port's baud rate.
    #[arg(long, value_name = "B", default_value_t = 921_600)]
    pub baud: u32,
    /// Write every frame, lost frame and sequence gap as a CSV row.
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Stop after this many wall-clock seconds.
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Print the final summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
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
}

enum Source {
    Port(crate::serial_link::SerialLink),
    Reader(Box<dyn Read + Send>),
}

/// Runs `pada capture`.
pub fn run(args: CaptureArgs) -> Result<(), CliError> {
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            return Err(usage(format!(
                "--seconds {s} is out of range: valid is > 0"
            )));
        }
    }
    if args.baud == 0 || args.baud > 12_000_000 {
        return Err(usage(format!(
            "--baud {} is out of range: valid is 1..=12000000",
            args.baud
        )));
    }
    let (mut source, name) = match (&args.port, &args.file) {
        (Some(port), _) => {
            let p = crate::serial_link::SerialLink::open(port, args.baud)
                .map_err(|e| usage(format!("--port {}: cannot open: {e}", port.display())))?;
            (Source::Port(p), port.display().to_string())
        }
        (None, Some(file)) if file.as_os_str() == "-" => (
            Source::Reader(Box::new(std::io::stdin())),
            "standard input".to_string(),
        ),
        (None, Some(file)) => {
            if file.is_dir() {
                return Err(usage(format!(
                    "--file {}: is a directory; valid is a recorded stream file or - for standard input",
                    file.display()
                )));
            }
            let f = std::fs::File::open(file)
                .map_err(|e| usage(format!("--file {}: cannot open: {e}", file.display())))?;
            (Source::Reader(Box::new(f)), file.display().to_string())
        }
        (None, None) => return Err(usage("give --port DEVICE or --file FILE")),
    };
    let csv: Option<Box<dyn Write + Send>> = match &args.out {
        Some(p) => Some(Box::new(std::io::BufWriter::new(
            std::fs::File::create(p)
                .map_err(|e| usage(format!("--out {}: cannot create: {e}", p.display())))?,
        ))),
        None => None,
    };
    let mut rec = Recorder::new(csv)
        .context("cannot write the CSV header")
        .map_err(CliError::Runtime)?;

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
            .seconds
            .is_some_and(|s| started.elapsed().as_secs_f64() >= s)
        {
            break ("time limit".to_string(), false, false);
        }
        let n = match &mut source {
            Source::Port(p) => match p.read(&mut buf) {
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
            Source::Reader(r) => match r.read(&mut buf) {
                Ok(0) => break ("end of file".to_string(), true, false),
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => 0,
                Err(e) => break (format!("read error ({e})"), true, true),
            },
        };
        frames.clear();
        rec.feed(&buf[..n], started.elapsed().as_secs_f64(), &mut frames)
            .context("cannot write the CSV")
            .map_err(CliError::Runtime)?;
        let every = if tty {
            Duration::from_millis(100)
        } else {
            Duration::from_secs(1)
        };
        if last_status.elapsed() >= every {
            last_status = Instant::now();
            status(&rec, tty, false);
        }
    };
    if input_ended {
        rec.finish(started.elapsed().as_secs_f64())
            .context("cannot write the CSV")
            .map_err(CliError::Runtime)?;
    }
    rec.flush()
        .context("cannot write the CSV")
        .map_err(CliError::Runtime)?;
    status(&rec, tty, true);
    let link = rec.stats();
    let disconnects = match &source {
        Source::Port(p) => p.disconnects(),
        Source::Reader(_) => 0,
    };
    let summary = CaptureSummary {
        disconnects,
        source: name,
        ended,
        wall_s: started.elapsed().as_secs_f64(),
        link,
        bad_frames: link.bad_frames(),
        messages: rec.counts(),
        latest: rec.latest().clone(),
    };
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?
        )?;
    } else {
        errln!(
            "capture of {} ended ({}): {} frames, {} lost, {} sequence gaps ({} frames missing), {} disconnects",
            summary.source,
            summary.ended,
            link.frames,
            summary.bad_frames,
            link.seq_gaps,
            link.frames_missed,
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

fn status(rec: &Recorder, tty: bool, last: bool) {
    let line = rec.status_line();
    let mut err = std::io::stderr().lock();
    if tty {
        let _ = write!(err, "\r\x1b[K{line}");
        if last {
            let _ = writeln!(err);
        }
    } else {
        let _ = writeln!(err, "{line}");
    }
    let _ = err.flush();
}
