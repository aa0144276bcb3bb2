//! Dynamixel Protocol 1.0 transactions (the RX and MX series as shipped):
//! READ, PING, WRITE, SYNC_WRITE of Moving Speed, and the set-up of a
//! servo for the control loop (wheel mode, return delay, status return
//! level). The packets come from `pada_core::dynamixel`.
//!
//! Worst case per period with the defaults (1 Mbps, 7 servos, 2 attempts of
//! at most 1 ms each): 14 ms of a 33 ms LEO period; a healthy read takes
//! about 0.25 ms per servo (8-byte READ, 14-byte status, 50 µs return
//! delay).

use super::{BusStats, Exchange, ServoBus, ServoSetup, SetupError, Status, RETURN_DELAY, STATUS_RETURN_LEVEL};
use crate::io::{BusPort, PortError};
use pada_core::dynamixel::{self, table, DecodeError, ErrorFlags, Reply, BROADCAST_ID};

impl<P: BusPort> ServoBus<P> {
    /// READ `len` bytes at `addr` of servo `id`, with up to
    /// [`BusConfig::attempts`] attempts.
    pub async fn read(&mut self, id: u8, addr: u8, len: u8) -> Exchange {
        self.read_within(id, addr, len, self.config.attempts.max(1)).await
    }

    /// READ with `attempts` attempts (a Feetech servo that a SYNC READ
    /// missed gets the attempts left).
    pub(super) async fn read_within(&mut self, id: u8, addr: u8, len: u8, attempts: u8) -> Exchange {
        let mut exchange = Exchange { status: None, timeouts: 0, checksum_errors: 0 };
        let Ok(n) = dynamixel::read_data(id, addr, len, &mut self.tx).map(|p| p.len()) else {
            // Only an invalid ID gets here; it can never answer.
            exchange.timeouts = 1;
            return exchange;
        };
        for _ in 0..attempts {
            match self.request(Reply { id, params: len }, n, &mut exchange.checksum_errors).await {
                Some(status) if status.params.len() == len as usize => {
                    exchange.status = Some(status);
                    return exchange;
                }
                // A short answer is as good as none.
                _ => exchange.timeouts = exchange.timeouts.saturating_add(1),
            }
        }
        exchange
    }

    /// PING servo `id`.
    pub async fn ping(&mut self, id: u8) -> Exchange {
        let mut exchange = Exchange { status: None, timeouts: 0, checksum_errors: 0 };
        let Ok(n) = dynamixel::ping(id, &mut self.tx).map(|p| p.len()) else {
            exchange.timeouts = 1;
            return exchange;
        };
        for _ in 0..self.config.attempts.max(1) {
            if let Some(status) = self.request(Reply { id, params: 0 }, n, &mut exchange.checksum_errors).await {
                exchange.status = Some(status);
                return exchange;
            }
            exchange.timeouts = exchange.timeouts.saturating_add(1);
        }
        exchange
    }

    /// Present Position, Speed, Load, Voltage and Temperature of `id` (one
    /// 8-byte READ from address 36).
    pub async fn read_present(&mut self, id: u8) -> (Option<table::PresentState>, Exchange) {
        let exchange = self.read(id, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN).await;
        let state = exchange.status.as_ref().and_then(|s| table::PresentState::from_bytes(&s.params));
        (state, exchange)
    }

    /// SYNC_WRITE of Moving Speed to several servos (no reply).
    pub async fn write_speeds(&mut self, entries: &[(u8, u16)]) -> Result<(), PortError> {
        let n = dynamixel::sync_write_u16(table::MOVING_SPEED, entries, &mut self.tx)
            .map(|p| p.len())
            .map_err(|_| PortError::Transmit)?;
        self.send(n).await
    }

    /// Torque Enable of every servo at once (broadcast WRITE, no reply).
    pub async fn torque_all(&mut self, on: bool) -> Result<(), PortError> {
        self.write_no_reply(BROADCAST_ID, table::TORQUE_ENABLE, &[on as u8]).await
    }

