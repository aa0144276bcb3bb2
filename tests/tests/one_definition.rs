//! What the board learns is what the host learns: the host's runner and the
//! firmware build their learners by different code paths (the runner from
//! its task description, the firmware's controller from the robot's
//! definition and the board's profile), and the configuration hashes of the
//! two agents must be equal for every robot, board and policy. The hash is
//! computed from what each built agent knows of itself (its tile coder as
//! prepared, its actions and their tiles, its parameters, its table), so
//! any drift between the two — a state range, a tile width, a level, a
//! parameter, a table size, a claim table's weight or tag width — makes it
//! fail. The episodes' rules (length,
//! test cadence, footstep remap), the control period and the counted
//! gearboxes are compared directly.
//!
//! A robot of files comes to the chip as generated constants
//! (`pada_robot_file::rust_source`, run by the firmware's build.rs); the
//! example arm's are compiled here (tests/build.rs) and their learner must
//! hash as the one the host builds from the same files.

use pada::experiment::algo::{algo_of, policy_kind_of, Algo, PolicyFlags};
use pada::experiment::build_agent;
use pada::experiment::table::HostTable;
use pada::experiment::task::{Task, TaskSpec};
use pada::leo::rl::{leo_params, LeoTask};
use pada::robots::{sim_robot, DynRules};
use pada_core::policy::PolicyKind;
use pada_core::profile::{config_hash, Board, LearnerProfile};
use pada_core::robot::{leo, pendulum, registry, RobotRules};
use pada_core::tile_coding::Layout;
use pada_core::weights::WeightStore;
use pada_firmware::control::Controller;

/// The constants an image of the example arm holds: `ROBOT`, `ThisRobot`,
/// `this_robot()` (tests/build.rs generates them as the firmware's
/// build.rs does).
mod arm2 {
    include!(concat!(env!("OUT_DIR"), "/arm2_robot.rs"));
}

/// The same arm with a squared-distance term and an elbow with levels of
/// its own (tests/build.rs).
mod words {
    include!(concat!(env!("OUT_DIR"), "/words_robot.rs"));
}

/// Every policy of `--algo`, each with its default parameters (and PADA
/// with LEO's Δ = 1/6 besides).
fn policies() -> Vec<PolicyKind> {
    let mut all: Vec<PolicyKind> = Algo::ALL
        .into_iter()
        .map(|a| {
            policy_kind_of(a, &PolicyFlags::default())
                .unwrap_or_else(|e| panic!("{}: no default policy: {e}", a.name()))
        })
        .collect();
    all.push(PolicyKind::Pada { delta: 1.0 / 6.0 });
    all
}

#[test]
fn every_policy_every_robot_and_every_board_is_checked() {
    assert_eq!(Algo::ALL.len(), 10, "a new policy: it is checked by the loops below");
    assert_eq!(registry::BUILT_IN.len(), 3, "every robot of the registry is checked by the loop below");
    assert_eq!(Board::ALL.len(), 3);
    let kinds: std::collections::BTreeSet<&str> = policies().iter().map(|p| algo_of(p).name()).collect();
    assert_eq!(kinds.len(), Algo::ALL.len(), "one policy of every algorithm");
}

/// A table of `weights` entries laid out as `profile` says: a claim table
/// of the profile's weight and tag widths, or a plain one.
fn table_of(profile: LearnerProfile, weights: usize) -> HostTable {
    match profile.layout {
        Layout::Claimed => HostTable::claimed(weights, profile.format, profile.tag_bytes).unwrap().on_full(profile.when_full),
        Layout::Exact | Layout::Hashed => HostTable::plain_of(weights, profile.format).unwrap(),
    }
}

/// The rules of `profile`'s robot, as the host builds them.
fn rules(profile: LearnerProfile) -> DynRules {
    sim_robot(profile.robot).unwrap().rules()
}

/// The firmware controller's hash for `profile` and `policy` on a table of
/// `weights` weights.
fn firmware_hash(profile: LearnerProfile, policy: PolicyKind, weights: usize) -> u32 {
    let table = table_of(profile, weights);
    let ctl = Controller::new(rules(profile), profile, policy, table, 1)
        .unwrap_or_else(|e| panic!("{} on {}: {e}", profile.robot.name, profile.board.name()));
    ctl.config_hash()
}

