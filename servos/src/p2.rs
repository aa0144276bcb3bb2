//! A virtual X-series servo on Protocol 2.0: its control table (pada's
//! `ControlTable` of the model, docs/reference/dynamixel.md § 5, with the
//! e-Manual's initial values) and what it does with every instruction of
//! the Protocol 2.0 page (§ 3), answering with the Error Numbers of § 4.
//!
//! | instruction | answered (Status Return Level) | what it does |
//! |---|---|---|
//! | PING | always (even at level 0) | Model Number and Firmware Version |
//! | READ | 1 and 2 | the bytes; past the table Access Error, length 0 Data Length Error |
//! | WRITE, REG WRITE | 2 | `ControlTable::check_write`: Access (read-only, undefined, EEPROM while torque is on, a goal while the Bus Watchdog has tripped), Data Length (part of an item), Data Range, Data Limit (Goal PWM beyond PWM Limit); nothing written on an error |
//! | ACTION | 2 | the held REG WRITE; without one Instruction Error |
//! | FACTORY RESET | 2 | the initial values (all, all but the ID, all but ID and baud rate) |
//! | REBOOT | 2 | RAM back to its initial values (torque off, the hardware error cleared) |
//! | CLEAR | 2 | Present Position back into one turn; Result Fail while it turns |
//! | SYNC READ, BULK READ | its turn, 1 and 2 | its part, as READ |
//! | FAST SYNC READ, FAST BULK READ | its block of the one reply | its part (the bus builds the reply) |
//! | SYNC WRITE, BULK WRITE | never | its part, as WRITE |
//! | another code | 2 | Instruction Error; bad parameters Data Length Error |
//! | a damaged packet to it | 2 | CRC Error |
//!
//! In PWM Control Mode (Operating Mode 16) with torque on, Goal PWM drives
//! the motor with that fraction of the supply; the other modes' position
//! and velocity controllers are not emulated (the motor gets 0 V). A
//! hardware error (`--fault error-bits`) sets the Alert bit of every
//! answer until a REBOOT, and switches torque off when Shutdown (63) has
//! its bit. The Bus Watchdog (98) stops a servo whose torque is on when no
//! instruction reaches the bus for its time: Goal PWM 0, the watchdog −1,
//! goals refused until it is written 0.

use pada_core::dynamixel::control_table::x_series::{self, mode, HardwareError};
use pada_core::dynamixel::control_table::{ControlTable, TableError};
use pada_core::dynamixel::v2::{self as dxl2, fast::FastBlock, ErrorNumber, Instruction, PingReply, ResetMode, StatusError};
use pada_core::robot::JointSpec;
use pada_core::servo::ServoModel;
use pada_sim::rig::{x_reading, JointState};

/// Bytes of the longest packet a virtual servo decodes or answers.
pub const PACKET_LEN: usize = 1024;

/// The firmware version the virtual servos report: new enough for Fast Sync
/// Read (X430 from 45, X330 from 46).
pub const FIRMWARE: u8 = 46;

