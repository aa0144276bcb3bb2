//! The channels of a recording: which telemetry record goes on which topic,
//! and the JSON each message carries. The same list serves the MCAP file
//! ([`super::writer`]) and the live Foxglove server ([`crate::foxglove`]).
//!
//! One topic per record kind, so a viewer plots each without a filter:
//!
//! | topic | one message per | schema |
//! |---|---|---|
//! | `/hello` | `Hello` | `pada.Hello` |
//! | `/step` | `Step` | `pada.Step` |
//! | `/fatigue/<k>` | `Step`, for gearbox k | `pada.Fatigue` |
//! | `/episode` | `Episode` | `pada.Episode` |
//! | `/health` | `Health` | `pada.Health` |
//! | `/claims` | `Health` of a claim table | `pada.Claims` |
//! | `/safety/state` | `State` | `pada.StateChange` |
//! | `/safety/fault` | `Fault` | `pada.Fault` |
//! | `/policy` | `Policy` | `pada.Policy` |
//! | `/governor` | `Policy` with a wear governor | `pada.Governor` |
//! | `/event` | checkpoint report, log, warning, weights, ack, nack | `pada.Event` |
//! | `/link` | lost frame, sequence gap, `Health`, the end | `pada.Link` |
//! | `/scene` | `Step` of a known robot | `foxglove.SceneUpdate` |
//! | `/checkpoint` | save or restore of a checkpoint the host keeps (its chunks, requests and report) | `pada.Checkpoint` |
//!
//! A new record kind is one [`Topic`] variant, its view, its schema in
//! [`super::schemas`] and a line in [`Channelizer::frame`], as `/claims`
//! (the claim table's occupancy, from `Health`) shows.

use super::scene::SceneBuilder;
use crate::capture::transfer::{Transfer, Transfers};
use crate::capture::{describe, loss_name, mode_name, step_kind_name};
use pada_core::wire::{Decoded, FrameError, Hello, LinkStats, SeqGap, ToHost, MAX_GEARBOXES};
use serde::{Deserialize, Serialize};

/// A channel of a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Topic {
    /// `Hello`: who is talking.
    Hello,
    /// `Step`: one control step.
    Step,
    /// The fatigue of gearbox k, from each `Step`.
    Fatigue(u8),
    /// `Episode`: one finished episode.
    Episode,
    /// `Health`: the periodic health report.
    Health,
    /// The claim table's occupancy, from each `Health` of a board whose
    /// table is a claim table.
    Claims,
    /// `State`: a safety state change.
    SafetyState,
    /// `Fault`: entering Fault.
    SafetyFault,
    /// `Policy`: the action policy in force.
    Policy,
    /// The wear governor's status, from each `Policy` that carries one.
    Governor,
    /// Checkpoint, log, warning, weights, ack and nack reports.
    Event,
    /// The link's counters: at every lost frame, sequence gap, `Health`
    /// and at the end of the stream.
    Link,
    /// The robot drawn from the joint angles (`foxglove.SceneUpdate`).
    Scene,
    /// One save or restore of a checkpoint the host keeps, from its
    /// frames (`crate::capture::transfer`; appended last, so the other
    /// channels keep their ids).
    Checkpoint,
}

impl Topic {
    /// Every channel, in a fixed order (the live server advertises them
    /// all at once; a file holds those that have messages).
    pub fn all() -> Vec<Topic> {
        let mut v = vec![Topic::Hello, Topic::Step];
        v.extend((0..MAX_GEARBOXES as u8).map(Topic::Fatigue));
        v.extend([
            Topic::Episode,
            Topic::Health,
            Topic::Claims,
            Topic::SafetyState,
            Topic::SafetyFault,
            Topic::Policy,
            Topic::Governor,
            Topic::Event,
            Topic::Link,
            Topic::Scene,
            Topic::Checkpoint,
        ]);
        v
    }

    /// A stable number, 1 and up (the live server's channel id).
    pub fn id(self) -> u32 {
        Topic::all().iter().position(|t| *t == self).map_or(0, |i| i as u32 + 1)
    }

