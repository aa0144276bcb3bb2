//! The telemetry and command protocol between the chip and the host.
//!
//! Both ends import these types, so the host decodes exactly what the chip
//! encodes (the layout of postcard-rpc's "icd" crates). The host's own
//! simulation runs speak the same format, so one capture path serves
//! simulation, emulation and hardware.
//!
//! # Messages
//!
//! | message | direction | payload | when |
//! |---|---|---|---|
//! | [`ToHost::Hello`] | chip → host | [`Hello`] | at boot and in answer to `Ping` |
//! | [`ToHost::Step`] | chip → host | [`Step`] | every control period |
//! | [`ToHost::Episode`] | chip → host | [`Episode`] | at the end of every episode |
//! | [`ToHost::Health`] | chip → host | [`Health`] | periodically |
//! | [`ToHost::State`] | chip → host | [`StateChange`] | on every safety state change |
//! | [`ToHost::Fault`] | chip → host | [`Fault`] | on entering Fault |
//! | [`ToHost::Checkpoint`] | chip → host | [`CheckpointReport`] | after a save or load |
//! | [`ToHost::Log`] | chip → host | [`Log`] | free text |
//! | [`ToHost::Warning`] | chip → host | [`Warning`] | e.g. a checkpoint ignored at boot |
//! | [`ToHost::Weights`] | chip → host | [`WeightsChunk`] | in answer to `ReadWeights` |
//! | [`ToHost::Ack`] | chip → host | [`Ack`] | a command was carried out |
//! | [`ToHost::Nack`] | chip → host | [`Nack`] | a command was refused |
//! | [`ToHost::Policy`] | chip → host | [`PolicyReport`] | after `Hello`, and whenever the policy or its α/Δ changes |
//! | [`ToChip::Ping`] | host → chip | — | answered by `Hello` |
//! | [`ToChip::Start`] | host → chip | [`RunMode`] | learn or test, torque on |
//! | [`ToChip::Stop`] | host → chip | — | to Idle, torque off |
//! | [`ToChip::Pause`] | host → chip | — | to Paused, torque off |
//! | [`ToChip::SetPolicy`] | host → chip | [`PolicySpec`] | one of the six policies and its α/Δ |
//! | [`ToChip::SwitchToSarsa`] | host → chip | — | end of the exploration phase (Section VIII) |
//! | [`ToChip::SetEpsilon`] | host → chip | `f32` | exploration rate |
//! | [`ToChip::SaveCheckpoint`] | host → chip | — | weights and learner state to flash |
//! | [`ToChip::LoadCheckpoint`] | host → chip | — | weights and learner state from flash |
//! | [`ToChip::ReadWeights`] | host → chip | offset `u32`, count `u32` | answered by `Weights` chunks |
//! | [`ToChip::ClearFault`] | host → chip | — | Fault → Idle |
//!
//! Every command is answered by exactly one `Ack` or `Nack` carrying the
//! command frame's sequence number, after any data it asks for (`Hello`,
//! `Weights`, `Checkpoint`).
//!
//! # Frames
//!
//! ```text
//! frame   = COBS( body ‖ crc32_le(body) ) ‖ 0x00
//! body    = postcard( (seq: u32, message: ToHost | ToChip) )
//!           seq: varint, 1–5 bytes; message: variant index (varint) then fields
//! crc32   = CRC-32/ISO-HDLC of body, 4 bytes little endian
//! ```
//!
//! Each direction numbers its frames 0, 1, 2, … (wrapping); the receiver
//! counts a gap whenever a sequence number is not the one expected. COBS
//! removes every 0x00 from the frame, so 0x00 only ever delimits frames: a
//! receiver that joins mid-stream or sees garbage loses at most the frame
//! in progress and resynchronises at the next 0x00. [`FrameDecoder`] counts
//! every loss in [`LinkStats`]. A frame's body is at most [`MAX_BODY`]
//! bytes and a frame on the wire at most [`MAX_FRAME_LEN`].
//!
//! COBS is implemented here rather than taken from a crate so that encoding
//! runs in place in the caller's buffer and decoding runs incrementally on
//! the decoder's own buffer, without a second frame-sized buffer on the
//! chip's stack. CRC-32 is the `crc` crate's table-driven one shared with
//! the checkpoints ([`crate::checkpoint::CRC32`]).