/// The e-Manual's initial values (address, bytes, value) of the items
/// pada's table lists, per model number; the rest of the table reads 0.
fn initial_values(model_number: u16) -> &'static [(u16, u8, i64)] {
    use x_series::*;
    const COMMON: [(u16, u8, i64); 10] = [
        (RETURN_DELAY_TIME, 1, 250),
        (OPERATING_MODE, 1, mode::POSITION as i64),
        (TEMPERATURE_LIMIT, 1, 80),
        (PWM_LIMIT, 2, 885),
        (MAX_POSITION_LIMIT, 4, 4095),
        (MIN_POSITION_LIMIT, 4, 0),
        (SHUTDOWN, 1, 52),
        (STATUS_RETURN_LEVEL, 1, 2),
        (BAUD_RATE, 1, 1),
        (ID, 1, 1),
    ];
    match model_number {
        // XM430-W350: 9.5–16 V, Current Limit 1193, Velocity Limit 200.
        1020 => &[
            COMMON[0], COMMON[1], COMMON[2], COMMON[3], COMMON[4], COMMON[5], COMMON[6], COMMON[7], COMMON[8], COMMON[9],
            (MAX_VOLTAGE_LIMIT, 2, 160), (MIN_VOLTAGE_LIMIT, 2, 95), (CURRENT_LIMIT, 2, 1193), (VELOCITY_LIMIT, 4, 200),
        ],
        // XL430-W250: 6–14 V, Velocity Limit 265, Temperature Limit 72.
        1060 => &[
            COMMON[0], COMMON[1], (TEMPERATURE_LIMIT, 1, 72), COMMON[3], COMMON[4], COMMON[5], COMMON[6], COMMON[7], COMMON[8],
            COMMON[9], (MAX_VOLTAGE_LIMIT, 2, 140), (MIN_VOLTAGE_LIMIT, 2, 60), (VELOCITY_LIMIT, 4, 265),
        ],
        // XL330-M288: 3.5–7 V, Current Limit 1750, Velocity Limit 445,
        // Temperature Limit 70.
        _ => &[
            COMMON[0], COMMON[1], (TEMPERATURE_LIMIT, 1, 70), COMMON[3], COMMON[4], COMMON[5], COMMON[6], COMMON[7], COMMON[8],
            COMMON[9], (MAX_VOLTAGE_LIMIT, 2, 70), (MIN_VOLTAGE_LIMIT, 2, 35), (CURRENT_LIMIT, 2, 1750), (VELOCITY_LIMIT, 4, 445),
        ],
    }
}

/// What a servo answers: its ERROR byte and parameters; `None`: nothing.
pub type Answer = Option<(StatusError, Vec<u8>)>;

/// One virtual X-series servo.
#[derive(Debug, Clone)]
pub struct P2Servo {
    /// Its model.
    pub model: &'static ServoModel,
    /// Its control table's description.
    pub table: &'static ControlTable,
    /// Its control table's bytes.
    pub memory: Vec<u8>,
    /// The joint it drives (the robot's calibration), if any.
    pub joint: Option<JointSpec>,
    /// A REG WRITE held for ACTION.
    registered: Option<(u16, Vec<u8>)>,
    /// Whole turns taken off Present Position by CLEAR \[counts\].
    pub cleared_counts: i32,
    /// When the bus last carried an instruction while its torque was on
    /// \[µs\] (the Bus Watchdog's reference).
    pub heard_us: u64,
}

impl P2Servo {
    /// A servo of `model` with its initial values, at `id` and Baud Rate
    /// value `baud`.
    pub fn new(model: &'static ServoModel, table: &'static ControlTable, id: u8, baud: u8, joint: Option<JointSpec>) -> Self {
        let mut s = P2Servo {
            model,
            table,
            memory: vec![0; table.end as usize],
            joint,
            registered: None,
            cleared_counts: 0,
            heard_us: 0,
        };
        s.reset(ResetMode::All);
        s.put(x_series::ID, 1, id as i64);
        s.put(x_series::BAUD_RATE, 1, baud as i64);
        s
    }

    fn put(&mut self, addr: u16, size: u8, value: i64) {
        let bytes = value.to_le_bytes();
        if let Some(dst) = self.memory.get_mut(addr as usize..addr as usize + size as usize) {
            dst.copy_from_slice(&bytes[..size as usize]);
        }
    }

    fn get(&self, addr: u16) -> i64 {
        self.table.value(&self.memory, addr).unwrap_or(0)
    }

