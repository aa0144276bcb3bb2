//! Dynamixel Protocol 2.0 transactions (every X-series servo): PING, READ,
//! WRITE, SYNC WRITE of Goal PWM, the (fast) sync read of every servo's
//! present block, the Hardware Error Status after an alert, the Bus
//! Watchdog, and the set-up of a servo for the control loop (PWM Control
//! Mode, return delay, status return level). The packets come from
//! `pada_core::dynamixel::v2`; the addresses from
//! `pada_core::dynamixel::control_table::x_series` (docs/reference/
//! dynamixel.md).
//!
//! A period reads every servo with one FAST SYNC READ of Present PWM …
//! Present Temperature (addresses 124–146), whose one combined reply
//! carries each servo's block with its own ERROR and CRC, where every
//! servo's firmware has it (X430 from firmware 45, XL330 from 46); else
//! with one SYNC READ, whose replies follow one another. A servo missing
//! from it is asked again alone, so a timeout names the servo that is
//! silent. It writes every servo's Goal PWM with one SYNC WRITE.

use super::{ServoBus, ServoSetup, SetupError, Status2, RETURN_DELAY, STATUS_RETURN_LEVEL};
use crate::io::{BusPort, PortError};
use heapless::Vec;
use pada_core::dynamixel::control_table::x_series::{self, mode, HardwareError, PresentState};
use pada_core::dynamixel::v2::{encoders, fast, DecodeError, ErrorNumber, PingReply, Reply, StatusError, BROADCAST_ID};
use pada_core::dynamixel::ErrorFlags;
use pada_core::limits::MAX_SERVOS;

/// Bytes of the present block one period reads from each servo.
pub const PRESENT_LEN: u16 = x_series::PRESENT_BLOCK_LEN;

/// Bytes on the wire of a status packet with `params` parameter bytes
/// (unstuffed): header 4, ID, LENGTH 2, 0x55, ERROR, CRC 2.
pub const fn status_len(params: usize) -> usize {
    11 + params
}

/// Bytes on the wire of the fast sync read's reply of `servos` present
/// blocks (`status_len` of its parameters).
pub const fn fast_reply_len(servos: usize) -> usize {
    match fast::fast_sync_reply_params(servos, PRESENT_LEN) {
        Some(p) => status_len(p as usize),
        None => 0,
    }
}

// The receive decoder holds the fast reply of every servo a robot may have.
const _: () = assert!(fast_reply_len(MAX_SERVOS) <= super::STATUS2_LEN);

/// Protocol 1.0's error bits for a Protocol 2.0 ERROR byte's Error Number,
/// so that one safety machine counts both: a CRC error (the servo received
/// a damaged instruction) as CHECKSUM, the data errors as RANGE, the
/// others as INSTRUCTION. The Alert bit is not among them: it is a fault
/// of its own ([`pada_core::safety::Event::HardwareAlert`]).
pub fn flags_of(error: StatusError) -> ErrorFlags {
    match error.number() {
        None => ErrorFlags::NONE,
        Some(ErrorNumber::Crc) => ErrorFlags::CHECKSUM,
        Some(ErrorNumber::DataRange | ErrorNumber::DataLength | ErrorNumber::DataLimit) => ErrorFlags::RANGE,
        Some(ErrorNumber::ResultFail | ErrorNumber::Instruction | ErrorNumber::Access) => ErrorFlags::INSTRUCTION,
    }
}

/// The Bus Watchdog value (20 ms units) for a control period of
/// `period_us`: the smallest multiple of 20 ms that is at least the period
/// plus 10 ms. A servo hears an instruction at least once a period (the
/// sync read at its start, the sync write at its end), so it stops only
/// when the controller is silent for that long: a hung board, a pulled
/// adapter, a PC stalled by more than 10 ms.
pub const fn watchdog_units(period_us: u32) -> u8 {
    let units = (period_us as u64 + 10_000).div_ceil(20_000);
    if units < 1 {
        1
    } else if units > 127 {
        127
    } else {
        units as u8
    }
}

