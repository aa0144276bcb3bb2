//! Software in the loop: what the emulated board (`src/board/qemu.rs`,
//! cargo feature `qemu`) and the host's plant side (`pada sil`,
//! `host/src/sil/`) agree on. Both import this module, so the two ends
//! cannot disagree.
//!
//! # Two serial ports and a clock channel
//!
//! QEMU's `netduinoplus2` connects its `-serial` back ends to USART1,
//! USART2, … in that order:
//!
//! | channel | carries | framing |
//! |---|---|---|
//! | USART1 | the servo bus: Dynamixel Protocol 1.0, exactly the bytes a real bus carries | Dynamixel packets |
//! | USART2 | telemetry and commands | `pada_core::wire` frames |
//! | two FIFOs through semihosting | the lock-step clock ([`FromBoard`], [`ToBoard`]) | `pada_core::wire` framing (postcard, CRC-32, COBS) |
//!
//! The clock does not use a third USART because QEMU's USART model hands
//! the guest one received byte per turn of its main loop (about 60 µs on
//! this kind of machine); a semihosting read moves a whole message at once,
//! which makes the emulation several times faster.
//!
//! # Lock step: the plant is the clock
//!
//! The firmware's time (embassy-time's `Instant`) does not run by itself on
//! the emulated board. Whenever the executor has nothing to do, the board
//! sends [`FromBoard::Idle`]: the time it has now, when its next timer
//! expires, and how many bytes it has written to USART1 and USART2 so far.
//! The host answers [`ToBoard::Advance`]: the new time (at most the timer's
//! expiry, earlier if a byte arrives first) and how many bytes it has written
//! to each port in total. The board waits until it has received exactly
//! those bytes, sets its clock and runs whatever is due. Nothing depends on
//! how fast the host or QEMU run, so a run is deterministic and as fast as
//! the emulation allows.
//!
//! The byte counts make the channels' order irrelevant: each channel
//! delivers its bytes in order, but not in order with the others; counting
//! them tells each side when it has everything that happened before a
//! message.
//!
//! Computation takes no time on the lock-step clock: the firmware's work in
//! a period happens at the instant it was woken. The board's cycle counter
//! (the `loop_us` and `agent_cycles` of telemetry) adds the instructions the
//! firmware executed, counted by QEMU (`-icount`), to the clock.
//!
//! # Sensors as a bus device
//!
//! QEMU cannot emulate a quadrature encoder or foot switches, so on the
//! emulated board they are one more device on the servo bus, ID
//! [`SENSOR_ID`], with a Dynamixel control table ([`sensor_table`]); the
//! board reads it with an ordinary READ. On a real board they stay timer and
//! GPIO peripherals, behind the same `io::Sensors` trait.

use serde::{Deserialize, Serialize};

/// Version of the clock protocol; the board sends it in [`FromBoard::Boot`].
pub const CLOCK_PROTOCOL: u16 = 1;

/// Instructions of the calibration loop of [`FromBoard::Boot`].
pub const CALIBRATION_INSTRUCTIONS: u32 = 20_000;

/// "No timer pending" in [`FromBoard::Idle::until_us`].
pub const NEVER: u64 = u64::MAX;

/// Board → host on the clock channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FromBoard {
    /// Sent once, after the USARTs are enabled and before the first `Idle`.
    Boot {
        /// [`CLOCK_PROTOCOL`].
        protocol: u16,
        /// The robot the image drives ([`crate::config::Robot::code`]).
        robot: u8,
        /// Counts of the board's instruction counter over a loop of
        /// [`CALIBRATION_INSTRUCTIONS`] instructions: equal to it when QEMU
        /// runs with `-icount shift=0` (one count per instruction).
        calibration: u32,
    },
    /// Nothing to run until `until_us`.
    Idle {
        /// The board's clock \[µs\] (as last advanced).
        now_us: u64,
        /// When its next timer expires \[µs\] ([`NEVER`] if none).
        until_us: u64,
        /// Bytes written to the servo bus (USART1) since boot.
        bus_tx: u64,
        /// Bytes written to the telemetry port (USART2) since boot.
        telemetry_tx: u64,
        /// Instructions executed outside the idle loop since boot.
        instructions: u64,
    },
}

