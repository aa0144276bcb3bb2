//! A virtual RX-28 on Protocol 1.0: its control table
//! ([`pada_core::dynamixel::control_table::rx28::RX28`]) and what it does
//! with every instruction of the e-Manual's Protocol 1.0 page
//! (docs/reference/rx28.md, docs/servos.md).
//!
//! | instruction | answered (Status Return Level) | what it does |
//! |---|---|---|
//! | PING | always | nothing |
//! | READ | 1 and 2 | the table's bytes; past the table: Range Error, no data |
//! | WRITE, REG WRITE | 2 | every byte must belong to a whole writable item and be in its range, else Range Error and nothing written; REG WRITE holds it (Registered = 1) |
//! | ACTION | 2 | writes what REG WRITE held; without one: Instruction Error |
//! | RESET | 2 | the factory table (ID 1, the factory baud rate) |
//! | SYNC WRITE | never | its own entry, as WRITE |
//! | BULK READ | its turn, 1 and 2 | its own entry, as READ |
//! | another code, bad parameters | 2 | Instruction Error |
//! | a damaged packet to it | 2 | Checksum Error |
//!
//! A broadcast instruction is never answered. The present values
//! (addresses 36–43) are the robot's at the instant of the read; Moving
//! Speed and Torque Enable drive it (the bus does: [`super::bus`]).

use pada_core::dynamixel::control_table::rx28::RX28;
use pada_core::dynamixel::control_table::TableError;
use pada_core::dynamixel::table::{self, PresentState};
use pada_core::dynamixel::{ErrorFlags, Instruction};
use pada_core::robot::JointSpec;

/// The factory Baud Rate value of an RX-28: 34 (57,142 bps, the e-Manual's
/// "Initial Value").
pub const FACTORY_BAUD: u8 = 34;

/// The RX-28's factory control table at ID `id`, at Baud Rate value `baud`
/// (the e-Manual's initial values; the firmware writes wheel mode, return
/// delay and status return level itself).
pub fn factory_table(id: u8, baud: u8) -> [u8; table::TABLE_LEN] {
    let mut t = [0u8; table::TABLE_LEN];
    t[table::MODEL_NUMBER as usize..][..2].copy_from_slice(&table::RX28_MODEL.to_le_bytes());
    t[table::FIRMWARE_VERSION as usize] = 0x24;
    t[table::ID as usize] = id;
    t[table::BAUD_RATE as usize] = baud;
    t[table::RETURN_DELAY_TIME as usize] = 250;
    t[table::CCW_ANGLE_LIMIT as usize..][..2].copy_from_slice(&table::POSITION_MAX.to_le_bytes());
    t[table::HIGHEST_LIMIT_TEMPERATURE as usize] = 80;
    t[table::LOWEST_LIMIT_VOLTAGE as usize] = 60;
    t[table::HIGHEST_LIMIT_VOLTAGE as usize] = 160;
    t[table::MAX_TORQUE as usize..][..2].copy_from_slice(&table::MAGNITUDE_MAX.to_le_bytes());
    t[table::STATUS_RETURN_LEVEL as usize] = 2;
    t[table::ALARM_LED as usize] = 0x24;
    t[table::ALARM_SHUTDOWN as usize] = 0x24;
    t[table::CW_COMPLIANCE_MARGIN as usize] = 1;
    t[table::CCW_COMPLIANCE_MARGIN as usize] = 1;
    t[table::CW_COMPLIANCE_SLOPE as usize] = 32;
    t[table::CCW_COMPLIANCE_SLOPE as usize] = 32;
    t[table::TORQUE_LIMIT as usize..][..2].copy_from_slice(&table::MAGNITUDE_MAX.to_le_bytes());
    t[table::PUNCH as usize..][..2].copy_from_slice(&32u16.to_le_bytes());
    t
}

/// `table` with the present values `p` (addresses 36–43).
pub fn with_present(mut t: [u8; table::TABLE_LEN], p: &PresentState) -> [u8; table::TABLE_LEN] {
    let at = table::PRESENT_BLOCK as usize;
    t[at..at + table::PRESENT_BLOCK_LEN as usize].copy_from_slice(&p.to_bytes());
    t
}

/// One virtual RX-28.
#[derive(Debug, Clone)]
pub struct P1Servo {
    /// Its control table.
    pub table: [u8; table::TABLE_LEN],
    /// The joint it drives (the robot's calibration), if any.
    pub joint: Option<JointSpec>,
    /// The Baud Rate value it came with (a RESET restores the factory's).
    registered: Option<(u8, Vec<u8>)>,
}