    /// The topic's name.
    pub fn name(self) -> String {
        match self {
            Topic::Hello => "/hello".into(),
            Topic::Step => "/step".into(),
            Topic::Fatigue(k) => format!("/fatigue/{k}"),
            Topic::Episode => "/episode".into(),
            Topic::Health => "/health".into(),
            Topic::Claims => "/claims".into(),
            Topic::SafetyState => "/safety/state".into(),
            Topic::SafetyFault => "/safety/fault".into(),
            Topic::Policy => "/policy".into(),
            Topic::Governor => "/governor".into(),
            Topic::Event => "/event".into(),
            Topic::Link => "/link".into(),
            Topic::Scene => "/scene".into(),
            Topic::Checkpoint => "/checkpoint".into(),
        }
    }

    /// The topic named `name`.
    pub fn from_name(name: &str) -> Option<Topic> {
        Topic::all().into_iter().find(|t| t.name() == name)
    }
}

/// `/hello`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HelloView {
    /// The sender's protocol version.
    pub protocol: u16,
    /// Hash of the running configuration (0: a host run).
    pub config_hash: u32,
    /// The same, as 8 hexadecimal digits.
    pub config_hash_hex: String,
    /// Weights in the table.
    pub weight_count: u32,
    /// Control period \[µs\].
    pub period_us: u32,
    /// State dimensions per step.
    pub state_dims: u8,
    /// Learned joints.
    pub joints: u8,
    /// The robot these dimensions belong to (`leo`, `pendulum`, `unknown`).
    pub robot: String,
}

/// `/step` (the fatigue is on `/fatigue/<k>`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepView {
    /// Control step index since boot.
    pub step: u32,
    /// The board's clock \[ms since boot\].
    pub time_ms: u32,
    /// Episode index.
    pub episode: u32,
    /// `learning` or `testing`.
    pub mode: String,
    /// `start`, `step`, `absorbing` or `timeout`.
    pub kind: String,
    /// The observation.
    pub state: Vec<f32>,
    /// The learner's joint action index.
    pub action: u32,
    /// Output per action dimension, after the policy.
    pub output: Vec<f32>,
    /// Reward of the transition into this observation.
    pub reward: f32,
    /// TD error δ (the raw Q15.16 divided by 65536).
    pub td_error: f64,
    /// Whether the action was exploratory.
    pub explored: bool,
    /// Whether this step followed a footstep (LEO's mirrored memory).
    pub footstep: bool,
    /// Gearboxes counted (the `/fatigue/<k>` messages of this step).
    pub gearboxes: u8,
    /// Duration of this period's work \[µs\].
    pub loop_us: u32,
    /// Cycles of the agent call.
    pub agent_cycles: u32,
}

/// `/fatigue/<k>`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FatigueView {
    /// Control step index.
    pub step: u32,
    /// The gearbox k.
    pub gearbox: u8,
    /// Accumulated damage J.
    pub damage: f64,
    /// Backlash re-engagements counted.
    pub reengagements: u32,
}

/// `/episode`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeView {
    /// Episode index.
    pub index: u32,
    /// `learning` or `testing`.
    pub mode: String,
    /// Sum of rewards.
    pub total_reward: f32,
    /// Steps.
    pub length: u32,
    /// The agent's weight checksum.
    pub weights_checksum: u32,
}

/// `/health`: the `Health` record itself (its fields, as the wire defines
/// them), with the hottest servo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HealthView<'a> {
    /// The report.
    #[serde(flatten)]
    pub health: &'a pada_core::wire::Health,
    /// The hottest servo \[°C\] (0 without servos).
    pub max_servo_temp_c: u8,
}

/// `/safety/state`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateView {
    /// Step index when it happened.
    pub step: u32,
    /// The state before.
    pub from: String,
    /// The state after.
    pub to: String,
    /// Whether the state after is Fault.
    pub to_fault: bool,
}

/// `/safety/fault`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultView {
    /// Step index when it happened.
    pub step: u32,
    /// The board's clock \[ms since boot\].
    pub time_ms: u32,
    /// The cause's short name.
    pub cause: String,
    /// The cause with the servo or joint concerned.
    pub detail: String,
}

