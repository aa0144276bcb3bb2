//! A robot of files on the command line, as its user runs it: learn with
//! `pada run --robot`, save the weights, draw the learned motion with
//! `pada render --robot`, and a clear line for every bad input.

mod common;
use common::*;
use std::path::PathBuf;

fn reacher() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../robot-file/tests/data/reacher/robot.toml")
        .display()
        .to_string()
}

#[test]
fn a_robot_of_files_learns_and_its_motion_is_drawn_and_judged() {
    let dir = tempfile::tempdir().unwrap();
    let weights = dir.path().join("reacher.wts");
    let (w, run_out, render_out) = (
        weights.display().to_string(),
        dir.path().join("run").display().to_string(),
        dir.path().join("render").display().to_string(),
    );
    let robot = reacher();
    let out = ok(&pada(&[
        "run", "--robot", &robot, "--algo", "pada", "--trials", "1", "--seconds", "60", "--threads", "1",
        "--out", &run_out, "--save-weights", &w,
    ]));
    assert!(out.contains("reacher, pada"), "{out}");
    let out = ok(&pada(&["render", "--robot", &robot, "--policy", &w, "--out", &render_out]));
    // One judgement per distance term of the reward (the reacher has one).
    let judged: Vec<&str> = out.lines().filter(|l| l.starts_with("tip: over the last half")).collect();
    assert_eq!(judged.len(), 1, "{out}");
    let csv = std::fs::read_to_string(dir.path().join("render/motion.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.starts_with("time_s,") && header.ends_with("tip_distance_m"), "{header}");
    // The judgement is the trajectory's: its largest distance over the
    // last half of the rows, and held exactly when that is within 2 cm.
    let d: Vec<f64> = csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect();
    assert!(d.len() > 10, "{csv}");
    let max_cm = d[d.len() / 2..].iter().copied().fold(0.0, f64::max) * 100.0;
    assert!(judged[0].contains(&format!("at most {max_cm:.2} cm")), "{} against {max_cm:.2}", judged[0]);
    let held = !judged[0].contains("not held");
    assert_eq!(held, max_cm <= 2.0, "{}", judged[0]);
    let png = std::fs::read(dir.path().join("render/motion.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn bad_robot_input_is_one_line() {
    let robot = reacher();
    assert_bad_input(&["render", "--robot", &robot, "--policy", "/nonexistent.wts", "--hold-cm", "0"], &["--hold-cm 0", "0 < cm <= 100"]);
    assert_bad_input(&["render", "--robot", "/nonexistent/robot.toml", "--policy", "x.wts"], &["/nonexistent/robot.toml"]);
    assert_bad_input(&["render", "--robot", &robot, "--policy", "/nonexistent.wts"], &["/nonexistent.wts"]);
    assert_bad_input(&["run", "--robot", "/nonexistent/robot.toml", "--algo", "pada"], &["/nonexistent/robot.toml"]);
}

#[test]
fn a_new_robot_runs_as_written_on_the_host_and_as_the_board_would() {
    let dir = tempfile::tempdir().unwrap();
    let parent = dir.path().display().to_string();
    let out = ok(&pada(&["new-robot", "flipper", "--dir", &parent]));
    assert!(out.contains("robot.toml") && out.contains("flipper.urdf"), "{out}");
    let toml = dir.path().join("flipper/robot.toml").display().to_string();
    let runs = dir.path().join("runs").display().to_string();
    let host = ok(&pada(&["run", "--robot", &toml, "--algo", "pada", "--trials", "1", "--seconds", "30", "--out", &format!("{runs}/host")]));
    assert!(host.contains("flipper, pada"), "{host}");
    let board = ok(&pada(&[
        "run", "--robot", &toml, "--board", "f405", "--algo", "pada", "--trials", "1", "--seconds", "30", "--out", &format!("{runs}/board"),
    ]));
    assert!(board.contains("flipper"), "{board}");
    // Never over what is there.
    assert_bad_input(&["new-robot", "flipper", "--dir", &parent], &["exists already"]);
    assert_bad_input(&["new-robot", "Flipper", "--dir", &parent], &["lowercase letters"]);
    assert_bad_input(&["new-robot", "leo", "--dir", &parent], &["pada's own robots"]);
}

/// A robot whose rules let it fall past a soft limit faults on the board,
/// and nobody clears a fault in `pada run --board`: the run says so, with
/// the cause and the way out, instead of running out its periods.
#[test]
fn a_robot_that_faults_on_the_board_is_told_why() {
    let dir = tempfile::tempdir().unwrap();
    let parent = dir.path().display().to_string();
    ok(&pada(&["new-robot", "faller", "--dir", &parent]));
    let toml = dir.path().join("faller/robot.toml");
    let text = std::fs::read_to_string(&toml).unwrap();
    // The template's end keeps the arm inside its soft limits. Without it,
    // and with limits narrower than the level arm the reward asks for, the
    // arm swings past them.
    let start = text.find("[[end]]").expect("the template has an end");
    let stop = start + text[start..].find("\n\n").unwrap();
    let text = format!("{}{}", &text[..start], &text[stop..]);
    let narrow = text.replace("soft_limit_rad = [-2.5, 2.5]", "soft_limit_rad = [-0.5, 0.5]");
    assert_ne!(narrow, text, "the template's soft limits moved");
    std::fs::write(&toml, narrow).unwrap();
    let (toml, out_dir) = (toml.display().to_string(), dir.path().join("run").display().to_string());
    let out = pada(&["run", "--robot", &toml, "--board", "f405", "--algo", "sarsa", "--trials", "1", "--seconds", "120", "--out", &out_dir]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("soft-limit") && stderr.contains("shoulder"), "{stderr}");
    assert!(stderr.contains("[[end]]"), "no way out named: {stderr}");
    assert!(!stderr.contains("no end after"), "{stderr}");
}

/// Where a run stopped at a soft limit, as its error line tells it: the
/// episode, the step within it, the joint and its angle.
#[derive(Debug, PartialEq)]
struct SoftLimitEvent {
    episode: String,
    step: u32,
    joint: String,
    position: f64,
}

fn soft_limit_event(stderr: &str) -> SoftLimitEvent {
    let after = |key: &str| {
        let i = stderr.find(key).unwrap_or_else(|| panic!("no {key:?} in: {stderr}"));
        stderr[i + key.len()..].to_string()
    };
    // "… at step 7 of test episode 0 (soft-limit): joint 1 (elbow) at 0.102 rad, …"
    let at_step = after(" at step ");
    let (step, rest) = at_step.split_once(" of ").unwrap();
    let episode = rest.split_once(" (").unwrap().0.to_string();
    let joint_at = after("(soft-limit): joint ");
    let (joint, rest) = joint_at.split_once(" at ").unwrap();
    let position = rest.split_once(" rad").unwrap().0.parse().unwrap();
    SoftLimitEvent { episode, step: step.parse().unwrap(), joint: joint.to_string(), position }
}

/// The host's simulation stops at a soft limit as the board does: the same
/// joint at the same step of the same episode, and the trial ends there
/// with the cause, on the host as on the board.
///
/// The two learners draw their random tie-breaks from different generators
/// (the runner's PCG64, the board's PCG32), so here nothing they choose
/// moves the arm: the elbow is held by its P law towards 1 rad, past its
/// soft limit of 0.5 rad, and the learned shoulder's two levels lie below
/// one step of its servo's Goal PWM (0 V on the board, a tenth of a
/// millivolt apart on the host). Both runs follow the same trajectory up to
/// the servos' counts and the board's PWM steps.
#[test]
fn a_soft_limit_stops_the_host_as_it_stops_the_board() {
    let dir = tempfile::tempdir().unwrap();
    let arm2 = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2");
    std::fs::copy(arm2.join("arm2.urdf"), dir.path().join("arm2.urdf")).unwrap();
    let text = std::fs::read_to_string(arm2.join("robot.toml")).unwrap();
    let narrowed = text
        .replace(
            "id = 2\nzero_count = 2048\nstart_rad = 0.0",
            "id = 2\nzero_count = 2048\nsoft_limit_rad = [-0.1, 0.5]\nstart_rad = 0.0\nlearned = false\nhold_gain_v_per_rad = 1.5\nhold_target_rad = 1.0",
        )
        .replace("(arm straight up)\nstart_rad = 0.0", "(arm straight up)\nsoft_limit_rad = [-2.0, 2.0]\nstart_rad = 0.0")
        .replace("levels_v = [-2.0, -1.0, 0.0, 1.0, 2.0]", "levels_v = [0.0, 0.0001]");
    let edits = ["[-0.1, 0.5]", "[-2.0, 2.0]", "[0.0, 0.0001]"].map(|e| narrowed.matches(e).count());
    assert_eq!(edits, [1, 1, 1], "arm2's robot.toml moved");
    let toml = dir.path().join("robot.toml");
    std::fs::write(&toml, narrowed).unwrap();
    let toml = toml.display().to_string();
    let run = |board: &[&str], out: &str| {
        let out_dir = dir.path().join(out).display().to_string();
        let mut args = vec!["run", "--robot", &toml, "--algo", "sarsa", "--trials", "1", "--seconds", "30", "--out", &out_dir];
        args.extend_from_slice(board);
        let out = pada(&args);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(out.status.code(), Some(1), "the trial ends at the soft limit: {stderr}");
        assert!(stderr.contains("[[end]]"), "no way out named: {stderr}");
        soft_limit_event(&stderr)
    };
    let host = run(&[], "host");
    let board = run(&["--board", "f405"], "board");
    assert_eq!((host.joint.as_str(), host.episode.as_str()), ("1 (elbow)", "test episode 0"), "{host:?}");
    assert!(host.step > 10, "the arm moved for a while first: {host:?}");
    assert_eq!((&host.episode, host.step, &host.joint), (&board.episode, board.step, &board.joint), "{host:?} against {board:?}");
    // The board reads the angle in its servo's counts (4096 a turn).
    let count = std::f64::consts::TAU / 4096.0;
    assert!((host.position - board.position).abs() <= 2.0 * count, "{host:?} against {board:?}");
    assert!(host.position > 0.5, "{host:?}");
}

/// `pada run --help` says that `--board` runs a robot of files too.
#[test]
fn run_help_names_robots_of_files_for_a_board() {
    let help = String::from_utf8_lossy(&pada(&["run", "--help"]).stdout).into_owned();
    let board = help.split("--board <NAME>").nth(1).expect("--board in the help");
    let board = board.split("\n  -").next().unwrap().split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(board.contains("a robot of files (--robot robot.toml"), "{board}");
}

/// A squared-distance term and quadratic terms on a point's coordinates
/// are drawn and judged by `pada render` as a distance term is; a joint
/// with levels of its own learns on the host and on a board.
#[test]
fn every_target_on_a_point_is_drawn_and_judged_and_joints_may_have_their_own_levels() {
    let dir = tempfile::tempdir().unwrap();
    let src = PathBuf::from(reacher());
    std::fs::copy(src.with_file_name("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    let text = std::fs::read_to_string(&src).unwrap();
    let edited = text
        .replace("term = \"distance\"", "term = \"distance_squared\"")
        .replace("weight = -10.0", "weight = -50.0")
        .replace("id = 2\nzero_count = 2048\nstart_rad = 0.0", "id = 2\nzero_count = 2048\nstart_rad = 0.0\nlevels_v = [-1.0, 0.0, 1.0, 2.0]")
        + "\n[[reward]]\nterm = \"quadratic\"\nsignal = \"tip.x\"\ntarget = 0.1\nweight = 0.0\n\n[[reward]]\nterm = \"quadratic\"\nsignal = \"tip.z\"\ntarget = 0.2\nweight = 0.0\n";
    assert_eq!(edited.matches("levels_v = [-1.0, 0.0, 1.0, 2.0]").count(), 1, "the reacher's robot.toml moved");
    let toml = dir.path().join("robot.toml");
    std::fs::write(&toml, edited).unwrap();
    let toml = toml.display().to_string();
    let w = dir.path().join("w.wts").display().to_string();
    let out = |name: &str| dir.path().join(name).display().to_string();
    ok(&pada(&["run", "--robot", &toml, "--algo", "pada", "--trials", "1", "--seconds", "30", "--out", &out("host"), "--save-weights", &w]));
    ok(&pada(&["run", "--robot", &toml, "--board", "f405", "--algo", "pada", "--trials", "1", "--seconds", "10", "--out", &out("board")]));
    let rendered = ok(&pada(&["render", "--robot", &toml, "--policy", &w, "--out", &out("render")]));
    // The squared distance's goal, and the two coordinates' together.
    assert!(rendered.lines().any(|l| l.starts_with("tip: over the last half")), "{rendered}");
    assert!(rendered.lines().any(|l| l.starts_with("tip_xz: over the last half")), "{rendered}");
    let csv = std::fs::read_to_string(dir.path().join("render/motion.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.ends_with("tip_distance_m,tip_xz_distance_m"), "{header}");
    // Both targets are the same point: (0.1, 0, 0.2) and (0.1, ·, 0.2) on
    // an arm that moves in the x–z plane.
    for row in csv.lines().skip(1) {
        let v: Vec<f64> = row.rsplit(',').take(2).map(|x| x.parse().unwrap()).collect();
        assert!((v[0] - v[1]).abs() < 1e-5, "{row}");
    }
}
