//! A virtual servo on Protocol 1.0's framing: an RX-28
//! ([`pada_core::dynamixel::control_table::rx28::RX28`], the e-Manual's
//! Protocol 1.0 page: docs/reference/rx28.md, docs/servos.md) or a Feetech
//! STS3215 ([`pada_core::feetech::control_table::sts3215::STS3215`],
//! docs/reference/feetech.md), which answer the instructions they share
//! alike; [`Layout`] says where each keeps what the answers depend on.
//! The STS3215's own parts (SYNC READ, its position loop, its alarms) are
//! the STS3215's own module (`ft.rs`).
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
//! (The levels are the RX-28's Status Return Level; the STS3215's
//! Response Status Level 0 and 1 answer as the RX-28's 1 and 2.)
//!
//! A broadcast instruction is never answered. The present values
//! (addresses 36–43) are the robot's at the instant of the read; Moving
//! Speed and Torque Enable drive it (the bus does: [`super::bus`]).

use pada_core::dynamixel::control_table::rx28::RX28;
use pada_core::dynamixel::control_table::{ControlTable, TableError};
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

/// An RX-28's `table` with the present values `p` (addresses 36–43).
pub fn with_present(t: &mut [u8], p: &PresentState) {
    let at = table::PRESENT_BLOCK as usize;
    if let Some(block) = t.get_mut(at..at + table::PRESENT_BLOCK_LEN as usize) {
        block.copy_from_slice(&p.to_bytes());
    }
}

/// Where a model on Protocol 1.0's framing keeps what its answers depend
/// on, and its factory table.
#[derive(Debug)]
pub struct Layout {
    /// Its control table.
    pub table: &'static ControlTable,
    /// The factory table at an ID and a Baud Rate value.
    pub factory: fn(u8, u8) -> Vec<u8>,
    /// ID's address.
    pub id: u8,
    /// Baud Rate's address.
    pub baud: u8,
    /// Return Delay Time's address (2 µs per unit on both models).
    pub return_delay: u8,
    /// The address of the level that says which instructions are
    /// answered.
    pub level: u8,
    /// What that level's 0 stands for on the RX-28's scale (0 PING only, 1
    /// READ too, 2 all): RX-28 0, STS3215 1 (its 0 answers READ and PING).
    pub level_base: u8,
    /// The address of the flag a held REG WRITE sets.
    pub registered: u8,
    /// Torque Enable's address.
    pub torque: u8,
}

/// The RX-28's layout.
pub static RX28_LAYOUT: Layout = Layout {
    table: &RX28,
    factory: |id, baud| factory_table(id, baud).to_vec(),
    id: table::ID,
    baud: table::BAUD_RATE,
    return_delay: table::RETURN_DELAY_TIME,
    level: table::STATUS_RETURN_LEVEL,
    level_base: 0,
    registered: table::REGISTERED,
    torque: table::TORQUE_ENABLE,
};

/// One virtual servo on Protocol 1.0's framing.
#[derive(Debug, Clone)]
pub struct P1Servo {
    /// Its model.
    pub layout: &'static Layout,
    /// Its control table (memory table), indexed by address.
    pub table: Vec<u8>,
    /// The joint it drives (the robot's calibration), if any.
    pub joint: Option<JointSpec>,
    /// An STS3215's output under its own position loop (`ft.rs`);
    /// `None` for an RX-28, whose output is the rig's.
    pub own_loop: Option<super::ft_output::Output>,
    /// The Baud Rate value it came with (a RESET restores the factory's).
    registered: Option<(u8, Vec<u8>)>,
}

/// What a servo answers: its error bits and parameters; `None`: nothing.
pub type Answer = Option<(ErrorFlags, Vec<u8>)>;

impl P1Servo {
    /// An RX-28 with the factory table at `id` and Baud Rate value `baud`.
    pub fn new(id: u8, baud: u8, joint: Option<JointSpec>) -> Self {
        Self::of(&RX28_LAYOUT, id, baud, joint)
    }

    /// A servo of `layout`'s model with its factory table at `id` and Baud
    /// Rate value `baud`.
    pub fn of(layout: &'static Layout, id: u8, baud: u8, joint: Option<JointSpec>) -> Self {
        let own_loop = (!core::ptr::eq(layout, &RX28_LAYOUT)).then(super::ft_output::Output::default);
        P1Servo { layout, table: (layout.factory)(id, baud), joint, own_loop, registered: None }
    }

