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
