//! The rapier3d LEO behind the bus: seven RX-28s whose voltages drive the
//! model's joints, the boom's encoder reading the torso's pitch, the four
//! foot switches, and an operator who sets the robot upright between
//! episodes.
//!
//! - **Timing.** The model advances in whole control periods of 33 333 µs
//!   (its own step, [`crate::leo::model::LeoModel::control_step`]), on the
//!   boundaries `k · T`: a reading at any instant of period k is the state
//!   at `k · T`, and the voltages in force at `(k + 1) · T` drive the step
//!   from `k · T` to `(k + 1) · T` (a zero-order hold of the last
//!   command, as the servo holds its Moving Speed). The firmware reads at
//!   the start of its period and commands right after, so this is the
//!   simulation's own control step; and the result does not depend on
//!   where within a period a transaction lands, so the emulated bus and a
//!   direct run on the host drive the same trajectory.
//! - **Sensors as the board sees them.** Present Position in RX-28 counts
//!   (300° over 1023, the firmware's default calibration: 512 at 0, counts
//!   growing with the joint angle), Present Speed from the joint rate,
//!   Present Load from the gear torque, Present Voltage 14.0 V; the boom's
//!   encoder at 4096 counts per turn (the torso angle φ is minus the
//!   torso's pitch, so the counter reads the pitch, from vertical: LEO
//!   powered up upright); the toe and heel switches as
//!   `pada_core::robot::leo::contact` bits.
//! - **Between episodes.** When the firmware reports an episode's end (or a
//!   fault), the operator puts LEO back into the start pose of §1.8 (the
//!   state after its first control period, as the simulation's episodes
//!   start) and holds it still: the physics does not run, so the firmware
//!   reads the start pose until it has seen the torso upright with a foot
//!   down for its second and starts the next episode, when the operator
//!   lets go. LEO is held from boot too.
//! - **Walked distance.** The plant measures it as the host's LEO task
//!   does (`crate::leo`, §3.3): the sum of footstep lengths from the true
//!   joint angles, torso pitch and foot contacts at every period boundary,
//!   from the operator letting go.
//! - **Torque off** (a fault, Stop): modelled as 0 V, the motor shorted,
//!   which brakes the joint a little more than the RX-28's open winding.

use super::periodic::{PeriodBody, Periodic};
use super::JointState;
use crate::leo::model::{InitialPose, LeoModel, ModelOptions, Snapshot, NUM_JOINTS};
use pada_core::robot::leo::{ankle_x, Leg, StanceTracker, CONTROL_PERIOD_US, JOINTS};
use pada_core::robot::{EncoderSpec, RobotSpec};
use pada_core::rx28::Rx28;
use pada_core::robot::leo::contact;

/// LEO on its boom, behind seven emulated RX-28s.
pub type LeoRig = Periodic<LeoOnBoom>;

/// LEO's physics on its boom: the model, its start pose, the boom's
/// encoder and the footsteps ([`LeoRig`]'s body).
pub struct LeoOnBoom {
    model: LeoModel,
    /// The start of every episode: the reference pose after its first
    /// control period at 0 V.
    start: Snapshot,
    /// The servos' IDs and calibration and the boom's encoder: the robot's
    /// one hardware definition.
    hw: &'static RobotSpec,
    /// The boom's encoder of that definition.
    encoder: EncoderSpec,
    /// Mean gear torque of each joint over the last simulated period.
    torques: [f32; NUM_JOINTS],
    /// Footsteps since the operator let go.
    stance: StanceTracker,
}

impl LeoRig {
    /// LEO held at its start pose at time 0, torque off, with the servos
    /// and encoder of its hardware definition.
    pub fn new(options: ModelOptions) -> anyhow::Result<Self> {
        Self::with_hardware(options, &pada_core::robot::leo::SPEC)
    }

