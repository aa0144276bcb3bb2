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
