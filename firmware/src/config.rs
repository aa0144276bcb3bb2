//! The robots the firmware drives, and the learner's fixed sizes.
//!
//! # Sizes (compile time)
//!
//! | item | value | why |
//! |---|---|---|
//! | tilings | 16 | the paper's and GRL's (grl-facts §3.9, §4) |
//! | weight table | 2¹⁴ = 16 384 Q16 weights = 64 KiB | exactly the STM32F405's core-coupled RAM (CCM, zero wait states, no DMA traffic), leaving all 128 KiB of SRAM to the stack, the trace, the buffers and the executor; the hashed layout needs a power of two, and the next one (2¹⁵ = 128 KiB) would take all of SRAM |
//! | trace | 64 entries | LEO's γλ = 0.9962 · 0.8582 keeps 30 entries above 0.01, the paper's default γλ = 0.99 · 0.92 keeps 49 |
//! | servos | up to 7 | LEO: shoulder, hips, knees, ankles |
//!
//! GRL hashed LEO into 2²³–2²⁴ weights; 2¹⁴ means many more hash
//! collisions. It is what fits on the chip without external RAM (the
//! F407VG's FSMC could add some); the host runs with larger tables to show
//! the difference.
//!
//! # Robots (run time)
//!
//! [`Robot::Pendulum33`] is the physical inverted pendulum of Section VII
//! (33 Hz, {−3, 0, +3} V, GRL constants, grl-facts §4): one RX-28 in wheel
//! mode turns the pendulum, a quadrature encoder on the axis measures the
//! angle. [`Robot::Pendulum20`] is the same hardware at the simulated
//! pendulum's 20 Hz. [`Robot::Leo`] is LEO on its boom (Section VIII,
//! grl-facts §3): 7 RX-28s, the boom's encoder for the torso pitch, four
//! foot switches; 3 learned joints (stance hip, swing hip, swing knee), the
//! others held by the PD laws of grl-facts §3.5.
//!
//! The learning parameters and state/action descriptions match the host's
//! tasks (`host/src/pendulum/physical.rs`, `shared/benches/agent_step.rs`),
//! so that an agent built here and one built on the host with the same seed
//! take the same decisions (issue 6's bit-for-bit replay).

use crate::servo::Joint;
use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::agent::{Agent, SarsaParams, WeightInit};
use pada_core::checkpoint::ConfigHasher;
use pada_core::error::ConfigError;
use pada_core::fixed::Q16;
use pada_core::policy::{Policy, PolicyKind};
use pada_core::safety::SoftLimit;
use pada_core::tile_coding::{Layout, StateDim};
use pada_core::trace::TraceKind;

/// Tilings of the tile coder.
pub const TILINGS: usize = 16;
/// log₂ of the weight table's size.
pub const WEIGHTS_LOG2: u32 = 14;
/// Weights in the table: 16 384 × 4 bytes = 64 KiB, the F405's CCM RAM.
pub const WEIGHTS: usize = 1 << WEIGHTS_LOG2;
/// Capacity of the eligibility trace, in (state, action) entries.
pub const TRACE: usize = 64;
/// Most servos on the bus.
pub const MAX_SERVOS: usize = 7;
/// Most observation dimensions (LEO's 10).
pub const MAX_OBS: usize = 10;
/// The weight table's layout.
pub const LAYOUT: Layout = Layout::Hashed;

/// Tile width of LEO's learned voltages \[V\] (grl-facts §3.9: voltage
/// scale 0.15 ↔ 6.67 V).
pub const LEO_ACTION_TILE_WIDTH: f32 = 6.67;

/// The agent the firmware runs.
pub type FirmwareAgent<W> = Agent<W, TILINGS, TRACE>;
/// The weight table.
pub type WeightTable = [Q16; WEIGHTS];

/// The seed of the agent's generator when the host sets none.
pub const DEFAULT_SEED: u64 = 0x5041_4441;

/// Which robot the firmware drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Robot {
    /// The physical pendulum of Section VII at 33 Hz (30 ms).
    Pendulum33,
    /// The same pendulum at 20 Hz (50 ms).
    Pendulum20,
    /// LEO at 30 Hz.
    Leo,
}