/// The firmware from which a model answers FAST SYNC READ (e-Manual,
/// Protocol 2.0, "Fast Sync Read": X430/X540 from 45, X330 from 46).
pub const fn fast_read_firmware(model_number: u16) -> u8 {
    match model_number {
        1200 => 46,
        _ => 45,
    }
}

/// One servo's part of a sync read of the present block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Read2 {
    /// Its present block, if it answered.
    pub state: Option<PresentState>,
    /// The ERROR byte of its answer.
    pub error: StatusError,
    /// Attempts without its answer.
    pub timeouts: u8,
    /// Damaged answers (bad CRC, a block that does not check).
    pub checksum_errors: u8,
}

/// What one Protocol 2.0 request to one servo came to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exchange2 {
    /// The servo's answer, if one came.
    pub status: Option<Status2>,
    /// Attempts that ended without an answer.
    pub timeouts: u8,
    /// Damaged answers seen.
    pub checksum_errors: u8,
}

impl<P: BusPort> ServoBus<P> {
    /// Listens for one status packet (`reply`, or any with `None`) until
    /// the deadline: the reply timeout plus `expect_bytes` on the wire.
    async fn listen2(&mut self, reply: Option<Reply>, expect_bytes: usize, checksum_errors: &mut u8) -> Option<Status2> {
        self.decoder2.expect(reply);
        let wire = (expect_bytes as u64).saturating_mul(self.config.byte_us as u64);
        let deadline = self.port.now_us() + self.config.reply_timeout_us as u64 + wire;
        loop {
            let Some(got) = self.receive(deadline).await else { break };
            let mut corrupted = false;
            for i in 0..got {
                let mut next = self.decoder2.push(self.rx[i]);
                while let Some(result) = next {
                    match result {
                        Ok(status) => {
                            self.stats.replies = self.stats.replies.wrapping_add(1);
                            return Some(status);
                        }
                        Err(DecodeError::BadCrc { .. } | DecodeError::BadStuffing { .. }) => {
                            self.stats.checksum_errors = self.stats.checksum_errors.wrapping_add(1);
                            *checksum_errors = checksum_errors.saturating_add(1);
                            corrupted = true;
                        }
                        Err(_) => self.stats.stray_packets = self.stats.stray_packets.wrapping_add(1),
                    }
                    next = self.decoder2.poll();
                }
            }
            if corrupted {
                // The answer came and was damaged: the next attempt asks
                // again at once.
                return None;
            }
        }
        self.stats.timeouts = self.stats.timeouts.wrapping_add(1);
        None
    }

    /// One attempt: send the first `n` bytes of the transmit buffer, listen
    /// for `reply` of `params` parameter bytes.
    async fn request2(&mut self, reply: Reply, n: usize, checksum_errors: &mut u8) -> Option<Status2> {
        self.port.discard_input();
        self.decoder2.reset();
        self.send(n).await.ok()?;
        self.listen2(Some(reply), status_len(reply.params as usize), checksum_errors).await
    }

    /// A request of `n` bytes in the transmit buffer answered by `reply`,
    /// with up to [`super::BusConfig::attempts`] attempts.
    async fn exchange2(&mut self, reply: Reply, n: usize) -> Exchange2 {
        self.exchange2_within(reply, n, self.config.attempts.max(1)).await
    }

    /// The same with `attempts` attempts.
    async fn exchange2_within(&mut self, reply: Reply, n: usize, attempts: u8) -> Exchange2 {
        let mut exchange = Exchange2 { status: None, timeouts: 0, checksum_errors: 0 };
        for _ in 0..attempts {
            match self.request2(reply, n, &mut exchange.checksum_errors).await {
                Some(status) if status.params.len() == reply.params as usize => {
                    exchange.status = Some(status);
                    return exchange;
                }
                // A short answer (or one with an error and no data) is as
                // good as none for a read; a PING or write reply has none.
                Some(status) if status.params.is_empty() && !status.error.succeeded() => {
                    exchange.status = Some(status);
                    return exchange;
                }
                _ => exchange.timeouts = exchange.timeouts.saturating_add(1),
            }
        }
        exchange
    }

