//! The safety state machine of the firmware: when the servos may have
//! torque, and which faults take it away.
//!
//! One [`Safety`] value sees every event: host commands and what the control
//! loop observes (servo replies and timeouts, checksum errors, servo error
//! bits, joint positions, loop timing, a watchdog reset at boot). Every
//! transition goes through [`Safety::on`], which returns a [`Transition`]
//! whose `torque_enable` the firmware applies to the servos in the same
//! control period.
//!
//! # States and torque
//!
//! | state | torque | left by |
//! |---|---|---|
//! | `Idle` | off | `Start(mode)` → Learning/Testing; any fault → Fault |
//! | `Learning` | **on** | `Start(Testing)`, `Pause`, `Stop`; any fault |
//! | `Testing` | **on** | `Start(Learning)`, `Pause`, `Stop`; any fault |
//! | `Paused` | off | `Start(mode)`, `Stop`; any fault |
//! | `Fault(cause)` | off | only `ClearFault` → Idle |
//!
//! Torque is on only while a controller computes commands (Learning and
//! Testing). Paused is off as well: the servos run in wheel mode, where a
//! servo with torque on keeps turning at the last Moving Speed it was given,
//! so holding torque with nobody commanding is not safe.
//!
//! # Commands that do not apply
//!
//! In Fault every command except `ClearFault` is rejected
//! ([`Rejection::InFault`]), so leaving Fault always takes the explicit
//! command; `Pause` in Idle is rejected ([`Rejection::NotRunning`]). Commands
//! that ask for the state already in force (`Stop` in Idle, `Start(Learning)`
//! in Learning, `Pause` in Paused, `ClearFault` outside Fault) are accepted
//! and change nothing.
//!
//! # Faults
//!
//! Faults are detected in every state but Fault (a servo that overheats
//! while Idle is still reported, and Start then faults at once); the first
//! cause is kept until `ClearFault`, which also resets every counter:
//!
//! - a servo that has not answered `1 + servo_retry_budget` consecutive
//!   requests ([`FaultCause::ServoTimeout`]);
//! - `checksum_threshold` checksum errors within `checksum_window_ms`
//!   (received status packets with a bad checksum, and status packets whose
//!   CHECKSUM bit says a servo received a corrupted instruction);
//! - a status packet with an error bit in `servo_fault_mask`
//!   (at least input voltage, overheating and overload);
//! - a Protocol 2.0 status packet with its Alert bit (bit 7) set: the
//!   servo has a hardware error, whose Hardware Error Status the fault
//!   carries ([`FaultCause::HardwareAlert`]);
//! - a joint position outside its soft limit, or not finite;
//! - `overrun_streak` consecutive control periods that overran;
//! - a reset by the independent watchdog (reported at boot).

use crate::dynamixel::control_table::x_series::HardwareError;
use crate::dynamixel::ErrorFlags;
use crate::error::ConfigError;
use heapless::Vec;

/// Joints that can have a soft limit: one per servo.
pub const MAX_SOFT_LIMITS: usize = crate::limits::MAX_SERVOS;
/// Largest accepted `checksum_threshold`.
pub const MAX_CHECKSUM_THRESHOLD: u8 = 32;
/// Largest accepted `servo_retry_budget`.
pub const MAX_RETRY_BUDGET: u8 = 16;

/// What runs while torque is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RunMode {
    /// ε-greedy actions and learning updates.
    Learning,
    /// Greedy actions, no updates (test runs).
    Testing,
}

/// Why the firmware entered Fault.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultCause {
    /// A servo did not answer `attempts` consecutive requests (more than
    /// the retry budget allows).
    ServoTimeout {
        /// Dynamixel ID of the servo.
        servo: u8,
        /// Consecutive requests without an answer.
        attempts: u8,
    },
    /// `count` checksum errors within `window_ms`.
    ChecksumErrors {
        /// Errors counted (the threshold).
        count: u8,
        /// The window they fell in.
        window_ms: u32,
    },
    /// A servo reported error bits of the fault mask.
    ServoError {
        /// Dynamixel ID of the servo.
        servo: u8,
        /// All error bits the servo reported.
        error: ErrorFlags,
    },
    /// A joint beyond its soft limit (or a non-finite position).
    SoftLimit {
        /// Index of the joint.
        joint: u8,
        /// The position that was out of range, in radians.
        position: f32,
    },
    /// `count` consecutive control periods overran.
    OverrunStreak {
        /// Length of the streak (the configured limit).
        count: u16,
    },
    /// The independent watchdog reset the chip.
    WatchdogReset,
    /// A Protocol 2.0 servo's status packet had its Alert bit set: a
    /// hardware error, which the servo's Shutdown setting may already have
    /// answered by switching its own torque off (wire protocol 10;
    /// appended last).
    HardwareAlert {
        /// Dynamixel ID of the servo.
        servo: u8,
        /// Its Hardware Error Status (address 70) as read after the alert;
        /// empty if that read failed.
        error: HardwareError,
    },
}

