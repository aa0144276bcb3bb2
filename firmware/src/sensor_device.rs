//! The sensor device: a robot's sensors that are not servos (the encoder
//! on the pendulum's axis or LEO's boom, LEO's foot switches) as one more
//! device on the servo bus, ID [`SENSOR_ID`], with a small Dynamixel
//! control table ([`sensor_table`]) read with an ordinary READ in the
//! protocol of the robot's servos.
//!
//! Where it is used: the emulated boards (QEMU cannot emulate a
//! quadrature encoder or foot switches; `crate::sil`), and a PC driving
//! the robot through a USB adapter (`pada drive`), which has no timer or
//! GPIO of its own: a small microcontroller that answers as this device
//! (for instance an Arduino with ROBOTIS' Dynamixel2Arduino in its slave
//! role) gives it the encoder, and `pada servos` emulates it beside the
//! virtual servos. A real board keeps them as timer and GPIO peripherals,
//! behind the same `io::Sensors` trait.
//!
//! The controller also writes [`sensor_table::OPERATOR`] when an episode
//! ends or starts ([`crate::bus::OperatorCall`]): a call for whoever (or
//! whatever) brings the robot back to its start. A real device may light a
//! lamp; the virtual robot's simulated operator acts on it, as `pada run
//! --board`'s operator does when the controller reports the episode.

/// Dynamixel ID of the sensor device. Above every servo ID the robots use
/// (1–7) and below the broadcast ID.
pub const SENSOR_ID: u8 = 100;

/// The sensor device's control table (the same addresses in both
/// protocols; Protocol 2.0 sends them as 16-bit addresses).
pub mod sensor_table {
    /// Model number, 2 bytes (read-only): [`MODEL`].
    pub const MODEL_NUMBER: u8 = 0;
    /// The encoder's counter, 2 bytes little endian (a 16-bit quadrature
    /// counter after ×4 decoding, wrapping, as the timer's CNT).
    pub const ENCODER_COUNT: u8 = 36;
    /// Foot contacts, 1 byte: bits of `pada_core::robot::leo::contact`.
    pub const CONTACTS: u8 = 38;
    /// The operator's call, 1 byte (written by the controller, no reply):
    /// `crate::bus::OperatorCall`'s values.
    pub const OPERATOR: u8 = 39;
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

    #[test]
    fn sensor_reads() {
        assert_eq!(parse_sensor_read(&[0x34, 0x12, 0b0101]), Some((0x1234, 0b0101)));
        assert_eq!(parse_sensor_read(&[1, 2]), None);
        assert!((sensor_table::CONTACTS as usize) < sensor_table::TABLE_LEN);
        assert!((sensor_table::OPERATOR as usize) < sensor_table::TABLE_LEN);
        assert_eq!(sensor_table::ENCODER_COUNT + 2, sensor_table::CONTACTS);
    }
}