    /// The factory's values, keeping what `keep` keeps.
    fn reset(&mut self, keep: ResetMode) {
        let (id, baud) = (self.memory.get(x_series::ID as usize).copied(), self.memory.get(x_series::BAUD_RATE as usize).copied());
        self.memory.fill(0);
        self.put(x_series::MODEL_NUMBER, 2, self.model.model_number as i64);
        self.put(x_series::FIRMWARE_VERSION, 1, FIRMWARE as i64);
        for &(addr, size, value) in initial_values(self.model.model_number) {
            self.put(addr, size, value);
        }
        if keep != ResetMode::All {
            self.put(x_series::ID, 1, id.unwrap_or(1) as i64);
        }
        if keep == ResetMode::ExceptIdAndBaudRate {
            self.put(x_series::BAUD_RATE, 1, baud.unwrap_or(1) as i64);
        }
        self.registered = None;
        self.cleared_counts = 0;
    }

    /// RAM (addresses 64 on) back to its initial values: a REBOOT or a
    /// power cycle.
    pub fn reboot(&mut self) {
        let eeprom = self.memory[..64].to_vec();
        self.reset(ResetMode::All);
        self.memory[..64].copy_from_slice(&eeprom);
    }

    /// Its ID now.
    pub fn id(&self) -> u8 {
        self.get(x_series::ID) as u8
    }

    /// Its Baud Rate value now.
    pub fn baud(&self) -> u8 {
        self.get(x_series::BAUD_RATE) as u8
    }

    /// Torque Enable.
    pub fn torque(&self) -> bool {
        self.get(x_series::TORQUE_ENABLE) != 0
    }

    /// Goal PWM.
    pub fn goal_pwm(&self) -> i16 {
        self.get(x_series::GOAL_PWM) as i16
    }

    /// Hardware Error Status.
    pub fn hardware_error(&self) -> HardwareError {
        HardwareError(self.get(x_series::HARDWARE_ERROR_STATUS) as u8)
    }

    /// Whether its Bus Watchdog has tripped (−1).
    pub fn watchdog_tripped(&self) -> bool {
        self.get(x_series::BUS_WATCHDOG) < 0
    }

    /// Its Bus Watchdog time \[µs\] while armed and not tripped.
    pub fn watchdog_us(&self) -> Option<u64> {
        let v = self.get(x_series::BUS_WATCHDOG);
        (v > 0).then_some(v as u64 * 20_000)
    }

    /// What its motor gets: Goal PWM's fraction of the supply in PWM
    /// Control Mode with torque on \[V\]; 0 otherwise.
    pub fn volts(&self, supply: f64) -> f64 {
        let pwm_mode = self.get(x_series::OPERATING_MODE) == mode::PWM as i64;
        if self.torque() && pwm_mode && !self.watchdog_tripped() {
            self.goal_pwm() as f64 / pada_core::servo::encoding::X_PWM_FULL as f64 * supply
        } else {
            0.0
        }
    }

    /// Return Delay Time \[µs\].
    pub fn return_delay_us(&self) -> u64 {
        self.get(x_series::RETURN_DELAY_TIME) as u64 * 2
    }

    fn level(&self) -> i64 {
        self.get(x_series::STATUS_RETURN_LEVEL)
    }

    /// The ERROR byte of an answer with Error Number `number`: the Alert
    /// bit while a hardware error stands.
    pub fn status(&self, number: Option<ErrorNumber>) -> StatusError {
        StatusError::new(number, self.hardware_error().0 != 0)
    }

    fn answer(&self, broadcast: bool, kind: i64, number: Option<ErrorNumber>, params: Vec<u8>) -> Answer {
        (!broadcast && (kind == 0 || self.level() >= kind)).then(|| (self.status(number), params))
    }

    /// Reads `len` bytes at `addr`: its Error Number and data.
    pub fn read(&self, addr: u16, len: u16) -> (Option<ErrorNumber>, Vec<u8>) {
        match self.table.check_read(addr, len) {
            Ok(()) => (None, self.memory[addr as usize..addr as usize + len as usize].to_vec()),
            Err(e) => (Some(e.error_number()), Vec::new()),
        }
    }