use crate::checkpoint::{LoadOutcome, Saved, CRC32};
use crate::policy::PolicyKind;
use crate::safety::{FaultCause, Rejection, State};
use core::marker::PhantomData;
use heapless::{String, Vec};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

pub use crate::safety::RunMode;

/// Version of this protocol, sent in [`Hello`]; changes with any change of
/// a message's layout.
pub const PROTOCOL_VERSION: u16 = 3;
/// State dimensions a [`Step`] carries.
pub const MAX_STATE_DIMS: usize = 16;
/// Action dimensions (motor outputs) a [`Step`] carries.
pub const MAX_OUTPUTS: usize = 4;
/// Learned joints with a fatigue counter in a [`Step`].
pub const MAX_JOINTS: usize = 4;
/// Servos reported in [`Health`] (LEO has seven).
pub const MAX_SERVOS: usize = 8;
/// Weights per [`WeightsChunk`].
pub const WEIGHTS_PER_CHUNK: usize = 32;
/// Bytes of text in [`Log`] and [`Warning::Text`].
pub const MAX_TEXT: usize = 64;
/// Largest postcard body of a frame, sequence number included.
pub const MAX_BODY: usize = 256;
/// Bytes of the CRC after the body.
pub const CRC_LEN: usize = 4;
/// Largest frame on the wire: COBS of body and CRC, plus the 0x00.
pub const MAX_FRAME_LEN: usize = cobs_max_len(MAX_BODY + CRC_LEN) + 1;

/// Longest COBS encoding of `n` bytes.
pub const fn cobs_max_len(n: usize) -> usize {
    n + n / 254 + 1
}

// ---------------------------------------------------------------------------
// Chip → host
// ---------------------------------------------------------------------------

/// Everything the chip sends.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ToHost {
    /// Who is talking.
    Hello(Hello),
    /// One control step.
    Step(Step),
    /// One finished episode.
    Episode(Episode),
    /// Periodic health.
    Health(Health),
    /// A safety state change.
    State(StateChange),
    /// Entering Fault.
    Fault(Fault),
    /// Result of a checkpoint save or load.
    Checkpoint(CheckpointReport),
    /// Free text.
    Log(Log),
    /// Something the host should know about.
    Warning(Warning),
    /// Part of the weight table.
    Weights(WeightsChunk),
    /// A command was carried out.
    Ack(Ack),
    /// A command was refused.
    Nack(Nack),
    /// The action policy in force (protocol 3; appended last, so that
    /// streams of protocol 2 still decode).
    Policy(PolicyReport),
}

/// Sent at boot and in answer to [`ToChip::Ping`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`] of the sender.
    pub protocol: u16,
    /// Hash of the running configuration (as in checkpoints).
    pub config_hash: u32,
    /// Number of weights in the table.
    pub weight_count: u32,
    /// Control period in microseconds.
    pub period_us: u32,
    /// State dimensions per step.
    pub state_dims: u8,
    /// Learned joints.
    pub joints: u8,
}

/// What a step's observation and reward mean to the agent; with them the
/// host can replay the run through the host build of the same agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepKind {
    /// First observation of an episode (`start_episode`); reward is 0.
    Start,
    /// A step (`step`): reward for the last transition, then the new observation.
    Step,
    /// The episode ended in an absorbing state; no bootstrap.
    Absorbing,
    /// The episode hit its time limit; the observation is bootstrapped.
    Timeout,
}

/// Fatigue of one learned joint (Section IV).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct JointFatigue {
    /// Accumulated damage J since the counter started.
    pub damage: f64,
    /// Backlash re-engagements counted.
    pub reengagements: u32,
}

/// One control step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Control step index since boot.
    pub step: u32,
    /// Time since boot in ms.
    pub time_ms: u32,
    /// Episode index.
    pub episode: u32,
    /// Learning or testing.
    pub mode: RunMode,
    /// What the observation and reward are.
    pub kind: StepKind,
    /// The observation.
    pub state: Vec<f32, MAX_STATE_DIMS>,
    /// The learner's joint action index.
    pub action: u32,
    /// Output applied per action dimension, after the policy.
    pub output: Vec<f32, MAX_OUTPUTS>,
    /// Reward of the transition into this observation.
    pub reward: f32,
    /// TD error δ of the update, raw Q15.16 ([`crate::fixed::Q16`]).
    pub td_error: i32,
    /// Whether the action was an exploratory draw.
    pub explored: bool,
    /// Fatigue per learned joint.
    pub joints: Vec<JointFatigue, MAX_JOINTS>,
    /// Duration of this control period's work, µs.
    pub loop_us: u32,
    /// Cycles of the agent call of this period (DWT cycles on the chip;
    /// instructions executed on the emulated board); 0 if none was taken.
    pub agent_cycles: u32,
}