impl FaultCause {
    /// The joint or servo the fault concerns, if any (a Dynamixel ID for
    /// servo faults, a joint index for soft limits).
    pub fn joint(&self) -> Option<u8> {
        match *self {
            FaultCause::ServoTimeout { servo, .. }
            | FaultCause::ServoError { servo, .. }
            | FaultCause::HardwareAlert { servo, .. } => Some(servo),
            FaultCause::SoftLimit { joint, .. } => Some(joint),
            _ => None,
        }
    }

    /// A short name for logs and CSV.
    pub fn name(&self) -> &'static str {
        match self {
            FaultCause::ServoTimeout { .. } => "servo-timeout",
            FaultCause::ChecksumErrors { .. } => "checksum-errors",
            FaultCause::ServoError { .. } => "servo-error",
            FaultCause::SoftLimit { .. } => "soft-limit",
            FaultCause::OverrunStreak { .. } => "overrun-streak",
            FaultCause::WatchdogReset => "watchdog-reset",
            FaultCause::HardwareAlert { .. } => "hardware-alert",
        }
    }
}

/// The state of the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum State {
    /// Torque off, waiting for Start.
    Idle,
    /// Learning with torque on.
    Learning,
    /// Testing (greedy) with torque on.
    Testing,
    /// Stopped by the host, torque off; Start resumes.
    Paused,
    /// Torque off until ClearFault.
    Fault(FaultCause),
}

impl State {
    /// Whether the servos may have torque in this state.
    pub fn torque_enabled(&self) -> bool {
        matches!(self, State::Learning | State::Testing)
    }

    /// The run mode while Learning or Testing.
    pub fn run_mode(&self) -> Option<RunMode> {
        match self {
            State::Learning => Some(RunMode::Learning),
            State::Testing => Some(RunMode::Testing),
            _ => None,
        }
    }

    /// The fault cause while in Fault.
    pub fn fault(&self) -> Option<FaultCause> {
        match *self {
            State::Fault(c) => Some(c),
            _ => None,
        }
    }

    fn running(mode: RunMode) -> State {
        match mode {
            RunMode::Learning => State::Learning,
            RunMode::Testing => State::Testing,
        }
    }
}

/// A host command that the safety machine handles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Run (or resume, or switch to) `mode` with torque on.
    Start(RunMode),
    /// Back to Idle, torque off.
    Stop,
    /// Paused, torque off.
    Pause,
    /// Leave Fault for Idle.
    ClearFault,
}

/// Everything the machine reacts to.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A host command.
    Command(Command),
    /// A servo answered a request (resets its timeout count).
    ServoReply {
        /// Dynamixel ID.
        servo: u8,
    },
    /// A request to a servo timed out (one attempt).
    ServoTimeout {
        /// Dynamixel ID.
        servo: u8,
    },
    /// A status packet with a bad checksum was received.
    ChecksumError {
        /// Time of the error in ms (any monotonic clock; wraps).
        at_ms: u32,
    },
    /// A status packet arrived (counts as a reply too).
    ServoStatus {
        /// Dynamixel ID.
        servo: u8,
        /// Its error bits.
        error: ErrorFlags,
        /// Time in ms (for the CHECKSUM bit, which counts as a checksum error).
        at_ms: u32,
    },
    /// A joint's measured position.
    JointPosition {
        /// Joint index (the soft limit's index in the configuration).
        joint: u8,
        /// Position in radians.
        position: f32,
    },
    /// One control period ended, on time or not.
    LoopTiming {
        /// Whether it overran its period.
        overrun: bool,
    },
    /// At boot: the reset was caused by the independent watchdog.
    WatchdogReset,
    /// A Protocol 2.0 servo raised its Alert bit (counts as a reply too).
    HardwareAlert {
        /// Dynamixel ID.
        servo: u8,
        /// Its Hardware Error Status, as read (empty if unread).
        error: HardwareError,
    },
}

/// Why a command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rejection {
    /// In Fault only ClearFault is accepted.
    InFault,
    /// Pause while nothing runs.
    NotRunning,
}

/// What an event did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// The state changed.
    Changed,
    /// Accepted (or just observed) without a change of state.
    Unchanged,
    /// A command that does not apply in this state; nothing changed.
    Rejected(Rejection),
}

/// The result of one event.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Transition {
    /// State before the event.
    pub from: State,
    /// State after the event.
    pub to: State,
    /// What happened.
    pub outcome: Outcome,
    /// Torque enable to apply to every servo now (`to.torque_enabled()`).
    pub torque_enable: bool,
}

