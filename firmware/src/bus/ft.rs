//! Feetech transactions (the STS series: the STS3215 of the SO-100/SO-101
//! arm). Feetech's framing is Dynamixel Protocol 1.0's, so a READ, a
//! WRITE, their retries and the decoder are Protocol 1.0's ([`super::v1`]);
//! what is Feetech's own is here: the SYNC READ of every servo's present
//! block, the SYNC WRITE of every servo's torque and command in one
//! packet, the byte order and sign bits of the values, and the set-up
//! (Response Status Level, return delay, Operating Mode). The packets come
//! from `pada_core::feetech`; the addresses from its STS3215 memory table
//! (docs/reference/feetech.md).
//!
//! One period on the bus (docs/servos.md, "Bus time per period"):
//!
//! | transaction | packet | answer |
//! |---|---|---|
//! | read | one SYNC READ (0x82) of Present Position … Present Temperature (56–63) from every servo | one status packet per servo, in the order of the IDs |
//! | write | one SYNC WRITE (0x83) of Torque Enable … Goal Time (40–45) to every servo | none |
//!
//! A servo missing from the SYNC READ's answers is asked again alone (a
//! READ) with the attempts left, so that a timeout names the servo that is
//! silent. Torque off is the same SYNC WRITE with Torque Enable 0 and a
//! zero duty cycle; at boot and on the way out, two broadcast WRITEs do it
//! for every servo, whatever the robot's IDs.

use super::v1::count_refusal;
use super::{ServoBus, ServoRead, ServoSetup, SetupError, RETURN_DELAY};
use crate::io::{BusPort, PortError};
use heapless::Vec;
use pada_core::dynamixel::{ErrorFlags, BROADCAST_ID};
use pada_core::feetech::command::{Command, COMMAND_BLOCK, COMMAND_LEN};
use pada_core::feetech::control_table::sts3215 as sts;
use pada_core::feetech::{self, present, status, ByteOrder};
use pada_core::limits::MAX_SERVOS;

/// Response Status Level pada sets: 0, so that only READ and PING are
/// answered and a WRITE never puts a reply on the bus (Feetech's 0 is
/// Dynamixel's 1).
pub const RESPONSE_STATUS_LEVEL: u8 = 0;
/// Lock (55): 0 lets an EEPROM write be saved, 1 keeps it in RAM only.
const LOCK_OPEN: u8 = 0;
const LOCK_CLOSED: u8 = 1;
/// Firmware Major Version … Model Number: the first READ of the set-up.
const IDENTITY_LEN: u8 = sts::MODEL_NUMBER + 2;
/// Operating Mode (33) … Acceleration (41): the set-up's second READ.
const MODE_BLOCK_LEN: u8 = sts::ACCELERATION - sts::OPERATING_MODE + 1;

/// Protocol 1.0's error bits for a Feetech ERROR byte, so that one safety
/// machine counts both: Feetech's bits 0, 1, 2 and 5 mean what
/// Dynamixel's do (voltage, angle, overheating, overload); its bit 3 is
/// over-current where Dynamixel has its Range Error, and counts as an
/// overload, a hardware condition that faults
/// (docs/reference/feetech.md § "Status").
pub fn flags_of_ft(error: ErrorFlags) -> ErrorFlags {
    if error.intersects(status::OVERCURRENT) {
        ErrorFlags(error.bits() & !status::OVERCURRENT.bits()) | ErrorFlags::OVERLOAD
    } else {
        error
    }
}

/// A servo's set-up, and what the period's SYNC WRITE must keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FtSetup {
    /// Model, firmware, whether anything was written.
    pub setup: ServoSetup,
    /// Its byte order (END, address 2).
    pub order: ByteOrder,
    /// Its Acceleration (41), written back unchanged every period.
    pub acceleration: u8,
}

impl<P: BusPort> ServoBus<P> {
    /// Torque Enable 0 and a zero duty cycle (Goal Time 0) on every
    /// servo at once (two broadcast WRITEs, no reply): at boot, whatever
    /// the servos did before, and on the way out.
    pub async fn stop_all_ft(&mut self) -> Result<(), PortError> {
        let torque = self.write_no_reply(BROADCAST_ID, sts::TORQUE_ENABLE, &[0]).await;
        let duty = self.write_no_reply(BROADCAST_ID, sts::GOAL_TIME, &[0, 0]).await;
        torque.and(duty)
    }