/// One finished episode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Episode {
    /// Episode index.
    pub index: u32,
    /// Learning or test run.
    pub mode: RunMode,
    /// Sum of rewards.
    pub total_reward: f32,
    /// Steps.
    pub length: u32,
    /// The agent's weight checksum at the end (for bit-for-bit replay).
    pub weights_checksum: u32,
}

/// Periodic health. Counters are totals since boot.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Health {
    /// Time since boot in ms.
    pub uptime_ms: u32,
    /// Present Temperature of each servo, °C.
    pub servo_temps_c: Vec<u8, MAX_SERVOS>,
    /// Lowest Present Voltage over the servos, 0.1 V.
    pub min_voltage_dv: u8,
    /// Servo-bus transactions that failed for any reason.
    pub bus_errors: u32,
    /// Status packets with a bad checksum.
    pub checksum_errors: u32,
    /// Servo requests that timed out.
    pub timeouts: u32,
    /// Eligibility-trace entries dropped for lack of capacity.
    pub trace_drops: u32,
    /// Weight updates that saturated.
    pub weight_saturations: u32,
    /// Control periods that overran.
    pub overruns: u32,
    /// Longest control period's work, µs.
    pub max_loop_us: u32,
    /// Telemetry frames dropped because the link was busy.
    pub telemetry_drops: u32,
}

/// A safety state change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StateChange {
    /// Step index when it happened.
    pub step: u32,
    /// State before.
    pub from: State,
    /// State after.
    pub to: State,
}

/// The machine entered Fault; torque is off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fault {
    /// Step index when it happened.
    pub step: u32,
    /// Time since boot in ms.
    pub time_ms: u32,
    /// Why (with the servo or joint concerned).
    pub cause: FaultCause,
}

/// Result of a checkpoint operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CheckpointReport {
    /// Saved.
    Saved(Saved),
    /// A save failed; the previous checkpoint is intact.
    SaveFailed,
    /// What a load found (at boot or on command).
    Load(LoadOutcome),
}

/// Severity of a [`Log`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LogLevel {
    /// Information.
    Info,
    /// Something unusual.
    Warn,
    /// Something failed.
    Error,
}

/// Free text.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Log {
    /// Severity.
    pub level: LogLevel,
    /// The text (at most [`MAX_TEXT`] bytes).
    pub text: String<MAX_TEXT>,
}

/// Something the host should know about that is not a fault.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum Warning {
    /// The checkpoint found at boot was not loaded (the outcome says why:
    /// configuration mismatch, size mismatch, corruption, format version, a
    /// learner state out of range).
    CheckpointIgnored(LoadOutcome),
    /// Frames that could not be sent since the last warning.
    TelemetryDropped {
        /// Frames dropped.
        frames: u32,
    },
    /// Anything else.
    Text(String<MAX_TEXT>),
}

/// Weights `offset .. offset + weights.len()` of `total`, raw Q15.16.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct WeightsChunk {
    /// Index of the first weight.
    pub offset: u32,
    /// Weights in the table.
    pub total: u32,
    /// The weights.
    pub weights: Vec<i32, WEIGHTS_PER_CHUNK>,
}

/// A command was carried out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Ack {
    /// Sequence number of the command's frame.
    pub seq: u32,
}

/// Why a command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NackReason {
    /// The safety state machine refused it.
    State(Rejection),
    /// A parameter out of range (ε, α, Δ …).
    InvalidParameter,
    /// A weight range outside the table.
    OutOfRange,
    /// Not possible right now (e.g. saving while learning).
    Busy,
    /// The checkpoint operation failed.
    CheckpointFailed,
    /// Not supported by this firmware.
    Unsupported,
}

/// A command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Nack {
    /// Sequence number of the command's frame.
    pub seq: u32,
    /// Why.
    pub reason: NackReason,
}