    /// Moving Speed 0 on every servo at once (broadcast WRITE, no reply).
    pub async fn stop_all(&mut self) -> Result<(), PortError> {
        self.write_no_reply(BROADCAST_ID, table::MOVING_SPEED, &[0, 0]).await
    }

    /// WRITE without waiting for an answer (broadcast, or a servo whose
    /// status return level is 1).
    pub async fn write_no_reply(&mut self, id: u8, addr: u8, data: &[u8]) -> Result<(), PortError> {
        let n = dynamixel::write_data(id, addr, data, &mut self.tx).map(|p| p.len()).map_err(|_| PortError::Transmit)?;
        self.send(n).await
    }

    /// Prepares servo `id` for the control loop: checks that it answers,
    /// then writes (only where different) wheel mode (both angle limits 0),
    /// the return delay and the status return level. Torque is left as it
    /// is (the caller switches it off for every servo first). Its model
    /// number is returned; [`super::robot::RobotBus`] compares it with the
    /// robot's definition.
    pub async fn setup(&mut self, id: u8) -> Result<ServoSetup, SetupError> {
        // Model number.
        let model = self.read(id, table::MODEL_NUMBER, 2).await;
        let Some(status) = model.status else {
            return Err(SetupError::NoAnswer { id });
        };
        if status.error.intersects(ErrorFlags::HARDWARE) {
            return Err(SetupError::Error { id, error: status.error });
        }
        let model = status.u16_at(0).unwrap_or(0);
        // Addresses 5..=16: return delay, CW and CCW limits, …, status
        // return level.
        let first = table::RETURN_DELAY_TIME;
        let len = table::STATUS_RETURN_LEVEL - first + 1;
        let block = self.read(id, first, len).await;
        let Some(block) = block.status else {
            return Err(SetupError::NoAnswer { id });
        };
        let at = |addr: u8| block.u8_at((addr - first) as usize).unwrap_or(0xFF);
        let at16 = |addr: u8| block.u16_at((addr - first) as usize).unwrap_or(0xFFFF);
        let mut wrote = false;
        // A servo at status return level 2 answers this WRITE: listen for
        // it, so it does not collide with the next request.
        let answers_writes = at(table::STATUS_RETURN_LEVEL) >= 2;
        if at(table::STATUS_RETURN_LEVEL) != STATUS_RETURN_LEVEL {
            self.write_maybe_reply(id, table::STATUS_RETURN_LEVEL, &[STATUS_RETURN_LEVEL], answers_writes).await;
            wrote = true;
        }
        if at(table::RETURN_DELAY_TIME) != RETURN_DELAY {
            self.write_no_reply(id, table::RETURN_DELAY_TIME, &[RETURN_DELAY]).await.ok();
            wrote = true;
        }
        if at16(table::CW_ANGLE_LIMIT) != 0 || at16(table::CCW_ANGLE_LIMIT) != 0 {
            self.write_no_reply(id, table::CW_ANGLE_LIMIT, &[0, 0, 0, 0]).await.ok();
            wrote = true;
        }
        Ok(ServoSetup { model, firmware: 0, wrote })
    }

    pub(super) async fn write_maybe_reply(&mut self, id: u8, addr: u8, data: &[u8], reply: bool) {
        if reply {
            let Ok(n) = dynamixel::write_data(id, addr, data, &mut self.tx).map(|p| p.len()) else {
                return;
            };
            let mut checksum_errors = 0;
            let _ = self.request(Reply { id, params: 0 }, n, &mut checksum_errors).await;
        } else {
            self.write_no_reply(id, addr, data).await.ok();
        }
    }

