//! The bus time of one control period: the bytes each transaction of
//! [`super::RobotBus`]'s steady period (torque on) puts on the wire, counted
//! by encoding the very packets it sends, and their time at a baud rate.
//!
//! ```text
//! time = 10 bits × (bytes out + bytes in) / baud  +  status packets × return delay
//! ```
//!
//! (8N1: ten bits a byte; each status packet waits the servo's Return
//! Delay Time, 50 µs as pada sets it, except those of a fast sync read
//! after the first, which follow the previous servo's block at once. The
//! USB adapter's latency on a PC comes on top: `pada drive` reports it.)
//!
//! | transaction | Protocol 1.0 (per servo) | Protocol 2.0 (n servos) | Feetech (n servos) |
//! |---|---|---|---|
//! | read | READ 8 B → status 14 B, per servo | FAST SYNC READ 14 + n B → one reply 11 + 27 n − 3 B | SYNC READ 8 + n B → n status packets of 14 B |
//! | torque | WRITE (broadcast) 8 B | WRITE (broadcast) 13 B | in the command's SYNC WRITE |
//! | command | SYNC_WRITE 8 + 3 n B | SYNC WRITE 14 + 3 n B | SYNC WRITE 8 + 7 n B (Torque Enable … Goal Time) |
//! | sensor device | READ 8 B → 9 B | READ 14 B → 14 B | READ 8 B → 9 B |

use super::v2::{fast_reply_len, status_len, PRESENT_LEN};
use pada_core::dynamixel::control_table::x_series;
use pada_core::dynamixel::{self, table, v2::encoders, BROADCAST_ID};
use pada_core::feetech::{self, command, control_table::sts3215 as sts};
use pada_core::robot::RobotSpec;
use pada_core::servo::ServoProtocol;

/// The length of an encoded packet (0 if it did not encode).
fn len<E>(r: Result<&[u8], E>) -> usize {
    r.map_or(0, <[u8]>::len)
}

/// What one steady period puts on the bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PeriodTraffic {
    /// Instruction packets sent.
    pub packets_out: u32,
    /// Their bytes.
    pub bytes_out: u32,
    /// Status packets received (each after a return delay).
    pub packets_in: u32,
    /// Their bytes.
    pub bytes_in: u32,
}

impl PeriodTraffic {
    /// The traffic of `robot`'s period on its own bus; with the sensor
    /// device's READ if `sensor` (an emulated board, a PC).
    pub fn of(robot: &RobotSpec, sensor: bool) -> PeriodTraffic {
        let mut t = PeriodTraffic::default();
        let mut buf = [0u8; 256];
        let out = |t: &mut PeriodTraffic, n: usize| {
            t.packets_out += 1;
            t.bytes_out += n as u32;
        };
        let count = |p: ServoProtocol| robot.joints.iter().filter(|j| j.servo.protocol == p).count();
        let (v1, v2, ft) = (count(ServoProtocol::V1), count(ServoProtocol::V2), count(ServoProtocol::Feetech));
        if v1 > 0 {
            let read = len(dynamixel::read_data(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN, &mut buf));
            for _ in 0..v1 {
                out(&mut t, read);
                t.packets_in += 1;
                t.bytes_in += (dynamixel::OVERHEAD + table::PRESENT_BLOCK_LEN as usize) as u32;
            }
            let speeds = [(1u8, 0u16); 8];
            out(&mut t, len(dynamixel::sync_write_u16(table::MOVING_SPEED, &speeds[..v1.min(8)], &mut buf)));
            out(&mut t, len(dynamixel::write_data(BROADCAST_ID, table::TORQUE_ENABLE, &[1], &mut buf)));
        }
        if v2 > 0 {
            let ids = [1u8, 2, 3, 4, 5, 6, 7, 8];
            let ids = &ids[..v2.min(8)];
            out(&mut t, len(encoders::fast_sync_read(x_series::PRESENT_BLOCK, PRESENT_LEN, ids, &mut buf)));
            t.packets_in += 1;
            t.bytes_in += fast_reply_len(ids.len()) as u32;
            out(&mut t, len(encoders::write(BROADCAST_ID, x_series::TORQUE_ENABLE, &[1], &mut buf)));
            let pwms: [(u8, [u8; 2]); 8] = core::array::from_fn(|i| (i as u8 + 1, [0, 0]));
            out(&mut t, len(encoders::sync_write_values(x_series::GOAL_PWM, &pwms[..ids.len()], &mut buf)));
        }
        if ft > 0 {
            t.add_feetech(ft);
        }
        if sensor {
            let first = robot.joints.first().map_or(ServoProtocol::V1, |j| j.servo.protocol);
            let (request, reply) = match first {
                // A Feetech READ is Protocol 1.0's packet to the byte.
                ServoProtocol::V1 | ServoProtocol::Feetech => (len(dynamixel::read_data(100, 36, 3, &mut buf)), dynamixel::OVERHEAD + 3),
                ServoProtocol::V2 => (len(encoders::read(100, 36, 3, &mut buf)), status_len(3)),
            };
            out(&mut t, request);
            t.packets_in += 1;
            t.bytes_in += reply as u32;
        }
        t
    }