impl Transition {
    /// The cause, if this event moved the machine into Fault.
    pub fn entered_fault(&self) -> Option<FaultCause> {
        match (self.from, self.to) {
            (State::Fault(_), _) => None,
            (_, State::Fault(c)) => Some(c),
            _ => None,
        }
    }

    /// Whether the state changed.
    pub fn changed(&self) -> bool {
        self.outcome == Outcome::Changed
    }
}

/// Allowed range of one joint, in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SoftLimit {
    /// Lowest allowed position.
    pub min: f32,
    /// Highest allowed position.
    pub max: f32,
}

impl SoftLimit {
    /// The fault of joint `joint` at `position` \[rad\]: past this limit,
    /// or not finite (a broken reading). The one check of a soft limit:
    /// the board's safety machine makes it of every reading
    /// ([`Event::JointPosition`]), and the host's simulation of every
    /// simulated reading (`RobotSpec::soft_limit_fault`), so both stop at
    /// the same reading.
    pub fn fault(&self, joint: u8, position: f32) -> Option<FaultCause> {
        let inside = position >= self.min && position <= self.max;
        (!inside).then_some(FaultCause::SoftLimit { joint, position })
    }
}

/// Thresholds of the fault detection. [`Default`]: retry budget 2,
/// 5 checksum errors within 1 s, voltage/overheating/overload bits, 3
/// overruns in a row, no soft limits.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyConfig {
    /// Retries after a timed-out request before a fault, `0..=16`.
    pub servo_retry_budget: u8,
    /// Checksum errors within the window that make a fault, `1..=32`.
    pub checksum_threshold: u8,
    /// The window of `checksum_threshold`, ms, `≥ 1`.
    pub checksum_window_ms: u32,
    /// Servo error bits that make a fault; must include
    /// [`ErrorFlags::HARDWARE`] and no unknown bit.
    pub servo_fault_mask: ErrorFlags,
    /// Consecutive overrunning periods that make a fault, `≥ 1`.
    pub overrun_streak: u16,
    /// Soft limits of joints `0..len`; joints beyond have none.
    pub soft_limits: Vec<SoftLimit, MAX_SOFT_LIMITS>,
}

impl Default for SafetyConfig {
    fn default() -> Self {
        SafetyConfig {
            servo_retry_budget: 2,
            checksum_threshold: 5,
            checksum_window_ms: 1000,
            servo_fault_mask: ErrorFlags::HARDWARE,
            overrun_streak: 3,
            soft_limits: Vec::new(),
        }
    }
}

impl SafetyConfig {
    /// Checks every threshold; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if self.servo_retry_budget > MAX_RETRY_BUDGET {
            return Err(ConfigError::new(
                "servo_retry_budget",
                self.servo_retry_budget as f32,
                "0 <= servo_retry_budget <= 16",
            ));
        }
        if self.checksum_threshold == 0 || self.checksum_threshold > MAX_CHECKSUM_THRESHOLD {
            return Err(ConfigError::new(
                "checksum_threshold",
                self.checksum_threshold as f32,
                "1 <= checksum_threshold <= 32",
            ));
        }
        if self.checksum_window_ms == 0 {
            return Err(ConfigError::new("checksum_window_ms", 0.0, "checksum_window_ms >= 1"));
        }
        let mask = self.servo_fault_mask;
        if !ErrorFlags::ALL.contains(mask) || !mask.contains(ErrorFlags::HARDWARE) {
            return Err(ConfigError::new(
                "servo_fault_mask",
                mask.bits() as f32,
                "bits 0-6 only, including input voltage (0x01), overheating (0x04) and overload (0x20)",
            ));
        }
        if self.overrun_streak == 0 {
            return Err(ConfigError::new("overrun_streak", 0.0, "overrun_streak >= 1"));
        }
        for (i, l) in self.soft_limits.iter().enumerate() {
            if !l.min.is_finite() {
                return Err(ConfigError::new("soft_limits.min", l.min, "finite, min < max").at(i));
            }
            if !(l.max.is_finite() && l.max > l.min) {
                return Err(ConfigError::new("soft_limits.max", l.max, "finite, min < max").at(i));
            }
        }
        Ok(())
    }
}

/// The safety state machine with its fault counters.
#[derive(Debug, Clone)]
pub struct Safety {
    config: SafetyConfig,
    state: State,
    /// Consecutive timeouts per Dynamixel ID.
    timeouts: [u8; 256],
    /// Times of the last `checksum_threshold` checksum errors (a ring).
    checksum_times: [u32; MAX_CHECKSUM_THRESHOLD as usize],
    checksum_head: usize,
    checksum_filled: usize,
    overruns: u16,
}