    /// PING servo `id`: its model number and firmware.
    pub async fn ping2(&mut self, id: u8) -> Exchange2 {
        let Ok(n) = encoders::ping(id, &mut self.tx).map(|p| p.len()) else {
            return Exchange2 { status: None, timeouts: 1, checksum_errors: 0 };
        };
        self.exchange2(Reply::status(id, PingReply::PARAMS as u16), n).await
    }

    /// READ `len` bytes at `addr` of servo `id`.
    pub async fn read2(&mut self, id: u8, addr: u16, len: u16) -> Exchange2 {
        let Ok(n) = encoders::read(id, addr, len, &mut self.tx).map(|p| p.len()) else {
            return Exchange2 { status: None, timeouts: 1, checksum_errors: 0 };
        };
        self.exchange2(Reply::status(id, len), n).await
    }

    /// WRITE `data` at `addr` of servo `id` (or every servo, to the
    /// broadcast ID); waits for the status packet only if `reply` (a servo
    /// at status return level 2 during set-up), so it does not collide with
    /// the next request.
    pub async fn write2(&mut self, id: u8, addr: u16, data: &[u8], reply: bool) -> Result<(), PortError> {
        let n = encoders::write(id, addr, data, &mut self.tx).map(|p| p.len()).map_err(|_| PortError::Transmit)?;
        if reply && id != BROADCAST_ID {
            let mut checksum_errors = 0;
            self.port.discard_input();
            self.decoder2.reset();
            self.send(n).await?;
            let _ = self.listen2(Some(Reply::status(id, 0)), status_len(0), &mut checksum_errors).await;
            Ok(())
        } else {
            self.send(n).await
        }
    }

    /// Torque Enable of every servo at once (broadcast WRITE, no reply).
    pub async fn torque_all2(&mut self, on: bool) -> Result<(), PortError> {
        self.write2(BROADCAST_ID, x_series::TORQUE_ENABLE, &[on as u8], false).await
    }

    /// Goal PWM 0 on every servo at once (broadcast WRITE, no reply).
    pub async fn stop_all2(&mut self) -> Result<(), PortError> {
        self.write2(BROADCAST_ID, x_series::GOAL_PWM, &0i16.to_le_bytes(), false).await
    }

    /// Clears a tripped Bus Watchdog (a servo that tripped takes no goal
    /// until then) and arms it at `units` × 20 ms, on every servo at once.
    pub async fn arm_watchdog2(&mut self, units: u8) -> Result<(), PortError> {
        self.write2(BROADCAST_ID, x_series::BUS_WATCHDOG, &[0], false).await?;
        self.write2(BROADCAST_ID, x_series::BUS_WATCHDOG, &[units], false).await
    }

    /// SYNC WRITE of Goal PWM to several servos (no reply).
    pub async fn sync_write_pwm(&mut self, entries: &[(u8, i16)]) -> Result<(), PortError> {
        let mut values: Vec<(u8, [u8; 2]), MAX_SERVOS> = Vec::new();
        for &(id, pwm) in entries {
            values.push((id, pwm.to_le_bytes())).map_err(|_| PortError::Transmit)?;
        }
        let n = encoders::sync_write_values(x_series::GOAL_PWM, &values, &mut self.tx)
            .map(|p| p.len())
            .map_err(|_| PortError::Transmit)?;
        self.send(n).await
    }

    /// REBOOT servo `id`: the one way, short of its power, out of a
    /// hardware-error shutdown. Its RAM comes back at its initial values
    /// (Torque Enable off, the Bus Watchdog disarmed), its EEPROM as it
    /// was. No status is awaited: at pada's Status Return Level (1) a
    /// servo sends none for it.
    pub async fn reboot2(&mut self, id: u8) -> Result<(), PortError> {
        let n = encoders::reboot(id, &mut self.tx).map(|p| p.len()).map_err(|_| PortError::Transmit)?;
        self.send(n).await
    }

    /// Hardware Error Status of servo `id` (after an alert); `None` if it
    /// did not answer.
    pub async fn hardware_error(&mut self, id: u8) -> Option<HardwareError> {
        let exchange = self.read2(id, x_series::HARDWARE_ERROR_STATUS, 1).await;
        exchange.status.and_then(|s| s.u8_at(0)).map(HardwareError)
    }

