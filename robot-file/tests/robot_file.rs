//! Robots read from their files: a two-joint reacher (`tests/data/reacher`,
//! an arm in a vertical plane), a new robot's template, and every kind of
//! bad file, each refused in one line that names the file, the line, the
//! field and the valid values.

use pada_core::profile::{Board, TILINGS};
use pada_core::robot::vocabulary::{RewardTerm, Signal};
use pada_core::robot::{RobotRules, TableNeed};
use pada_robot_file::{load, template};
use std::path::{Path, PathBuf};

fn reacher() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reacher/robot.toml")
}

/// The arm's files copied into a fresh directory, `edit` applied to its
/// `robot.toml` (and `urdf_edit` to its URDF); the error of loading it.
fn refused(edit: impl Fn(String) -> String, urdf_edit: impl Fn(String) -> String) -> String {
    let dir = tempfile::tempdir().unwrap();
    let src = reacher();
    let toml = std::fs::read_to_string(&src).unwrap();
    let urdf = std::fs::read_to_string(src.with_file_name("reacher.urdf")).unwrap();
    std::fs::write(dir.path().join("robot.toml"), edit(toml)).unwrap();
    std::fs::write(dir.path().join("reacher.urdf"), urdf_edit(urdf)).unwrap();
    let e = load(&dir.path().join("robot.toml")).expect_err("a bad file is refused").to_string();
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    assert!(e.contains("robot.toml"), "names the file: {e}");
    e
}

#[test]
fn the_arm_reads_as_its_files_say() {
    let r = load(&reacher()).unwrap();
    let s = r.spec;
    assert_eq!((s.name, s.period_us, s.episode_steps, s.test_interval), ("reacher", 30_000, 200, 10));
    assert_eq!(s.joints.iter().map(|j| (j.name, j.servo.name, j.id)).collect::<Vec<_>>(), [("shoulder", "XM430-W350", 1), ("elbow", "XL330-M288", 2)]);
    assert_eq!((s.counted.start, s.counted.end, s.motor_dims), (0, 2, 2));
    // 11 × 15 tiles of the two angles, 16 tilings, 3 × 3 actions: an exact
    // table that fits an F405.
    assert_eq!(s.exact_table_len::<TILINGS>(pada_core::policy::PolicyKind::Sarsa), Ok(23_760));
    assert_eq!(s.table, TableNeed::Exact { weights: 23_760 });
    assert!(r.profile(Board::F405).is_ok());
    let v = r.vocabulary();
    assert_eq!(v.observation, [Signal::Angle(0), Signal::Angle(1)]);
    assert!(matches!(v.rewards[0], RewardTerm::Distance { point: 0, weight, .. } if weight == -10.0));
    // The tip, straight up: 46 mm + 120 mm + 100 mm above the base.
    let mut rules = r.rules();
    let mut angles = [None; pada_core::limits::MAX_SERVOS];
    angles[0] = Some(0.0);
    angles[1] = Some(0.0);
    rules.sense(&pada_core::robot::Sensed { angles, encoder_angle: None, contacts: 0, applied: [0.0; 8] });
    let tip = rules.point(0).unwrap();
    assert!((tip[2] - 0.266).abs() < 1e-6 && tip[0].abs() < 1e-6, "{tip:?}");
    // Read twice, the same definition.
    assert_eq!(load(&reacher()).unwrap().spec.definition_hash(), s.definition_hash());
}

#[test]
fn a_robots_directory_reads_as_its_robot_toml() {
    let dir = reacher().parent().unwrap().to_path_buf();
    let r = load(&dir).unwrap();
    assert_eq!(r.spec.definition_hash(), load(&reacher()).unwrap().spec.definition_hash());
    // A directory without one names the file it looked for.
    let empty = tempfile::tempdir().unwrap();
    let e = load(empty.path()).unwrap_err().to_string();
    assert!(e.contains("robot.toml") && e.contains("cannot read it"), "{e}");
}

#[test]
fn a_new_robots_template_reads_as_it_is() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("robot.toml"), template::robot_toml("my-arm")).unwrap();
    std::fs::write(dir.path().join("my-arm.urdf"), template::urdf("my-arm")).unwrap();
    let r = load(&dir.path().join("robot.toml")).unwrap();
    assert_eq!((r.spec.name, r.spec.joints.len(), r.spec.state.len(), r.substeps, r.solver_iterations), ("my-arm", 1, 2, 1, 2));
    assert!(r.profile(Board::F405).is_ok() && r.profile(Board::F429Sdram).is_ok());
}