    /// One attempt: send the first `n` bytes of the transmit buffer, listen
    /// for the `reply` (the servo asked, with the parameter count the
    /// request implies) until the reply deadline. Anything else on the bus
    /// is discarded and counted as stray; the decoder resynchronises on the
    /// next header.
    async fn request(&mut self, reply: Reply, n: usize, checksum_errors: &mut u8) -> Option<Status> {
        self.port.discard_input();
        self.decoder.reset();
        self.decoder.expect(Some(reply));
        self.send(n).await.ok()?;
        let deadline = self.port.now_us() + self.config.reply_timeout_us as u64;
        loop {
            let Some(got) = self.receive(deadline).await else { break };
            let mut found = None;
            let mut corrupted = false;
            for result in self.decoder.feed(&self.rx[..got]) {
                match result {
                    Ok(status) => {
                        found = Some(status);
                        break;
                    }
                    Err(e) => corrupted |= count_refusal(&mut self.stats, e, checksum_errors),
                }
            }
            if found.is_some() {
                self.stats.replies = self.stats.replies.wrapping_add(1);
                return found;
            }
            if corrupted {
                // The answer came and was damaged: no point waiting for the
                // deadline, the next attempt asks again.
                return None;
            }
        }
        self.stats.timeouts = self.stats.timeouts.wrapping_add(1);
        None
    }
}

