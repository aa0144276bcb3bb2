//! The passive rollout: LEO from its reference start (§1.8)
//! with 0 V on the three learned joints (stance hip, swing hip, swing
//! knee) and the auto-actuated joints on (shoulder, stance knee and ankles
//! under their P controllers, §3.5), one record per control step, until it
//! falls (§3.8) or the time is up.
//!
//! Nothing learns here, so the rollout is a fixed test of the model alone:
//! `pada leo passive` prints it for comparison with another simulator or
//! the robot, and the sanity tests check that it converges with the step.

use serde::Serialize;

use super::constants::CONTROL_PERIOD;
use super::model::{Joint, ModelOptions};
use super::task::ACTION_DIM;
use super::{LeoConfig, LeoEnv, LeoError, Terminal};

/// The seven joint angles of one record (rad, ODE's q = θ_parent − θ_child,
/// `docs/reference/grl.md` §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct JointAngles {
    /// Torso → arm.
    pub shoulder: f32,
    /// Torso → left thigh.
    pub hip_left: f32,
    /// Torso → right thigh.
    pub hip_right: f32,
    /// Left thigh → left shank.
    pub knee_left: f32,
    /// Right thigh → right shank.
    pub knee_right: f32,
    /// Left shank → left foot.
    pub ankle_left: f32,
    /// Right shank → right foot.
    pub ankle_right: f32,
}

impl JointAngles {
    fn from_model_order(q: &[f32; 7]) -> Self {
        Self {
            shoulder: q[Joint::Shoulder as usize],
            hip_left: q[Joint::HipLeft as usize],
            hip_right: q[Joint::HipRight as usize],
            knee_left: q[Joint::KneeLeft as usize],
            knee_right: q[Joint::KneeRight as usize],
            ankle_left: q[Joint::AnkleLeft as usize],
            ankle_right: q[Joint::AnkleRight as usize],
        }
    }
}

/// The two ankles' voltages held over a step (V), from their P controllers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AnkleVoltages {
    /// Left ankle.
    pub left: f32,
    /// Right ankle.
    pub right: f32,
}

/// One control step of the passive rollout.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PassiveStep {
    /// Control steps since the first observation (1 for the first).
    pub step: u32,
    /// Simulated time since the first observation (s).
    pub time_s: f32,
    /// Torso angle φ after the step (rad; §3.1: φ = −pitch, the fall
    /// criterion is |φ| > 1).
    pub torso_angle_rad: f32,
    /// Its rate (rad/s, exact, not the task's filtered rate).
    pub torso_rate_rad_s: f32,
    /// Every joint angle after the step.
    pub joint_angles_rad: JointAngles,
    /// The ankle voltages held during the step.
    pub ankle_voltages_v: AnkleVoltages,
    /// The task's reward for the step (§3.7).
    pub reward: f32,
}

/// A whole passive rollout and how it ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassiveRollout {
    /// Physics steps per control period.
    pub substeps: u32,
    /// Rapier solver iterations per physics step.
    pub solver_iterations: usize,
    /// The rollout's length limit (s).
    pub seconds: f64,
    /// One record per control step.
    pub steps: Vec<PassiveStep>,
    /// Whether the robot fell (§3.8) within the time.
    pub fell: bool,
    /// When the fall was detected (s after the first observation).
    pub fall_time_s: Option<f32>,
    /// After how many control steps.
    pub fall_steps: Option<u32>,
    /// The sum of the rewards.
    #[serde(rename = "return")]
    pub total_return: f64,
    /// Simulation blow-ups (a blow-up ends the rollout as a fall).
    pub blow_ups: u64,
}

impl PassiveRollout {
    /// The largest difference of the torso angle between two rollouts over
    /// the control steps both have (rad): "until the fall" when both run
    /// until they fall.
    pub fn largest_torso_angle_difference(&self, other: &PassiveRollout) -> f32 {
        self.steps
            .iter()
            .zip(&other.steps)
            .map(|(a, b)| (a.torso_angle_rad - b.torso_angle_rad).abs())
            .fold(0.0, f32::max)
    }

    /// The time (s) at which |φ| first reaches `angle`, linearly
    /// interpolated between control steps (the fall criterion's crossing
    /// with sub-step resolution); `None` if it never does. Starts from the
    /// reference start's φ before the first step.
    pub fn torso_crossing_time(&self, angle: f32) -> Option<f32> {
        let start = -super::task::INIT_TORSO_PITCH;
        let mut previous = (0.0f32, start.abs());
        for s in &self.steps {
            let now = (s.time_s, s.torso_angle_rad.abs());
            if now.1 >= angle && previous.1 < angle {
                let f = (angle - previous.1) / (now.1 - previous.1);
                return Some(previous.0 + f * (now.0 - previous.0));
            }
            previous = now;
        }
        None
    }
}

/// Largest rollout accepted (s): an hour of simulated standing or lying.
pub const MAX_PASSIVE_SECONDS: f64 = 3600.0;

/// Runs the passive rollout with these physics settings for up to
/// `seconds` (0 < seconds ≤ [`MAX_PASSIVE_SECONDS`]; the caller checks the
/// range, a value outside it runs one step or the maximum).
pub fn passive_rollout(options: ModelOptions, seconds: f64) -> Result<PassiveRollout, LeoError> {
    let seconds = seconds.clamp(0.0, MAX_PASSIVE_SECONDS);
    let steps = ((seconds / CONTROL_PERIOD as f64).round() as u32).max(1);
    let config = LeoConfig {
        model: options,
        // The rollout's own length decides; the task's 25 s timeout must
        // not end it first.
        timeout: Some((steps as f32 + 1.0) * CONTROL_PERIOD),
        ..LeoConfig::default()
    };
    let mut env = LeoEnv::new(config)?;
    // The reference start is deterministic: the generator is never read.
    let mut rng = rand_pcg::Pcg32::new(0, 0);
    env.reset(&mut rng);
    let mut records = Vec::with_capacity(steps as usize);
    let mut total = 0.0f64;
    let mut fall = None;
    for k in 1..=steps {
        let r = env.step([0.0; ACTION_DIM]);
        total += r.reward as f64;
        let model = env.model();
        let s = model.state();
        let u = model.voltages();
        records.push(PassiveStep {
            step: k,
            time_s: r.info.time,
            torso_angle_rad: -s.torso_pitch,
            torso_rate_rad_s: -s.torso_rate,
            joint_angles_rad: JointAngles::from_model_order(&s.angles),
            ankle_voltages_v: AnkleVoltages {
                left: u[Joint::AnkleLeft as usize],
                right: u[Joint::AnkleRight as usize],
            },
            reward: r.reward,
        });
        if r.terminal == Terminal::Fall {
            fall = Some((r.info.time, k));
            break;
        }
    }
    Ok(PassiveRollout {
        substeps: options.substeps,
        solver_iterations: options.solver_iterations,
        seconds,
        steps: records,
        fell: fall.is_some(),
        fall_time_s: fall.map(|f| f.0),
        fall_steps: fall.map(|f| f.1),
        total_return: total,
        blow_ups: env.blow_ups(),
    })
}