    /// Writes `data` at `addr` if the table takes it; a tripped Bus
    /// Watchdog makes the goals read-only (e-Manual, "Bus Watchdog"), and
    /// torque stays off after a shutdown until a REBOOT (pada answers Result
    /// Fail, which the e-Manual leaves open).
    pub fn write(&mut self, addr: u16, data: &[u8]) -> Result<(), ErrorNumber> {
        self.table.check_write(addr, data, &self.memory).map_err(TableError::error_number)?;
        let end = addr as usize + data.len();
        let goals = x_series::GOAL_PWM as usize..x_series::GOAL_POSITION as usize + 4;
        if self.watchdog_tripped() && (addr as usize) < goals.end && end > goals.start {
            return Err(ErrorNumber::Access);
        }
        let torque = x_series::TORQUE_ENABLE as usize;
        let shut_down = self.hardware_error().0 & self.get(x_series::SHUTDOWN) as u8 != 0;
        if shut_down && (addr as usize..end).contains(&torque) && data[torque - addr as usize] != 0 {
            return Err(ErrorNumber::ResultFail);
        }
        self.memory[addr as usize..end].copy_from_slice(data);
        Ok(())
    }

    /// Raises a hardware error (an injected fault): the Alert bit from now
    /// on, and torque off if Shutdown has its bit.
    pub fn raise(&mut self, error: HardwareError) {
        let bits = self.hardware_error().0 | error.0;
        self.put(x_series::HARDWARE_ERROR_STATUS, 1, bits as i64);
        if bits & self.get(x_series::SHUTDOWN) as u8 != 0 {
            self.put(x_series::TORQUE_ENABLE, 1, 0);
        }
    }

    /// Trips its Bus Watchdog: the motor stops, the goals are refused.
    pub fn trip_watchdog(&mut self) {
        self.put(x_series::GOAL_PWM, 2, 0);
        self.put(x_series::BUS_WATCHDOG, 1, -1);
    }

    /// Executes an instruction addressed to it (or broadcast); returns its
    /// answer. `turning`: whether its joint moves (for CLEAR).
    pub fn execute(&mut self, ins: &Instruction<'_>, broadcast: bool, turning: bool) -> Answer {
        let done = |r: Result<(), ErrorNumber>| r.err();
        match *ins {
            Instruction::Ping => {
                let reply = PingReply { model_number: self.model.model_number, firmware: FIRMWARE };
                self.answer(broadcast, 0, None, reply.to_params().to_vec())
            }
            Instruction::Read { addr, len } => {
                let (number, data) = self.read(addr, len);
                self.answer(broadcast, 1, number, data)
            }
            Instruction::Write { addr, data } => {
                // Answered at the level in force when it arrived (a WRITE
                // of Status Return Level 1 is still answered).
                let level = self.level();
                let number = done(self.write(addr, data));
                (!broadcast && level >= 2).then(|| (self.status(number), Vec::new()))
            }
            Instruction::RegWrite { addr, data } => {
                let number = self.table.check_write(addr, data, &self.memory).map_err(TableError::error_number).err();
                if number.is_none() {
                    self.registered = Some((addr, data.to_vec()));
                    self.put(x_series::REGISTERED_INSTRUCTION, 1, 1);
                }
                self.answer(broadcast, 2, number, Vec::new())
            }
            Instruction::Action => {
                let number = match self.registered.take() {
                    Some((addr, data)) => {
                        self.put(x_series::REGISTERED_INSTRUCTION, 1, 0);
                        done(self.write(addr, &data))
                    }
                    None => Some(ErrorNumber::Instruction),
                };
                self.answer(broadcast, 2, number, Vec::new())
            }
            Instruction::FactoryReset(keep) => {
                // From firmware 42, a reset of everything sent to every
                // servo at once is ignored (e-Manual, "Factory Reset").
                if broadcast && keep == ResetMode::All {
                    return None;
                }
                let answer = self.answer(broadcast, 2, None, Vec::new());
                self.reset(keep);
                answer
            }
            Instruction::Reboot => {
                let answer = self.answer(broadcast, 2, None, Vec::new());
                self.reboot();
                answer
            }
            Instruction::ClearMultiTurn => {
                let number = turning.then_some(ErrorNumber::ResultFail);
                if !turning {
                    let position = self.get(x_series::PRESENT_POSITION) as i32;
                    self.cleared_counts += position - position.rem_euclid(x_series::PULSES_PER_REV as i32);
                }
                self.answer(broadcast, 2, number, Vec::new())
            }
            Instruction::SyncRead { addr, len, .. } | Instruction::FastSyncRead { addr, len, .. } => {
                let id = self.id();
                if !ins.ids().any(|i| i == id) || self.level() < 1 {
                    return None;
                }
                let (number, data) = self.read(addr, len);
                Some((self.status(number), data))
            }
            Instruction::BulkRead { .. } | Instruction::FastBulkRead { .. } => {
                let id = self.id();
                let entry = ins.bulk_read_entries().find(|e| e.id == id)?;
                if self.level() < 1 {
                    return None;
                }
                let (number, data) = self.read(entry.addr, entry.len);
                Some((self.status(number), data))
            }
            Instruction::SyncWrite { addr, .. } => {
                let id = self.id();
                let data: Option<Vec<u8>> = ins.sync_write_entries().find(|(i, _)| *i == id).map(|(_, d)| d.to_vec());
                if let Some(data) = data {
                    let _ = self.write(addr, &data);
                }
                None
            }
            Instruction::BulkWrite { .. } => {
                let id = self.id();
                let entry = ins.bulk_write_entries().find(|e| e.id == id).map(|e| (e.addr, e.data.to_vec()));
                if let Some((addr, data)) = entry {
                    let _ = self.write(addr, &data);
                }
                None
            }
        }
    }

