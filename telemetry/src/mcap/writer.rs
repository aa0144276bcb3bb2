//! The MCAP file of `--mcap FILE`: one channel per [`Topic`], each with
//! its JSON Schema (message encoding `json`, schema encoding
//! `jsonschema`), chunked and indexed without compression. A channel is
//! added with its first message. At the end, two metadata records:
//! `pada` (pada's version, the configuration hash of the stream's `Hello`,
//! the protocol, the robot) and `pada.link` (the link's final counters, as
//! `pada capture`'s summary has them).

use super::channels::{ChannelMessage, Topic};
use super::{ChannelSink, StreamEnd};
use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// The metadata record's name for pada's version and configuration.
pub const META_PADA: &str = "pada";
/// The metadata record's name for the link's counters.
pub const META_LINK: &str = "pada.link";

/// An MCAP file being written.
pub struct McapFile {
    w: Option<::mcap::Writer<BufWriter<File>>>,
    channels: HashMap<Topic, u16>,
    schemas: HashMap<&'static str, u16>,
}

fn io(e: ::mcap::McapError) -> std::io::Error {
    std::io::Error::other(e.to_string())
}

impl McapFile {
    /// Creates (or truncates) `path` and writes the MCAP header.
    pub fn create(path: &Path) -> std::io::Result<McapFile> {
        let f = File::create(path)?;
        let w = ::mcap::WriteOptions::new()
            .compression(None)
            .profile("")
            .library(format!("pada {}", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(f))
            .map_err(io)?;
        Ok(McapFile { w: Some(w), channels: HashMap::new(), schemas: HashMap::new() })
    }

    fn channel(&mut self, topic: Topic) -> std::io::Result<u16> {
        if let Some(&id) = self.channels.get(&topic) {
            return Ok(id);
        }
        let w = self.w.as_mut().ok_or_else(|| std::io::Error::other("the MCAP file is closed"))?;
        let (name, text) = super::schemas::of(topic);
        let schema = match self.schemas.get(name) {
            Some(&id) => id,
            None => {
                let id = w.add_schema(name, "jsonschema", text.as_bytes()).map_err(io)?;
                self.schemas.insert(name, id);
                id
            }
        };
        let id = w.add_channel(schema, &topic.name(), "json", &BTreeMap::new()).map_err(io)?;
        self.channels.insert(topic, id);
        Ok(id)
    }
}

impl ChannelSink for McapFile {
    fn write(&mut self, msg: &ChannelMessage) -> std::io::Result<()> {
        let id = self.channel(msg.topic)?;
        let w = self.w.as_mut().ok_or_else(|| std::io::Error::other("the MCAP file is closed"))?;
        let header = ::mcap::records::MessageHeader {
            channel_id: id,
            sequence: msg.sequence,
            log_time: msg.log_time,
            publish_time: msg.log_time,
        };
        w.write_to_known_channel(&header, &msg.data).map_err(io)
    }

    fn finish(&mut self, end: &StreamEnd<'_>) -> std::io::Result<()> {
        let Some(mut w) = self.w.take() else { return Ok(()) };
        w.write_metadata(&::mcap::records::Metadata { name: META_PADA.into(), metadata: pada_metadata(end) })
            .map_err(io)?;
        w.write_metadata(&::mcap::records::Metadata { name: META_LINK.into(), metadata: link_metadata(end) })
            .map_err(io)?;
        w.finish().map_err(io)?;
        let mut inner = w.into_inner();
        std::io::Write::flush(&mut inner)
    }
}

/// `pada`: the version, and what the `Hello`s said (the last one's
/// configuration hash; all distinct ones when the board changed).
fn pada_metadata(end: &StreamEnd<'_>) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("version".into(), env!("CARGO_PKG_VERSION").into());
    let last = end.hellos.last();
    m.insert(
        "config_hash".into(),
        last.map_or_else(|| "unknown (no Hello in the stream)".into(), |h| format!("{:08x}", h.config_hash)),
    );
    let mut hashes: Vec<String> = end.hellos.iter().map(|h| format!("{:08x}", h.config_hash)).collect();
    hashes.dedup();
    m.insert("config_hashes".into(), hashes.join(","));
    if let Some(h) = last {
        m.insert("protocol".into(), h.protocol.to_string());
        m.insert("weight_count".into(), h.weight_count.to_string());
        m.insert("period_us".into(), h.period_us.to_string());
        m.insert("robot".into(), h.robot.as_str().into());
        m.insert("robot_hash".into(), format!("{:08x}", h.robot_hash));
    }
    m
}

/// `pada.link`: the link's final counters, each as a decimal string.
fn link_metadata(end: &StreamEnd<'_>) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    if let Ok(serde_json::Value::Object(o)) = serde_json::to_value(end.stats) {
        for (k, v) in o {
            m.insert(k, v.to_string());
        }
    }
    m.insert("bad_frames".into(), end.stats.bad_frames().to_string());
    m
}