    /// The traffic of `n` Feetech servos' period (at most 8 counted): one
    /// SYNC READ of the present block and its `n` status packets, one SYNC
    /// WRITE of torque and command.
    pub fn feetech(n: usize) -> PeriodTraffic {
        let mut t = PeriodTraffic::default();
        t.add_feetech(n);
        t
    }

    fn add_feetech(&mut self, n: usize) {
        let mut buf = [0u8; 256];
        let ids = [1u8, 2, 3, 4, 5, 6, 7, 8];
        let ids = &ids[..n.min(8)];
        self.packets_out += 2;
        self.bytes_out += len(feetech::sync_read(sts::PRESENT_BLOCK, sts::PRESENT_BLOCK_LEN, ids, &mut buf)) as u32;
        let block = [0u8; command::COMMAND_LEN as usize];
        let entries: [(u8, &[u8]); 8] = core::array::from_fn(|i| (i as u8 + 1, &block[..]));
        self.bytes_out += len(feetech::sync_write(command::COMMAND_BLOCK, command::COMMAND_LEN, &entries[..ids.len()], &mut buf)) as u32;
        self.packets_in += ids.len() as u32;
        self.bytes_in += (ids.len() * (feetech::OVERHEAD + sts::PRESENT_BLOCK_LEN as usize)) as u32;
    }

    /// Bytes both ways.
    pub fn bytes(&self) -> u32 {
        self.bytes_out + self.bytes_in
    }