/// What a servo answers: its error bits and parameters; `None`: nothing.
pub type Answer = Option<(ErrorFlags, Vec<u8>)>;

impl P1Servo {
    /// A servo with the factory table at `id` and Baud Rate value `baud`.
    pub fn new(id: u8, baud: u8, joint: Option<JointSpec>) -> Self {
        P1Servo { table: factory_table(id, baud), joint, registered: None }
    }

    /// Its ID now.
    pub fn id(&self) -> u8 {
        self.table[table::ID as usize]
    }

    /// Its Baud Rate value now.
    pub fn baud(&self) -> u8 {
        self.table[table::BAUD_RATE as usize]
    }

    /// Torque Enable.
    pub fn torque(&self) -> bool {
        self.table[table::TORQUE_ENABLE as usize] != 0
    }

    /// Moving Speed.
    pub fn moving_speed(&self) -> u16 {
        u16::from_le_bytes([self.table[table::MOVING_SPEED as usize], self.table[table::MOVING_SPEED as usize + 1]])
    }

    /// The voltage its Moving Speed applies in wheel mode on `supply` \[V\]
    /// (0 in joint mode, whose position control is not emulated).
    pub fn volts(&self, supply: f64) -> f64 {
        let wheel = self.table[table::CW_ANGLE_LIMIT as usize..table::CCW_ANGLE_LIMIT as usize + 2].iter().all(|&b| b == 0);
        if wheel {
            table::ratio_from_moving_speed(self.moving_speed()) as f64 * supply
        } else {
            0.0
        }
    }

    /// Return Delay Time \[µs\].
    pub fn return_delay_us(&self) -> u64 {
        self.table[table::RETURN_DELAY_TIME as usize] as u64 * 2
    }

    fn level(&self) -> u8 {
        self.table[table::STATUS_RETURN_LEVEL as usize]
    }

    /// Answers with `error` and `params` if its Status Return Level answers
    /// `kind` (0 PING only, 1 READ, 2 everything), never to a broadcast.
    fn answer(&self, broadcast: bool, kind: u8, error: ErrorFlags, params: Vec<u8>) -> Answer {
        (!broadcast && (kind == 0 || self.level() >= kind)).then_some((error, params))
    }

    /// Reads `len` bytes at `addr` (its answer's error and data).
    pub fn read(&self, addr: u8, len: u8) -> (ErrorFlags, Vec<u8>) {
        match RX28.check_read(addr as u16, len as u16) {
            Ok(()) => (ErrorFlags::NONE, self.table[addr as usize..addr as usize + len as usize].to_vec()),
            Err(_) => (ErrorFlags::RANGE, Vec::new()),
        }
    }

    /// Writes `data` at `addr` if the table takes it (whole writable items,
    /// values in range, EEPROM not locked).
    pub fn write(&mut self, addr: u8, data: &[u8]) -> Result<(), TableError> {
        RX28.check_write(addr as u16, data, &self.table)?;
        self.table[addr as usize..addr as usize + data.len()].copy_from_slice(data);
        Ok(())
    }

