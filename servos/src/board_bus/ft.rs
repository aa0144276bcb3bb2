//! The Feetech side of the emulated bus: a robot's STS3215s, each the
//! virtual servo of `pada servos` ([`P1Servo`] of the STS3215's layout,
//! its joint in the rig behind it: [`crate::ft`]). Feetech's framing
//! is Protocol 1.0's, so the bus's Protocol 1.0 decoder hands over the
//! packets for these servos (and broadcasts); this file decides which
//! servos an instruction concerns and what they answer. When the answers
//! arrive, the faults and the counters are the bus's ([`super::BusEmulator`]).
//!
//! A SYNC READ (the firmware's read of every servo, once a period) gets one
//! status packet per servo, in the order of its IDs, one after the other.

use pada_sim::rig::Rig;
use crate::bus::baud_value;
use crate::ft::{self, STS3215_LAYOUT};
use crate::p1::P1Servo;
use pada_core::dynamixel::{self as dxl1, ErrorFlags, Instruction as DxlInstruction, BROADCAST_ID};
use pada_core::feetech::control_table::sts3215::STS3215;
use pada_core::feetech::Instruction;
use pada_core::robot::RobotSpec;
use pada_core::servo::ServoProtocol;

/// The rate the firmware's bus runs at (the servos' factory rate; under
/// QEMU the UART's rate is not modelled).
const BUS_BPS: u32 = 1_000_000;

/// One servo's status packet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FtAnswer {
    /// The servo.
    pub id: u8,
    /// The status packet.
    pub bytes: Vec<u8>,
    /// Its Return Delay Time \[µs\].
    pub return_delay_us: u64,
}

/// A robot's Feetech servos.
#[derive(Debug, Clone)]
pub struct FtServos {
    servos: Vec<(P1Servo, ft::Output)>,
    supply_v: f64,
}

impl FtServos {
    /// The Feetech servos among `ids` (each of its joint of `robot`), at the
    /// bus's rate; `None` if there are none.
    pub fn new(robot: &RobotSpec, ids: &[u8], supply_v: f64) -> Result<Option<Self>, String> {
        let mut servos = Vec::new();
        for &id in ids {
            let Some(joint) = robot.joints.iter().find(|j| j.id == id && j.servo.protocol == ServoProtocol::Feetech) else { continue };
            if joint.servo.model_number != STS3215.model_number {
                let (name, model) = (joint.name, joint.servo.name);
                return Err(format!("joint {name}: a virtual {model} is not emulated on Feetech's protocol: the valid model is STS3215"));
            }
            let baud = baud_value(&STS3215, BUS_BPS).ok_or_else(|| format!("the {} takes no {BUS_BPS} bps", joint.servo.name))?;
            servos.push((P1Servo::of(&STS3215_LAYOUT, id, baud, Some(*joint)), ft::Output::default()));
        }
        Ok((!servos.is_empty()).then_some(FtServos { servos, supply_v }))
    }

    /// Whether a packet to `id` with instruction `code` is theirs: one to
    /// one of them, a broadcast, or a SYNC READ (Feetech's own).
    pub fn concerns(&self, id: u8, code: u8) -> bool {
        id == BROADCAST_ID || code == pada_core::feetech::instruction::SYNC_READ || self.servos.iter().any(|(s, _)| s.id() == id)
    }

    /// Every servo's ID and torque.
    pub fn torques(&self) -> impl Iterator<Item = (u8, bool)> + '_ {
        self.servos.iter().map(|(s, _)| (s.id(), s.torque()))
    }

    /// A power cut at `t_us`: every servo back to its factory table, its
    /// joint limp.
    pub fn power_off(&mut self, t_us: u64, rig: &mut dyn Rig) {
        for (s, out) in &mut self.servos {
            *s = P1Servo::of(&STS3215_LAYOUT, s.id(), s.baud(), s.joint);
            *out = ft::Output::default();
            rig.drive(t_us, s.id(), false, 0.0);
        }
    }

    /// Executes the packet to `id` of instruction `code` with `params`,
    /// complete at `t`: the answers, in order; the rig is read for a read
    /// and driven after a write.
    pub fn execute(&mut self, id: u8, code: u8, params: &[u8], t: u64, rig: &mut dyn Rig) -> Vec<FtAnswer> {
        let broadcast = id == BROADCAST_ID;
        let mut answers = Vec::new();
        let Ok(ins) = Instruction::parse(code, params) else {
            // An instruction it does not know: Instruction Error, as its
            // level allows.
            if let Some((s, _)) = self.servos.iter().find(|(s, _)| s.id() == id) {
                let error = ft::answer_error(s, ErrorFlags::INSTRUCTION);
                if let Some(a) = s.refuse(broadcast, error) {
                    answers.push(answer(s, a));
                }
            }
            return answers;
        };
        let (order, reads): (Vec<usize>, bool) = match &ins {
            Instruction::SyncRead { ids, .. } => (ids.iter().filter_map(|&i| self.index(i)).collect(), true),
            Instruction::Shared(DxlInstruction::Read { .. }) => (self.index(id).into_iter().collect(), true),
            _ if broadcast => ((0..self.servos.len()).collect(), false),
            _ => (self.index(id).into_iter().collect(), false),
        };
        for i in order {
            let (s, out) = &mut self.servos[i];
            if reads {
                if let Some(joint) = s.joint {
                    let present = pada_sim::rig::x_reading(&joint, rig.joint_state(t, joint.id), 0, self.supply_v).into();
                    ft::with_robot(s, out, &present, t);
                }
            }
            let a = match &ins {
                Instruction::Shared(d) => s.execute(d, broadcast && !matches!(d, DxlInstruction::BulkRead { .. })),
                Instruction::SyncRead { addr, len, .. } => Some(s.read(*addr, *len)),
            };
            if let Some((error, data)) = a {
                let error = ft::answer_error(s, error);
                answers.push(answer(s, (error, data)));
            }
        }
        if !reads {
            for (s, _) in &self.servos {
                rig.drive(t, s.id(), s.torque(), s.volts(self.supply_v));
            }
        }
        answers
    }

    fn index(&self, id: u8) -> Option<usize> {
        self.servos.iter().position(|(s, _)| s.id() == id)
    }
}

/// Servo `s`'s status packet of `error` and `data`.
fn answer(s: &P1Servo, (error, data): (ErrorFlags, Vec<u8>)) -> FtAnswer {
    let mut buf = vec![0u8; data.len() + 16];
    let bytes = dxl1::StatusPacket::<64>::new(s.id(), error, &data)
        .and_then(|p| p.encode(&mut buf).map(<[u8]>::to_vec))
        .unwrap_or_default();
    FtAnswer { id: s.id(), bytes, return_delay_us: s.return_delay_us() }
}