/// Checks every policy on `profile`: where the host builds a learner, the
/// firmware builds the same one; where the host refuses one (a Markov
/// filter's learner on a pendulum's exact table, sized for the plain
/// state), the firmware refuses it too. Returns how many it refused.
fn check(spec: &TaskSpec, profile: LearnerProfile) -> usize {
    assert_eq!(spec.profile, Some(profile));
    let (robot, board) = (profile.robot.name, profile.board.name());
    let fw = rules(profile).spec();
    // The episodes: the runner's task and the firmware's robot run the
    // same cycle (`pada_core::episodes`) under the same rules.
    assert_eq!(spec.episode_rules(), fw.episode_rules(), "{robot}: the host's episodes and the firmware's differ");
    assert_eq!(spec.control_period_s, fw.period_s(), "{robot}: control period");
    assert_eq!(spec.gearboxes, fw.gearboxes(), "{robot}: counted gearboxes");
    let mut refused = 0;
    for policy in policies() {
        let host = match build_agent(spec, policy) {
            Ok(host) => host,
            Err(host_error) => {
                let table = table_of(profile, profile.weights().unwrap_or(1 << 10));
                assert!(
                    Controller::new(rules(profile), profile, policy, table, 1).is_err(),
                    "{robot} on {board}: the host refuses {policy:?} ({host_error}) but the firmware builds it"
                );
                refused += 1;
                continue;
            }
        };
        let host_hash = config_hash(&profile, &host);
        let fw = firmware_hash(profile, policy, host.weights().len());
        assert_eq!(
            (host.weights().claims(), host.weights().format(), host.weights().tag_bytes()),
            (profile.layout == Layout::Claimed, profile.format, profile.tag_bytes),
            "{robot} on {board}: the host's table is not the profile's"
        );
        assert_eq!(
            host_hash, fw,
            "{robot} on {board} with {policy:?}: the host's learner and the firmware's differ"
        );
        if let Some(n) = profile.weights() {
            assert_eq!(host.weights().len(), n, "the runner sizes the table as the profile says");
        }
    }
    refused
}

#[test]
fn host_and_firmware_build_the_same_learner_for_every_robot_on_every_board() {
    for robot in registry::specs() {
        for board in Board::ALL {
            let profile = board.profile(robot).unwrap();
            let task = sim_robot(robot).unwrap().task_spec(profile).unwrap();
            let refused = check(&task, profile);
            if robot == &leo::SPEC {
                // A claim table where it holds what LEO writes; the F405's
                // 64 KiB is a hashed table (docs/board.md, "A full table").
                let layout = if board == Board::F405 { Layout::Hashed } else { Layout::Claimed };
                assert_eq!(profile.layout, layout, "LEO on {}", board.name());
                assert_eq!(refused, 0, "LEO's tables hold every learner");
            } else {
                assert!(refused <= 2, "{}: only the two Markov filters are refused", robot.name);
            }
        }
    }
}

#[test]
fn the_hash_tells_boards_robots_and_learners_apart() {
    let pendulum = |board: Board| {
        let p = board.profile(&pendulum::SPEC_33HZ).unwrap();
        let n = sim_robot(&pendulum::SPEC_33HZ).unwrap().task_spec(p).unwrap().profile.and_then(|p| p.weights()).unwrap_or(24_960);
        firmware_hash(p, PolicyKind::Sarsa, n)
    };
    // The same exact table on two boards: a checkpoint of one is refused by
    // the other.
    assert_ne!(pendulum(Board::F405), pendulum(Board::F429Sdram));
    let leo = |policy| firmware_hash(Board::F405.profile(&leo::SPEC).unwrap(), policy, 1 << 15);
    // PADA and the low-pass filter share SARSA's weights (Section VIII's
    // switch); the integrator learns −Δ/0/+Δ and does not.
    assert_eq!(leo(PolicyKind::Sarsa), leo(PolicyKind::Pada { delta: 0.5 }));
    assert_eq!(leo(PolicyKind::Sarsa), leo(PolicyKind::LowPass { alpha: 0.2 }));
    assert_ne!(leo(PolicyKind::Sarsa), leo(PolicyKind::Integrator { delta: 0.5 }));
    // The F429's claim table with Q16 weights and 32-bit tags instead of
    // 16-bit ones: another learner (what it stores and what a feature may
    // share differ).
    let f429 = Board::F429Sdram.profile(&leo::SPEC).unwrap();
    let wide = f429.with_hashed_table(Layout::Claimed, 21, pada_core::weights::WeightFormat::Q16, 4);
    assert_ne!(firmware_hash(wide, PolicyKind::Sarsa, 1 << 21), firmware_hash(f429, PolicyKind::Sarsa, 1 << 21));
    // Other learning parameters: another learner.
    let mut params = leo_params();
    params.lambda = 0.9;
    let profile = Board::Host.profile(&leo::SPEC).unwrap();
    let task = LeoTask::with_profile(profile, params);
    let other = config_hash(&profile, &build_agent(task.spec(), PolicyKind::Sarsa).unwrap());
    let default = LeoTask::with_profile(profile, leo_params());
    let same = config_hash(&profile, &build_agent(default.spec(), PolicyKind::Sarsa).unwrap());
    assert_ne!(other, same);
}

