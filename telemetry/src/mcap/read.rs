//! A recording read back (`pada capture --file X.mcap`): the counts, the
//! latest values and the link's counters of `pada capture`'s summary,
//! rebuilt from the channels' JSON in the file's order, as the capture
//! built them from the frames.

use super::channels::{EpisodeView, FatigueView, FaultView, LinkView, StateView, StepView, Topic};
use crate::capture::{Latest, MessageCounts};
use pada_core::wire::LinkStats;
use serde::de::DeserializeOwned;
use std::collections::BTreeMap;

/// The first bytes of every MCAP file.
pub const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Whether `head` (a file's first bytes) starts as an MCAP file does.
pub fn is_mcap(head: &[u8]) -> bool {
    head.starts_with(MAGIC)
}

/// What a recording says.
#[derive(Debug, Clone, PartialEq)]
pub struct Replayed {
    /// The link's final counters (the last `/link` message).
    pub link: LinkStats,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The latest values.
    pub latest: Latest,
    /// Messages per topic.
    pub per_topic: BTreeMap<String, u64>,
    /// The metadata records by name.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
}

fn parse<T: DeserializeOwned>(topic: &str, data: &[u8]) -> Result<T, String> {
    serde_json::from_slice(data).map_err(|e| format!("a {topic} message is not its schema's JSON ({e})"))
}

/// Reads a whole MCAP file; an error names what is wrong with it.
pub fn replay(bytes: &[u8]) -> Result<Replayed, String> {
    // The summary section and its indexes must be intact too.
    ::mcap::Summary::read(bytes).map_err(|e| format!("not a valid MCAP file ({e})"))?;
    let mut messages = MessageCounts::default();
    let mut latest = Latest::default();
    let mut link = None;
    let mut per_topic = BTreeMap::new();
    // Every chunk's CRC checked: a damaged message is an error, not a
    // different summary.
    let options = ::mcap::read::Options::ValidateChunkCrcs.into();
    let stream =
        ::mcap::MessageStream::new_with_options(bytes, options).map_err(|e| format!("not a valid MCAP file ({e})"))?;
    for m in stream {
        let m = m.map_err(|e| format!("not a valid MCAP file ({e})"))?;
        let name = m.channel.topic.as_str();
        *per_topic.entry(name.to_string()).or_insert(0) += 1;
        let data = m.data.as_ref();
        match Topic::from_name(name) {
            Some(Topic::Hello) => messages.hello += 1,
            Some(Topic::Step) => {
                let s: StepView = parse(name, data)?;
                messages.step += 1;
                latest.step = Some(s.step);
                latest.damage.clear();
                latest.reengagements.clear();
            }
            Some(Topic::Fatigue(_)) => {
                let f: FatigueView = parse(name, data)?;
                latest.damage.push(f.damage);
                latest.reengagements.push(f.reengagements);
            }
            Some(Topic::Episode) => {
                let e: EpisodeView = parse(name, data)?;
                messages.episode += 1;
                if e.mode == "testing" {
                    latest.test_episodes += 1;
                    latest.test_return = Some(e.total_reward);
                } else {
                    latest.learning_episodes += 1;
                    latest.learning_return = Some(e.total_reward);
                }
            }
            Some(Topic::Health) => {
                // The wire's own record (the view adds the hottest servo).
                let h: pada_core::wire::Health = parse(name, data)?;
                messages.health += 1;
                latest.table = crate::capture::TableOccupancy::of(&h);
            }
            Some(Topic::SafetyState) => {
                let s: StateView = parse(name, data)?;
                messages.state += 1;
                if !s.to_fault {
                    latest.fault = None;
                }
                latest.state = Some(s.to);
            }
            Some(Topic::SafetyFault) => {
                let f: FaultView = parse(name, data)?;
                messages.fault += 1;
                latest.fault = Some(f.cause);
            }
            Some(Topic::Policy | Topic::Event) => messages.other += 1,
            Some(Topic::Checkpoint) => {
                // One message for a save's chunks or a restore's requests,
                // and the board's report that closed it.
                let t: crate::capture::transfer::Transfer = parse(name, data)?;
                match t.direction {
                    crate::capture::transfer::Direction::Save => messages.checkpoint_chunk += t.chunks as u64,
                    crate::capture::transfer::Direction::Restore => messages.restore_wanted += t.requests as u64,
                }
                messages.other += t.reported as u64;
            }
            Some(Topic::Link) => link = Some(parse::<LinkView>(name, data)?.stats),
            Some(Topic::Governor | Topic::Claims | Topic::Scene) | None => {}
        }
    }
    let mut metadata = BTreeMap::new();
    for r in ::mcap::read::LinearReader::new(bytes).map_err(|e| format!("not a valid MCAP file ({e})"))? {
        if let ::mcap::records::Record::Metadata(md) = r.map_err(|e| format!("not a valid MCAP file ({e})"))? {
            metadata.insert(md.name, md.metadata);
        }
    }
    let link = link.ok_or("the recording has no /link message (it was not written by pada, or not finished)")?;
    Ok(Replayed { link, messages, latest, per_topic, metadata })
}
