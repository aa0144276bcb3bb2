//! `pada servos`' loop: bytes from the pseudo-terminal into the virtual
//! bus, its answers back when they are due, the Bus Watchdogs and the
//! physics kept up with the wall clock (real time), until Ctrl-C or
//! `--seconds`. Each servo event is a line on stderr as it happens; the
//! summary says what the bus carried and what every servo did.
//!
//! In real time the loop's thread asks for `pada drive`'s real-time
//! treatment (`SCHED_FIFO`, locked memory: [`crate::realtime`]):
//! the virtual servos stand in for hardware that a busy PC cannot slow
//! down. The summary says what was granted.

use super::bus::{BusStats, Event, Reply, VirtualBus};
use super::pty::Pty;
use crate::realtime::{Linux, Realtime, RealtimeReport};
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long a read waits for the client at most: the Bus Watchdog's and
/// the physics' resolution in real time.
const POLL: Duration = Duration::from_millis(1);

/// What a run of the virtual servos came to.
#[derive(Debug, Clone, Serialize)]
pub struct ServeSummary {
    /// The robot.
    pub robot: String,
    /// The link the port was at, and its device.
    pub port: String,
    /// Its pseudo-terminal.
    pub device: String,
    /// The servos' rate \[bps\].
    pub baud: u32,
    /// `real-time` or `lock-step`.
    pub clock: &'static str,
    /// What the operating system granted the loop's thread.
    pub realtime: RealtimeReport,
    /// Why it ended.
    pub ended: String,
    /// Wall time \[s\].
    pub wall_s: f64,
    /// Bus time at the end \[s\].
    pub bus_s: f64,
    /// Bytes that came at another rate than the servos' (and were not
    /// heard).
    pub wrong_rate_bytes: u64,
    /// The rates those bytes came at.
    pub wrong_rates: Vec<u32>,
    /// The bus's counters.
    pub stats: BusStats,
    /// What the servos did, in order.
    pub events: Vec<Event>,
}

/// How to serve.
pub struct ServeOptions<'a> {
    /// The servos' rate \[bps\].
    pub bps: u32,
    /// Stop after this many wall-clock seconds.
    pub seconds: Option<f64>,
    /// The robot's name.
    pub name: &'a str,
    /// Lock step (the physics advance at each SYNC WRITE).
    pub lock_step: bool,
    /// In real time, ask for a real-time thread.
    pub realtime: bool,
}

/// Serves `bus` on `pty` until `stop` or `opts.seconds`.
pub fn serve(bus: &mut VirtualBus, pty: &Pty, stop: &AtomicBool, opts: &ServeOptions) -> std::io::Result<ServeSummary> {
    let ServeOptions { bps, seconds, name, lock_step, .. } = *opts;
    // In lock step the loop only waits for the client: nothing to hold.
    let why_not = if lock_step { "lock step: the servos wait for the client" } else { "--no-realtime" };
    let mut rt = Realtime::enter(Linux, opts.realtime && !lock_step, why_not);
    for line in rt.report().lines() {
        errln(format_args!("servos: real time: {line}"));
    }
    let started = Instant::now();
    let mut pending: Vec<Reply> = Vec::new();
    let mut out: Vec<u8> = Vec::new();
    let mut buf = vec![0u8; 4096];
    let (mut wrong_rate_bytes, mut wrong_rates) = (0u64, Vec::new());
    let mut logged = 0;
    let ended = loop {
        if stop.load(Ordering::SeqCst) {
            break "interrupted".to_string();
        }
        if seconds.is_some_and(|s| started.elapsed().as_secs_f64() >= s) {
            break "time limit".to_string();
        }
        let now = started.elapsed().as_micros() as u64;
        bus.tick(now);
        // Answers due.
        let bus_now = if lock_step { u64::MAX } else { now };
        pending.sort_by_key(|r| r.at_us);
        let due = pending.iter().take_while(|r| r.at_us <= bus_now).count();
        for r in pending.drain(..due) {
            out.extend_from_slice(&r.bytes);
        }
        if !out.is_empty() {
            let n = pty.write(&out)?;
            out.drain(..n);
        }
        let wait = pending.first().map_or(POLL, |r| Duration::from_micros(r.at_us.saturating_sub(now)).min(POLL));
        let n = pty.read(&mut buf, wait)?;
        for e in &bus.events()[logged..] {
            errln(format_args!("servos: {:.6} s: {} {}", e.at_us as f64 * 1e-6, device_name(e.id), e.what));
        }
        logged = bus.events().len();
        if n == 0 {
            continue;
        }
        let line = pty.line_bps();
        if !bus.anyone_hears(line) {
            // The servos hear garbage: nothing they decode, no answer.
            wrong_rate_bytes += n as u64;
            if !wrong_rates.contains(&line) {
                errln(format_args!("servos: bytes at {line} bps; no servo listens at that rate (they were started at {bps} bps): not heard"));
                wrong_rates.push(line);
            }
            continue;
        }
        let now = started.elapsed().as_micros() as u64;
        pending.extend(bus.receive(&buf[..n], now, line));
    };
    rt.leave();
    Ok(ServeSummary {
        robot: name.to_string(),
        port: pty.link().display().to_string(),
        device: pty.device().to_string(),
        baud: bps,
        clock: if lock_step { "lock-step" } else { "real-time" },
        realtime: rt.report().clone(),
        ended,
        wall_s: started.elapsed().as_secs_f64(),
        bus_s: bus.now_us() as f64 * 1e-6,
        wrong_rate_bytes,
        wrong_rates,
        stats: bus.stats(),
        events: bus.events().to_vec(),
    })
}

fn device_name(id: u8) -> String {
    if id == pada_firmware::sensor_device::SENSOR_ID {
        "sensor device".to_string()
    } else {
        format!("servo {id}")
    }
}

/// One line on standard error. A standard error that cannot be written
/// (a closed pipe) is dropped, as the `pada` command's own messages are:
/// there is nowhere left to report it, and `eprintln!` would panic.
fn errln(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(args).and_then(|()| err.write_all(b"\n"));
}