#[test]
fn the_firmware_constants_of_a_robot_of_files_learn_as_the_host_reads_the_files() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2/robot.toml");
    let file = pada_robot_file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    // The same definition, every float by its bits (the hash reads them).
    assert_eq!(arm2::ROBOT, file.spec);
    assert_eq!(arm2::ROBOT.definition_hash(), file.spec.definition_hash());
    let sim = pada::robots::from_file(&file).unwrap();
    let mut compared = 0;
    for board in [Board::F405, Board::F429Sdram] {
        // The firmware's profile comes from its constants, the host's from
        // the file it read.
        let chip = board.profile(arm2::ROBOT).unwrap();
        let host_profile = file.profile(board).unwrap();
        let task = sim.task_spec(host_profile).unwrap();
        assert_eq!(task.episode_rules(), arm2::ROBOT.episode_rules(), "{}: episodes", board.name());
        assert_eq!(task.control_period_s, arm2::ROBOT.period_s(), "{}: control period", board.name());
        assert_eq!(task.gearboxes, arm2::ROBOT.gearboxes(), "{}: counted gearboxes", board.name());
        for policy in policies() {
            let weights = chip.weights().expect("a board's table has a size");
            let firmware = Controller::new(arm2::this_robot(), chip, policy, table_of(chip, weights), 1);
            let host = match build_agent(&task, policy) {
                Ok(host) => host,
                Err(e) => {
                    assert!(firmware.is_err(), "arm2 on {}: the host refuses {policy:?} ({e}) but the firmware builds it", board.name());
                    continue;
                }
            };
            let firmware = firmware.unwrap_or_else(|e| panic!("arm2 on {}: the firmware refuses {policy:?}: {e}", board.name()));
            assert_eq!(host.weights().len(), weights, "arm2 on {}: table size", board.name());
            assert_eq!(
                config_hash(&host_profile, &host),
                firmware.config_hash(),
                "arm2 on {} with {policy:?}: the host's learner and the generated firmware's differ",
                board.name()
            );
            compared += 1;
        }
    }
    assert!(compared >= 2 * (policies().len() - 2), "{compared} learners compared");
}

#[test]
fn the_firmware_constants_of_every_word_are_the_files() {
    let path = std::path::Path::new(env!("OUT_DIR")).join("words/robot.toml");
    let file = pada_robot_file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(words::ROBOT, file.spec);
    assert_eq!(words::ROBOT.definition_hash(), file.spec.definition_hash());
    assert!(matches!(words::ROBOT.levels, pada_core::robot::MotorLevels::PerMotor(l) if l.len() == 2 && l[1] == [-1.0, 0.0, 1.0]));
    let rewards = words::ROBOT.vocabulary.unwrap().rewards;
    assert!(matches!(rewards[0], pada_core::robot::vocabulary::RewardTerm::DistanceSquared { .. }), "{rewards:?}");
    let chip = Board::F405.profile(words::ROBOT).unwrap();
    let firmware = Controller::new(words::this_robot(), chip, PolicyKind::Sarsa, table_of(chip, chip.weights().unwrap()), 1).unwrap();
    let host = build_agent(&pada::robots::from_file(&file).unwrap().task_spec(file.profile(Board::F405).unwrap()).unwrap(), PolicyKind::Sarsa).unwrap();
    assert_eq!(config_hash(&file.profile(Board::F405).unwrap(), &host), firmware.config_hash());
}
