//! The messages between the chip and the host: the table of the module
//! documentation ([`crate::wire`]) as types. Framing is in
//! [`crate::wire::frame`]; nothing here knows about bytes.

use crate::checkpoint::stream::Chunk;
use crate::checkpoint::{LoadOutcome, Saved};
use crate::governor::GovernorStatus;
use crate::policy::PolicyKind;
use crate::safety::{FaultCause, Rejection, State};
use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

pub use crate::safety::RunMode;

/// Version of this protocol, sent in [`Hello`]; changes with any change of
/// a message's layout (3: `Health` reports the checkpoint sectors' wear,
/// `Saved` the erase count, `NackReason::FlashWear`; `SetPolicy` carries
/// [`PolicyKind`] itself, in the same bytes as before; 4: the
/// [`ToHost::Policy`] report and [`CheckpointReport::TooLarge`], appended
/// last; 5: `Step::footstep`; 6: the gentle explorations appended to
/// [`PolicyKind`], the wear governor's status in [`PolicyReport`] and
/// [`ToChip::SetMtbfBudget`]; 7: the claim table's occupancy at the end
/// of [`Health`]; 8: the checkpoint the host keeps,
/// [`ToHost::CheckpointChunk`], [`ToHost::RestoreWanted`],
/// [`ToHost::Restored`], [`CheckpointReport::Streamed`],
/// [`ToChip::RestoreChunk`] and [`ToChip::RestoreNone`], all appended
/// last; `ToChip` is no longer `Copy`); 9: [`Hello`] names the robot
/// and its definition's hash instead of leaving it to be guessed from its
/// dimensions (a robot is a definition, not a case of a closed list), and
/// a restore's batch is [`RESTORE_BATCH`] = 24 chunks, not 3, which a
/// protocol 8 board's 512-byte command buffer cannot hold; 10:
/// [`FaultCause::HardwareAlert`], a Protocol 2.0 servo's Alert bit with
/// its Hardware Error Status, appended last.
pub const PROTOCOL_VERSION: u16 = 10;
/// The capacities of a [`Step`] (state dimensions, motor outputs and
/// counted gearboxes) and of a [`Health`] report (servos): pada-core's own
/// ([`crate::limits`]).
pub use crate::limits::{MAX_ACTION_DIMS, MAX_GEARBOXES, MAX_SERVOS, MAX_STATE_DIMS};
/// Weights per [`WeightsChunk`].
pub const WEIGHTS_PER_CHUNK: usize = 32;
/// Bytes of text in [`Log`] and [`Warning::Text`].
pub const MAX_TEXT: usize = 64;
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
    /// The action policy in force (protocol 4; appended last).
    Policy(PolicyReport),
    /// One chunk of a checkpoint streamed to the host, which keeps it
    /// ([`crate::checkpoint::stream`]; protocol 8): the body in ascending
    /// order, the header last.
    CheckpointChunk(Chunk),
    /// The board asks the host for the checkpoint it keeps, from an offset
    /// on (protocol 8): at boot from 0, then after every batch.
    RestoreWanted(RestoreRequest),
    /// What the board's restore from the host came to (protocol 8).
    Restored(RestoreOutcome),
}

/// Sent at boot and in answer to [`ToChip::Ping`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`] of the sender. First, so that a reader can
    /// tell another version's `Hello` even where the rest of it does not
    /// decode ([`super::frame::hello_protocol`]).
    pub protocol: u16,
    /// The robot's name (`RobotSpec::name` of `crate::robot`).
    pub robot: heapless::String<{ crate::limits::MAX_ROBOT_NAME }>,
    /// Its definition's hash (`RobotSpec::definition_hash`).
    pub robot_hash: u32,
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
    pub output: Vec<f32, MAX_ACTION_DIMS>,
    /// Reward of the transition into this observation.
    pub reward: f32,
    /// TD error δ of the update, raw Q15.16 ([`crate::fixed::Q16`]).
    pub td_error: i32,
    /// Whether the action was an exploratory draw.
    pub explored: bool,
    /// Whether the policy's memory was mirrored before this call (a
    /// footstep of LEO, `RobotSpec::footstep_remap`): a replay must do the
    /// same to take the same action.
    pub footstep: bool,
    /// Fatigue per learned joint.
    pub joints: Vec<JointFatigue, MAX_GEARBOXES>,
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
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
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
    /// Erases of the more worn of the two checkpoint flash sectors, as the
    /// newest checkpoint counted them ([`crate::checkpoint::FlashWear`]).
    pub checkpoint_erases: u32,
    /// Saves refused since boot because they would wear the sector out
    /// before its stated lifetime ([`crate::checkpoint::WearBudget`]).
    pub saves_refused: u32,
    /// Slots of the claim table claimed ([`crate::claim_table`]; 0 for a
    /// plain table).
    pub table_claimed: u32,
    /// Slots of the claim table (0 for a plain table).
    pub table_slots: u32,
    /// Claims the full claim table refused: updates dropped.
    pub claims_refused: u32,
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
    /// A save refused before flash was touched: the checkpoint (header,
    /// learner state and weights) does not fit a slot — LEO's 8 MiB table
    /// on the F429 against its 128 KiB flash sectors. (Appended last, so
    /// the earlier variants keep their encoding.)
    TooLarge {
        /// Bytes the checkpoint needs.
        needed: u32,
        /// Bytes a slot holds.
        capacity: u32,
    },
    /// A checkpoint streamed to the host, whole (protocol 8): the host keeps
    /// it once every chunk checked ([`ToHost::CheckpointChunk`]).
    Streamed {
        /// Its generation.
        generation: u32,
        /// Chunks sent.
        chunks: u32,
        /// Bytes of the image.
        image_len: u32,
    },
}