    /// Executes an instruction addressed to it (or broadcast); returns its
    /// answer.
    pub fn execute(&mut self, ins: &Instruction<'_>, broadcast: bool) -> Answer {
        match *ins {
            Instruction::Ping => self.answer(broadcast, 0, ErrorFlags::NONE, Vec::new()),
            Instruction::Read { addr, len } => {
                let (error, data) = self.read(addr, len);
                self.answer(broadcast, 1, error, data)
            }
            Instruction::Write { addr, data } => {
                // Answered at the level in force when it arrived: a WRITE
                // of Status Return Level 1 is still answered (the firmware
                // listens for it, so the answer cannot collide).
                let level = self.level();
                let error = self.write(addr, data).map_or(ErrorFlags::RANGE, |()| ErrorFlags::NONE);
                (!broadcast && level >= 2).then_some((error, Vec::new()))
            }
            Instruction::RegWrite { addr, data } => {
                let error = match RX28.check_write(addr as u16, data, &self.table) {
                    Ok(()) => {
                        self.registered = Some((addr, data.to_vec()));
                        self.table[table::REGISTERED as usize] = 1;
                        ErrorFlags::NONE
                    }
                    Err(_) => ErrorFlags::RANGE,
                };
                self.answer(broadcast, 2, error, Vec::new())
            }
            Instruction::Action => {
                let error = match self.registered.take() {
                    Some((addr, data)) => {
                        self.table[table::REGISTERED as usize] = 0;
                        self.write(addr, &data).map_or(ErrorFlags::RANGE, |()| ErrorFlags::NONE)
                    }
                    None => ErrorFlags::INSTRUCTION,
                };
                self.answer(broadcast, 2, error, Vec::new())
            }
            Instruction::Reset => {
                let answer = self.answer(broadcast, 2, ErrorFlags::NONE, Vec::new());
                self.table = factory_table(1, FACTORY_BAUD);
                self.registered = None;
                answer
            }
            Instruction::SyncWrite { addr, .. } => {
                let id = self.id();
                let data: Option<Vec<u8>> = ins.sync_entries().find(|(i, _)| *i == id).map(|(_, d)| d.to_vec());
                if let Some(data) = data {
                    let _ = self.write(addr, &data);
                }
                None
            }
            Instruction::BulkRead { .. } => {
                let id = self.id();
                let (_, addr, len) = ins.bulk_read_entries().find(|e| e.0 == id)?;
                let (error, data) = self.read(addr, len);
                // Its turn in the chain, at level 1 or 2 (the bus orders).
                (self.level() >= 1).then_some((error, data))
            }
        }
    }

    /// The answer to an instruction it cannot execute (an unknown code, bad
    /// parameters): Instruction Error, at level 2.
    pub fn refuse(&self, broadcast: bool, error: ErrorFlags) -> Answer {
        self.answer(broadcast, 2, error, Vec::new())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_e_manuals_answers() {
        let mut s = P1Servo::new(1, 1, None);
        assert_eq!(s.execute(&Instruction::Ping, false), Some((ErrorFlags::NONE, vec![])));
        assert_eq!(s.execute(&Instruction::Read { addr: 0, len: 2 }, false), Some((ErrorFlags::NONE, vec![28, 0])));
        assert_eq!(s.execute(&Instruction::Read { addr: 49, len: 2 }, false), Some((ErrorFlags::RANGE, vec![])));
        // Out of range: Range Error, nothing written.
        assert_eq!(s.execute(&Instruction::Write { addr: 3, data: &[254] }, false), Some((ErrorFlags::RANGE, vec![])));
        assert_eq!(s.id(), 1);
        assert_eq!(s.execute(&Instruction::Write { addr: 32, data: &[0x00, 0x02] }, false), Some((ErrorFlags::NONE, vec![])));
        assert_eq!(s.moving_speed(), 512);
        // Broadcast: done, never answered.
        assert_eq!(s.execute(&Instruction::Write { addr: 24, data: &[1] }, true), None);
        assert!(s.torque());
        // Action without Reg Write.
        assert_eq!(s.execute(&Instruction::Action, false), Some((ErrorFlags::INSTRUCTION, vec![])));
        assert_eq!(s.execute(&Instruction::RegWrite { addr: 25, data: &[1] }, false), Some((ErrorFlags::NONE, vec![])));
        assert_eq!(s.table[table::REGISTERED as usize], 1);
        assert_eq!(s.execute(&Instruction::Action, true), None);
        assert_eq!((s.table[25], s.table[table::REGISTERED as usize]), (1, 0));
        // The WRITE that lowers the level to 1 is answered at the level it
        // came at (2); the next WRITE is not.
        let lower = Instruction::Write { addr: table::STATUS_RETURN_LEVEL, data: &[1] };
        assert_eq!(s.execute(&lower, false), Some((ErrorFlags::NONE, vec![])));
        assert_eq!(s.execute(&Instruction::Write { addr: 25, data: &[1] }, false), None);
        // Level 1: reads only.
        s.table[table::STATUS_RETURN_LEVEL as usize] = 1;
        assert_eq!(s.execute(&Instruction::Write { addr: 25, data: &[0] }, false), None);
        assert!(s.execute(&Instruction::Read { addr: 25, len: 1 }, false).is_some());
        s.table[table::STATUS_RETURN_LEVEL as usize] = 0;
        assert_eq!(s.execute(&Instruction::Read { addr: 25, len: 1 }, false), None);
        assert!(s.execute(&Instruction::Ping, false).is_some());
    }
}