/// The action policy in force: sent after every [`Hello`] and whenever it
/// changes (`SetPolicy`, `SwitchToSarsa`, a loaded checkpoint, the host
/// runner's switch at `--switch-at`), so a viewer that joins knows what
/// the learner restricts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PolicyReport {
    /// Control step index when it took effect.
    pub step: u32,
    /// The policy the learner was built with, and its α (Eq. 8) or Δ
    /// (Eq. 9).
    pub built: PolicySpec,
    /// Whether PADA or the low-pass filter has switched back to plain
    /// SARSA(λ) (Section VIII); then `built` is what it explored with.
    pub switched_to_sarsa: bool,
}

// ---------------------------------------------------------------------------
// Host → chip
// ---------------------------------------------------------------------------

/// Everything the host sends.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ToChip {
    /// Ask for a [`Hello`].
    Ping,
    /// Learn or test with torque on (also resumes from Paused).
    Start(RunMode),
    /// To Idle, torque off.
    Stop,
    /// To Paused, torque off.
    Pause,
    /// Choose the action policy.
    SetPolicy(PolicySpec),
    /// Switch PADA or low-pass back to plain SARSA (Section VIII).
    SwitchToSarsa,
    /// Set the exploration rate ε.
    SetEpsilon(f32),
    /// Save the weights and the learner's state to flash
    /// ([`crate::checkpoint`]).
    SaveCheckpoint,
    /// Load the weights and the learner's state from flash, if the
    /// configuration matches and the state is in range.
    LoadCheckpoint,
    /// Send weights `offset .. offset + count`.
    ReadWeights {
        /// First weight.
        offset: u32,
        /// Number of weights.
        count: u32,
    },
    /// Leave Fault for Idle.
    ClearFault,
}

/// The six policies of Section V with their parameter, as sent on the wire
/// (the same as [`PolicyKind`], which converts both ways).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PolicySpec {
    /// Plain SARSA(λ).
    Sarsa,
    /// Low-pass filtered actions with coefficient α.
    LowPass(f32),
    /// Markov low-pass with coefficient α.
    MarkovLowPass(f32),
    /// Integrating controller with increment Δ.
    Integrator(f32),
    /// Markov integrating controller with increment Δ.
    MarkovIntegrator(f32),
    /// PADA with reach Δ.
    Pada(f32),
}

impl From<PolicyKind> for PolicySpec {
    fn from(k: PolicyKind) -> Self {
        match k {
            PolicyKind::Sarsa => PolicySpec::Sarsa,
            PolicyKind::LowPass { alpha } => PolicySpec::LowPass(alpha),
            PolicyKind::MarkovLowPass { alpha } => PolicySpec::MarkovLowPass(alpha),
            PolicyKind::Integrator { delta } => PolicySpec::Integrator(delta),
            PolicyKind::MarkovIntegrator { delta } => PolicySpec::MarkovIntegrator(delta),
            PolicyKind::Pada { delta } => PolicySpec::Pada(delta),
        }
    }
}

impl From<PolicySpec> for PolicyKind {
    fn from(s: PolicySpec) -> Self {
        match s {
            PolicySpec::Sarsa => PolicyKind::Sarsa,
            PolicySpec::LowPass(alpha) => PolicyKind::LowPass { alpha },
            PolicySpec::MarkovLowPass(alpha) => PolicyKind::MarkovLowPass { alpha },
            PolicySpec::Integrator(delta) => PolicyKind::Integrator { delta },
            PolicySpec::MarkovIntegrator(delta) => PolicyKind::MarkovIntegrator { delta },
            PolicySpec::Pada(delta) => PolicyKind::Pada { delta },
        }
    }
}

// ---------------------------------------------------------------------------
// Framing
// ---------------------------------------------------------------------------

/// Why a frame could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireError {
    /// The output buffer cannot hold the frame (use [`MAX_FRAME_LEN`]).
    BufferTooSmall,
    /// postcard refused the message (a value it cannot encode).
    Serialize,
}