/// The quadrature encoder on the pendulum's axis or LEO's boom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncoderConfig {
    /// Counts per revolution after the timer's ×4 decoding (a 1024-line
    /// encoder gives 4096).
    pub counts_per_rev: u32,
    /// +1 if counting up turns the measured angle positive.
    pub sign: i8,
}

/// Everything fixed about one robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotConfig {
    /// Which robot.
    pub robot: Robot,
    /// Name for logs and telemetry.
    pub name: &'static str,
    /// Control period \[µs\].
    pub period_us: u32,
    /// Control steps of an episode before its time limit.
    pub episode_steps: u32,
    /// One greedy test episode after this many learning episodes.
    pub test_interval: u32,
    /// The servos, in the robot's joint order.
    pub joints: &'static [Joint],
    /// Soft limit per joint (same order), `None` for a joint without one.
    pub soft_limits: &'static [Option<SoftLimit>],
    /// The encoder.
    pub encoder: EncoderConfig,
    /// Supply voltage assumed until a servo reports it \[V\].
    pub supply_nominal_v: f32,
}

impl RobotConfig {
    /// The control period in seconds.
    pub fn period_s(&self) -> f32 {
        self.period_us as f32 * 1e-6
    }
}

/// The pendulum's motor: Dynamixel ID 1, position counts increasing with
/// the positive (counter-clockwise) voltage.
const PENDULUM_JOINTS: [Joint; 1] = [Joint { id: 1, zero: 512, sign: 1 }];

/// LEO's servos in GRL's raw action order (grl-facts §3.1): shoulder,
/// hip R, hip L, knee R, knee L, ankle R, ankle L, IDs 1–7. `zero` is the
/// raw position at joint angle 0 and `sign` maps the servo's direction to
/// GRL's joint sign (§1.2, §1.5): **calibrate both on your robot**; these
/// are the mid-range defaults.
const LEO_JOINTS: [Joint; 7] = [
    Joint { id: 1, zero: 512, sign: 1 },
    Joint { id: 2, zero: 512, sign: 1 },
    Joint { id: 3, zero: 512, sign: 1 },
    Joint { id: 4, zero: 512, sign: 1 },
    Joint { id: 5, zero: 512, sign: 1 },
    Joint { id: 6, zero: 512, sign: 1 },
    Joint { id: 7, zero: 512, sign: 1 },
];

/// Margin outside GRL's joint stops (grl-facts §1.5) before a soft-limit
/// fault \[rad\]: the stops are soft springs, a joint that passes them by
/// this much is being driven into them.
const STOP_MARGIN: f32 = 0.15;

const fn limit(min: f32, max: f32) -> Option<SoftLimit> {
    Some(SoftLimit { min: min - STOP_MARGIN, max: max + STOP_MARGIN })
}

/// LEO's soft limits in joint order: the shoulder has no stop in the model
/// (±90° here), hips −45°…146°, knees −150°…+2°, ankles −90°…83°.
const LEO_LIMITS: [Option<SoftLimit>; 7] = {
    use core::f32::consts::{FRAC_PI_2, FRAC_PI_4};
    [
        limit(-FRAC_PI_2, FRAC_PI_2),
        limit(-FRAC_PI_4, 2.548_181),
        limit(-FRAC_PI_4, 2.548_181),
        limit(-2.617_994, 0.034_907),
        limit(-2.617_994, 0.034_907),
        limit(-FRAC_PI_2, 1.448_623),
        limit(-FRAC_PI_2, 1.448_623),
    ]
};

/// The pendulum turns freely: no soft limit.
const PENDULUM_LIMITS: [Option<SoftLimit>; 1] = [None];

impl Robot {
    /// Every robot, for iteration.
    pub const ALL: [Robot; 3] = [Robot::Pendulum33, Robot::Pendulum20, Robot::Leo];