/// `/policy`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolicyView {
    /// Step index when it took effect.
    pub step: u32,
    /// The policy's name.
    pub policy: String,
    /// The policy with its parameters.
    pub built: String,
    /// Whether it switched back to plain SARSA(λ).
    pub switched_to_sarsa: bool,
    /// Whether a wear governor runs (then `/governor` has its status).
    pub governed: bool,
}

/// `/governor`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GovernorView {
    /// Step index of the report.
    pub step: u32,
    /// The MTBF budget \[s\].
    pub budget_s: f32,
    /// `delta` or `alpha`.
    pub restricts: String,
    /// The Δ or α in force.
    pub parameter: f32,
    /// The rung in force, 0 the floor.
    pub rung: u8,
    /// Rungs on the ladder.
    pub rungs: u8,
    /// Learning actions in the window.
    pub window_steps: u32,
    /// The weakest gearbox's damage rate \[J per s\].
    pub damage_rate: f32,
    /// The window's predicted MTBF \[s\] (null when infinite).
    pub window_mtbf_s: Option<f32>,
    /// Moves so far.
    pub moves: u32,
    /// Learning actions after which the window was over budget.
    pub over_budget_steps: u32,
}

/// `/event`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventView {
    /// `checkpoint`, `log`, `warning`, `weights`, `ack` or `nack`.
    pub kind: String,
    /// One line of what it says.
    pub detail: String,
}

/// `/link`: the link's counters after an event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkView {
    /// `lost` (a frame), `gap` (a sequence gap), `health` or `end`.
    pub event: String,
    /// What was lost, or empty.
    pub detail: String,
    /// Frames unusable so far (every kind).
    pub bad_frames: u32,
    /// The counters.
    #[serde(flatten)]
    pub stats: LinkStats,
}

/// The robot a `Hello` names, if it is one of pada's own with the same
/// definition (its name and definition hash): the robots whose bodies the
/// scene can draw.
pub fn robot_of(hello: &Hello) -> Option<&'static pada_core::robot::RobotSpec> {
    let robot = pada_core::robot::registry::find(&hello.robot)?.spec;
    (robot.definition_hash() == hello.robot_hash).then_some(robot)
}

/// The body the scene draws for a `Hello`: its robot's; for the simulated
/// pendulum of Section VII (a task of no robot, named `pendulum` with
/// definition hash 0), the physical pendulum's, whose observation starts
/// with the same angle. (Since the robot refactor named robots by
/// definition, that task's run had an empty `/scene`; the live Foxglove
/// test found it.)
fn scene_robot(hello: &Hello) -> Option<&'static pada_core::robot::RobotSpec> {
    robot_of(hello).or_else(|| {
        let simulated_pendulum = hello.robot_hash == 0 && hello.robot.as_str() == "pendulum";
        simulated_pendulum.then(|| pada_core::robot::registry::find("pendulum").map(|b| b.spec)).flatten()
    })
}

/// The robot's name as `/hello` gives it.
fn robot_name(hello: &Hello) -> &str {
    hello.robot.as_str()
}

/// One message for a channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelMessage {
    /// Its channel.
    pub topic: Topic,
    /// Log time \[ns\] on the board's clock ([`BoardClock`]).
    pub log_time: u64,
    /// The wire frame's sequence number it came from (0 for link events
    /// without a frame).
    pub sequence: u32,
    /// The JSON.
    pub data: Vec<u8>,
}

/// The board's clock as log times: milliseconds since boot from `Step`,
/// `Health` and `Fault`; records without a time take the last one. After a
/// reboot the board's clock starts again at 0: the log time then goes on
/// from the last one, so a recording's times never run backwards.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BoardClock {
    offset_ns: u64,
    last_ns: u64,
}

impl BoardClock {
    /// The board says it is `ms` since boot.
    pub fn at_ms(&mut self, ms: u32) -> u64 {
        let t = ms as u64 * 1_000_000;
        if t + self.offset_ns < self.last_ns {
            self.offset_ns = self.last_ns - t;
        }
        self.last_ns = t + self.offset_ns;
        self.last_ns
    }

    /// The last time the board gave.
    pub fn now(&self) -> u64 {
        self.last_ns
    }
}