/// Encodes `msg` with sequence number `seq` into `out` and returns the
/// frame, delimiter included. A buffer of [`MAX_FRAME_LEN`] bytes holds any
/// [`ToHost`] or [`ToChip`] message.
pub fn encode_frame<'b, M: Serialize>(msg: &M, seq: u32, out: &'b mut [u8]) -> Result<&'b [u8], WireError> {
    // The body is serialised `shift` bytes into `out` and COBS-encoded
    // forwards to the start of `out`: the output never overtakes the input
    // because COBS adds at most one byte per 254 plus one.
    let shift = 2 + out.len() / 254;
    let room = out.len().checked_sub(shift + CRC_LEN + 1).ok_or(WireError::BufferTooSmall)?;
    let body_len = {
        let area = out.get_mut(shift..shift + room).ok_or(WireError::BufferTooSmall)?;
        match postcard::to_slice(&(seq, msg), area) {
            Ok(body) => body.len(),
            Err(postcard::Error::SerializeBufferFull) => return Err(WireError::BufferTooSmall),
            Err(_) => return Err(WireError::Serialize),
        }
    };
    let crc = CRC32.checksum(out.get(shift..shift + body_len).ok_or(WireError::BufferTooSmall)?);
    out.get_mut(shift + body_len..shift + body_len + CRC_LEN)
        .ok_or(WireError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    let n = cobs_encode_in_place(out, shift, body_len + CRC_LEN).ok_or(WireError::BufferTooSmall)?;
    *out.get_mut(n).ok_or(WireError::BufferTooSmall)? = 0;
    Ok(&out[..=n])
}

/// COBS-encodes `buf[src..src + len]` into `buf[0..]`, returning the encoded
/// length; `src` must be at least `1 + len / 254` so that no unread byte is
/// overwritten. `None` if the buffer is too short (never for the callers
/// here).
fn cobs_encode_in_place(buf: &mut [u8], src: usize, len: usize) -> Option<usize> {
    if src < 1 + len / 254 {
        return None;
    }
    let mut code_at = 0usize;
    let mut w = 1usize;
    let mut code = 1u8;
    for i in src..src.checked_add(len)? {
        let b = *buf.get(i)?;
        if b == 0 {
            *buf.get_mut(code_at)? = code;
            code_at = w;
            w += 1;
            code = 1;
        } else {
            *buf.get_mut(w)? = b;
            w += 1;
            code += 1;
            if code == 0xFF {
                *buf.get_mut(code_at)? = code;
                code_at = w;
                w += 1;
                code = 1;
            }
        }
    }
    *buf.get_mut(code_at)? = code;
    Some(w)
}

/// Decodes a COBS frame (without its 0x00) in place; `None` if it is not
/// valid COBS.
fn cobs_decode_in_place(buf: &mut [u8]) -> Option<usize> {
    let n = buf.len();
    let (mut r, mut w) = (0usize, 0usize);
    while r < n {
        let code = *buf.get(r)? as usize;
        if code == 0 {
            return None;
        }
        let end = r + code;
        if end > n {
            return None;
        }
        buf.copy_within(r + 1..end, w);
        w += code - 1;
        r = end;
        if code != 0xFF && r < n {
            *buf.get_mut(w)? = 0;
            w += 1;
        }
    }
    Some(w)
}

/// Numbers outgoing frames: 0, 1, 2, … (wrapping).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameEncoder {
    next_seq: u32,
}

impl FrameEncoder {
    /// Starts at sequence number 0.
    pub const fn new() -> Self {
        FrameEncoder { next_seq: 0 }
    }

    /// The sequence number the next frame gets.
    pub fn next_seq(&self) -> u32 {
        self.next_seq
    }

    /// Encodes `msg` with the next sequence number; the number is used up
    /// only if encoding succeeds.
    pub fn encode<'b, M: Serialize>(&mut self, msg: &M, out: &'b mut [u8]) -> Result<&'b [u8], WireError> {
        let frame = encode_frame(msg, self.next_seq, out)?;
        self.next_seq = self.next_seq.wrapping_add(1);
        Ok(frame)
    }

    /// Counts a frame as sent without sending it (e.g. dropped for a full
    /// queue), so that the receiver sees the gap.
    pub fn skip(&mut self) {
        self.next_seq = self.next_seq.wrapping_add(1);
    }
}

/// Why a frame was lost. Each is also counted in [`LinkStats`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// More bytes than the decoder holds before a 0x00.
    Oversize,
    /// Not valid COBS.
    Cobs,
    /// Shorter than a body byte plus the CRC.
    TooShort,
    /// The CRC does not match.
    Crc {
        /// CRC computed over the body.
        computed: u32,
        /// CRC received.
        received: u32,
    },
    /// The CRC matched but postcard could not decode the body (or bytes
    /// were left over): a sender of another protocol version.
    Decode,
}