    /// One SYNC WRITE of every servo's torque and command (no reply).
    pub async fn sync_write_ft(&mut self, entries: &[(u8, Command)], order: ByteOrder) -> Result<(), PortError> {
        let mut blocks: Vec<(u8, [u8; COMMAND_LEN as usize]), MAX_SERVOS> = Vec::new();
        for &(id, command) in entries {
            blocks.push((id, command.block(order))).map_err(|_| PortError::Transmit)?;
        }
        let mut refs: Vec<(u8, &[u8]), MAX_SERVOS> = Vec::new();
        for (id, block) in &blocks {
            refs.push((*id, &block[..])).map_err(|_| PortError::Transmit)?;
        }
        let n = feetech::sync_write(COMMAND_BLOCK, COMMAND_LEN, &refs, &mut self.tx)
            .map(|p| p.len())
            .map_err(|_| PortError::Transmit)?;
        self.send(n).await
    }

    /// The present block of every servo in `ids` into `out` (same order):
    /// one SYNC READ; a servo that did not answer it is asked again alone
    /// (READ) while attempts remain.
    pub async fn read_present_ft(&mut self, ids: &[u8], order: ByteOrder, out: &mut [ServoRead]) {
        let n = ids.len().min(out.len()).min(MAX_SERVOS);
        let (ids, out) = (&ids[..n], &mut out[..n]);
        for r in out.iter_mut() {
            *r = ServoRead::default();
        }
        if n == 0 {
            return;
        }
        self.sync_read_ft(ids, order, out).await;
        let retries = self.config.attempts.max(1) - 1;
        for (&id, r) in ids.iter().zip(out.iter_mut()) {
            if r.state.is_some() || retries == 0 {
                continue;
            }
            let exchange = self.read_within(id, sts::PRESENT_BLOCK, sts::PRESENT_BLOCK_LEN, retries).await;
            r.timeouts = r.timeouts.saturating_add(exchange.timeouts);
            r.checksum_errors = r.checksum_errors.saturating_add(exchange.checksum_errors);
            if let Some(s) = exchange.status {
                r.error = flags_of_ft(s.error);
                r.state = present(&s.params, order);
            }
        }
    }

    /// One SYNC READ: the answers follow one another in the order of the
    /// IDs. Any ID is taken (a silent servo must not hide the next one's
    /// answer) and put in its place; each answer has the reply timeout from
    /// the one before. A damaged answer is counted against the first servo
    /// still silent, the one whose turn it was.
    async fn sync_read_ft(&mut self, ids: &[u8], order: ByteOrder, out: &mut [ServoRead]) {
        let sent = match feetech::sync_read(sts::PRESENT_BLOCK, sts::PRESENT_BLOCK_LEN, ids, &mut self.tx) {
            Ok(p) => {
                let n = p.len();
                self.port.discard_input();
                self.decoder.reset();
                self.decoder.expect(None);
                self.send(n).await.is_ok()
            }
            Err(_) => false,
        };
        let mut pending = if sent { ids.len() } else { 0 };
        while pending > 0 {
            let deadline = self.port.now_us() + self.config.reply_timeout_us as u64;
            let Some(got) = self.receive(deadline).await else { break };
            for result in self.decoder.feed(&self.rx[..got]) {
                let status = match result {
                    Ok(status) => status,
                    Err(e) => {
                        let mut damaged = 0u8;
                        if count_refusal(&mut self.stats, e, &mut damaged) {
                            if let Some(r) = out.iter_mut().find(|r| r.state.is_none()) {
                                r.checksum_errors = r.checksum_errors.saturating_add(damaged);
                            }
                        }
                        continue;
                    }
                };
                match ids.iter().position(|&id| id == status.id) {
                    Some(i) if out[i].state.is_none() && status.params.len() == sts::PRESENT_BLOCK_LEN as usize => {
                        out[i].error = flags_of_ft(status.error);
                        out[i].state = present(&status.params, order);
                        self.stats.replies = self.stats.replies.wrapping_add(1);
                        pending -= 1;
                    }
                    _ => self.stats.stray_packets = self.stats.stray_packets.wrapping_add(1),
                }
            }
        }
        for r in out.iter_mut().filter(|r| r.state.is_none()) {
            r.timeouts = r.timeouts.saturating_add(1);
            self.stats.timeouts = self.stats.timeouts.wrapping_add(1);
        }
    }