    /// The period's bus time \[µs\] at `baud` with a return delay of
    /// `return_delay_us` before each status packet.
    pub fn time_us(&self, baud: u32, return_delay_us: u32) -> f64 {
        self.bytes() as f64 * 10.0 * 1e6 / baud.max(1) as f64 + self.packets_in as f64 * return_delay_us as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::robot::{leo, pendulum, JointSpec, RobotSpec};

    fn with_servo(robot: &'static RobotSpec, joints: &'static [JointSpec]) -> RobotSpec {
        RobotSpec { joints, ..*robot }
    }

    #[test]
    fn the_formulas_of_the_table() {
        // One RX-28 (the pendulum), with the sensor device.
        let t = PeriodTraffic::of(&pendulum::SPEC_33HZ, true);
        assert_eq!(t, PeriodTraffic { packets_out: 4, bytes_out: 8 + 11 + 8 + 8, packets_in: 2, bytes_in: 14 + 9 });
        // LEO's seven RX-28s.
        let t = PeriodTraffic::of(&leo::SPEC, false);
        assert_eq!((t.bytes_out, t.bytes_in, t.packets_in), (7 * 8 + 8 + 21 + 8, 7 * 14, 7));
        // Six X-series servos: 20 + 13 + 32 out, one reply of 11 + 6·27 − 3.
        static X6: [JointSpec; 6] = {
            let j = JointSpec { name: "x", servo: &pada_core::servo::XM430_W350, id: 1, zero: 2048, sign: 1, soft_limit: None };
            [j, JointSpec { id: 2, ..j }, JointSpec { id: 3, ..j }, JointSpec { id: 4, ..j }, JointSpec { id: 5, ..j }, JointSpec { id: 6, ..j }]
        };
        let t = PeriodTraffic::of(&with_servo(&leo::SPEC, &X6), false);
        assert_eq!(t, PeriodTraffic { packets_out: 3, bytes_out: 20 + 13 + 32, packets_in: 1, bytes_in: 11 + 6 * 27 - 3 });
        // 235 bytes: 2.40 ms at 1 Mbps (8 % of 30 ms), 40.8 ms at 57,600 (more than the period).
        assert!((t.time_us(1_000_000, 50) - 2400.0).abs() < 1e-9);
        assert!((t.time_us(57_600, 50) - 40_848.6).abs() < 0.1);
        // The arm's two: 16 + 13 + 20 out, 11 + 2·27 − 3 back: 111 bytes,
        // 1.16 ms at 1 Mbps (3.9 % of 30 ms), 19.3 ms at 57,600 (64 %).
        static X2: [JointSpec; 2] = {
            let j = JointSpec { name: "x", servo: &pada_core::servo::XM430_W350, id: 1, zero: 2048, sign: 1, soft_limit: None };
            [j, JointSpec { id: 2, servo: &pada_core::servo::XL430_W250, ..j }]
        };
        let t = PeriodTraffic::of(&with_servo(&leo::SPEC, &X2), false);
        assert_eq!(t, PeriodTraffic { packets_out: 3, bytes_out: 16 + 13 + 20, packets_in: 1, bytes_in: 11 + 2 * 27 - 3 });
        assert!((t.time_us(1_000_000, 50) - 1160.0).abs() < 1e-9);
        assert!((t.time_us(57_600, 50) - 19_320.8).abs() < 0.1);
    }

    #[test]
    fn six_sts3215_at_1_mbaud() {
        // SYNC READ 8 + 6, SYNC WRITE 8 + 7·6 out; six status packets of
        // 6 + 8 back: 148 bytes, 1.48 ms on the wire and six return delays
        // of 50 µs: 1.78 ms, 5.9 % of a 30 ms period, 8.9 % of 20 ms.
        let t = PeriodTraffic::feetech(6);
        assert_eq!(t, PeriodTraffic { packets_out: 2, bytes_out: 14 + 50, packets_in: 6, bytes_in: 6 * 14 });
        static FT6: [JointSpec; 6] = {
            let j = JointSpec { name: "s", servo: &pada_core::servo::STS3215, id: 1, zero: 2048, sign: 1, soft_limit: None };
            [j, JointSpec { id: 2, ..j }, JointSpec { id: 3, ..j }, JointSpec { id: 4, ..j }, JointSpec { id: 5, ..j }, JointSpec { id: 6, ..j }]
        };
        assert_eq!(PeriodTraffic::of(&with_servo(&leo::SPEC, &FT6), false), t);
        assert!((t.time_us(1_000_000, 50) - 1780.0).abs() < 1e-9);
        // LeRobot's return delay (0) and its 1 Mbaud: 1.48 ms.
        assert!((t.time_us(1_000_000, 0) - 1480.0).abs() < 1e-9);
    }

    #[test]
    fn the_feetech_arithmetic_is_the_bytes_the_bus_puts_on_the_wire() {
        use crate::bus::ft::tests::FtFake;
        use crate::bus::{BusConfig, ServoBus, ServoRead};
        use embassy_futures::block_on;
        use pada_core::feetech::{ByteOrder, Command};
        let ids = [1u8, 2, 3, 4, 5, 6];
        let mut bus = ServoBus::new(FtFake::with_servos(&ids), BusConfig::default());
        let mut out = [ServoRead::default(); 6];
        block_on(bus.read_present_ft(&ids, ByteOrder::Little, &mut out));
        let commands = ids.map(|id| (id, Command { torque: true, acceleration: 0, goal_position: 2048, duty: 300 }));
        block_on(bus.sync_write_ft(&commands, ByteOrder::Little)).unwrap();
        let fake = bus.port_mut();
        let sent: usize = fake.sent.iter().map(Vec::len).sum();
        let t = PeriodTraffic::feetech(6);
        assert_eq!((fake.sent.len() as u32, sent as u32), (t.packets_out, t.bytes_out));
        assert_eq!(fake.received, t.bytes_in as u64);
        assert!(out.iter().all(|r| r.state.is_some()));
    }
}
