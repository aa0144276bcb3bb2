//! The live server: a listener thread that accepts clients, and one thread
//! per client that completes the WebSocket handshake (choosing the
//! subprotocol the client offers, [`super::protocol::choose`]), sends
//! `serverInfo` and `advertise`, then forwards the messages of the
//! channels it subscribed to and reads its `subscribe` and `unsubscribe`.
//! Blocking, like the rest of the command; no async runtime.

use super::protocol::{self, ClientOp};
use crate::mcap::channels::{ChannelMessage, Topic};
use crate::mcap::{ChannelSink, StreamEnd};
use std::collections::HashMap;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::{Message, WebSocket};

/// Messages a client's queue may hold before new ones are dropped for it
/// (and counted): about a minute of LEO's telemetry at 30 Hz with every
/// channel, far more than a connected viewer falls behind.
pub const MAX_QUEUED: u64 = 1 << 20;

/// How long [`FoxgloveServer::close`] waits for the clients' queues to
/// empty.
const DRAIN: Duration = Duration::from_secs(10);

enum Outgoing {
    Message { channel: u32, log_time: u64, data: Arc<[u8]> },
    Close,
}

struct Client {
    tx: Sender<Outgoing>,
    queued: Arc<AtomicU64>,
    thread: JoinHandle<()>,
}

/// What the server did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct LiveStats {
    /// Clients that completed the handshake.
    pub clients: u64,
    /// Messages sent to clients (each client counted).
    pub sent: u64,
    /// Messages dropped because a client's queue was full.
    pub dropped: u64,
    /// Connections refused (no Foxglove subprotocol offered, a failed
    /// handshake).
    pub refused: u64,
}

#[derive(Default)]
struct Counters {
    clients: AtomicU64,
    sent: AtomicU64,
    dropped: AtomicU64,
    refused: AtomicU64,
}

struct Hub {
    clients: Mutex<Vec<Client>>,
    counters: Counters,
    stop: AtomicBool,
    session: String,
}

/// A running server.
pub struct FoxgloveServer {
    /// The address it listens on.
    pub addr: SocketAddr,
    hub: Arc<Hub>,
    accept: Option<JoinHandle<()>>,
}

impl FoxgloveServer {
    /// Listens on `addr` and starts accepting clients.
    pub fn start(addr: SocketAddr) -> std::io::Result<FoxgloveServer> {
        let listener = TcpListener::bind(addr)?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let session = format!(
            "pada-{}-{}",
            std::process::id(),
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_millis())
        );
        let hub = Arc::new(Hub { clients: Mutex::new(Vec::new()), counters: Counters::default(), stop: AtomicBool::new(false), session });
        let h = hub.clone();
        let accept = std::thread::Builder::new()
            .name("foxglove-accept".into())
            .spawn(move || accept_loop(listener, h))?;
        Ok(FoxgloveServer { addr, hub, accept: Some(accept) })
    }

    /// A sink that sends every channel message to the connected clients.
    pub fn sink(&self) -> Box<dyn ChannelSink> {
        Box::new(LiveSink { hub: self.hub.clone() })
    }

    /// What the server did so far.
    pub fn stats(&self) -> LiveStats {
        let c = &self.hub.counters;
        LiveStats {
            clients: c.clients.load(Ordering::SeqCst),
            sent: c.sent.load(Ordering::SeqCst),
            dropped: c.dropped.load(Ordering::SeqCst),
            refused: c.refused.load(Ordering::SeqCst),
        }
    }

    /// Stops accepting, lets every client receive what is queued for it
    /// (up to 10 s), closes the connections and says what it did.
    pub fn close(mut self) -> LiveStats {
        self.hub.stop.store(true, Ordering::SeqCst);
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
        let clients: Vec<Client> = std::mem::take(&mut *self.hub.clients.lock().unwrap_or_else(|e| e.into_inner()));
        for c in &clients {
            let _ = c.tx.send(Outgoing::Close);
        }
        let deadline = Instant::now() + DRAIN;
        for c in clients {
            while !c.thread.is_finished() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(10));
            }
            if c.thread.is_finished() {
                let _ = c.thread.join();
            } else {
                // Still sending after the deadline: what is left is lost.
                self.hub.counters.dropped.fetch_add(c.queued.load(Ordering::SeqCst), Ordering::SeqCst);
            }
        }
        self.stats()
    }
}