    /// Its present values (addresses 124–146) with its joint in `state` on
    /// a `supply_v` supply (`pada_sim::rig::x_reading`), less the turns
    /// CLEAR took off.
    pub fn set_present(&mut self, joint: &JointSpec, state: JointState, supply_v: f64) {
        let pwm = if self.torque() { self.goal_pwm() } else { 0 };
        let mut r = x_reading(joint, state, pwm, supply_v);
        r.position = r.position.wrapping_sub(self.cleared_counts);
        let at = x_series::PRESENT_BLOCK as usize;
        let bytes = r.to_bytes();
        self.memory[at..at + bytes.len()].copy_from_slice(&bytes);
    }

    /// The answer to an instruction it cannot execute (an unknown code, bad
    /// parameters, a damaged packet), at level 2.
    pub fn refuse(&self, broadcast: bool, number: ErrorNumber) -> Answer {
        self.answer(broadcast, 2, Some(number), Vec::new())
    }
}

/// The status packet of servo `id`'s answer.
pub fn encode(id: u8, (error, params): (StatusError, Vec<u8>)) -> Vec<u8> {
    let mut buf = vec![0u8; 2 * params.len() + 16];
    dxl2::StatusPacket::<PACKET_LEN>::new(id, error, &params)
        .and_then(|p| p.encode(&mut buf).map(<[u8]>::to_vec))
        .unwrap_or_default()
}

