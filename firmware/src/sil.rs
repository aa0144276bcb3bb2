//! Software in the loop: what the emulated boards (`src/board/lockstep/`
//! with `qemu.rs` for QEMU's `netduinoplus2` or `mps2.rs` for its
//! `mps2-an386`) and the host's plant side (`pada sil`, `host/src/sil/`)
//! agree on. Both import this module, so the two ends cannot disagree.
//!
//! # One channel: the lock-step clock
//!
//! Everything between the emulated board and the host travels as
//! `pada_core::wire` frames (postcard, CRC-32, COBS) over two FIFOs that
//! the board opens through semihosting: the servo bus's bytes (exactly the
//! Dynamixel Protocol 1.0 bytes a real bus carries), the telemetry link's
//! bytes (exactly the `pada_core::wire` frames a real board's telemetry
//! USART carries) and the clock. QEMU's serial models hand the guest one
//! received byte per turn of QEMU's main loop (about 60 µs on this kind of
//! machine) and take one system call per sent byte; a semihosting call
//! moves a whole buffer. With the bytes on the USARTs, waiting for them
//! took 99 % of a run's wall time.
//!
//! # Lock step: the plant is the clock
//!
//! The firmware's time (embassy-time's `Instant`) does not run by itself
//! on the emulated board. Whenever the executor has nothing to do, the
//! board sends what it wrote since it last reported ([`FromBoard::Output`],
//! each chunk with the instant it was written at) and [`FromBoard::Idle`]:
//! the time it has now and when its next timer expires. The host takes the
//! bytes — servo-bus bytes into its bus emulator, which schedules the
//! servos' answers at the times a 1 Mbps bus gives, telemetry into its
//! recorder — and answers with the bytes due at the next instant
//! ([`ToBoard::Input`]) and [`ToBoard::Advance`] to that instant: the first
//! of the board's timer, the next answer and the next command. Nothing
//! depends on how fast the host or QEMU run, so a run is deterministic and
//! as fast as the emulation allows.
//!
//! Computation takes no time on the lock-step clock: the firmware's work in
//! a period happens at the instant it was woken. The board's cycle counter
//! (the `loop_us` and `agent_cycles` of telemetry) adds the instructions the
//! firmware executed, counted by QEMU (`-icount shift=0`), to the clock.
//!
//! # Forecasts: a period's bus traffic in one exchange
//!
//! A control period reads every servo in turn, each read a request and an
//! answer, so plain lock step costs one exchange per answer (LEO: seven
//! servos and the sensor device). The host forecasts them: with an
//! [`Advance`](ToBoard::Advance) it sends [`ToBoard::Forecast`]s, each
//! "if at `request_at_us` you send exactly `request`, the bus answers
//! `reply` at `reply_at_us`", in the order it expects them (the requests
//! that followed the same requests before). The board uses a forecast only
//! if its next bus write at that instant is byte for byte the forecast's
//! request, it has written nothing else since it last reported, its next
//! timer is not earlier than the answer, and the answer comes before the
//! host's `horizon_us` (its next command or scheduled answer). Then it
//! advances its own clock to the answer and delivers it without asking;
//! otherwise it drops every forecast left and reports as usual. Likewise,
//! while it has nothing to report but such requests, it lets a timer that
//! expires before the horizon fire without asking (embassy leaves a reply
//! deadline in its timer queue after the answer came; each would cost an
//! exchange). It reports each used request
//! ([`FromBoard::Output::answered`]), and the host runs it through its bus
//! emulator as if it had come the usual way and checks that the answer is
//! the one it forecast. A forecast is computed without changing the plant,
//! at the instant the answer would be computed anyway, so a run with
//! forecasts is the same run, byte for byte, with fewer exchanges.
//!
//! # Sensors as a bus device
//!
//! QEMU cannot emulate a quadrature encoder or foot switches, so on the
//! emulated board they are one more device on the servo bus, ID
//! [`SENSOR_ID`], with a Dynamixel control table ([`sensor_table`]); the
//! board reads it with an ordinary READ. On a real board they stay timer and
//! GPIO peripherals, behind the same `io::Sensors` trait.

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

/// Version of the clock protocol; the board sends it in [`FromBoard::Boot`].
pub const CLOCK_PROTOCOL: u16 = 4;

/// Instructions of the calibration loop of [`FromBoard::Boot`].
pub const CALIBRATION_INSTRUCTIONS: u32 = 20_000;

/// "No timer pending" in [`FromBoard::Idle::until_us`], "no host event
/// pending" in [`ToBoard::Advance::horizon_us`].
pub const NEVER: u64 = u64::MAX;