/// Turns decoded frames and losses into channel messages.
#[derive(Debug, Default)]
pub struct Channelizer {
    clock: BoardClock,
    scene: SceneBuilder,
    hellos: Vec<Hello>,
}

impl Channelizer {
    /// A channelizer at time 0, robot unknown until a `Hello`.
    pub fn new() -> Self {
        Self::default()
    }

    /// The `Hello`s seen, in order (the file's metadata names them).
    pub fn hellos(&self) -> &[Hello] {
        &self.hellos
    }

    /// The messages of one decoded frame, appended to `out`.
    pub fn frame(&mut self, frame: &Decoded<ToHost>, out: &mut Vec<ChannelMessage>) {
        let seq = frame.seq;
        let mut push = |topic: Topic, log_time: u64, data: Vec<u8>| {
            out.push(ChannelMessage { topic, log_time, sequence: seq, data })
        };
        match &frame.msg {
            ToHost::Hello(h) => {
                self.hellos.push(h.clone());
                self.scene.robot(scene_robot(h));
                push(Topic::Hello, self.clock.now(), json(&HelloView {
                    protocol: h.protocol,
                    config_hash: h.config_hash,
                    config_hash_hex: format!("{:08x}", h.config_hash),
                    weight_count: h.weight_count,
                    period_us: h.period_us,
                    state_dims: h.state_dims,
                    joints: h.joints,
                    robot: robot_name(h).into(),
                }));
            }
            ToHost::Step(s) => {
                let t = self.clock.at_ms(s.time_ms);
                push(Topic::Step, t, json(&StepView {
                    step: s.step,
                    time_ms: s.time_ms,
                    episode: s.episode,
                    mode: mode_name(s.mode).into(),
                    kind: step_kind_name(s.kind).into(),
                    state: s.state.to_vec(),
                    action: s.action,
                    output: s.output.to_vec(),
                    reward: s.reward,
                    td_error: s.td_error as f64 / 65536.0,
                    explored: s.explored,
                    footstep: s.footstep,
                    gearboxes: s.joints.len() as u8,
                    loop_us: s.loop_us,
                    agent_cycles: s.agent_cycles,
                }));
                for (k, j) in s.joints.iter().enumerate() {
                    push(Topic::Fatigue(k as u8), t, json(&FatigueView {
                        step: s.step,
                        gearbox: k as u8,
                        damage: j.damage,
                        reengagements: j.reengagements,
                    }));
                }
                if let Some(scene) = self.scene.step(s, t) {
                    push(Topic::Scene, t, scene);
                }
            }
            ToHost::Episode(e) => push(Topic::Episode, self.clock.now(), json(&EpisodeView {
                index: e.index,
                mode: mode_name(e.mode).into(),
                total_reward: e.total_reward,
                length: e.length,
                weights_checksum: e.weights_checksum,
            })),
            ToHost::Health(h) => {
                let t = self.clock.at_ms(h.uptime_ms);
                push(Topic::Health, t, json(&HealthView {
                    health: h,
                    max_servo_temp_c: h.servo_temps_c.iter().copied().max().unwrap_or(0),
                }));
                if let Some(occupancy) = crate::capture::TableOccupancy::of(h) {
                    push(Topic::Claims, t, json(&occupancy));
                }
            }
            ToHost::State(s) => push(Topic::SafetyState, self.clock.now(), json(&StateView {
                step: s.step,
                from: format!("{:?}", s.from),
                to: format!("{:?}", s.to),
                to_fault: s.to.fault().is_some(),
            })),
            ToHost::Fault(f) => {
                let t = self.clock.at_ms(f.time_ms);
                push(Topic::SafetyFault, t, json(&FaultView {
                    step: f.step,
                    time_ms: f.time_ms,
                    cause: f.cause.name().into(),
                    detail: format!("{:?}", f.cause),
                }));
            }
            ToHost::Policy(p) => {
                let t = self.clock.now();
                push(Topic::Policy, t, json(&PolicyView {
                    step: p.step,
                    policy: p.built.name().into(),
                    built: format!("{:?}", p.built),
                    switched_to_sarsa: p.switched_to_sarsa,
                    governed: p.governor.is_some(),
                }));
                if let Some(g) = &p.governor {
                    push(Topic::Governor, t, json(&GovernorView {
                        step: p.step,
                        budget_s: g.budget_s,
                        restricts: format!("{:?}", g.restricts).to_lowercase(),
                        parameter: g.parameter,
                        rung: g.rung,
                        rungs: g.rungs,
                        window_steps: g.window_steps,
                        damage_rate: g.damage_rate,
                        window_mtbf_s: g.window_mtbf_s.is_finite().then_some(g.window_mtbf_s),
                        moves: g.moves,
                        over_budget_steps: g.over_budget_steps,
                    }));
                }
            }
            // A checkpoint transfer's frames are one `/checkpoint` message
            // when it ends ([`Channelizer::transfer`]).
            other if Transfers::is_transfer_frame(other) => {}
            other => {
                let (kind, detail) = describe(other);
                push(Topic::Event, self.clock.now(), json(&EventView { kind: kind.into(), detail }));
            }
        }
    }