/// The one status packet of a FAST SYNC READ or FAST BULK READ: each
/// servo's block (ID, ERROR byte, data) in turn; `None` if it does not
/// encode.
pub fn fast_reply(blocks: &[(u8, StatusError, Vec<u8>)]) -> Option<Vec<u8>> {
    let parts: Vec<FastBlock<'_>> = blocks.iter().map(|(id, error, data)| FastBlock { id: *id, error: *error, data }).collect();
    let packet = dxl2::StatusPacket::<PACKET_LEN>::fast_reply(&parts).ok()?;
    let mut buf = vec![0u8; PACKET_LEN + 16];
    packet.encode(&mut buf).ok().map(<[u8]>::to_vec)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::dynamixel::control_table::x_series::XM430_W350;

    fn xm() -> P2Servo {
        P2Servo::new(&pada_core::servo::XM430_W350, &XM430_W350, 1, 3, None)
    }

    #[test]
    fn the_e_manuals_answers() {
        let mut s = xm();
        assert_eq!(s.execute(&Instruction::Ping, false, false), Some((StatusError(0), vec![0xFC, 0x03, FIRMWARE])));
        assert_eq!(s.execute(&Instruction::Read { addr: 0, len: 2 }, false, false), Some((StatusError(0), vec![0xFC, 0x03])));
        let write = |s: &mut P2Servo, addr, data: &[u8]| s.execute(&Instruction::Write { addr, data }, false, false).map(|a| a.0.number());
        // Goal PWM beyond its range, beyond PWM Limit, and within.
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &886i16.to_le_bytes()), Some(Some(ErrorNumber::DataRange)));
        assert_eq!(write(&mut s, x_series::PWM_LIMIT, &500u16.to_le_bytes()), Some(None));
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &600i16.to_le_bytes()), Some(Some(ErrorNumber::DataLimit)));
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &(-400i16).to_le_bytes()), Some(None));
        assert_eq!(s.goal_pwm(), -400);
        // Read-only, part of an item, EEPROM with torque on.
        assert_eq!(write(&mut s, x_series::PRESENT_POSITION, &[0, 0, 0, 0]), Some(Some(ErrorNumber::Access)));
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &[1]), Some(Some(ErrorNumber::DataLength)));
        assert_eq!(write(&mut s, x_series::TORQUE_ENABLE, &[1]), Some(None));
        assert_eq!(write(&mut s, x_series::OPERATING_MODE, &[16]), Some(Some(ErrorNumber::Access)));
        // PWM mode drives the motor with the fraction of the supply.
        assert_eq!(s.volts(12.0), 0.0, "position mode: not emulated");
        write(&mut s, x_series::TORQUE_ENABLE, &[0]);
        assert_eq!(write(&mut s, x_series::OPERATING_MODE, &[16]), Some(None));
        write(&mut s, x_series::TORQUE_ENABLE, &[1]);
        assert!((s.volts(12.0) + 400.0 / 885.0 * 12.0).abs() < 1e-12);
        // An alert: bit 7 of every answer, torque off (overload is in
        // Shutdown's 52), refused until a reboot.
        s.raise(HardwareError::OVERLOAD);
        assert!(!s.torque());
        let (status, _) = s.execute(&Instruction::Ping, false, false).unwrap();
        assert!(status.alert() && status.number().is_none());
        assert_eq!(write(&mut s, x_series::TORQUE_ENABLE, &[1]), Some(Some(ErrorNumber::ResultFail)));
        s.execute(&Instruction::Reboot, false, false);
        assert_eq!((s.hardware_error(), s.torque(), s.level()), (HardwareError(0), false, 2));
        assert_eq!(s.get(x_series::OPERATING_MODE), 16, "EEPROM kept");
        // Level 1: writes unanswered.
        write(&mut s, x_series::STATUS_RETURN_LEVEL, &[1]);
        assert_eq!(write(&mut s, x_series::LED, &[1]), None);
        assert!(s.execute(&Instruction::Read { addr: 65, len: 1 }, false, false).is_some());
        assert_eq!(s.execute(&Instruction::Read { addr: 700, len: 1 }, false, false).unwrap().0.number(), Some(ErrorNumber::Access));
        // The watchdog: tripped, the goals refused until it is written 0.
        write(&mut s, x_series::STATUS_RETURN_LEVEL, &[2]);
        s.trip_watchdog();
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &[0, 0]), Some(Some(ErrorNumber::Access)));
        assert_eq!(write(&mut s, x_series::BUS_WATCHDOG, &[0]), Some(None));
        assert_eq!(write(&mut s, x_series::GOAL_PWM, &[0, 0]), Some(None));
    }
}
