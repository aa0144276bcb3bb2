//! The page's HTTP server (tiny_http): a few worker threads answer GET and
//! HEAD for the page, its live part, the plots and `/api/state`; anything
//! else gets a 4xx. A worker copies the state under its lock and renders
//! outside it, so the decoder waits at most for that copy, never for a
//! viewer: a viewer that reads slowly or not at all holds only its worker
//! (while its socket buffer is full), and one that disconnects costs an
//! ignored write error.

use super::page::{self, Clock, STALL_AFTER_S};
use super::plots::{EpisodePlot, FatiguePlot, ReturnsPlot};
use super::state::WatchState;
use crate::plot::to_svg;
use serde::Serialize;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use tiny_http::{Header, Method, Request, Response, StatusCode};

/// Workers answering requests at once. Rendering takes a few ms, so eight
/// serve many viewers polling once a second; more only help against
/// viewers that stop reading.
pub const WORKERS: usize = 8;

/// Longest request target accepted (longer: 414).
pub const MAX_URL: usize = 2048;

/// What the decoder thread and the server share.
pub struct Shared {
    /// The state, updated by the decoder after every chunk.
    pub state: Mutex<WatchState>,
    /// When `pada watch` started.
    pub started: Instant,
    /// Milliseconds after `started` when the last byte arrived, plus one
    /// (0: nothing yet).
    last_data_ms: AtomicU64,
    /// Requests answered.
    pub requests: AtomicU64,
    /// Set when decoding ended in a failure (a read error, the CSV).
    pub failed: std::sync::atomic::AtomicBool,
    /// Times the serial port went away (and was waited for).
    pub disconnects: std::sync::atomic::AtomicU32,
    /// The last rendering of `/live`, reused within the same second.
    live_cache: Mutex<Option<(LiveKey, Arc<String>)>>,
}

type LiveKey = (u64, u64, Option<u64>);

impl Shared {
    /// Nothing received yet.
    pub fn new(state: WatchState) -> Self {
        Shared {
            state: Mutex::new(state),
            started: Instant::now(),
            last_data_ms: AtomicU64::new(0),
            requests: AtomicU64::new(0),
            failed: std::sync::atomic::AtomicBool::new(false),
            disconnects: std::sync::atomic::AtomicU32::new(0),
            live_cache: Mutex::new(None),
        }
    }

    /// Notes that bytes arrived now.
    pub fn data_arrived(&self) {
        let ms = self.started.elapsed().as_millis() as u64 + 1;
        self.last_data_ms.store(ms, Ordering::Relaxed);
    }

    /// Seconds since start, and since the last byte.
    pub fn clock(&self) -> Clock {
        let now = self.started.elapsed().as_secs_f64();
        let last = self.last_data_ms.load(Ordering::Relaxed);
        Clock {
            wall_s: now,
            since_data_s: (last > 0).then(|| (now - (last - 1) as f64 * 1e-3).max(0.0)),
        }
    }

    /// Why the stream ended, if it did.
    pub fn snapshot_ended(&self) -> Option<String> {
        self.state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .ended
            .clone()
    }

    /// A copy of the state (the lock is held for the copy only).
    pub fn snapshot(&self) -> WatchState {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

/// `/api/state`: the state and the clock.
#[derive(Serialize)]
pub struct ApiState<'a> {
    /// Everything the page shows.
    #[serde(flatten)]
    pub state: &'a WatchState,
    /// Seconds since `pada watch` started.
    pub wall_s: f64,
    /// Seconds since the last byte arrived (`null`: nothing yet).
    pub no_data_for_s: Option<f64>,
    /// Whether the page shows the stream as stalled.
    pub stalled: bool,
    /// Times the serial port went away (and was waited for).
    pub disconnects: u32,
}

impl<'a> ApiState<'a> {
    /// The state with the clock.
    pub fn new(state: &'a WatchState, clock: Clock) -> Self {
        let silent = clock.since_data_s.unwrap_or(clock.wall_s);
        ApiState {
            state,
            wall_s: clock.wall_s,
            no_data_for_s: clock.since_data_s,
            stalled: state.ended.is_none() && silent >= STALL_AFTER_S,
            disconnects: 0,
        }
    }
}

/// A running server.
pub struct Server {
    /// The address it listens on (the port chosen when 0 was asked).
    pub addr: SocketAddr,
    _server: Arc<tiny_http::Server>,
}

/// Listens on `addr` and starts the workers.
pub fn start(addr: SocketAddr, shared: Arc<Shared>) -> anyhow::Result<Server> {
    let server = tiny_http::Server::http(addr).map_err(|e| anyhow::anyhow!("{e}"))?;
    let addr = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| anyhow::anyhow!("not an IP listener"))?;
    let server = Arc::new(server);
    for i in 0..WORKERS {
        let server = server.clone();
        let shared = shared.clone();
        std::thread::Builder::new()
            .name(format!("watch-http-{i}"))
            .spawn(move || {
                // recv fails only when the server is dropped.
                while let Ok(rq) = server.recv() {
                    handle(rq, &shared);
                }
            })?;
    }
    Ok(Server {
        addr,
        _server: server,
    })
}