    /// The robot's name as the command line and telemetry spell it.
    pub const fn name(self) -> &'static str {
        match self {
            Robot::Pendulum33 => "pendulum-33hz",
            Robot::Pendulum20 => "pendulum-20hz",
            Robot::Leo => "leo",
        }
    }

    /// A stable number for the configuration hash and the wire.
    pub const fn code(self) -> u8 {
        match self {
            Robot::Pendulum33 => 1,
            Robot::Pendulum20 => 2,
            Robot::Leo => 3,
        }
    }

    /// The robot with this [`code`](Self::code).
    pub fn from_code(code: u8) -> Option<Robot> {
        Robot::ALL.into_iter().find(|r| r.code() == code)
    }

    /// The fixed description.
    pub const fn config(self) -> RobotConfig {
        match self {
            Robot::Pendulum33 | Robot::Pendulum20 => {
                let period_us = if matches!(self, Robot::Pendulum33) { 30_000 } else { 50_000 };
                RobotConfig {
                    robot: self,
                    name: self.name(),
                    period_us,
                    // 3 s episodes (grl-facts §4): 100 or 60 steps.
                    episode_steps: 3_000_000 / period_us,
                    test_interval: 10,
                    joints: &PENDULUM_JOINTS,
                    soft_limits: &PENDULUM_LIMITS,
                    encoder: EncoderConfig { counts_per_rev: 4096, sign: 1 },
                    supply_nominal_v: 12.0,
                }
            }
            Robot::Leo => RobotConfig {
                robot: self,
                name: self.name(),
                period_us: 33_333,
                // 25 s trials (grl-facts §3.8).
                episode_steps: 750,
                test_interval: 10,
                joints: &LEO_JOINTS,
                soft_limits: &LEO_LIMITS,
                // The boom's encoder; the torso pitch is minus its angle (§3.1).
                encoder: EncoderConfig { counts_per_rev: 4096, sign: 1 },
                // LEO_SUPPLY_VOLTAGE (grl-facts §2.2).
                supply_nominal_v: 14.0,
            },
        }
    }

    /// Observation dimensions (before any policy extension): ranges and
    /// tile widths.
    pub fn state_dims(self) -> heapless::Vec<StateDim, MAX_OBS> {
        use core::f32::consts::PI;
        let mut dims = heapless::Vec::new();
        match self {
            Robot::Pendulum33 | Robot::Pendulum20 => {
                // GRL: resolution [0.31415 rad, 3.1415 rad/s], θ̇ within ±12π
                // (grl-facts §4); as the host's physical pendulum.
                let _ = dims.push(StateDim { min: -PI, max: PI, tile_width: 2.0 * PI / 20.0, wrap: true });
                let _ = dims.push(StateDim { min: -12.0 * PI, max: 12.0 * PI, tile_width: PI, wrap: false });
            }
            Robot::Leo => {
                // grl-facts §3.9 (cfg/leosim/sarsa.yaml resolution), in the
                // observation order of §3.4.
                let angle = StateDim { min: -PI, max: PI, tile_width: 0.28, wrap: false };
                let rate = StateDim { min: -30.0, max: 30.0, tile_width: 10.0, wrap: false };
                let _ = dims.push(StateDim { min: -1.0, max: 1.0, tile_width: 0.14, wrap: false });
                let _ = dims.push(StateDim { min: -30.0, max: 30.0, tile_width: 5.0, wrap: false });
                for _ in 0..4 {
                    let _ = dims.push(angle);
                    let _ = dims.push(rate);
                }
            }
        }
        dims
    }

    /// The learner's motor: voltage levels per learned joint.
    pub fn action_space(self) -> ActionSpace {
        match self {
            Robot::Pendulum33 | Robot::Pendulum20 => {
                // Checked constant levels: cannot fail.
                let dim = ActionDim::from_levels(&[-3.0, 0.0, 3.0]).unwrap_or_else(|_| unreachable!());
                ActionSpace::new(&[dim]).unwrap_or_else(|_| unreachable!())
            }
            Robot::Leo => {
                // 7 levels over ±10.7 V for stance hip, swing hip, swing
                // knee (grl-facts §3.4): 343 joint actions.
                let dim = ActionDim::uniform(-10.7, 10.7, 7).unwrap_or_else(|_| unreachable!());
                ActionSpace::repeated(dim, 3).unwrap_or_else(|_| unreachable!())
            }
        }
    }

    /// Tile widths of the learner's action dimensions when the agent
    /// generalises over actions: LEO's voltages in 6.67 V tiles, as GRL's
    /// LEO learner and the host's LEO task (grl-facts §3.9,
    /// `generalizeActions`); the pendulums keep one weight set per action.
    pub fn action_tiles(self) -> Option<[f32; 3]> {
        match self {
            Robot::Pendulum33 | Robot::Pendulum20 => None,
            Robot::Leo => Some([LEO_ACTION_TILE_WIDTH; 3]),
        }
    }

    /// The robot's agent learning with `policy` on `weights` (weights not
    /// yet initialised): the one place the firmware, its tests and the
    /// host's replay build it.
    pub fn agent<W>(self, policy: PolicyKind, weights: W) -> Result<FirmwareAgent<W>, ConfigError>
    where
        W: AsRef<[Q16]> + AsMut<[Q16]>,
    {
        let mut agent = FirmwareAgent::new(&self.state_dims(), self.action_space(), policy, self.params(), LAYOUT, weights)?;
        if let Some(widths) = self.action_tiles() {
            agent.generalise_actions(&widths)?;
        }
        Ok(agent)
    }

    /// SARSA(λ) parameters.
    pub fn params(self) -> SarsaParams {
        match self {
            // As the host's physical pendulum: the paper's defaults, U[0, 1].
            Robot::Pendulum33 | Robot::Pendulum20 => {
                SarsaParams { init: WeightInit::Uniform { min: 0.0, max: 1.0 }, ..SarsaParams::default() }
            }
            // LEO's original constants (grl-facts §3.9, LW `<policy>`).
            Robot::Leo => SarsaParams {
                alpha: 0.2,
                gamma: 0.9962,
                lambda: 0.8582,
                epsilon: 0.05,
                trace_threshold: 0.01,
                trace_kind: TraceKind::Replacing,
                init: WeightInit::Uniform { min: 0.0, max: 0.01 },
            },
        }
    }
}