/// Counts a status packet the decoder refused: a bad checksum (a damaged
/// answer, also in `checksum_errors`; returns true) or a stray packet
/// (another ID, an impossible length, a broadcast status).
pub(super) fn count_refusal(stats: &mut BusStats, e: DecodeError, checksum_errors: &mut u8) -> bool {
    match e {
        DecodeError::BadChecksum { .. } => {
            stats.checksum_errors = stats.checksum_errors.wrapping_add(1);
            *checksum_errors = checksum_errors.saturating_add(1);
            true
        }
        DecodeError::UnexpectedId { .. } | DecodeError::BadLength { .. } | DecodeError::BroadcastStatus => {
            stats.stray_packets = stats.stray_packets.wrapping_add(1);
            false
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::bus::BusConfig;
    use embassy_futures::block_on;
    use pada_core::dynamixel::{Instruction, InstructionDecoder};
    use std::collections::VecDeque;

    /// A fake bus: decodes what the firmware sends and answers as scripted
    /// servos with a control table each; time advances only by waiting.
    pub struct FakeBus {
        pub tables: Vec<(u8, [u8; table::TABLE_LEN])>,
        pub inbox: VecDeque<u8>,
        pub sent: Vec<Vec<u8>>,
        pub now: u64,
        /// Answers to drop (counted down), to corrupt, and a stray prefix.
        pub drop_next: u32,
        pub corrupt_next: u32,
        /// Bytes put on the bus before the next answer (noise, other
        /// servos' packets).
        pub stray: Vec<u8>,
        pub decoder: InstructionDecoder<64>,
    }

    impl FakeBus {
        pub fn with_servos(ids: &[u8]) -> Self {
            let tables = ids
                .iter()
                .map(|&id| {
                    let mut t = [0u8; table::TABLE_LEN];
                    t[0] = 28; // model 28
                    t[table::ID as usize] = id;
                    t[table::RETURN_DELAY_TIME as usize] = 250;
                    t[table::CCW_ANGLE_LIMIT as usize] = 0xFF;
                    t[table::CCW_ANGLE_LIMIT as usize + 1] = 0x03;
                    t[table::STATUS_RETURN_LEVEL as usize] = 2;
                    t[table::PRESENT_POSITION as usize] = 0x00;
                    t[table::PRESENT_POSITION as usize + 1] = 0x02;
                    t[table::PRESENT_VOLTAGE as usize] = 120;
                    t[table::PRESENT_TEMPERATURE as usize] = 40;
                    (id, t)
                })
                .collect();
            FakeBus {
                tables,
                inbox: VecDeque::new(),
                sent: Vec::new(),
                now: 0,
                drop_next: 0,
                corrupt_next: 0,
                stray: Vec::new(),
                decoder: InstructionDecoder::new(),
            }
        }

        pub fn table(&self, id: u8) -> &[u8; table::TABLE_LEN] {
            &self.tables.iter().find(|(i, _)| *i == id).unwrap().1
        }

        fn answer(&mut self, id: u8, params: &[u8]) {
            if self.drop_next > 0 {
                self.drop_next -= 1;
                return;
            }
            let mut buf = [0u8; 64];
            let bytes = Status::new(id, ErrorFlags::NONE, params).unwrap().encode(&mut buf).unwrap().to_vec();
            let mut bytes = bytes;
            if self.corrupt_next > 0 {
                self.corrupt_next -= 1;
                let last = bytes.len() - 1;
                bytes[last] ^= 0x55;
            }
            self.inbox.extend(self.stray.drain(..));
            self.inbox.extend(bytes);
        }
    }

    impl BusPort for FakeBus {
        fn discard_input(&mut self) {
            self.inbox.clear();
        }

        async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
            self.sent.push(bytes.to_vec());
            self.now += bytes.len() as u64 * 10; // 10 µs per byte at 1 Mbps
            let packets: Vec<_> = self.decoder.feed(bytes).collect();
            for p in packets {
                let p = p.expect("the firmware sends valid packets");
                let id = p.id;
                let srl = self.tables.iter().find(|(i, _)| *i == id).map(|(_, t)| t[16]);
                match p.instruction().unwrap() {
                    Instruction::Ping if srl.is_some() => self.answer(id, &[]),
                    Instruction::Read { addr, len } => {
                        if let Some((_, t)) = self.tables.iter().find(|(i, _)| *i == id) {
                            let data = t[addr as usize..(addr + len) as usize].to_vec();
                            self.answer(id, &data);
                        }
                    }
                    Instruction::Write { addr, data } => {
                        for (i, t) in self.tables.iter_mut() {
                            if *i == id || id == BROADCAST_ID {
                                t[addr as usize..addr as usize + data.len()].copy_from_slice(data);
                            }
                        }
                        if id != BROADCAST_ID && srl >= Some(2) {
                            self.answer(id, &[]);
                        }
                    }
                    Instruction::SyncWrite { addr, .. } => {
                        let entries: Vec<(u8, Vec<u8>)> =
                            p.instruction().unwrap().sync_entries().map(|(i, d)| (i, d.to_vec())).collect();
                        for (sid, d) in entries {
                            if let Some((_, t)) = self.tables.iter_mut().find(|(i, _)| *i == sid) {
                                t[addr as usize..addr as usize + d.len()].copy_from_slice(&d);
                            }
                        }
                    }
                    _ => {}
                }
            }
            Ok(())
        }

        async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
            Ok(crate::bus::fake_receive(&mut self.inbox, &mut self.now, buf, deadline_us, 5))
        }

        fn now_us(&self) -> u64 {
            self.now
        }
    }

    #[test]
    fn reads_present_state() {
        let mut bus = ServoBus::new(FakeBus::with_servos(&[1, 2]), BusConfig::default());
        let (state, ex) = block_on(bus.read_present(2));
        let state = state.unwrap();
        assert_eq!(state.position, 512);
        assert_eq!(state.voltage, 120);
        assert_eq!(state.temperature, 40);
        assert_eq!((ex.timeouts, ex.checksum_errors), (0, 0));
        assert_eq!(bus.stats().replies, 1);
    }

    #[test]
    fn a_missing_servo_times_out_within_the_attempt_budget() {
        let mut bus = ServoBus::new(FakeBus::with_servos(&[1]), BusConfig { reply_timeout_us: 1000, attempts: 3, ..BusConfig::default() });
        let before = bus.port_mut().now;
        let (state, ex) = block_on(bus.read_present(9));
        assert!(state.is_none());
        assert_eq!(ex.timeouts, 3);
        // Bounded: three attempts of one timeout each, plus the bytes sent.
        let spent = bus.port_mut().now - before;
        assert!((3000..3000 + 3 * 8 * 10 + 1).contains(&spent), "{spent}");
        assert_eq!(bus.stats().timeouts, 3);
    }

    #[test]
    fn retries_after_a_lost_or_corrupted_answer() {
        let mut bus = ServoBus::new(FakeBus::with_servos(&[1]), BusConfig::default());
        bus.port_mut().drop_next = 1;
        let (state, ex) = block_on(bus.read_present(1));
        assert!(state.is_some());
        assert_eq!(ex.timeouts, 1);

        bus.port_mut().corrupt_next = 1;
        let before = bus.port_mut().now;
        let (state, ex) = block_on(bus.read_present(1));
        // A damaged answer is retried at once, without waiting for the deadline.
        assert!(bus.port_mut().now - before < 1000, "{}", bus.port_mut().now - before);
        assert!(state.is_some());
        assert_eq!((ex.timeouts, ex.checksum_errors), (1, 1));
        assert_eq!(bus.stats().checksum_errors, 1);

        bus.port_mut().corrupt_next = 5;
        let (state, ex) = block_on(bus.read_present(1));
        assert!(state.is_none());
        assert_eq!((ex.timeouts, ex.checksum_errors), (2, 2));
    }

    #[test]
    fn stray_packets_before_the_reply_are_discarded_and_counted() {
        // Regression: a valid packet from another servo, one from
        // the asked servo with the wrong length, and a spurious header with
        // a large LENGTH come before the real reply.
        let mut bus = ServoBus::new(FakeBus::with_servos(&[1]), BusConfig::default());
        let mut buf = [0u8; 64];
        let mut stray = Status::new(2, ErrorFlags::NONE, &[0; 8]).unwrap().encode(&mut buf).unwrap().to_vec();
        stray.extend_from_slice(Status::new(1, ErrorFlags::NONE, &[0; 3]).unwrap().encode(&mut buf).unwrap());
        stray.extend_from_slice(&[0xFF, 0xFF, 1, 28]);
        bus.port_mut().stray = stray;
        let (state, ex) = block_on(bus.read_present(1));
        assert_eq!(state.map(|s| s.position), Some(512));
        assert_eq!((ex.timeouts, ex.checksum_errors), (0, 0));
        assert_eq!(bus.stats().stray_packets, 3);
        assert_eq!(bus.stats().replies, 1);
    }

    #[test]
    fn setup_writes_wheel_mode_once() {
        let mut bus = ServoBus::new(FakeBus::with_servos(&[3]), BusConfig::default());
        let s = block_on(bus.setup(3)).unwrap();
        assert_eq!(s, ServoSetup { model: 28, firmware: 0, wrote: true });
        let t = *bus.port_mut().table(3);
        assert_eq!(&t[6..10], &[0, 0, 0, 0]);
        assert_eq!(t[table::STATUS_RETURN_LEVEL as usize], STATUS_RETURN_LEVEL);
        assert_eq!(t[table::RETURN_DELAY_TIME as usize], RETURN_DELAY);
        // Second time: nothing to write.
        let s = block_on(bus.setup(3)).unwrap();
        assert!(!s.wrote);
        assert_eq!(block_on(bus.setup(4)), Err(SetupError::NoAnswer { id: 4 }));
    }

    #[test]
    fn speeds_and_torque_reach_every_servo() {
        let mut bus = ServoBus::new(FakeBus::with_servos(&[1, 2]), BusConfig::default());
        block_on(bus.write_speeds(&[(1, 0x123), (2, 0x456)])).unwrap();
        block_on(bus.torque_all(true)).unwrap();
        let t1 = *bus.port_mut().table(1);
        let t2 = *bus.port_mut().table(2);
        assert_eq!(u16::from_le_bytes([t1[32], t1[33]]), 0x123);
        assert_eq!(u16::from_le_bytes([t2[32], t2[33]]), 0x456);
        assert_eq!((t1[24], t2[24]), (1, 1));
        block_on(bus.stop_all()).unwrap();
        assert_eq!(bus.port_mut().table(2)[32], 0);
    }
}