#[test]
fn an_unknown_servo_model_names_the_valid_ones() {
    let e = refused(|t| t.replace("\"XL330-M288\"", "\"XL999\""), |u| u);
    assert!(e.contains(":29:9:") && e.contains("joint[1].servo"), "{e}");
    assert!(e.contains("XL999") && e.contains("XM430-W350, XL430-W250, XL330-M288"), "{e}");
}

#[test]
fn a_joint_the_urdf_lacks_names_the_urdfs_joints() {
    let e = refused(|t| t.replace("urdf = \"elbow\"", "urdf = \"wrist\""), |u| u);
    assert!(e.contains("joint[1].urdf") && e.contains("\"wrist\" is no joint") && e.contains("shoulder, elbow"), "{e}");
}

#[test]
fn a_floating_or_planar_joint_is_no_servos() {
    for kind in ["floating", "planar", "prismatic"] {
        let e = refused(|t| t, |u| u.replace("<joint name=\"elbow\" type=\"revolute\">", &format!("<joint name=\"elbow\" type=\"{kind}\">")));
        assert!(e.contains("joint[1].urdf") && e.contains("revolute or continuous"), "{kind}: {e}");
    }
}

#[test]
fn a_range_with_min_not_below_max_is_refused() {
    let e = refused(|t| t.replace("range = [-1.6, 1.6]", "range = [1.6, -1.6]"), |u| u);
    assert!(e.contains("observe[0].range") && e.contains("min < max"), "{e}");
    let e = refused(|t| in_shoulder(t, |j| format!("{j}\nsoft_limit_rad = [1.5, 1.5]")), |u| u);
    assert!(e.contains("joint[0].soft_limit_rad") && e.contains("min < max"), "{e}");
}