fn header(name: &str, value: &str) -> Header {
    // Only called with constant ASCII names and values.
    Header::from_bytes(name.as_bytes(), value.as_bytes()).unwrap_or_else(|_| unreachable!())
}

fn respond(rq: Request, status: u16, content_type: &str, body: Vec<u8>) {
    let response = Response::from_data(body)
        .with_status_code(StatusCode(status))
        .with_header(header("Content-Type", content_type))
        .with_header(header("Cache-Control", "no-store"));
    // A viewer that went away: nothing to do.
    let _ = rq.respond(response);
}

fn error(rq: Request, status: u16, message: &str) {
    respond(
        rq,
        status,
        "text/plain; charset=utf-8",
        format!("{status}: {message}\n").into_bytes(),
    );
}

/// Answers one request.
pub fn handle(rq: Request, shared: &Shared) {
    shared.requests.fetch_add(1, Ordering::Relaxed);
    if !matches!(rq.method(), Method::Get | Method::Head) {
        let method = rq.method().to_string();
        let response = Response::from_string(format!(
            "405: {method} is not supported; valid methods are GET and HEAD\n"
        ))
        .with_status_code(StatusCode(405))
        .with_header(header("Allow", "GET, HEAD"))
        .with_header(header("Content-Type", "text/plain; charset=utf-8"));
        let _ = rq.respond(response);
        return;
    }
    if rq.url().len() > MAX_URL {
        return error(
            rq,
            414,
            &format!("request target longer than {MAX_URL} bytes"),
        );
    }
    let path = rq.url().split(['?', '#']).next().unwrap_or("").to_string();
    let svg = |f: anyhow::Result<String>| match f {
        Ok(s) => (200, s),
        Err(e) => (500, format!("{e:#}")),
    };
    match path.as_str() {
        "/" | "/index.html" => {
            let state = shared.snapshot();
            let body = page::page(&state, shared.clock());
            respond(rq, 200, "text/html; charset=utf-8", body.into_bytes());
        }
        "/live" => {
            let body = live(shared);
            respond(rq, 200, "text/html; charset=utf-8", body.as_bytes().to_vec());
        }
        "/api/state" => {
            let state = shared.snapshot();
            let mut api = ApiState::new(&state, shared.clock());
            api.disconnects = shared.disconnects.load(std::sync::atomic::Ordering::SeqCst);
            match serde_json::to_vec(&api) {
                Ok(body) => respond(rq, 200, "application/json", body),
                Err(e) => error(rq, 500, &e.to_string()),
            }
        }
        "/plot/returns.svg" | "/plot/damage.svg" | "/plot/reengagements.svg"
        | "/plot/episode.svg" => {
            let state = shared.snapshot();
            let (status, body) = svg(match path.as_str() {
                "/plot/returns.svg" => to_svg(&ReturnsPlot(&state)),
                "/plot/damage.svg" => to_svg(&FatiguePlot::damage(&state)),
                "/plot/reengagements.svg" => to_svg(&FatiguePlot::reengagements(&state)),
                _ => to_svg(&EpisodePlot(&state)),
            });
            respond(rq, status, "image/svg+xml", body.into_bytes());
        }
        _ => error(
            rq,
            404,
            "no such page; valid are /, /live, /api/state and /plot/{returns,damage,reengagements,episode}.svg",
        ),
    }
}

/// `/live`, rendered once per state version and second.
fn live(shared: &Shared) -> Arc<String> {
    let clock = shared.clock();
    let version = shared
        .state
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .version;
    let key = (
        version,
        clock.wall_s as u64,
        clock.since_data_s.map(|s| s as u64),
    );
    if let Some((k, body)) = &*shared.live_cache.lock().unwrap_or_else(|e| e.into_inner()) {
        if *k == key {
            return body.clone();
        }
    }
    let state = shared.snapshot();
    let body = Arc::new(page::live(&state, clock));
    *shared.live_cache.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, body.clone()));
    body
}