impl Safety {
    /// A machine in Idle with validated thresholds.
    pub fn new(config: SafetyConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Safety {
            config,
            state: State::Idle,
            timeouts: [0; 256],
            checksum_times: [0; MAX_CHECKSUM_THRESHOLD as usize],
            checksum_head: 0,
            checksum_filled: 0,
            overruns: 0,
        })
    }

    /// The current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// Whether the servos may have torque now.
    pub fn torque_enabled(&self) -> bool {
        self.state.torque_enabled()
    }

    /// The thresholds.
    pub fn config(&self) -> &SafetyConfig {
        &self.config
    }

    /// Current consecutive overrun count.
    pub fn overrun_streak(&self) -> u16 {
        self.overruns
    }

    /// Current consecutive timeouts of servo `id`.
    pub fn consecutive_timeouts(&self, id: u8) -> u8 {
        self.timeouts[id as usize]
    }

    /// Handles one event.
    pub fn on(&mut self, event: Event) -> Transition {
        let from = self.state;
        let outcome = match event {
            Event::Command(c) => self.command(c),
            _ if matches!(self.state, State::Fault(_)) => Outcome::Unchanged,
            _ => match self.detect(event) {
                Some(cause) => {
                    self.state = State::Fault(cause);
                    Outcome::Changed
                }
                None => Outcome::Unchanged,
            },
        };
        Transition { from, to: self.state, outcome, torque_enable: self.state.torque_enabled() }
    }

    fn command(&mut self, c: Command) -> Outcome {
        let next = match (self.state, c) {
            (State::Fault(_), Command::ClearFault) => {
                self.clear_counters();
                State::Idle
            }
            (State::Fault(_), _) => return Outcome::Rejected(Rejection::InFault),
            (_, Command::ClearFault) => self.state,
            (_, Command::Start(mode)) => State::running(mode),
            (_, Command::Stop) => State::Idle,
            (State::Idle, Command::Pause) => return Outcome::Rejected(Rejection::NotRunning),
            (_, Command::Pause) => State::Paused,
        };
        if next == self.state {
            Outcome::Unchanged
        } else {
            self.state = next;
            Outcome::Changed
        }
    }

    fn clear_counters(&mut self) {
        self.timeouts = [0; 256];
        self.checksum_head = 0;
        self.checksum_filled = 0;
        self.overruns = 0;
    }

    /// Updates the counters; returns a fault cause if a threshold is crossed.
    fn detect(&mut self, event: Event) -> Option<FaultCause> {
        match event {
            Event::Command(_) => None,
            Event::ServoReply { servo } => {
                self.timeouts[servo as usize] = 0;
                None
            }
            Event::ServoTimeout { servo } => {
                let n = &mut self.timeouts[servo as usize];
                *n = n.saturating_add(1);
                (*n > self.config.servo_retry_budget).then_some(FaultCause::ServoTimeout { servo, attempts: *n })
            }
            Event::ChecksumError { at_ms } => self.checksum_error(at_ms),
            Event::ServoStatus { servo, error, at_ms } => {
                self.timeouts[servo as usize] = 0;
                if error.intersects(self.config.servo_fault_mask) {
                    return Some(FaultCause::ServoError { servo, error });
                }
                if error.contains(ErrorFlags::CHECKSUM) {
                    return self.checksum_error(at_ms);
                }
                None
            }
            Event::JointPosition { joint, position } => self.config.soft_limits.get(joint as usize)?.fault(joint, position),
            Event::LoopTiming { overrun } => {
                if !overrun {
                    self.overruns = 0;
                    return None;
                }
                self.overruns = self.overruns.saturating_add(1);
                (self.overruns >= self.config.overrun_streak)
                    .then_some(FaultCause::OverrunStreak { count: self.overruns })
            }
            Event::WatchdogReset => Some(FaultCause::WatchdogReset),
            Event::HardwareAlert { servo, error } => {
                self.timeouts[servo as usize] = 0;
                Some(FaultCause::HardwareAlert { servo, error })
            }
        }
    }

    fn checksum_error(&mut self, at_ms: u32) -> Option<FaultCause> {
        let n = self.config.checksum_threshold as usize;
        let len = self.checksum_times.len();
        if n == 0 || n > len {
            return None; // excluded by validation
        }
        let head = self.checksum_head % n;
        self.checksum_times[head] = at_ms;
        self.checksum_head = (head + 1) % n;
        self.checksum_filled = (self.checksum_filled + 1).min(n);
        if self.checksum_filled < n {
            return None;
        }
        // The ring holds the last n error times; the oldest is next to be
        // overwritten.
        let oldest = self.checksum_times[self.checksum_head];
        let span = at_ms.wrapping_sub(oldest);
        (span <= self.config.checksum_window_ms).then_some(FaultCause::ChecksumErrors {
            count: self.config.checksum_threshold,
            window_ms: self.config.checksum_window_ms,
        })
    }
}
