//! Foxglove's WebSocket protocol (v1), the part a data source serves:
//! `serverInfo` and `advertise` (JSON text) to each client, `subscribe`
//! and `unsubscribe` (JSON text) from it, and each message as a binary
//! `messageData` frame: opcode 1, the subscription id (u32, little
//! endian), the log time in ns (u64, little endian), the JSON payload.

use crate::mcap::channels::Topic;
use serde::Deserialize;
use serde_json::json;

/// The subprotocols served, in the order of preference when a client
/// offers several: the Foxglove SDK's name and the original one (the same
/// messages).
pub const SUBPROTOCOLS: [&str; 2] = ["foxglove.sdk.v1", "foxglove.websocket.v1"];

/// The opcode of a binary `messageData` frame.
pub const MESSAGE_DATA: u8 = 1;

/// The first of `offered` (a `Sec-WebSocket-Protocol` header's values, in
/// the client's order of preference) that is served.
pub fn choose<'a>(offered: impl IntoIterator<Item = &'a str>) -> Option<&'static str> {
    offered
        .into_iter()
        .map(str::trim)
        .find_map(|o| SUBPROTOCOLS.iter().copied().find(|s| *s == o))
}

/// The `serverInfo` message.
pub fn server_info(session: &str) -> String {
    json!({
        "op": "serverInfo",
        "name": "pada",
        "capabilities": [],
        "supportedEncodings": [],
        "metadata": {"version": env!("CARGO_PKG_VERSION")},
        "sessionId": session,
    })
    .to_string()
}

/// The `advertise` message of `topics`.
pub fn advertise(topics: &[Topic]) -> String {
    let channels: Vec<_> = topics
        .iter()
        .map(|t| {
            let (schema_name, schema) = crate::mcap::schemas::of(*t);
            json!({
                "id": t.id(),
                "topic": t.name(),
                "encoding": "json",
                "schemaName": schema_name,
                "schema": schema,
                "schemaEncoding": "jsonschema",
            })
        })
        .collect();
    json!({"op": "advertise", "channels": channels}).to_string()
}

/// A `status` message (level 0 info, 1 warning, 2 error).
pub fn status(level: u8, message: &str) -> String {
    json!({"op": "status", "level": level, "message": message}).to_string()
}

/// One subscription of a client.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct Subscription {
    /// The client's id for it.
    pub id: u32,
    /// The channel.
    pub channel_id: u32,
}

/// What a client sends.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(tag = "op", rename_all = "camelCase")]
pub enum ClientOp {
    /// Start receiving channels.
    Subscribe {
        /// The subscriptions.
        subscriptions: Vec<Subscription>,
    },
    /// Stop.
    #[serde(rename_all = "camelCase")]
    Unsubscribe {
        /// The client's ids of the subscriptions.
        subscription_ids: Vec<u32>,
    },
}

/// Parses a client's text message; `None` for operations not served
/// (parameters, services, client publishing) or malformed text.
pub fn parse_client(text: &str) -> Option<ClientOp> {
    serde_json::from_str(text).ok()
}

/// A binary `messageData` frame.
pub fn message_data(subscription: u32, log_time: u64, payload: &[u8]) -> Vec<u8> {
    let mut v = Vec::with_capacity(13 + payload.len());
    v.push(MESSAGE_DATA);
    v.extend_from_slice(&subscription.to_le_bytes());
    v.extend_from_slice(&log_time.to_le_bytes());
    v.extend_from_slice(payload);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_offered_subprotocol_that_is_served_wins() {
        assert_eq!(choose(["foxglove.websocket.v1"]), Some("foxglove.websocket.v1"));
        assert_eq!(choose(["foxglove.sdk.v1", "foxglove.websocket.v1"]), Some("foxglove.sdk.v1"));
        assert_eq!(choose(["x", " foxglove.websocket.v1"]), Some("foxglove.websocket.v1"));
        assert_eq!(choose(["chat"]), None);
    }

    #[test]
    fn client_operations() {
        assert_eq!(
            parse_client(r#"{"op":"subscribe","subscriptions":[{"id":7,"channelId":2}]}"#),
            Some(ClientOp::Subscribe { subscriptions: vec![Subscription { id: 7, channel_id: 2 }] })
        );
        assert_eq!(
            parse_client(r#"{"op":"unsubscribe","subscriptionIds":[7]}"#),
            Some(ClientOp::Unsubscribe { subscription_ids: vec![7] })
        );
        assert_eq!(parse_client(r#"{"op":"getParameters"}"#), None);
        let f = message_data(7, 1_000, b"{}");
        assert_eq!(&f[..5], &[1, 7, 0, 0, 0]);
        assert_eq!(u64::from_le_bytes(f[5..13].try_into().unwrap()), 1_000);
        assert_eq!(&f[13..], b"{}");
    }
}