#[test]
fn more_actions_than_a_boards_table_holds_is_refused_for_that_board() {
    // Five levels and finer tiles: an exact table of 16 × 15 × 29 × 25
    // weights, 696 KB, fits no memory of the F405 or the F429's SRAM.
    let dir = tempfile::tempdir().unwrap();
    let src = reacher();
    let toml = std::fs::read_to_string(&src).unwrap()
        .replace("levels_v = [-2.0, 0.0, 2.0]", "levels_v = [-2.0, -1.0, 0.0, 1.0, 2.0]")
        .replace("tile = 0.35\n\n[[observe]]", "tile = 0.35\n\n[[observe]]")
        .replace("range = [-2.4, 2.4]\ntile = 0.35", "range = [-2.4, 2.4]\ntile = 0.17")
        .replace("[robot]\n", "[robot]\ntable = \"exact\"\n");
    std::fs::write(dir.path().join("robot.toml"), toml).unwrap();
    std::fs::copy(src.with_file_name("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    let r = load(&dir.path().join("robot.toml")).unwrap();
    let e = r.profile(Board::F405).unwrap_err().to_string();
    assert!(e.contains("robot.toml") && e.contains("does not fit board f405") && e.contains("weights"), "{e}");
    assert!(r.profile(Board::Host).is_ok());
}

#[test]
fn an_unknown_field_a_missing_servo_and_a_bad_signal_are_refused_where_they_are() {
    let e = refused(|t| t.replace("period_ms = 30", "period_ms = 30\nperiod_hz = 33"), |u| u);
    assert!(e.contains(":10:1:") && e.contains("period_hz") && e.contains("period_ms"), "{e}");
    let e = refused(
        |t| {
            let second = t.find("[[joint]]\nurdf = \"elbow\"").unwrap();
            let end = t.find("# The tip").unwrap();
            format!("{}{}", &t[..second], &t[end..])
        },
        |u| u,
    );
    assert!(e.contains("\"elbow\" moves") && e.contains("no [[joint]]"), "{e}");
    let e = refused(|t| t.replace("signal = \"elbow.angle\"", "signal = \"elbow.torque\""), |u| u);
    assert!(e.contains("observe[1].signal") && e.contains("elbow.angle, elbow.rate"), "{e}");
    let e = refused(|t| t.replace("point = \"tip\"", "point = \"hand\""), |u| u);
    assert!(e.contains("reward[0].point") && e.contains("\"hand\" is no point"), "{e}");
    let e = refused(|t| t.replace("name = \"reacher\"", "name = \"leo\""), |u| u);
    assert!(e.contains("robot.name") && e.contains("pada's own"), "{e}");
}

/// The arm's `robot.toml` with `edit` applied to the `[[joint]]` table of
/// URDF joint `name` alone.
fn in_joint(name: &str, t: String, edit: impl Fn(&str) -> String) -> String {
    let start = t.find(&format!("[[joint]]\nurdf = \"{name}\"")).unwrap();
    let end = start + t[start..].find("\n\n").unwrap();
    format!("{}{}{}", &t[..start], edit(&t[start..end]), &t[end..])
}

fn in_elbow(t: String, edit: impl Fn(&str) -> String) -> String {
    in_joint("elbow", t, edit)
}

fn in_shoulder(t: String, edit: impl Fn(&str) -> String) -> String {
    in_joint("shoulder", t, edit)
}

#[test]
fn a_start_pose_outside_the_soft_limits_is_refused() {
    let e = refused(|t| in_shoulder(t, |j| j.replace("start_rad = 0.0", "soft_limit_rad = [-1.5, 1.5]\nstart_rad = 1.8")), |u| u);
    assert!(e.contains(":26:13:") && e.contains("joint[0].start_rad") && e.contains("1.8 is not valid"), "{e}");
    assert!(e.contains("[-1.5, 1.5]"), "names the valid range: {e}");
}

#[test]
fn a_zero_count_past_the_encoder_is_refused() {
    let e = refused(|t| in_elbow(t, |j| j.replace("zero_count = 2048", "zero_count = 5000")), |u| u);
    assert!(e.contains(":31:14:") && e.contains("joint[1].zero_count") && e.contains("5000 is not valid"), "{e}");
    assert!(e.contains("XL330-M288") && e.contains("0 to 4095"), "names the valid range: {e}");
}

#[test]
fn a_feetech_sts3215_joint_reads_with_its_4096_counts_a_turn() {
    // The elbow on an STS3215 leader variant: Feetech's protocol, its own
    // encoding and gears.
    let dir = tempfile::tempdir().unwrap();
    let src = reacher();
    let toml = std::fs::read_to_string(&src).unwrap().replace("\"XL330-M288\"", "\"sts3215-c046\"");
    std::fs::write(dir.path().join("robot.toml"), toml).unwrap();
    std::fs::copy(src.with_file_name("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    let r = load(&dir.path().join("robot.toml")).unwrap();
    let elbow = r.spec.joints[1];
    assert_eq!(elbow.servo.name, "STS3215-C046");
    assert_eq!(elbow.servo.protocol, pada_core::servo::ServoProtocol::Feetech);
    assert_eq!(elbow.servo.datasheet.gear_ratio, 147.0);
    // A quarter turn is 1024 of its 4096 counts; the encoder ends at 4095.
    assert_eq!(elbow.counts_of(std::f64::consts::FRAC_PI_2), 2048 + 1024);
    assert_eq!(elbow.counts_of(10.0), 4095);
    assert!((elbow.angle_of(3072) - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    // Its voltage command is Goal_Time in 0.1 % of the supply.
    assert_eq!(elbow.drive(3.7, Some(7.4), 7.4), pada_core::servo::Drive::GoalTime { time: 500, full: 1000 });
    // The same file with the C001 and a count past its encoder is refused.
    let e = refused(|t| in_elbow(t, |j| j.replace("\"XL330-M288\"", "\"STS3215\"").replace("zero_count = 2048", "zero_count = 4096")), |u| u);
    assert!(e.contains("joint[1].zero_count") && e.contains("4096 is not valid") && e.contains("STS3215's encoder, 0 to 4095"), "{e}");
}

#[test]
fn a_soft_limit_past_the_urdfs_limits_is_refused() {
    let e = refused(|t| in_shoulder(t, |j| format!("{j}\nsoft_limit_rad = [-1.9, 2.1]")), |u| u);
    assert!(e.contains(":26:18:") && e.contains("joint[0].soft_limit_rad") && e.contains("[-1.9, 2.1] is not valid"), "{e}");
    assert!(e.contains("\"shoulder\"") && e.contains("[-2, 2]"), "names the URDF's limits: {e}");
    // Within them, and the joints with limits first: read.
    loaded(|t| in_shoulder(t, |j| format!("{j}\nsoft_limit_rad = [-2.0, 2.0]")));
}

#[test]
fn a_string_for_a_bus_id_names_the_field_and_the_ids() {
    let e = refused(|t| in_elbow(t, |j| j.replace("id = 2", "id = \"2\"")), |u| u);
    assert!(e.contains(":30:6:") && e.contains("joint[1].id: \"2\" is not valid") && e.contains("0 to 252"), "{e}");
}

#[test]
fn a_bus_id_past_a_byte_names_the_field_and_the_ids() {
    let e = refused(|t| in_elbow(t, |j| j.replace("id = 2", "id = 300")), |u| u);
    assert!(e.contains(":30:6:") && e.contains("joint[1].id: 300 is not valid") && e.contains("0 to 252"), "{e}");
}

#[test]
fn a_soft_limit_of_one_number_names_the_field_and_its_shape() {
    let e = refused(|t| in_shoulder(t, |j| format!("{j}\nsoft_limit_rad = 2.5")), |u| u);
    assert!(e.contains(":26:18:") && e.contains("joint[0].soft_limit_rad: 2.5 is not valid") && e.contains("[min, max] in radians"), "{e}");
}

#[test]
fn a_target_of_two_numbers_names_the_field_and_its_shape() {
    let e = refused(|t| t.replace("target_m = [0.1, 0.0, 0.2]", "target_m = [0.1, 0.2]"), |u| u);
    assert!(e.contains("reward[0].target_m: [0.1, 0.2] is not valid") && e.contains("[x, y, z] in metres"), "{e}");
}

/// The arm's files with `edit` applied to its `robot.toml`, loaded.
fn loaded(edit: impl Fn(String) -> String) -> pada_robot_file::RobotFile {
    let dir = tempfile::tempdir().unwrap();
    let src = reacher();
    std::fs::write(dir.path().join("robot.toml"), edit(std::fs::read_to_string(&src).unwrap())).unwrap();
    std::fs::copy(src.with_file_name("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    load(&dir.path().join("robot.toml")).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_squared_distance_term_reads_and_is_written_for_the_chip() {
    let r = loaded(|t| t.replace("term = \"distance\"", "term = \"distance_squared\""));
    assert!(matches!(r.vocabulary().rewards[0], RewardTerm::DistanceSquared { point: 0, target, weight } if target == [0.1, 0.0, 0.2] && weight == -10.0));
    let source = pada_robot_file::rust_source(r.spec, "robot.toml").unwrap();
    assert!(source.contains("RewardTerm::DistanceSquared { point: 0,"), "{source}");
    let e = refused(|t| t.replace("term = \"distance\"", "term = \"distance_cubed\""), |u| u);
    assert!(e.contains("reward[0].term") && e.contains("distance_squared"), "{e}");
}

#[test]
fn a_learned_joint_may_have_levels_of_its_own() {
    // As written: one list for both joints.
    assert!(matches!(load(&reacher()).unwrap().spec.levels, pada_core::robot::MotorLevels::Listed(_)));
    let r = loaded(|t| in_elbow(t, |j| format!("{j}\nlevels_v = [-1.0, 0.0, 0.5, 1.0]")));
    let motor = r.spec.motor().unwrap();
    assert_eq!((motor.dim(0).values(), motor.dim(1).values()), (&[-2.0f32, 0.0, 2.0][..], &[-1.0f32, 0.0, 0.5, 1.0][..]));
    assert_eq!(motor.joint_count(), 12);
    let source = pada_robot_file::rust_source(r.spec, "robot.toml").unwrap();
    assert!(source.contains("static LEVELS_1: [f32; 4]") && source.contains("MotorLevels::PerMotor(&LEVELS)"), "{source}");
    assert_ne!(r.spec.definition_hash(), load(&reacher()).unwrap().spec.definition_hash());
    // Checked as [action]'s are, and refused on a joint nobody learns.
    let e = refused(|t| in_elbow(t, |j| format!("{j}\nlevels_v = [1.0, 0.0]")), |u| u);
    assert!(e.contains("joint[1].levels_v") && e.contains("increasing"), "{e}");
    let e = refused(|t| in_elbow(t, |j| format!("{j}\nlearned = false\nhold_gain_v_per_rad = 5.0\nlevels_v = [-1.0, 1.0]")), |u| u);
    assert!(e.contains("joint[1].levels_v") && e.contains("held joint"), "{e}");
}

/// Six observed signals at fine tiles: more features than an exact table
/// can index. The file reads, with a claim table; asking for an exact
/// table is refused with the reason.
#[test]
fn an_observation_too_fine_for_an_exact_table_takes_a_claim_table() {
    let fine = |t: String| {
        let mut more = String::new();
        for (s, lo, hi, tile) in [("shoulder.rate", -6.0, 6.0, 2.0), ("elbow.rate", -6.0, 6.0, 2.0), ("tip.x", -0.25, 0.25, 0.01), ("tip.z", -0.2, 0.3, 0.01)] {
            more += &format!("[[observe]]\nsignal = \"{s}\"\nrange = [{lo}, {hi}]\ntile = {tile}\n\n");
        }
        t.replace("tile = 0.35", "tile = 0.2").replacen("[[observe]]", &format!("{more}[[observe]]"), 1)
    };
    let r = loaded(fine);
    assert_eq!((r.spec.state.len(), r.spec.table), (6, TableNeed::Claimed));
    assert!(r.profile(Board::F405).is_ok() && r.profile(Board::Host).is_ok());
    let e = refused(|t| fine(t).replace("[robot]\n", "[robot]\ntable = \"exact\"\n"), |u| u);
    assert!(e.contains("robot.table") && e.contains("exact") && e.contains("claim"), "{e}");
}

#[test]
fn the_so101_example_is_six_sts3215_two_learned() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/so101");
    let r = load(&dir).unwrap();
    let s = r.spec;
    assert_eq!(s.name, "so101");
    // LeRobot's joint names and IDs, every servo the follower's STS3215-C001.
    let names = ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll", "gripper"];
    assert_eq!(s.joints.iter().map(|j| (j.name, j.id)).collect::<Vec<_>>(), names.iter().copied().zip(1..=6).collect::<Vec<_>>());
    for j in s.joints {
        assert_eq!((j.servo.name, j.servo.protocol, j.zero), ("STS3215", pada_core::servo::ServoProtocol::Feetech, 2048));
    }
    // The shoulder lift and the elbow learned and counted, the rest held.
    assert_eq!((s.counted.start, s.counted.end, s.motor_dims), (1, 3, 2));
    // The kit's 5 V supply, and an exact table that fits the F405.
    assert_eq!(s.supply_nominal_v, 5.0);
    assert_eq!(s.table, TableNeed::Exact { weights: 25_600 });
    assert!(r.profile(Board::F405).is_ok());
}

#[test]
fn plant_ranges_are_read_and_a_bad_one_is_refused_at_its_line() {
    // Without [plant] the robot is its model; with one, its ranges.
    assert!(load(&reacher()).unwrap().plant.is_model());
    let dir = tempfile::tempdir().unwrap();
    let src = reacher();
    let toml = std::fs::read_to_string(&src).unwrap() + "\n[plant]\nmass = [0.9, 1.1]\ndelay_periods = [0.0, 1.0]\n";
    std::fs::write(dir.path().join("robot.toml"), toml).unwrap();
    std::fs::copy(src.with_file_name("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    let r = load(&dir.path().join("robot.toml")).unwrap();
    assert_eq!((r.plant.mass.lo, r.plant.mass.hi, r.plant.delay_periods.hi), (0.9, 1.1, 1.0));
    assert_eq!(r.plant.motor_constant.lo, 1.0);
    let e = refused(|t| t + "\n[plant]\nmotor_constant = [0.1, 1.0]\n", |u| u);
    assert!(e.contains("plant.motor_constant") && e.contains("valid is 0.2 to 5"), "{e}");
    let e = refused(|t| t + "\n[plant]\ndelay_periods = [0.0, 1.5]\n", |u| u);
    assert!(e.contains("plant.delay_periods") && e.contains("whole"), "{e}");
    let e = refused(|t| t + "\n[plant]\nstiffness = [1.0, 2.0]\n", |u| u);
    assert!(e.contains("stiffness"), "{e}");
}