/// Most bytes of one [`FromBoard::Output`] or [`ToBoard::Input`].
pub const CHUNK_LEN: usize = 128;
/// Most bytes of a forecast's request (a READ is 8).
pub const MAX_REQUEST: usize = 16;
/// Most bytes of a forecast's answer (a status packet with up to 42
/// parameters; the present-state block is 14).
pub const MAX_REPLY: usize = 48;

/// Which of the board's byte streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Channel {
    /// The servo bus (Dynamixel Protocol 1.0).
    Bus,
    /// Telemetry out, commands in (`pada_core::wire` frames).
    Telemetry,
}

/// Board → host.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum FromBoard {
    /// Sent once at boot; the host answers [`ToBoard::Configure`].
    Boot {
        /// [`CLOCK_PROTOCOL`].
        protocol: u16,
        /// The name of the robot the image drives
        /// (`pada_core::robot::RobotSpec::name`).
        robot: String<{ pada_core::robot::MAX_NAME }>,
        /// Its definition's hash (`RobotSpec::definition_hash`): a robot
        /// is its name and this, never a number from a closed list.
        robot_hash: u32,
        /// The board learner profile of the image
        /// (`pada_core::profile::Board::name`).
        board: String<16>,
        /// The emulated machine (`netduinoplus2`, `mps2-an386`).
        machine: String<16>,
        /// Instructions counted over a loop of [`CALIBRATION_INSTRUCTIONS`]
        /// instructions: equal to it, to within `resolution`, when QEMU
        /// runs with `-icount shift=0` (one nanosecond per instruction).
        calibration: u32,
        /// Instructions per count of the board's instruction counter (its
        /// timer's period in nanoseconds under `-icount shift=0`).
        resolution: u16,
        /// The watchdog's period \[ms\] (0: the machine models none, as
        /// QEMU's netduinoplus2).
        watchdog_ms: u32,
        /// Why the board booted.
        reset: ResetCause,
    },
    /// The board stopped at the power cut the host armed
    /// ([`ToBoard::CutInSave`]), inside a checkpoint save, with the flash
    /// file as the cut leaves it; the host kills QEMU now.
    PowerCut {
        /// The board's clock \[µs\].
        now_us: u64,
    },
    /// Bytes the board wrote at `at_us`.
    Output {
        /// The stream.
        channel: Channel,
        /// When they were written \[µs\].
        at_us: u64,
        /// This bus request matched a [`ToBoard::Forecast`] and its answer
        /// was delivered from it.
        answered: bool,
        /// The bytes.
        bytes: Vec<u8, CHUNK_LEN>,
    },
    /// Nothing to run until `until_us`; everything written so far has been
    /// sent as [`FromBoard::Output`].
    Idle {
        /// The board's clock \[µs\].
        now_us: u64,
        /// When its next timer expires \[µs\] ([`NEVER`] if none).
        until_us: u64,
        /// Instructions executed by the firmware since boot, outside the
        /// board's lock-step transport (idle loop, exchanges, buffering).
        instructions: u64,
    },
}

/// Host → board.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ToBoard {
    /// The answer to [`FromBoard::Boot`]: what this run's board is.
    Configure {
        /// The seed of the learner's generator (a real board uses
        /// `crate::config::DEFAULT_SEED`).
        seed: u64,
        /// The board's clock at boot \[µs\]: the host's time, so a board
        /// booted again (after a power cut or a watchdog reset) goes on on
        /// the plant's clock.
        now_us: u64,
    },
    /// Power-cut injection: the next bytes the board writes to its
    /// checkpoint file (erases included) are cut after `after_bytes`, and
    /// the board stops there ([`FromBoard::PowerCut`]).
    CutInSave {
        /// Bytes written before the cut.
        after_bytes: u32,
    },
    /// Hang injection: the control loop stops at its next period (it spins
    /// without feeding the watchdog).
    Hang,
    /// Bytes arriving at the next [`ToBoard::Advance`]'s instant.
    Input {
        /// The stream.
        channel: Channel,
        /// The bytes.
        bytes: Vec<u8, CHUNK_LEN>,
    },
    /// If the board sends exactly `request` at `request_at_us`, the bus
    /// answers `reply`, its last byte in at `reply_at_us`.
    Forecast {
        /// When the request would be sent \[µs\].
        request_at_us: u64,
        /// The request.
        request: Vec<u8, MAX_REQUEST>,
        /// When the answer is in \[µs\].
        reply_at_us: u64,
        /// The answer.
        reply: Vec<u8, MAX_REPLY>,
    },
    /// Set the clock to `now_us` (not earlier than the board's, not later
    /// than its `until_us`) and take the `Input`s sent since the last
    /// `Advance`; the `Forecast`s sent since hold until `horizon_us`.
    Advance {
        /// The new time \[µs\].
        now_us: u64,
        /// The host's next event (a command, or an answer it has
        /// scheduled): the board advances on its own only before it \[µs\]
        /// ([`NEVER`] if none).
        horizon_us: u64,
    },
}