    /// The present block of every servo in `ids` (at most [`MAX_SERVOS`]),
    /// into `out` (same order): one FAST SYNC READ if `fast`, else one SYNC
    /// READ; a servo that did not answer it is asked again alone (READ),
    /// while attempts remain.
    pub async fn read_present2(&mut self, ids: &[u8], fast: bool, out: &mut [Read2]) {
        let n = ids.len().min(out.len()).min(MAX_SERVOS);
        for r in out.iter_mut().take(n) {
            *r = Read2::default();
        }
        if n == 0 {
            return;
        }
        let ids = &ids[..n];
        if fast {
            self.fast_sync_read(ids, out).await;
        } else {
            self.sync_read(ids, out).await;
        }
        // The attempts left, servo by servo.
        let retries = self.config.attempts.max(1) - 1;
        if retries == 0 {
            return;
        }
        for (i, &id) in ids.iter().enumerate() {
            if out[i].state.is_some() {
                continue;
            }
            let Ok(len) = encoders::read(id, x_series::PRESENT_BLOCK, PRESENT_LEN, &mut self.tx).map(|p| p.len()) else {
                continue;
            };
            let exchange = self.exchange2_within(Reply::status(id, PRESENT_LEN), len, retries).await;
            let r = &mut out[i];
            r.checksum_errors = r.checksum_errors.saturating_add(exchange.checksum_errors);
            r.timeouts = r.timeouts.saturating_add(exchange.timeouts);
            if let Some(s) = exchange.status {
                r.error = s.error;
                r.state = PresentState::from_bytes(&s.params);
            }
        }
    }

    async fn fast_sync_read(&mut self, ids: &[u8], out: &mut [Read2]) {
        let miss = |out: &mut [Read2], checksum: bool| {
            for r in out.iter_mut().take(ids.len()) {
                r.timeouts = r.timeouts.saturating_add(1);
                r.checksum_errors = r.checksum_errors.saturating_add(checksum as u8);
            }
        };
        let (Ok(n), Some(params)) = (
            encoders::fast_sync_read(x_series::PRESENT_BLOCK, PRESENT_LEN, ids, &mut self.tx).map(|p| p.len()),
            fast::fast_sync_reply_params(ids.len(), PRESENT_LEN),
        ) else {
            return miss(out, false);
        };
        let mut checksum_errors = 0;
        let Some(status) = self.request2(Reply::status(BROADCAST_ID, params), n, &mut checksum_errors).await else {
            return miss(out, checksum_errors > 0);
        };
        let mut seen = 0;
        for (i, block) in status.fast_blocks(fast::BlockLens::Uniform(PRESENT_LEN)).enumerate() {
            match (block, ids.get(i)) {
                (Ok(b), Some(&id)) if b.id == id => {
                    out[i].error = b.error;
                    out[i].state = PresentState::from_bytes(b.data);
                    seen += 1;
                }
                (Err(fast::FastReplyError::BlockCrc { .. }), _) => {
                    self.stats.checksum_errors = self.stats.checksum_errors.wrapping_add(1);
                    break;
                }
                _ => {
                    self.stats.stray_packets = self.stats.stray_packets.wrapping_add(1);
                    break;
                }
            }
        }
        for r in out.iter_mut().take(ids.len()).skip(seen) {
            r.timeouts = r.timeouts.saturating_add(1);
        }
    }

