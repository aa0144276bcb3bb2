//! `pada watch`: decodes a telemetry stream as `pada capture` does (same
//! decoder, same CSV, same summary) and serves a live page of it on
//! loopback.
//!
//! The stream's end (end of file, the sender gone) does not end the
//! command: the page keeps showing the final state until Ctrl-C or
//! `--seconds`, which print the summary as `pada capture` does.
//!
//! `--checkpoint PATH` keeps the board's streamed checkpoint and answers
//! its restore requests as `pada capture --checkpoint` does, on the
//! decoder thread.

use super::capture::CaptureSummary;
use super::stream_args::{Opened, StreamInput, StreamRecord};
use crate::capture::Recorder;
use crate::error::{usage, CliError};
use crate::watch::server::{self, Shared};
use crate::watch::source::{self, Source};
use crate::watch::state::WatchState;
use anyhow::Context;
use clap::Args;
use serde::Serialize;
use std::io::{IsTerminal, Write};
use std::net::{SocketAddr, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// `pada watch`.
#[derive(Debug, Clone, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["port", "file", "listen"])))]
pub struct WatchArgs {
    /// Where the telemetry comes from (or `--listen`).
    #[command(flatten)]
    pub input: StreamInput,
    /// Wait on this loopback address for one sender (`pada run --telemetry
    /// tcp:…`, `pada sil --telemetry tcp:…`); port 0 picks a free one.
    #[arg(long, value_name = "tcp:HOST:PORT")]
    pub listen: Option<String>,
    /// Where the page is served. Loopback unless another address is given
    /// here (the page has no authentication); port 0 picks a free one.
    #[arg(long, value_name = "HOST:PORT", default_value = "127.0.0.1:8080")]
    pub serve: String,
    /// What is kept of it (`--out` has the columns of `pada capture --out`).
    #[command(flatten)]
    pub record: StreamRecord,
}

/// The end of a watch: `pada capture --json`'s summary, plus the page.
#[derive(Debug, Clone, Serialize)]
pub struct WatchSummary {
    /// What `pada capture --json` reports.
    #[serde(flatten)]
    pub capture: CaptureSummary,
    /// The page's address.
    pub url: String,
    /// HTTP requests answered.
    pub requests: u64,
}

/// Parses `tcp:HOST:PORT` on the loopback interface.
pub fn parse_listen(spec: &str) -> Result<SocketAddr, CliError> {
    let Some(addr) = spec.strip_prefix("tcp:") else {
        return Err(usage(format!(
            "--listen {spec}: expected tcp:HOST:PORT (e.g. tcp:127.0.0.1:9000)"
        )));
    };
    let addrs: Vec<SocketAddr> = addr
        .to_socket_addrs()
        .map_err(|e| usage(format!("--listen {spec}: not a HOST:PORT ({e})")))?
        .collect();
    match addrs.first() {
        Some(a) if addrs.iter().all(|a| a.ip().is_loopback()) => Ok(*a),
        _ => Err(usage(format!(
            "--listen {spec}: only the loopback interface is allowed (127.0.0.1, ::1, localhost); \
             the stream is not authenticated"
        ))),
    }
}

/// Parses `--serve HOST:PORT`.
pub fn parse_serve(spec: &str) -> Result<SocketAddr, CliError> {
    spec.to_socket_addrs()
        .map_err(|e| usage(format!("--serve {spec}: not a HOST:PORT ({e})")))?
        .next()
        .ok_or_else(|| usage(format!("--serve {spec}: names no address")))
}

/// Runs `pada watch`.
pub fn run(args: WatchArgs) -> Result<(), CliError> {
    args.record.check()?;
    args.input.check()?;
    let serve = parse_serve(&args.serve)?;
    let (source, name) = open(&args)?;
    let keeper = args.record.keeper()?;
    if let Some(k) = &keeper {
        eprintln!("watch: {}", k.describe());
    }
    let csv = args.record.csv()?;
    let mut taps = args.record.taps("watch")?;
    let mut rec = Recorder::new(csv)
        .context("cannot write the CSV header")
        .map_err(CliError::Runtime)?;
    if let Some(tap) = taps.tap.take() {
        rec.set_tap(tap);
    }
    let recorder = Arc::new(Mutex::new(rec));
    let shared = Arc::new(Shared::new(WatchState::new(name.clone())));
    let server = server::start(serve, shared.clone())
        .map_err(|e| usage(format!("--serve {}: cannot listen: {e:#}", args.serve)))?;
    let url = format!("http://{}/", server.addr);
    eprintln!("watch: {url} (source: {name})");
    if !server.addr.ip().is_loopback() {
        eprintln!(
            "watch: warning: the page is served on {} beyond this machine, without authentication",
            server.addr.ip()
        );
    }

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // As in `pada capture`: a second handler cannot be installed in one
        // process; then Ctrl-C simply ends it.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let decoder_stop = Arc::new(AtomicBool::new(false));
    let decoder = source::spawn(
        source,
        recorder.clone(),
        shared.clone(),
        decoder_stop.clone(),
        keeper,
    )
    .context("cannot start the decoder thread")
    .map_err(CliError::Runtime)?;

    let tty = std::io::stderr().is_terminal();
    let every = if tty {
        Duration::from_millis(100)
    } else {
        Duration::from_secs(1)
    };
    let started = Instant::now();
    let mut last_status = Instant::now();
    let mut told_end = false;
    let stopped = loop {
        std::thread::sleep(Duration::from_millis(50));
        if stop.load(Ordering::SeqCst) {
            break "interrupted";
        }
        if args
            .record
            .seconds
            .is_some_and(|s| started.elapsed().as_secs_f64() >= s)
        {
            break "time limit";
        }
        // A failure (a read error, the CSV not written) ends the command as
        // it ends `pada capture`; the stream's normal end does not.
        if shared.failed.load(Ordering::SeqCst) {
            break "failed";
        }
        let ended = shared.snapshot_ended();
        if let (Some(why), false) = (&ended, told_end) {
            told_end = true;
            status(&recorder, tty, true);
            eprintln!("watch: the stream ended ({why}); the page stays at {url} until Ctrl-C");
        }
        if ended.is_none() && last_status.elapsed() >= every {
            last_status = Instant::now();
            status(&recorder, tty, false);
        }
    };
    // The stream's own end, if it came first, is why it ended.
    let ended = shared
        .snapshot_ended()
        .unwrap_or_else(|| stopped.to_string());
    decoder_stop.store(true, Ordering::SeqCst);
    // The decoder looks at the flag after every read (at most 100 ms for a
    // port or a socket); standard input can block longer, and is left.
    let deadline = Instant::now() + Duration::from_secs(1);
    while !decoder.is_finished() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    let mut rec = recorder.lock().unwrap_or_else(|e| e.into_inner());
    rec.end()
        .and_then(|()| rec.flush())
        .context("cannot write the CSV")
        .map_err(CliError::Runtime)?;
    let closed = rec.close_tap();
    let live = taps.close("watch");
    closed
        .context("cannot write the MCAP file")
        .map_err(CliError::Runtime)?;
    if !told_end {
        let line = rec.status_line();
        let mut err = std::io::stderr().lock();
        let _ = if tty {
            writeln!(err, "\r\x1b[K{line}")
        } else {
            writeln!(err, "{line}")
        };
    }
    let disconnects = shared.disconnects.load(Ordering::SeqCst);
    let mut capture = CaptureSummary::of(&rec, name, ended, started, disconnects);
    capture.foxglove = live;
    let summary = WatchSummary {
        capture,
        url,
        requests: shared.requests.load(Ordering::Relaxed),
    };
    drop(rec);
    if args.record.json {
        let text =
            serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?;
        let mut out = std::io::stdout().lock();
        writeln!(out, "{text}")
            .and_then(|_| out.flush())
            .context("cannot write the summary to standard output")
            .map_err(CliError::Runtime)?;
    } else {
        eprintln!(
            "watch of {} ended ({}): {} frames, {} lost, {} sequence gaps ({} frames missing), {} disconnects; {} requests served",
            summary.capture.source,
            summary.capture.ended,
            summary.capture.link.frames,
            summary.capture.bad_frames,
            summary.capture.link.seq_gaps,
            summary.capture.link.frames_missed,
            summary.capture.disconnects,
            summary.requests
        );
    }
    if shared.failed.load(Ordering::SeqCst) {
        return Err(CliError::Runtime(anyhow::anyhow!(
            "the stream of {} failed: {}",
            summary.capture.source,
            summary.capture.ended
        )));
    }
    Ok(())
}

/// Opens the source named by `--port`, `--file` or `--listen`.
fn open(args: &WatchArgs) -> Result<(Source, String), CliError> {
    match args.input.open()? {
        Some((Opened::Port(p), name)) => return Ok((Source::Port(p), name)),
        Some((Opened::Reader(r), name)) => return Ok((Source::Reader(r), name)),
        None => {}
    }
    if let Some(spec) = &args.listen {
        let addr = parse_listen(spec)?;
        let l = source::listen(addr)
            .map_err(|e| usage(format!("--listen {spec}: cannot listen: {e}")))?;
        let bound = l
            .local_addr()
            .map_err(|e| usage(format!("--listen {spec}: {e}")))?;
        eprintln!("watch: waiting for a telemetry sender on tcp:{bound}");
        return Ok((Source::Listener(l), format!("tcp:{bound}")));
    }
    Err(usage(
        "give --port DEVICE, --file FILE or --listen tcp:HOST:PORT",
    ))
}

fn status(recorder: &Mutex<Recorder>, tty: bool, last: bool) {
    let line = recorder.lock().unwrap_or_else(|e| e.into_inner()).status_line();
    crate::console::status_line(&line, tty, last);
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn the_page_is_served_on_loopback_unless_told_otherwise() {
        #[derive(Parser)]
        struct Watch {
            #[command(flatten)]
            args: WatchArgs,
        }
        let args = Watch::try_parse_from(["watch", "--file", "x.bin"]).unwrap().args;
        assert!(parse_serve(&args.serve).unwrap().ip().is_loopback());
        assert!(parse_listen("tcp:[::1]:9000").is_ok());
        assert!(parse_listen("tcp:localhost:9000").is_ok());
        for bad in ["tcp:0.0.0.0:9000", "tcp:192.168.1.2:9000", "9000", "tcp:"] {
            assert_eq!(parse_listen(bad).unwrap_err().exit_code(), 2, "{bad}");
        }
    }
}