/// A sequence number other than the one expected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SeqGap {
    /// The number expected.
    pub expected: u32,
    /// The number received.
    pub got: u32,
}

impl SeqGap {
    /// Frames missing in between, if the number moved forwards (a number
    /// that moved backwards, as after the sender restarted, gives 0).
    pub fn missed(&self) -> u32 {
        let d = self.got.wrapping_sub(self.expected);
        if d < 1 << 31 {
            d
        } else {
            0
        }
    }
}

/// A decoded frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded<M> {
    /// Its sequence number.
    pub seq: u32,
    /// The message.
    pub msg: M,
    /// Set when `seq` was not the one expected.
    pub gap: Option<SeqGap>,
}

/// What a [`FrameDecoder`] received and lost.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkStats {
    /// Frames decoded.
    pub frames: u32,
    /// Bytes received (delimiters included).
    pub bytes: u64,
    /// Frames with a wrong CRC.
    pub crc_errors: u32,
    /// Frames that were not valid COBS.
    pub cobs_errors: u32,
    /// Frames longer than the decoder's buffer.
    pub oversize: u32,
    /// Frames too short to hold a body and CRC.
    pub too_short: u32,
    /// Frames with a good CRC that postcard could not decode.
    pub decode_errors: u32,
    /// Times the sequence number was not the one expected.
    pub seq_gaps: u32,
    /// Frames missing according to the sequence numbers.
    pub frames_missed: u64,
}

impl LinkStats {
    /// Frames received but unusable (every error kind).
    pub fn bad_frames(&self) -> u32 {
        self.crc_errors
            .saturating_add(self.cobs_errors)
            .saturating_add(self.oversize)
            .saturating_add(self.too_short)
            .saturating_add(self.decode_errors)
    }

    /// Whether nothing was lost at all.
    pub fn is_clean(&self) -> bool {
        self.bad_frames() == 0 && self.seq_gaps == 0
    }
}

/// Incremental frame decoder for messages `M` ([`ToHost`] on the host,
/// [`ToChip`] on the chip), holding up to `N` encoded bytes of one frame.
pub struct FrameDecoder<M, const N: usize = MAX_FRAME_LEN> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
    expected: Option<u32>,
    stats: LinkStats,
    _msg: PhantomData<fn() -> M>,
}

impl<M: DeserializeOwned, const N: usize> Default for FrameDecoder<M, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M: DeserializeOwned, const N: usize> FrameDecoder<M, N> {
    /// A decoder that takes the first sequence number it sees as expected.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; N],
            len: 0,
            overflow: false,
            expected: None,
            stats: LinkStats {
                frames: 0,
                bytes: 0,
                crc_errors: 0,
                cobs_errors: 0,
                oversize: 0,
                too_short: 0,
                decode_errors: 0,
                seq_gaps: 0,
                frames_missed: 0,
            },
            _msg: PhantomData,
        }
    }

    /// Counters since creation.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Forgets the expected sequence number (e.g. after the peer restarted
    /// on purpose).
    pub fn resync_seq(&mut self) {
        self.expected = None;
    }

    /// Takes one byte; a 0x00 ends a frame, which is then decoded. Returns
    /// `None` for bytes inside a frame and for empty frames (two 0x00 in a
    /// row, which a sender may use to flush the line).
    pub fn push(&mut self, byte: u8) -> Option<Result<Decoded<M>, FrameError>> {
        self.stats.bytes = self.stats.bytes.saturating_add(1);
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                Some(slot) if !self.overflow => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => self.overflow = true,
            }
            return None;
        }
        let (len, overflow) = (self.len, self.overflow);
        self.len = 0;
        self.overflow = false;
        if overflow {
            self.stats.oversize = self.stats.oversize.saturating_add(1);
            return Some(Err(FrameError::Oversize));
        }
        if len == 0 {
            return None;
        }
        Some(self.decode(len))
    }

    fn decode(&mut self, len: usize) -> Result<Decoded<M>, FrameError> {
        let s = &mut self.stats;
        let frame = &mut self.buf[..len.min(N)];
        let Some(n) = cobs_decode_in_place(frame) else {
            s.cobs_errors = s.cobs_errors.saturating_add(1);
            return Err(FrameError::Cobs);
        };
        if n < 1 + CRC_LEN {
            s.too_short = s.too_short.saturating_add(1);
            return Err(FrameError::TooShort);
        }
        let (body, crc) = frame[..n].split_at(n - CRC_LEN);
        let received = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
        let computed = CRC32.checksum(body);
        if computed != received {
            s.crc_errors = s.crc_errors.saturating_add(1);
            return Err(FrameError::Crc { computed, received });
        }
        let (seq, msg) = match postcard::take_from_bytes::<(u32, M)>(body) {
            Ok((v, [])) => v,
            _ => {
                s.decode_errors = s.decode_errors.saturating_add(1);
                return Err(FrameError::Decode);
            }
        };
        let gap = match self.expected {
            Some(expected) if expected != seq => {
                let g = SeqGap { expected, got: seq };
                s.seq_gaps = s.seq_gaps.saturating_add(1);
                s.frames_missed = s.frames_missed.saturating_add(g.missed() as u64);
                Some(g)
            }
            _ => None,
        };
        self.expected = Some(seq.wrapping_add(1));
        s.frames = s.frames.saturating_add(1);
        Ok(Decoded { seq, msg, gap })
    }

    /// Feeds a chunk and iterates over the frames and losses it completes;
    /// a partial frame at the end waits for the next chunk.
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> FrameFeed<'s, 'b, M, N> {
        FrameFeed { decoder: self, rest: bytes }
    }
}