    /// The `/checkpoint` message of a save or restore that ended.
    pub fn transfer(&mut self, t: &Transfer) -> ChannelMessage {
        ChannelMessage { topic: Topic::Checkpoint, log_time: self.clock.now(), sequence: 0, data: json(t) }
    }

    /// The `/link` message of a lost frame.
    pub fn lost(&mut self, e: &FrameError, stats: LinkStats) -> ChannelMessage {
        self.link("lost", loss_name(e), stats, 0)
    }

    /// The `/link` message of a sequence gap before frame `seq`.
    pub fn gap(&mut self, gap: &SeqGap, seq: u32, stats: LinkStats) -> ChannelMessage {
        let detail = if gap.is_resync() {
            format!("expected seq {} got {} (resynchronised)", gap.expected, gap.got)
        } else {
            format!("expected seq {} got {} ({} missed)", gap.expected, gap.got, gap.missed())
        };
        self.link("gap", detail, stats, seq)
    }

    /// The `/link` message after a `Health` report, or at the end of the
    /// stream (`event` "health" or "end").
    pub fn counters(&mut self, event: &str, stats: LinkStats, seq: u32) -> ChannelMessage {
        self.link(event, String::new(), stats, seq)
    }

    fn link(&mut self, event: &str, detail: String, stats: LinkStats, seq: u32) -> ChannelMessage {
        ChannelMessage {
            topic: Topic::Link,
            log_time: self.clock.now(),
            sequence: seq,
            data: json(&LinkView { event: event.into(), detail, bad_frames: stats.bad_frames(), stats }),
        }
    }
}

/// A view as JSON bytes (the views hold no maps with non-string keys, so
/// this cannot fail; an empty object stands in if it ever did).
pub fn json<T: Serialize>(v: &T) -> Vec<u8> {
    serde_json::to_vec(v).unwrap_or_else(|_| b"{}".to_vec())
}

#[cfg(test)]
mod checkpoint_view_tests {
    use super::*;

    #[test]
    fn the_checkpoint_view_has_exactly_its_schemas_fields() {
        let t = crate::capture::transfer::Transfer {
            direction: crate::capture::transfer::Direction::Restore,
            generation: None,
            bytes: 1,
            chunks: 2,
            requests: 3,
            board_bytes: 4,
            host_bytes: 5,
            link_s: 0.5,
            outcome: "cut-off".into(),
            reported: false,
            reported_chunks: None,
            started_s: 1.0,
            ended_s: 2.0,
        };
        let view: serde_json::Value = serde_json::from_slice(&json(&t)).unwrap();
        let (_, schema) = super::super::schemas::of(Topic::Checkpoint);
        let schema: serde_json::Value = serde_json::from_str(schema).unwrap();
        let mut fields: Vec<&str> = view.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        let mut required: Vec<&str> = schema["required"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
        fields.sort_unstable();
        required.sort_unstable();
        assert_eq!(fields, required);
        assert_eq!(view["direction"], "restore");
        // The host's clock stays out of a recording.
        assert!(view.get("started_s").is_none());
    }
}
