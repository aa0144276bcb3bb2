//! What the board learns is what the host learns: the host's runner and the
//! firmware build their learners by different code paths (the runner from
//! its task description, the firmware's controller from the robot's
//! definition and the board's profile), and the configuration hashes of the
//! two agents must be equal for every robot, board and policy. The hash is
//! computed from what each built agent knows of itself (its tile coder as
//! prepared, its actions and their tiles, its parameters, its table), so
//! any drift between the two — a state range, a tile width, a level, a
//! parameter, a table size — makes it fail.

use pada::experiment::build_agent;
use pada::experiment::task::Task;
use pada::leo::rl::{leo_params, LeoTask};
use pada::pendulum::{PhysicalPendulumParams, PhysicalPendulumTask};
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::profile::{config_hash, Board, LearnerProfile};
use pada_core::robot::Robot;
use pada_core::weights::WeightStore;
use pada_firmware::control::Controller;
use pada_firmware::leo::Leo;
use pada_firmware::pendulum::Pendulum33;
use pada_firmware::robot::RobotAdapter;

const POLICIES: [PolicyKind; 4] = [
    PolicyKind::Sarsa,
    PolicyKind::Pada { delta: 1.0 / 6.0 },
    PolicyKind::LowPass { alpha: 0.5 },
    PolicyKind::Integrator { delta: 0.5 },
];

/// The firmware controller's hash for `profile` and `policy` on a table of
/// `weights` weights.
fn firmware_hash<R: RobotAdapter>(profile: LearnerProfile, policy: PolicyKind, weights: usize) -> u32 {
    let table = vec![Q16::ZERO; weights].into_boxed_slice();
    let ctl = Controller::<_, R>::new(profile, policy, table, 1)
        .unwrap_or_else(|e| panic!("{} on {}: {e}", profile.robot.name(), profile.board.name()));
    ctl.config_hash()
}

fn check<T: Task, R: RobotAdapter>(task: &T, profile: LearnerProfile) {
    let spec = task.spec();
    assert_eq!(spec.profile, Some(profile));
    for policy in POLICIES {
        let host = build_agent(spec, policy).unwrap();
        let host_hash = config_hash(&profile, &host);
        let fw = firmware_hash::<R>(profile, policy, host.weights().len());
        assert_eq!(
            host_hash,
            fw,
            "{} on {} with {policy:?}: the host's learner and the firmware's differ",
            profile.robot.name(),
            profile.board.name()
        );
        if let Some(n) = profile.weights() {
            assert_eq!(host.weights().len(), n, "the runner sizes the table as the profile says");
        }
    }
}

#[test]
fn host_and_firmware_build_the_same_pendulum_learner_on_every_board() {
    for board in Board::ALL {
        let profile = board.profile(Robot::Pendulum33);
        let task = PhysicalPendulumTask::with_profile(PhysicalPendulumParams::default(), profile);
        check::<_, Pendulum33>(&task, profile);
    }
}

#[test]
fn host_and_firmware_build_the_same_leo_learner_on_every_board() {
    for board in Board::ALL {
        let profile = board.profile(Robot::Leo);
        let task = LeoTask::with_profile(profile, leo_params());
        check::<_, Leo>(&task, profile);
    }
}

#[test]
fn the_hash_tells_boards_robots_and_learners_apart() {
    let pendulum = |board: Board| {
        let p = board.profile(Robot::Pendulum33);
        let n = PhysicalPendulumTask::with_profile(PhysicalPendulumParams::default(), p)
            .spec()
            .profile
            .and_then(|p| p.weights())
            .unwrap_or(24_960);
        firmware_hash::<Pendulum33>(p, PolicyKind::Sarsa, n)
    };
    // The same exact table on two boards: a checkpoint of one is refused by
    // the other.
    assert_ne!(pendulum(Board::F405), pendulum(Board::F429Sdram));
    let leo = |policy| firmware_hash::<Leo>(Board::F405.profile(Robot::Leo), policy, 1 << 14);
    // PADA and the low-pass filter share SARSA's weights (Section VIII's
    // switch); the integrator learns −Δ/0/+Δ and does not.
    assert_eq!(leo(PolicyKind::Sarsa), leo(PolicyKind::Pada { delta: 0.5 }));
    assert_eq!(leo(PolicyKind::Sarsa), leo(PolicyKind::LowPass { alpha: 0.2 }));
    assert_ne!(leo(PolicyKind::Sarsa), leo(PolicyKind::Integrator { delta: 0.5 }));
    // Other learning parameters: another learner.
    let mut params = leo_params();
    params.lambda = 0.9;
    let profile = Board::Host.profile(Robot::Leo);
    let task = LeoTask::with_profile(profile, params);
    let other = config_hash(&profile, &build_agent(task.spec(), PolicyKind::Sarsa).unwrap());
    let default = LeoTask::with_profile(profile, leo_params());
    let same = config_hash(&profile, &build_agent(default.spec(), PolicyKind::Sarsa).unwrap());
    assert_ne!(other, same);
}