    /// The same with another calibration of the same servos (a robot whose
    /// servos are mounted or zeroed differently).
    pub fn with_hardware(options: ModelOptions, hw: &'static RobotSpec) -> anyhow::Result<Self> {
        let encoder = match (hw.joints.len(), hw.encoder) {
            (NUM_JOINTS, Some(encoder)) => encoder,
            _ => anyhow::bail!(
                "LEO's rig needs LEO's {NUM_JOINTS} servos and its boom's encoder, not {} servos{} of {}",
                hw.joints.len(),
                if hw.encoder.is_some() { "" } else { " and no encoder" },
                hw.name
            ),
        };
        let mut model = LeoModel::new(options, &InitialPose::REFERENCE).map_err(|e| anyhow::anyhow!("{e}"))?;
        model.set_voltages([0.0; NUM_JOINTS]);
        model.control_step().map_err(|b| anyhow::anyhow!("the LEO model blew up settling into its start pose: {b:?}"))?;
        let start = model.snapshot();
        let body = LeoOnBoom { model, start, hw, encoder, torques: [0.0; NUM_JOINTS], stance: StanceTracker::new() };
        Ok(Periodic::of_body(body, CONTROL_PERIOD_US as u64))
    }

    /// The model (for inspection).
    pub fn model(&self) -> &LeoModel {
        &self.body.model
    }
}

impl LeoOnBoom {
    /// The stance tracker sees the state at this boundary (§3.3, as
    /// `crate::leo::LeoEnv` does).
    fn track_stance(&mut self) {
        let s = self.model.state();
        let phi = -s.torso_pitch;
        let ankle = |leg: Leg| ankle_x(phi, s.angles[leg.hip() as usize], s.angles[leg.knee() as usize]);
        self.stance.update(s.contacts[0] || s.contacts[1], s.contacts[2] || s.contacts[3], ankle(Leg::Left), ankle(Leg::Right));
    }
}

impl PeriodBody for LeoOnBoom {
    fn hw(&self) -> &'static RobotSpec {
        self.hw
    }

    fn step_period(&mut self, volts: &[f32]) -> bool {
        let mut u = [0.0; NUM_JOINTS];
        u.copy_from_slice(volts);
        self.model.set_voltages(u);
        let ok = match self.model.control_step() {
            Ok(t) => {
                self.torques = t;
                true
            }
            Err(_) => {
                // The simulation broke (NaN, a body far away): LEO is put
                // back as after a fall; the firmware sees the jump.
                self.model.restore(&self.start);
                self.torques = [0.0; NUM_JOINTS];
                false
            }
        };
        self.track_stance();
        ok
    }

    fn sensed(&self, k: usize) -> JointState {
        let (q, qd) = self.model.joint_state();
        let stall = Rx28::LEO.estimate_joint_torque(self.hw.supply_nominal_v, 0.0);
        let load = (self.torques[k] / stall).clamp(-1.0, 1.0);
        JointState { angle: q[k] as f64, rate: qd[k] as f64, load }
    }

    /// The boom's encoder and the foot switches now.
    fn sensors(&self) -> (u16, u8) {
        let s = self.model.state();
        let bits = [contact::TOE_L, contact::HEEL_L, contact::TOE_R, contact::HEEL_R];
        let contacts = s.contacts.iter().zip(bits).filter(|(on, _)| **on).fold(0, |b, (_, bit)| b | bit);
        (self.encoder.count_of(s.torso_pitch as f64), contacts)
    }

    fn put_back(&mut self) {
        self.model.restore(&self.start);
        self.torques = [0.0; NUM_JOINTS];
    }

    /// The walked distance counts from the start pose.
    fn let_go(&mut self) {
        self.stance = StanceTracker::new();
        self.track_stance();
    }

    fn gear_torque(&self, k: usize) -> f32 {
        self.torques[k]
    }

    fn walked_m(&self) -> Option<f64> {
        Some(self.stance.walked() as f64)
    }

    fn describe(&self) -> String {
        format!(
            "LEO in rapier3d (docs/reference/grl.md §1-2): {} RX-28s, the boom's {}-count encoder, 4 foot switches, set upright by an operator between episodes",
            self.hw.joints.len(),
            self.encoder.counts_per_rev
        )
    }
}

