//! The virtual sensor device (`pada_firmware::sensor_device`): the robot's
//! encoder count and foot contacts at the instant of a READ, in either
//! protocol, and the operator's call a WRITE of its OPERATOR register
//! carries. It answers PING and READ (as a servo at Status Return Level 1)
//! and never faults: it stands for a board's timer and GPIO pins.

use pada_core::dynamixel::table;
use pada_core::dynamixel::v2::{self as dxl2, PingReply, StatusError};
use pada_core::dynamixel::{self as dxl1, ErrorFlags};
use pada_core::servo::ServoProtocol;
use pada_firmware::sensor_device::{sensor_table, SENSOR_ID};

/// Its firmware version (PING on Protocol 2.0).
const FIRMWARE: u8 = 1;

/// The sensor device.
#[derive(Debug, Clone)]
pub struct SensorDevice {
    table: [u8; sensor_table::TABLE_LEN],
}

impl Default for SensorDevice {
    fn default() -> Self {
        Self::new()
    }
}

impl SensorDevice {
    /// Its table: model "SE", its ID.
    pub fn new() -> Self {
        let mut t = [0u8; sensor_table::TABLE_LEN];
        t[sensor_table::MODEL_NUMBER as usize..][..2].copy_from_slice(&sensor_table::MODEL.to_le_bytes());
        t[table::ID as usize] = SENSOR_ID;
        SensorDevice { table: t }
    }

    /// The encoder count and contacts of this instant.
    pub fn set(&mut self, count: u16, contacts: u8) {
        let at = sensor_table::ENCODER_COUNT as usize;
        self.table[at..at + 2].copy_from_slice(&count.to_le_bytes());
        self.table[sensor_table::CONTACTS as usize] = contacts;
    }

    /// Executes an instruction (its code and parameters) in `protocol`:
    /// the answer's bytes, if any, and the operator's call it carried.
    pub fn execute(&mut self, protocol: ServoProtocol, code: u8, params: &[u8]) -> (Option<Vec<u8>>, Option<u8>) {
        let mut buf = [0u8; 96];
        match protocol {
            // Feetech's PING, READ and WRITE are Protocol 1.0's packets.
            ServoProtocol::V1 | ServoProtocol::Feetech => match dxl1::Instruction::parse(code, params) {
                Ok(dxl1::Instruction::Ping) => (encode1(&[], &mut buf), None),
                Ok(dxl1::Instruction::Read { addr, len }) => {
                    let data = self.table.get(addr as usize..addr as usize + len as usize).map(<[u8]>::to_vec);
                    (data.and_then(|d| encode1(&d, &mut buf)), None)
                }
                Ok(dxl1::Instruction::Write { addr, data }) => (None, self.write(addr as u16, data)),
                _ => (None, None),
            },
            ServoProtocol::V2 => match dxl2::Instruction::parse(code, params) {
                Ok(dxl2::Instruction::Ping) => {
                    let p = PingReply { model_number: sensor_table::MODEL, firmware: FIRMWARE }.to_params();
                    (encode2(&p, &mut buf), None)
                }
                Ok(dxl2::Instruction::Read { addr, len }) => {
                    let data = self.table.get(addr as usize..addr as usize + len as usize).map(<[u8]>::to_vec);
                    (data.and_then(|d| encode2(&d, &mut buf)), None)
                }
                Ok(dxl2::Instruction::Write { addr, data }) => (None, self.write(addr, data)),
                _ => (None, None),
            },
        }
    }

    /// A write: only the operator's call is writable.
    fn write(&mut self, addr: u16, data: &[u8]) -> Option<u8> {
        match (addr, data) {
            (a, &[call]) if a == sensor_table::OPERATOR as u16 && (1..=2).contains(&call) => {
                self.table[sensor_table::OPERATOR as usize] = call;
                Some(call)
            }
            _ => None,
        }
    }
}

fn encode1(params: &[u8], buf: &mut [u8]) -> Option<Vec<u8>> {
    let p = dxl1::StatusPacket::<64>::new(SENSOR_ID, ErrorFlags::NONE, params).ok()?;
    p.encode(buf).ok().map(<[u8]>::to_vec)
}

fn encode2(params: &[u8], buf: &mut [u8]) -> Option<Vec<u8>> {
    let p = dxl2::StatusPacket::<64>::new(SENSOR_ID, StatusError(0), params).ok()?;
    p.encode(buf).ok().map(<[u8]>::to_vec)
}