/// Why an emulated board booted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ResetCause {
    /// Power on: a fresh emulator (the first boot, or after a power cut).
    PowerOn,
    /// The watchdog reset the chip (mps2-an386's CMSDK watchdog).
    Watchdog {
        /// The board's clock at the watchdog's last feed \[µs\].
        fed_at_us: u64,
        /// The board's clock when the control loop hung \[µs\].
        hung_at_us: u64,
        /// Emulated nanoseconds from the last feed to the reset, as the
        /// hung loop measured them on the instruction counter.
        since_feed_ns: u64,
    },
}

/// Largest encoded clock frame.
pub const CLOCK_FRAME_LEN: usize = 256;

/// The FIFO the board writes [`FromBoard`] frames to, in QEMU's working
/// directory.
pub const CLOCK_FROM_BOARD: &str = "clock-from-board";
/// The FIFO the board reads [`ToBoard`] frames from.
pub const CLOCK_TO_BOARD: &str = "clock-to-board";
/// The checkpoint file of the emulated board (both slots), in QEMU's
/// working directory.
pub const CHECKPOINT_FILE: &str = "pada-checkpoint.bin";
/// Bytes of each checkpoint slot of the emulated boards: one 128 KiB flash
/// sector, as on the real boards (sectors 10–11 of the F405, 22–23 of the
/// F429), so a checkpoint that a real board refuses (LEO's 8 MiB table on
/// the F429) is refused here too.
pub const CHECKPOINT_SLOT_LEN: usize = 128 * 1024;

// The sensor device is the emulated board's and the PC's alike.
pub use crate::sensor_device::{parse_sensor_read, sensor_table, SENSOR_ID};

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::wire::{encode_frame, FrameDecoder};

    fn round_trip<M>(msgs: &[M])
    where
        M: Serialize + serde::de::DeserializeOwned + PartialEq + core::fmt::Debug,
    {
        let mut dec: FrameDecoder<M, CLOCK_FRAME_LEN> = FrameDecoder::new();
        for (seq, m) in msgs.iter().enumerate() {
            let mut buf = [0u8; CLOCK_FRAME_LEN];
            let frame = encode_frame(m, u32::MAX - seq as u32, &mut buf).unwrap();
            let got: std::vec::Vec<_> = dec.feed(frame).collect();
            assert_eq!(got.len(), 1);
            assert_eq!(got[0].as_ref().unwrap().msg, *m);
        }
    }

    #[test]
    fn the_largest_clock_messages_fit_their_frame_and_round_trip() {
        let full = |n: usize| (0..n).map(|i| (i as u8) | 0x80).collect::<std::vec::Vec<u8>>();
        round_trip(&[
            FromBoard::Boot {
                protocol: CLOCK_PROTOCOL,
                robot: String::try_from("a-robot-name-of-32-bytes-exactly").unwrap(),
                robot_hash: u32::MAX,
                board: String::try_from("f429-sdram-xxxxx").unwrap(),
                machine: String::try_from("mps2-an386-xxxxx").unwrap(),
                calibration: u32::MAX,
                resolution: u16::MAX,
                watchdog_ms: u32::MAX,
                reset: ResetCause::Watchdog { fed_at_us: u64::MAX, hung_at_us: u64::MAX, since_feed_ns: u64::MAX },
            },
            FromBoard::PowerCut { now_us: u64::MAX },
            FromBoard::Output {
                channel: Channel::Telemetry,
                at_us: u64::MAX,
                answered: true,
                bytes: Vec::from_slice(&full(CHUNK_LEN)).unwrap(),
            },
            FromBoard::Idle { now_us: u64::MAX - 1, until_us: NEVER, instructions: u64::MAX },
        ]);
        round_trip(&[
            ToBoard::Configure { seed: u64::MAX, now_us: u64::MAX },
            ToBoard::CutInSave { after_bytes: u32::MAX },
            ToBoard::Hang,
            ToBoard::Input { channel: Channel::Bus, bytes: Vec::from_slice(&full(CHUNK_LEN)).unwrap() },
            ToBoard::Forecast {
                request_at_us: u64::MAX,
                request: Vec::from_slice(&full(MAX_REQUEST)).unwrap(),
                reply_at_us: u64::MAX,
                reply: Vec::from_slice(&full(MAX_REPLY)).unwrap(),
            },
            ToBoard::Advance { now_us: u64::MAX, horizon_us: NEVER },
        ]);
    }

}