/// Host → board on the clock channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ToBoard {
    /// Set the clock to `now_us` once `bus_rx` and `telemetry_rx` bytes
    /// (totals since boot) have been received on USART1 and USART2.
    Advance {
        /// The new time \[µs\], not earlier than the board's and not later
        /// than its `until_us`.
        now_us: u64,
        /// Bytes the host has written to the servo bus since boot.
        bus_rx: u64,
        /// Bytes the host has written to the telemetry port since boot.
        telemetry_rx: u64,
    },
}

/// Largest encoded clock frame.
pub const CLOCK_FRAME_LEN: usize = 64;

/// The FIFO the board writes [`FromBoard`] frames to, in QEMU's working
/// directory.
pub const CLOCK_FROM_BOARD: &str = "clock-from-board";
/// The FIFO the board reads [`ToBoard`] frames from.
pub const CLOCK_TO_BOARD: &str = "clock-to-board";
/// The checkpoint file of the emulated board (both slots), in QEMU's
/// working directory.
pub const CHECKPOINT_FILE: &str = "pada-checkpoint.bin";

/// Dynamixel ID of the emulated sensor device (encoder and foot switches).
/// Above every servo ID the robots use (1–7) and below the broadcast ID.
pub const SENSOR_ID: u8 = 100;

/// The sensor device's control table (Dynamixel Protocol 1.0 addresses).
pub mod sensor_table {
    /// Model number, 2 bytes (read-only): [`MODEL`].
    pub const MODEL_NUMBER: u8 = 0;
    /// The encoder's counter, 2 bytes little endian (a 16-bit quadrature
    /// counter after ×4 decoding, wrapping, as the timer's CNT).
    pub const ENCODER_COUNT: u8 = 36;
    /// Foot contacts, 1 byte: bits of `pada_firmware::leo::contact`.
    pub const CONTACTS: u8 = 38;
    /// Bytes read every control period: encoder count and contacts.
    pub const READ_LEN: u8 = 3;
    /// The model number the device reports ("SE" for sensors).
    pub const MODEL: u16 = 0x5345;
    /// Bytes of the table.
    pub const TABLE_LEN: usize = 40;
}

/// Encoder count and contacts from the sensor device's READ answer.
pub fn parse_sensor_read(params: &[u8]) -> Option<(u16, u8)> {
    match params {
        [lo, hi, contacts] => Some((u16::from_le_bytes([*lo, *hi]), *contacts)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::wire::{encode_frame, FrameDecoder};

    #[test]
    fn clock_messages_fit_their_frame_and_round_trip() {
        let msgs = [
            FromBoard::Boot { protocol: CLOCK_PROTOCOL, robot: 3, calibration: u32::MAX },
            FromBoard::Idle {
                now_us: u64::MAX - 1,
                until_us: NEVER,
                bus_tx: u64::MAX,
                telemetry_tx: u64::MAX,
                instructions: u64::MAX,
            },
        ];
        let mut dec: FrameDecoder<FromBoard, CLOCK_FRAME_LEN> = FrameDecoder::new();
        for (seq, m) in msgs.iter().enumerate() {
            let mut buf = [0u8; CLOCK_FRAME_LEN];
            let frame = encode_frame(m, seq as u32, &mut buf).unwrap();
            let got: Vec<_> = dec.feed(frame).collect();
            assert_eq!(got.len(), 1);
            assert_eq!(got[0].as_ref().unwrap().msg, *m);
        }
        let adv = ToBoard::Advance { now_us: u64::MAX, bus_rx: u64::MAX, telemetry_rx: u64::MAX };
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        let frame = encode_frame(&adv, u32::MAX, &mut buf).unwrap();
        let mut dec: FrameDecoder<ToBoard, CLOCK_FRAME_LEN> = FrameDecoder::new();
        assert_eq!(dec.feed(frame).next().unwrap().unwrap().msg, adv);
    }

    #[test]
    fn sensor_reads() {
        assert_eq!(parse_sensor_read(&[0x34, 0x12, 0b0101]), Some((0x1234, 0b0101)));
        assert_eq!(parse_sensor_read(&[1, 2]), None);
        assert!((sensor_table::CONTACTS as usize) < sensor_table::TABLE_LEN);
        assert_eq!(sensor_table::ENCODER_COUNT + 2, sensor_table::CONTACTS);
    }
}