const _: () = assert!(JOINTS.len() == NUM_JOINTS);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::Rig;
    use pada_core::dynamixel::table;
    use pada_core::robot::leo::{Joint, START_JOINT_ANGLES, START_PHI};

    #[test]
    fn held_at_the_start_pose_until_released() {
        let mut rig = LeoRig::new(ModelOptions::default()).unwrap();
        let hip_r = rig.ids[Joint::HipRight as usize];
        let knee_r = rig.ids[Joint::KneeRight as usize];
        let at = |rig: &mut LeoRig, t: u64| (rig.present(t, hip_r).position, rig.present(t, knee_r).position, rig.sensors(t));
        let before = at(&mut rig, 0);
        // Start pose: right hip 0.82 rad, right knee −1.27 rad, the torso
        // pitched 0.10 rad (φ = −0.10), the left foot down.
        let unit = table::POSITION_RANGE_RAD as f64 / table::POSITION_MAX as f64;
        assert!((before.0 as f64 - (512.0 + START_JOINT_ANGLES[Joint::HipRight as usize] as f64 / unit)).abs() <= 1.5);
        assert!((before.1 as f64 - (512.0 + START_JOINT_ANGLES[Joint::KneeRight as usize] as f64 / unit)).abs() <= 1.5);
        // (The first control period at 0 V tips the torso by a few mrad.)
        let pitch = before.2 .0 as i32 - rig.body.encoder.count_of(-START_PHI as f64) as i32;
        assert!(pitch.abs() <= 5, "{pitch} counts from the start pitch");
        assert_ne!(before.2 .1 & contact::LEFT, 0);
        // Held: a second passes, nothing moves, whatever is commanded.
        rig.drive(0, hip_r, true, 10.0);
        assert_eq!(at(&mut rig, 1_000_000), before);
        assert_eq!(rig.peek_present(5_000_000, hip_r), Some(rig.present(1_000_000, hip_r)));
        // Released: 10 V on the right hip moves it within a few periods.
        rig.episode_started(1_000_000);
        // Until the next boundary it stands; past it, only a simulation
        // can tell.
        let next = rig.next_step_us;
        assert_eq!(rig.peek_present(next - 1, hip_r), Some(rig.present(next - 1, hip_r)));
        assert_eq!(rig.peek_present(next, hip_r), None);
        assert_eq!(rig.walked_m(), Some(0.0));
        let t0 = rig.next_step_us;
        rig.advance_to(t0 + 5 * CONTROL_PERIOD_US as u64);
        let after = at(&mut rig, t0 + 5 * CONTROL_PERIOD_US as u64);
        assert!(after.0 > before.0 + 3, "{before:?} → {after:?}");
        assert!(rig.gear_torque(hip_r) > 0.1, "{}", rig.gear_torque(hip_r));
        // The operator resets and holds it again.
        rig.episode_ended(0);
        assert_eq!(at(&mut rig, t0 + 10 * CONTROL_PERIOD_US as u64), before);
    }

    #[test]
    fn an_offset_or_flipped_servo_reads_and_drives_in_its_own_frame() {
        use pada_core::robot::JointSpec;
        let stock: &'static RobotSpec = &pada_core::robot::leo::SPEC;
        let remounted: Vec<JointSpec> = stock.joints.iter().map(|j| JointSpec { zero: 400, sign: -j.sign, ..*j }).collect();
        let remounted: &'static RobotSpec =
            Box::leak(Box::new(RobotSpec { joints: Box::leak(remounted.into_boxed_slice()), ..*stock }));
        let mut rigs = [
            (LeoRig::new(ModelOptions::default()).unwrap(), stock),
            (LeoRig::with_hardware(ModelOptions::default(), remounted).unwrap(), remounted),
        ];
        let supply = stock.supply_nominal_v;
        let t = 5 * CONTROL_PERIOD_US as u64;
        let mut angles = Vec::new();
        for (rig, hw) in rigs.iter_mut() {
            rig.episode_started(0);
            // +6 V on the right hip, as the firmware sends it through this calibration.
            let j = hw.joints[Joint::HipRight as usize];
            let servo_volts = table::ratio_from_moving_speed(j.moving_speed(6.0, Some(supply), supply)) as f64 * supply as f64;
            rig.drive(0, j.id, true, servo_volts);
            let read: Vec<f32> = hw.joints.iter().map(|j| j.angle(rig.present(t, j.id).position)).collect();
            angles.push(read);
        }
        // The firmware's calibration undoes the mounting: the same joint
        // angles within a count, and the hip moved.
        for (a, b) in angles[0].iter().zip(&angles[1]) {
            assert!((a - b).abs() <= 1.01 * pada_core::robot::hardware::POSITION_UNIT_RAD, "{:?} against {:?}", angles[0], angles[1]);
        }
        assert!(angles[0][Joint::HipRight as usize] > START_JOINT_ANGLES[Joint::HipRight as usize] + 0.01);
        // A rig for another robot's servos is refused.
        assert!(LeoRig::with_hardware(ModelOptions::default(), &pada_core::robot::pendulum::SPEC_33HZ).is_err());
    }
}
