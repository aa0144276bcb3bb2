//! Where `pada watch` reads from — a board's serial port, a recorded
//! stream, or one sender on a loopback TCP port (`pada run --telemetry
//! tcp:…`, `pada sil --telemetry tcp:…`) — and the decoder thread that
//! feeds [`Recorder`] (the decoder and CSV of `pada capture`) and the
//! page's state, and with `--checkpoint` the board's checkpoint keeper
//! (answering its restore requests on a serial port).

use super::server::Shared;
use crate::capture::Recorder;
use crate::checkpoint_keeper::KeeperLink;
use crate::serial_link::LinkEvent;
use std::io::Read;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How often a blocked read looks at the stop flag.
const POLL: Duration = Duration::from_millis(100);

/// An open source.
pub enum Source {
    /// A serial port (reads time out every [`POLL`]); reopened when it
    /// goes away and comes back (`crate::serial_link`).
    Port(crate::serial_link::SerialLink),
    /// A file or standard input.
    Reader(Box<dyn Read + Send>),
    /// A listener waiting for its one sender.
    Listener(TcpListener),
}

/// Listens on `addr` for one sender.
pub fn listen(addr: SocketAddr) -> std::io::Result<TcpListener> {
    let l = TcpListener::bind(addr)?;
    l.set_nonblocking(true)?;
    Ok(l)
}

/// Why decoding ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct End {
    /// In words, as `pada capture` says it (`end of file`, …).
    pub reason: String,
    /// Whether it was a failure (a read error, the CSV not written) rather
    /// than the stream's end; `pada watch` then exits with 1.
    pub failed: bool,
}

fn ended(reason: impl Into<String>) -> End {
    End {
        reason: reason.into(),
        failed: false,
    }
}

fn failed(reason: String) -> End {
    End {
        reason,
        failed: true,
    }
}

/// Reads `source` until it ends or `stop` is set, recording every frame
/// and updating the shared state after every chunk; returns why it ended.
/// `keeper` takes the checkpoint's chunks and, on a port, answers restore
/// requests.
pub fn decode(
    source: Source,
    recorder: &Mutex<Recorder>,
    shared: &Shared,
    stop: &AtomicBool,
    keeper: &mut Option<KeeperLink>,
) -> End {
    let mut buf = vec![0u8; 4096];
    let mut frames = Vec::new();
    let mut source = source;
    // The listener's one sender, once it connected.
    let mut stream: Option<TcpStream> = None;
    loop {
        if stop.load(Ordering::SeqCst) {
            return ended("interrupted");
        }
        let n = match &mut source {
            Source::Port(p) => match p.read(&mut buf) {
                LinkEvent::Data(n) => n,
                LinkEvent::Nothing => 0,
                LinkEvent::Lost(why) => {
                    shared.disconnects.store(p.disconnects(), Ordering::SeqCst);
                    eprintln!("watch: {why}; waiting for the port to come back (disconnect {})", p.disconnects());
                    // A frame in progress can never complete: lost.
                    let mut rec = recorder.lock().unwrap_or_else(|e| e.into_inner());
                    if let Err(e) = rec.finish(shared.started.elapsed().as_secs_f64()) {
                        return failed(format!("cannot write the CSV ({e})"));
                    }
                    0
                }
                LinkEvent::Back => {
                    eprintln!("watch: the port is back");
                    0
                }
            },
            Source::Reader(r) => match r.read(&mut buf) {
                Ok(0) => return ended("end of file"),
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => 0,
                Err(e) => return failed(format!("read error ({e})")),
            },
            Source::Listener(l) => match stream.as_mut() {
                None => match l.accept() {
                    Ok((s, peer)) => {
                        let ready = s
                            .set_nonblocking(false)
                            .and_then(|_| s.set_read_timeout(Some(POLL)));
                        if let Err(e) = ready {
                            return failed(format!("cannot read from the sender {peer} ({e})"));
                        }
                        eprintln!("watch: telemetry sender connected from {peer}");
                        stream = Some(s);
                        0
                    }
                    Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                        std::thread::sleep(POLL / 2);
                        0
                    }
                    Err(e) => return failed(format!("cannot accept a sender ({e})")),
                },
                Some(s) => match s.read(&mut buf) {
                    Ok(0) => return ended("the sender closed the connection"),
                    Ok(n) => n,
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock
                                | std::io::ErrorKind::TimedOut
                                | std::io::ErrorKind::Interrupted
                        ) =>
                    {
                        0
                    }
                    Err(e) => return ended(format!("the connection failed ({e})")),
                },
            },
        };
        if n == 0 {
            continue;
        }
        shared.data_arrived();
        frames.clear();
        let mut rec = recorder.lock().unwrap_or_else(|e| e.into_inner());
        let t = shared.started.elapsed().as_secs_f64();
        if let Err(e) = rec.feed(&buf[..n], t, &mut frames) {
            return failed(if e.kind() == std::io::ErrorKind::InvalidData {
                e.to_string()
            } else {
                format!("cannot write the CSV ({e})")
            });
        }
        let (link, counts) = (rec.stats(), rec.counts());
        let latest = rec.latest().clone();
        drop(rec);
        if let Some(k) = keeper.as_mut().filter(|_| !frames.is_empty()) {
            let port = match &mut source {
                Source::Port(p) => Some(p),
                _ => None,
            };
            for line in k.frames(&frames, port) {
                eprintln!("watch: {line}");
            }
            let (chunks, bytes) = k.take_answered();
            recorder.lock().unwrap_or_else(|e| e.into_inner()).answered(chunks, bytes);
        }
        shared
            .state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .apply(&frames, link, counts, &latest);
    }
}

/// Starts [`decode`] on its own thread; the thread marks the state ended.
pub fn spawn(
    source: Source,
    recorder: Arc<Mutex<Recorder>>,
    shared: Arc<Shared>,
    stop: Arc<AtomicBool>,
    keeper: Option<KeeperLink>,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    std::thread::Builder::new()
        .name("watch-decoder".into())
        .spawn(move || {
            let mut keeper = keeper;
            let end = decode(source, &recorder, &shared, &stop, &mut keeper);
            for line in keeper.as_mut().map(KeeperLink::finish).unwrap_or_default() {
                eprintln!("watch: {line}");
            }
            // The stream ended by itself (not Ctrl-C, which cuts the frame
            // in progress itself): a frame cut off by the end counts as lost,
            // as `pada capture` counts it.
            if !stop.load(Ordering::SeqCst) {
                let mut rec = recorder.lock().unwrap_or_else(|e| e.into_inner());
                let t = shared.started.elapsed().as_secs_f64();
                if let Err(e) = rec.finish(t) {
                    shared.failed.store(true, Ordering::SeqCst);
                    eprintln!("watch: cannot write the CSV ({e})");
                }
                let (link, counts, latest) = (rec.stats(), rec.counts(), rec.latest().clone());
                drop(rec);
                shared.state.lock().unwrap_or_else(|e| e.into_inner()).apply(&[], link, counts, &latest);
            }
            if end.failed {
                shared.failed.store(true, Ordering::SeqCst);
            }
            shared
                .state
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .end(end.reason);
        })
}