/// The board's request for the checkpoint the host keeps: chunks from
/// `offset` on, at most [`RESTORE_BATCH`] of them, header first
/// ([`crate::checkpoint::stream::Order::HeaderFirst`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RestoreRequest {
    /// The board's configuration hash: the host refuses a checkpoint of
    /// another.
    pub config_hash: u32,
    /// Bytes of the board's image: the host refuses one of another size.
    pub image_len: u32,
    /// The first chunk wanted (0: the header, the stream's start).
    pub offset: u32,
}

/// Chunks the host sends per [`RestoreRequest`]: 24 of the largest frames
/// (about 170 bytes each) fit the board's [`CHIP_RX_BUFFER`], so a restore
/// never overruns it. Each request is a round trip on the link (on a USB
/// serial adapter 1–16 ms): LEO's table on the F429 (65 543 chunks) is
/// 2 731 requests (protocol 9; with the 3 chunks of protocol 8, 21 848).
pub const RESTORE_BATCH: usize = 24;

/// Bytes of the board's command receive buffer (the telemetry USART's
/// circular DMA buffer on a real board, the input queue on the emulated
/// ones): it holds a whole batch of [`RESTORE_BATCH`] of the largest
/// restore chunks (protocol 9; 512 bytes and 3 chunks before).
pub const CHIP_RX_BUFFER: usize = 4096;

/// Why the host sends no checkpoint ([`ToChip::RestoreNone`]); the host
/// logs the file and the values, the board reports the cause.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestoreDenied {
    /// The host keeps no checkpoint (none yet, or no keeper runs).
    NoCheckpoint,
    /// The kept file could not be read.
    Unreadable,
    /// The kept file is shorter than its header says.
    Truncated,
    /// The kept file fails its header or payload check.
    Corrupted,
    /// The kept checkpoint is of another configuration (robot, board,
    /// table or learner).
    OtherConfiguration,
    /// The kept checkpoint's image is of another size than the board's.
    WrongSize,
    /// The kept checkpoint is older than the board's own.
    Older,
    /// The request's offset starts no chunk of the kept stream (or the
    /// kept file changed in the middle of a restore).
    NotAChunk,
}

/// What a restore from the host came to ([`ToHost::Restored`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestoreOutcome {
    /// The weights and the learner's state of this checkpoint are loaded.
    Loaded {
        /// Its generation.
        generation: u32,
        /// Chunks received.
        chunks: u32,
    },
    /// The board starts fresh: the host sent none, and says why.
    Denied(RestoreDenied),
    /// The board starts fresh: no answer from the host within
    /// `waited_ms`.
    NoAnswer {
        /// How long the board waited \[ms\].
        waited_ms: u32,
    },
    /// The board starts fresh: a chunk was refused (out of order, another
    /// generation or configuration or size, corrupt, a bad header or
    /// payload CRC: [`crate::checkpoint::stream::AssembleError`]), at
    /// this image offset.
    ChunkRefused {
        /// The image offset the board expected next.
        offset: u32,
    },
    /// The board starts fresh: the image was whole, but its learner state
    /// is out of range for the running learner.
    InvalidState,
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
    /// A checkpoint save refused to keep the flash sector within its erase
    /// budget ([`crate::checkpoint::WearBudget`]); the previous checkpoint
    /// is intact.
    FlashWear,
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
/// changes (`SetPolicy`, `SwitchToSarsa`, `SetMtbfBudget`, a loaded
/// checkpoint, the host runner's switch at `--switch-at`, every move of the
/// wear governor), and at the end of every episode while a governor runs,
/// so a viewer that joins knows what the learner restricts and how fast
/// the gearboxes wear.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PolicyReport {
    /// Control step index when it took effect.
    pub step: u32,
    /// The policy the learner was built with, and its α (Eq. 8) or Δ
    /// (Eq. 9).
    pub built: PolicyKind,
    /// Whether PADA or the low-pass filter has switched back to plain
    /// SARSA(λ) (Section VIII); then `built` is what it explored with.
    pub switched_to_sarsa: bool,
    /// The wear governor, when one runs: its budget, the Δ or α in force
    /// (also `built`'s), and the damage rate and MTBF over its window
    /// ([`crate::governor`]).
    pub governor: Option<GovernorStatus>,
}

// ---------------------------------------------------------------------------
// Host → chip
// ---------------------------------------------------------------------------

/// Everything the host sends.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
    /// Learn within a gearbox life (protocol 6): a wear governor keeps the
    /// predicted MTBF over the last 1200 learning actions at or above this
    /// many seconds by moving PADA's Δ or the low-pass filter's α
    /// ([`crate::governor`]), starting at its floor; `None` stops it (the
    /// parameter stays where it is). Only with torque off, for a `pada` or
    /// `lowpass` learner, `0 < seconds <= 1e10`.
    SetMtbfBudget(Option<f32>),
    /// One chunk of the kept checkpoint, in answer to
    /// [`ToHost::RestoreWanted`] (protocol 8; not acknowledged: the next
    /// request is the acknowledgement).
    RestoreChunk(Chunk),
    /// No checkpoint for the board, and why (protocol 8; in answer to
    /// [`ToHost::RestoreWanted`], not acknowledged).
    RestoreNone(RestoreDenied),
}

/// The policies with their parameters, as sent on the wire: the learning
/// core's own [`PolicyKind`] (one definition, not a copy). Its postcard
/// encoding is the policy's variant index ([`PolicyName::code`]) then,
/// except for SARSA, its parameters as `f32`s (OU: θ then σ).
///
/// [`PolicyName::code`]: crate::policy::PolicyName::code
pub type PolicySpec = PolicyKind;