    async fn sync_read(&mut self, ids: &[u8], out: &mut [Read2]) {
        let Ok(n) = encoders::sync_read(x_series::PRESENT_BLOCK, PRESENT_LEN, ids, &mut self.tx).map(|p| p.len()) else {
            for r in out.iter_mut().take(ids.len()) {
                r.timeouts = r.timeouts.saturating_add(1);
            }
            return;
        };
        self.port.discard_input();
        self.decoder2.reset();
        if self.send(n).await.is_err() {
            for r in out.iter_mut().take(ids.len()) {
                r.timeouts = r.timeouts.saturating_add(1);
            }
            return;
        }
        // The replies follow one another in the order of the IDs; any ID is
        // taken (a silent servo must not hide the next one's reply) and put
        // in its place.
        let mut pending = ids.len();
        while pending > 0 {
            let mut checksum_errors = 0;
            let Some(status) = self.listen2(None, pending * status_len(PRESENT_LEN as usize), &mut checksum_errors).await else {
                if checksum_errors == 0 {
                    break;
                }
                continue;
            };
            match ids.iter().position(|&id| id == status.id) {
                Some(i) if out[i].state.is_none() && status.params.len() == PRESENT_LEN as usize => {
                    out[i].error = status.error;
                    out[i].state = PresentState::from_bytes(&status.params);
                    pending -= 1;
                }
                _ => self.stats.stray_packets = self.stats.stray_packets.wrapping_add(1),
            }
        }
        for r in out.iter_mut().take(ids.len()) {
            if r.state.is_none() {
                r.timeouts = r.timeouts.saturating_add(1);
            }
        }
    }

    /// Prepares servo `id` for the control loop: checks that it answers as
    /// `expected_model`, then writes (only where different) PWM Control
    /// Mode (Operating Mode 16), Drive Mode 0 (the definition's sign is
    /// for the normal direction, and bit 3 would let a Goal PWM switch
    /// torque back on), the return delay and the status return level, and
    /// arms the Bus Watchdog at `watchdog` × 20 ms. Torque must be off
    /// (EEPROM is locked while it is on; the caller switches every servo
    /// off first).
    pub async fn setup2(&mut self, id: u8, expected_model: u16, watchdog: u8) -> Result<ServoSetup, SetupError> {
        let ping = self.ping2(id).await;
        let Some(status) = ping.status else {
            return Err(SetupError::NoAnswer { id });
        };
        let Some(reply) = PingReply::from_params(&status.params) else {
            return Err(SetupError::Error { id, error: flags_of(status.error) });
        };
        if reply.model_number != expected_model {
            return Err(SetupError::WrongModel { id, found: reply.model_number, expected: expected_model });
        }
        if status.error.alert() {
            let error = self.hardware_error(id).await.unwrap_or_default();
            return Err(SetupError::Alert { id, error });
        }
        // Return Delay Time (9), Drive Mode (10), Operating Mode (11).
        let eeprom = self.read2(id, x_series::RETURN_DELAY_TIME, 3).await;
        let Some(eeprom) = eeprom.status else {
            return Err(SetupError::NoAnswer { id });
        };
        let level = self.read2(id, x_series::STATUS_RETURN_LEVEL, 1).await;
        let Some(level) = level.status.and_then(|s| s.u8_at(0)) else {
            return Err(SetupError::NoAnswer { id });
        };
        let at = |i: usize| eeprom.u8_at(i).unwrap_or(0xFF);
        let mut wrote = false;
        if level != STATUS_RETURN_LEVEL {
            // A servo at level 2 answers this WRITE: listen for it.
            self.write2(id, x_series::STATUS_RETURN_LEVEL, &[STATUS_RETURN_LEVEL], level >= 2).await.ok();
        }
        let wanted = [RETURN_DELAY, 0, mode::PWM];
        if [at(0), at(1), at(2)] != wanted {
            self.write2(id, x_series::RETURN_DELAY_TIME, &wanted, false).await.ok();
            wrote = true;
            let check = self.read2(id, x_series::RETURN_DELAY_TIME, 3).await;
            let got = check.status.as_ref().map(|s| [s.u8_at(0), s.u8_at(1), s.u8_at(2)]);
            if got != Some(wanted.map(Some)) {
                // EEPROM locked (torque on) or the write refused.
                let error = check.status.map_or(ErrorFlags::INSTRUCTION, |s| flags_of(s.error) | ErrorFlags::INSTRUCTION);
                return Err(SetupError::Error { id, error });
            }
        }
        self.write2(id, x_series::BUS_WATCHDOG, &[0], false).await.ok();
        self.write2(id, x_series::BUS_WATCHDOG, &[watchdog], false).await.ok();
        Ok(ServoSetup { model: reply.model_number, firmware: reply.firmware, wrote })
    }
}
