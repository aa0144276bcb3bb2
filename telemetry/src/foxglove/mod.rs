//! `--foxglove tcp:HOST:PORT`: a live view of the telemetry in the Foxglove
//! app (Open connection → Foxglove WebSocket → `ws://HOST:PORT`), served
//! with the channels and schemas of the MCAP recordings
//! ([`crate::mcap::channels`]).
//!
//! - [`protocol`]: the messages of Foxglove's WebSocket protocol;
//! - [`server`]: the blocking server, one thread per client.
//!
//! Every channel is advertised when a client connects. While it is
//! connected and subscribed, a client receives every message of its
//! channels: each client has its own queue, and a message is dropped (and
//! counted) only if that queue already holds [`server::MAX_QUEUED`]
//! messages. Loopback only unless another address is given, as for `pada
//! watch --serve`: the protocol has no authentication.

pub mod protocol;
pub mod server;

use std::net::{SocketAddr, ToSocketAddrs};

/// Parses `tcp:HOST:PORT` (port 0 picks a free one); the error is one
/// line for the user.
pub fn parse_addr(spec: &str) -> Result<SocketAddr, String> {
    let Some(addr) = spec.strip_prefix("tcp:") else {
        return Err(format!("--foxglove {spec}: expected tcp:HOST:PORT (e.g. tcp:127.0.0.1:8765)"));
    };
    addr.to_socket_addrs()
        .map_err(|e| format!("--foxglove {spec}: not a HOST:PORT ({e})"))?
        .next()
        .ok_or_else(|| format!("--foxglove {spec}: names no address"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses() {
        assert_eq!(parse_addr("tcp:127.0.0.1:8765").unwrap().port(), 8765);
        for bad in ["127.0.0.1:8765", "tcp:", "tcp:127.0.0.1", "tcp:nowhere.invalid:1", "ws://127.0.0.1:1"] {
            assert!(parse_addr(bad).unwrap_err().starts_with("--foxglove "), "{bad}");
        }
    }
}