/// Version of what [`config_hash`] covers; bump when its meaning changes.
pub const CONFIG_HASH_VERSION: u32 = 1;

/// The hash of everything that gives the weights their meaning (FNV-1a of
/// `pada_core::checkpoint`, stored in checkpoints and sent in `Hello`):
/// robot, table size and layout, tilings, trace capacity, every state
/// dimension the tile coder sees (the observation plus a Markov policy's
/// extension), the learner's action levels (all levels, or an integrator's
/// −Δ/0/+Δ) and their tile widths if actions are tile-coded, and α, γ, λ
/// and the trace settings.
///
/// Policies that share the learner's layout share the hash: weights learned
/// with PADA, SARSA or the low-pass filter load into each other (PADA
/// switches to SARSA on the same weights, Section VIII). ε and the
/// initialisation are left out: changing them keeps the weights meaningful.
pub fn config_hash(robot: Robot, policy: PolicyKind, params: &SarsaParams) -> Result<u32, ConfigError> {
    let policy = Policy::new(policy, robot.action_space())?;
    let mut h = ConfigHasher::new();
    h.write_u32(CONFIG_HASH_VERSION)
        .write_str(robot.name())
        .write_u32(TILINGS as u32)
        .write_u32(WEIGHTS as u32)
        .write_u32(TRACE as u32)
        .write_u32(match LAYOUT {
            Layout::Hashed => 1,
            Layout::Exact => 2,
        });
    let mut dim = |d: StateDim| {
        h.write_f32(d.min).write_f32(d.max).write_f32(d.tile_width).write_u32(d.wrap as u32);
    };
    for d in robot.state_dims() {
        dim(d);
    }
    for i in 0..policy.extension_len() {
        dim(policy.extension_dim(i)?);
    }
    if let Some(widths) = robot.action_tiles() {
        h.write_str("action tiles");
        for w in widths {
            h.write_f32(w);
        }
    }
    let space = policy.learner_space();
    for i in 0..space.dims() {
        h.write_u32(space.dim(i).len() as u32);
        for &v in space.dim(i).values() {
            h.write_f32(v);
        }
    }
    h.write_f32(params.alpha)
        .write_f32(params.gamma)
        .write_f32(params.lambda)
        .write_f32(params.trace_threshold)
        .write_u32(match params.trace_kind {
            TraceKind::Replacing => 1,
            TraceKind::Accumulating => 2,
        });
    Ok(h.finish())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;

    #[test]
    fn every_robot_and_policy_builds_an_agent_on_the_table() {
        let policies = [
            PolicyKind::Sarsa,
            PolicyKind::LowPass { alpha: 0.834 },
            PolicyKind::MarkovLowPass { alpha: 0.834 },
            PolicyKind::Integrator { delta: 0.5 },
            PolicyKind::MarkovIntegrator { delta: 0.5 },
            PolicyKind::Pada { delta: 0.5 },
        ];
        for robot in Robot::ALL {
            for policy in policies {
                let mut table = vec![Q16::ZERO; WEIGHTS];
                let agent = robot.agent(policy, &mut table[..]);
                assert!(agent.is_ok(), "{robot:?} {policy:?}: {:?}", agent.err());
                let tiled = agent.ok().and_then(|a| a.coder().action_tiles().map(|t| t.combos()));
                assert_eq!(tiled.is_some(), robot == Robot::Leo, "{robot:?}: action tiles {tiled:?}");
            }
        }
    }

    #[test]
    fn leo_is_ten_dimensional_with_343_actions() {
        assert_eq!(Robot::Leo.state_dims().len(), 10);
        assert_eq!(Robot::Leo.action_space().joint_count(), 343);
        assert_eq!(Robot::Leo.config().joints.len(), MAX_SERVOS);
        assert_eq!(Robot::Leo.config().soft_limits.len(), MAX_SERVOS);
        assert_eq!(Robot::Pendulum33.config().episode_steps, 100);
        assert_eq!(Robot::Pendulum20.config().episode_steps, 60);
    }

    #[test]
    fn the_table_is_all_of_ccm() {
        assert_eq!(core::mem::size_of::<WeightTable>(), 64 * 1024);
    }

    #[test]
    fn hash_changes_with_what_gives_weights_meaning_only() {
        let p = Robot::Leo.params();
        let h = |robot, policy, params: &SarsaParams| config_hash(robot, policy, params).unwrap();
        let base = h(Robot::Leo, PolicyKind::Sarsa, &p);
        assert_eq!(base, h(Robot::Leo, PolicyKind::Sarsa, &p));
        assert_ne!(base, h(Robot::Pendulum33, PolicyKind::Sarsa, &p));
        assert_ne!(base, h(Robot::Leo, PolicyKind::Sarsa, &SarsaParams { alpha: 0.1, ..p }));
        assert_eq!(base, h(Robot::Leo, PolicyKind::Sarsa, &SarsaParams { epsilon: 0.0, ..p }));
        // Same learner layout: PADA and the low-pass filter share SARSA's weights.
        assert_eq!(base, h(Robot::Leo, PolicyKind::Pada { delta: 0.5 }, &p));
        assert_eq!(base, h(Robot::Leo, PolicyKind::LowPass { alpha: 0.8 }, &p));
        // Another layout: an extra state dimension, or −Δ/0/+Δ actions.
        assert_ne!(base, h(Robot::Leo, PolicyKind::MarkovLowPass { alpha: 0.8 }, &p));
        assert_ne!(base, h(Robot::Leo, PolicyKind::Integrator { delta: 0.5 }, &p));
        assert_ne!(
            h(Robot::Leo, PolicyKind::Integrator { delta: 0.5 }, &p),
            h(Robot::Leo, PolicyKind::Integrator { delta: 0.25 }, &p)
        );
        assert!(config_hash(Robot::Leo, PolicyKind::Pada { delta: -1.0 }, &p).is_err());
    }

    #[test]
    fn same_seed_same_weights_as_the_host_would_draw() {
        // The firmware draws from pada_core's Pcg32, the host from
        // rand_pcg::Pcg32::seed_from_u64: the same weights (uniform
        // initialisation, so every weight is a draw).
        fn build<R: rand_core::RngCore>(rng: &mut R) -> u32 {
            let mut agent = FirmwareAgent::new(
                &Robot::Pendulum33.state_dims(),
                Robot::Pendulum33.action_space(),
                PolicyKind::Sarsa,
                Robot::Pendulum33.params(),
                LAYOUT,
                vec![Q16::ZERO; WEIGHTS].into_boxed_slice(),
            )
            .unwrap();
            agent.reset_weights(rng);
            agent.weights_checksum()
        }
        let firmware = build(&mut pada_core::rng::Pcg32::seed_from_u64(DEFAULT_SEED));
        let host = build(&mut rand_pcg::Pcg32::seed_from_u64(DEFAULT_SEED));
        assert_eq!(firmware, host);
        assert_ne!(firmware, build(&mut rand_pcg::Pcg32::seed_from_u64(DEFAULT_SEED + 1)));
    }
}