    fn at(&self, address: u8) -> u8 {
        self.table.get(address as usize).copied().unwrap_or(0)
    }

    /// Its ID now.
    pub fn id(&self) -> u8 {
        self.at(self.layout.id)
    }

    /// Its Baud Rate value now.
    pub fn baud(&self) -> u8 {
        self.at(self.layout.baud)
    }

    /// Its bit rate now \[bps\].
    pub fn baud_bps(&self) -> u32 {
        self.layout.table.baud_rate_bps(self.baud()).unwrap_or(0)
    }

    /// Torque Enable.
    pub fn torque(&self) -> bool {
        self.at(self.layout.torque) != 0
    }

    /// Whether it is an RX-28 (whose Moving Speed drives the rig).
    fn is_rx28(&self) -> bool {
        core::ptr::eq(self.layout, &RX28_LAYOUT)
    }

    /// Moving Speed.
    pub fn moving_speed(&self) -> u16 {
        u16::from_le_bytes([self.table[table::MOVING_SPEED as usize], self.table[table::MOVING_SPEED as usize + 1]])
    }

    /// The voltage its Moving Speed applies in wheel mode on `supply` \[V\]
    /// (0 in joint mode, whose position control is not emulated); an
    /// STS3215's, its duty cycle's ([`super::ft_output::volts`]).
    pub fn volts(&self, supply: f64) -> f64 {
        if !self.is_rx28() {
            // The STS3215's duty cycle in Operating Mode 2.
            return super::ft_output::volts(&self.table, supply);
        }
        let wheel = self.table[table::CW_ANGLE_LIMIT as usize..table::CCW_ANGLE_LIMIT as usize + 2].iter().all(|&b| b == 0);
        if wheel {
            table::ratio_from_moving_speed(self.moving_speed()) as f64 * supply
        } else {
            0.0
        }
    }

    /// Return Delay Time \[µs\].
    pub fn return_delay_us(&self) -> u64 {
        self.at(self.layout.return_delay) as u64 * 2
    }

    /// Its answering level on the RX-28's scale.
    fn level(&self) -> u8 {
        self.at(self.layout.level).saturating_add(self.layout.level_base)
    }

    /// Answers with `error` and `params` if its Status Return Level answers
    /// `kind` (0 PING only, 1 READ, 2 everything), never to a broadcast.
    fn answer(&self, broadcast: bool, kind: u8, error: ErrorFlags, params: Vec<u8>) -> Answer {
        (!broadcast && (kind == 0 || self.level() >= kind)).then_some((error, params))
    }

    /// Reads `len` bytes at `addr` (its answer's error and data).
    pub fn read(&self, addr: u8, len: u8) -> (ErrorFlags, Vec<u8>) {
        match self.layout.table.check_read(addr as u16, len as u16) {
            Ok(()) => (ErrorFlags::NONE, self.table[addr as usize..addr as usize + len as usize].to_vec()),
            Err(_) => (ErrorFlags::RANGE, Vec::new()),
        }
    }

    /// Writes `data` at `addr` if the table takes it (whole writable items,
    /// values in range, EEPROM not locked).
    pub fn write(&mut self, addr: u8, data: &[u8]) -> Result<(), TableError> {
        self.layout.table.check_write(addr as u16, data, &self.table)?;
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
                let error = match self.layout.table.check_write(addr as u16, data, &self.table) {
                    Ok(()) => {
                        self.registered = Some((addr, data.to_vec()));
                        self.table[self.layout.registered as usize] = 1;
                        ErrorFlags::NONE
                    }
                    Err(_) => ErrorFlags::RANGE,
                };
                self.answer(broadcast, 2, error, Vec::new())
            }
            Instruction::Action => {
                let error = match self.registered.take() {
                    Some((addr, data)) => {
                        self.table[self.layout.registered as usize] = 0;
                        self.write(addr, &data).map_or(ErrorFlags::RANGE, |()| ErrorFlags::NONE)
                    }
                    None => ErrorFlags::INSTRUCTION,
                };
                self.answer(broadcast, 2, error, Vec::new())
            }
            Instruction::Reset => {
                let answer = self.answer(broadcast, 2, ErrorFlags::NONE, Vec::new());
                self.table = (self.layout.factory)(1, self.factory_baud());
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

    /// The Baud Rate value a RESET (RECOVERY) restores: the RX-28's
    /// factory 34, the STS3215's 0 (1 Mbps).
    fn factory_baud(&self) -> u8 {
        if self.is_rx28() {
            FACTORY_BAUD
        } else {
            0
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