fn accept_loop(listener: TcpListener, hub: Arc<Hub>) {
    while !hub.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                let (tx, rx) = mpsc::channel();
                let queued = Arc::new(AtomicU64::new(0));
                let (h, q) = (hub.clone(), queued.clone());
                let spawned = std::thread::Builder::new()
                    .name("foxglove-client".into())
                    .spawn(move || serve_client(stream, rx, q, &h));
                if let Ok(thread) = spawned {
                    hub.clients.lock().unwrap_or_else(|e| e.into_inner()).push(Client { tx, queued, thread });
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// The handshake's header callback: accepts the first offered Foxglove
/// subprotocol, refuses a client that offers none.
#[allow(clippy::result_large_err)]
fn pick_subprotocol(req: &Request, mut resp: Response) -> Result<Response, ErrorResponse> {
    let offered: Vec<String> = req
        .headers()
        .get_all("Sec-WebSocket-Protocol")
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(',').map(|s| s.trim().to_string()))
        .collect();
    match protocol::choose(offered.iter().map(String::as_str)) {
        Some(p) => {
            if let Ok(v) = p.parse() {
                resp.headers_mut().insert("Sec-WebSocket-Protocol", v);
            }
            Ok(resp)
        }
        None => {
            let mut r = ErrorResponse::new(Some(format!(
                "offer one of the subprotocols {} (Sec-WebSocket-Protocol)",
                protocol::SUBPROTOCOLS.join(", ")
            )));
            *r.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
            Err(r)
        }
    }
}

fn serve_client(stream: TcpStream, rx: Receiver<Outgoing>, queued: Arc<AtomicU64>, hub: &Hub) {
    let _ = stream.set_nonblocking(false);
    let _ = stream.set_nodelay(true);
    let _ = stream.set_read_timeout(Some(Duration::from_secs(5)));
    let mut ws = match tungstenite::accept_hdr(stream, pick_subprotocol) {
        Ok(ws) => ws,
        Err(_) => {
            hub.counters.refused.fetch_add(1, Ordering::SeqCst);
            // Nothing more will be read: what was queued for it is not a loss.
            while rx.try_recv().is_ok() {}
            return;
        }
    };
    hub.counters.clients.fetch_add(1, Ordering::SeqCst);
    let _ = ws.get_ref().set_read_timeout(Some(Duration::from_millis(2)));
    let hello = [protocol::server_info(&hub.session), protocol::advertise(&Topic::all())];
    for text in hello {
        if ws.send(Message::text(text)).is_err() {
            return discard(rx, &queued);
        }
    }
    // Channel id → the client's subscription id.
    let mut subs: HashMap<u32, u32> = HashMap::new();
    loop {
        // Everything queued, then a look at what the client said.
        let mut wrote = false;
        let mut closing = false;
        loop {
            let next = if wrote { rx.try_recv().map_err(|_| RecvTimeoutError::Timeout) } else { rx.recv_timeout(Duration::from_millis(5)) };
            match next {
                Ok(Outgoing::Message { channel, log_time, data }) => {
                    queued.fetch_sub(1, Ordering::SeqCst);
                    if let Some(&sub) = subs.get(&channel) {
                        let frame = protocol::message_data(sub, log_time, &data);
                        if ws.write(Message::binary(frame)).is_err() {
                            return discard(rx, &queued);
                        }
                        hub.counters.sent.fetch_add(1, Ordering::SeqCst);
                        wrote = true;
                    }
                }
                Ok(Outgoing::Close) => {
                    closing = true;
                    break;
                }
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => {
                    closing = true;
                    break;
                }
            }
        }
        if wrote && ws.flush().is_err() {
            return discard(rx, &queued);
        }
        if closing {
            let _ = ws.close(None);
            let _ = ws.flush();
            return;
        }
        match read_op(&mut ws) {
            Ok(Some(ClientOp::Subscribe { subscriptions })) => {
                for s in subscriptions {
                    subs.insert(s.channel_id, s.id);
                }
            }
            Ok(Some(ClientOp::Unsubscribe { subscription_ids })) => {
                subs.retain(|_, sub| !subscription_ids.contains(sub));
            }
            Ok(None) => {}
            Err(()) => return discard(rx, &queued),
        }
    }
}

/// One client message, if one came; `Err` when the client is gone.
fn read_op(ws: &mut WebSocket<TcpStream>) -> Result<Option<ClientOp>, ()> {
    match ws.read() {
        Ok(Message::Text(t)) => Ok(protocol::parse_client(t.as_str())),
        Ok(Message::Close(_)) => Err(()),
        Ok(_) => Ok(None),
        Err(tungstenite::Error::Io(e))
            if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) =>
        {
            Ok(None)
        }
        Err(_) => Err(()),
    }
}

/// The client went away: what is queued for it is dropped without counting
/// (nobody is connected to lose it).
fn discard(rx: Receiver<Outgoing>, queued: &AtomicU64) {
    drop(rx);
    queued.store(0, Ordering::SeqCst);
}

struct LiveSink {
    hub: Arc<Hub>,
}

impl ChannelSink for LiveSink {
    fn write(&mut self, msg: &ChannelMessage) -> std::io::Result<()> {
        let mut clients = self.hub.clients.lock().unwrap_or_else(|e| e.into_inner());
        if clients.is_empty() {
            return Ok(());
        }
        let data: Arc<[u8]> = Arc::from(msg.data.as_slice());
        let channel = msg.topic.id();
        clients.retain(|c| {
            if c.queued.load(Ordering::SeqCst) >= MAX_QUEUED {
                self.hub.counters.dropped.fetch_add(1, Ordering::SeqCst);
                return true;
            }
            c.queued.fetch_add(1, Ordering::SeqCst);
            let sent = c.tx.send(Outgoing::Message { channel, log_time: msg.log_time, data: data.clone() });
            if sent.is_err() {
                // The client's thread has ended (it went away).
                c.queued.store(0, Ordering::SeqCst);
            }
            sent.is_ok()
        });
        Ok(())
    }

    fn finish(&mut self, _end: &StreamEnd<'_>) -> std::io::Result<()> {
        Ok(())
    }
}