    /// Prepares servo `id` for the control loop: checks that it answers as
    /// `expected_model`, then writes (only where different) Response Status
    /// Level 0, the return delay and Operating Mode `mode` (EEPROM, behind
    /// Lock), and checks them. Torque must be off (the caller switches
    /// every servo off first).
    pub async fn setup_ft(&mut self, id: u8, expected_model: u16, mode: u8) -> Result<FtSetup, SetupError> {
        // Firmware Major, Minor, END (the byte order), Model Number.
        let identity = self.read(id, sts::FIRMWARE_MAJOR, IDENTITY_LEN).await;
        let Some(identity) = identity.status else {
            return Err(SetupError::NoAnswer { id });
        };
        if identity.error.intersects(status::HARDWARE) {
            return Err(SetupError::Error { id, error: flags_of_ft(identity.error) });
        }
        let at = |s: &super::Status, addr: u8, first: u8| s.u8_at((addr - first) as usize).unwrap_or(0xFF);
        let order = if at(&identity, sts::END, 0) == 0 { ByteOrder::Little } else { ByteOrder::Big };
        let model = order.u16_at(&identity.params, sts::MODEL_NUMBER as usize).unwrap_or(0);
        if model != expected_model {
            return Err(SetupError::WrongModel { id, found: model, expected: expected_model });
        }
        let firmware = at(&identity, sts::FIRMWARE_MAJOR, 0);
        // Return Delay Time (7), Response Status Level (8).
        let levels = self.read(id, sts::RETURN_DELAY_TIME, 2).await;
        let Some(levels) = levels.status else {
            return Err(SetupError::NoAnswer { id });
        };
        let modes = self.read(id, sts::OPERATING_MODE, MODE_BLOCK_LEN).await;
        let Some(modes) = modes.status else {
            return Err(SetupError::NoAnswer { id });
        };
        let mut wrote = false;
        // A servo at level 1 answers this WRITE: listen for it, so it does
        // not collide with the next request.
        let level = at(&levels, sts::RESPONSE_STATUS_LEVEL, sts::RETURN_DELAY_TIME);
        if level != RESPONSE_STATUS_LEVEL {
            self.write_maybe_reply(id, sts::RESPONSE_STATUS_LEVEL, &[RESPONSE_STATUS_LEVEL], level >= 1).await;
            wrote = true;
        }
        let delay = at(&levels, sts::RETURN_DELAY_TIME, sts::RETURN_DELAY_TIME);
        let was_mode = at(&modes, sts::OPERATING_MODE, sts::OPERATING_MODE);
        if delay != RETURN_DELAY || was_mode != mode {
            self.write_no_reply(id, sts::LOCK, &[LOCK_OPEN]).await.ok();
            self.write_no_reply(id, sts::RETURN_DELAY_TIME, &[RETURN_DELAY]).await.ok();
            self.write_no_reply(id, sts::OPERATING_MODE, &[mode]).await.ok();
            self.write_no_reply(id, sts::LOCK, &[LOCK_CLOSED]).await.ok();
            wrote = true;
            let check = self.read(id, sts::OPERATING_MODE, 1).await;
            if check.status.as_ref().and_then(|s| s.u8_at(0)) != Some(mode) {
                let error = check.status.map_or(ErrorFlags::INSTRUCTION, |s| s.error | ErrorFlags::INSTRUCTION);
                return Err(SetupError::Error { id, error });
            }
        }
        let acceleration = at(&modes, sts::ACCELERATION, sts::OPERATING_MODE);
        Ok(FtSetup { setup: ServoSetup { model, firmware, wrote }, order, acceleration })
    }
}

#[cfg(test)]
#[path = "ft_tests.rs"]
pub(crate) mod tests;