/// Iterator returned by [`FrameDecoder::feed`].
pub struct FrameFeed<'s, 'b, M, const N: usize> {
    decoder: &'s mut FrameDecoder<M, N>,
    rest: &'b [u8],
}

impl<M: DeserializeOwned, const N: usize> Iterator for FrameFeed<'_, '_, M, N> {
    type Item = Result<Decoded<M>, FrameError>;
    fn next(&mut self) -> Option<Self::Item> {
        while let Some((&b, rest)) = self.rest.split_first() {
            self.rest = rest;
            if let Some(r) = self.decoder.push(b) {
                return Some(r);
            }
        }
        None
    }
}

/// The host's decoder of chip telemetry.
pub type HostDecoder = FrameDecoder<ToHost, MAX_FRAME_LEN>;
/// The chip's decoder of host commands.
pub type ChipDecoder = FrameDecoder<ToChip, 64>;

#[cfg(test)]
mod tests {
    use super::*;

    fn reference_cobs(data: &[u8]) -> heapless::Vec<u8, 700> {
        let mut out = heapless::Vec::<u8, 700>::new();
        for block in data.split(|&b| b == 0) {
            let mut rest = block;
            loop {
                let take = rest.len().min(254);
                let full = take == 254;
                out.push((take + 1) as u8).unwrap();
                out.extend_from_slice(&rest[..take]).unwrap();
                rest = &rest[take..];
                if !full || rest.is_empty() {
                    if full {
                        // The in-place encoder closes a full block and opens
                        // an empty one; both decode the same.
                        out.push(1).unwrap();
                    }
                    break;
                }
            }
        }
        out
    }

    #[test]
    fn cobs_in_place_matches_a_reference_and_round_trips() {
        let mut seed = 7u32;
        for len in (0..600).step_by(1) {
            let data: heapless::Vec<u8, 600> = (0..len)
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 17;
                    seed ^= seed << 5;
                    // Mostly non-zero, to exercise 254-byte runs.
                    if seed % 97 == 0 { 0 } else { (seed >> 8) as u8 | 1 }
                })
                .collect();
            let mut buf = [0u8; 1300];
            let shift = 1 + len / 254;
            buf[shift..shift + len].copy_from_slice(&data);
            let n = cobs_encode_in_place(&mut buf, shift, len).unwrap();
            assert_eq!(&buf[..n], &reference_cobs(&data)[..], "len {len}");
            assert!(n <= cobs_max_len(len));
            assert!(!buf[..n].contains(&0));
            let m = cobs_decode_in_place(&mut buf[..n]).unwrap();
            assert_eq!(&buf[..m], &data[..], "len {len}");
        }
    }

    #[test]
    fn cobs_rejects_bad_codes() {
        assert_eq!(cobs_decode_in_place(&mut [0, 1]), None);
        assert_eq!(cobs_decode_in_place(&mut [5, 1, 2]), None);
        assert_eq!(cobs_decode_in_place(&mut [1]), Some(0));
        assert_eq!(cobs_decode_in_place(&mut [1, 1]), Some(1));
    }
}
