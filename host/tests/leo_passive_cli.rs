//! `pada leo passive` through the real binary: the JSON's keys and their
//! consistency, the text table, one-line errors for bad flags, `--help`,
//! and a reader that closes the pipe early.

mod common;
use common::{assert_bad_input, pada};

use std::io::Read;
use std::process::{Command, Stdio};

#[test]
fn json_has_the_documented_keys_and_they_agree() {
    let out = pada(&["leo", "passive", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    for key in ["steps", "fell", "fall_time_s", "fall_steps", "return"] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    let steps = v["steps"].as_array().unwrap();
    assert_eq!(
        v["fell"], true,
        "the passive robot falls within the default 2 s"
    );
    let n = v["fall_steps"].as_u64().unwrap() as usize;
    assert_eq!(n, steps.len(), "the rollout stops at the fall");
    let period = 1.0 / 30.0;
    let t = v["fall_time_s"].as_f64().unwrap();
    assert!(
        (t - n as f64 * period).abs() < 1e-4,
        "fall at {t} s after {n} steps"
    );
    let sum: f64 = steps.iter().map(|s| s["reward"].as_f64().unwrap()).sum();
    let ret = v["return"].as_f64().unwrap();
    assert!(
        (sum - ret).abs() < 1e-3 * ret.abs().max(1.0),
        "return {ret} against the sum {sum}"
    );
    // The last step is the fall: |φ| > 1 or the fall reward.
    let last = steps.last().unwrap();
    assert!(last["reward"].as_f64().unwrap() < -100.0);
    for (k, s) in steps.iter().enumerate() {
        assert_eq!(s["step"].as_u64().unwrap() as usize, k + 1);
        assert!((s["time_s"].as_f64().unwrap() - (k + 1) as f64 * period).abs() < 1e-4);
        let q = s["joint_angles_rad"].as_object().unwrap();
        assert_eq!(q.len(), 7, "{q:?}");
        for name in pada_core::robot::leo::JOINT_SPECS.map(|j| j.name) {
            assert!(q[name].as_f64().unwrap().is_finite(), "{name}");
        }
        let u = &s["ankle_voltages_v"];
        for side in ["left", "right"] {
            assert!(
                u[side].as_f64().unwrap().abs() <= 10.7,
                "ankle voltage {side} {u}"
            );
        }
        assert!(s["torso_angle_rad"].as_f64().unwrap().is_finite());
        assert!(s["torso_rate_rad_s"].as_f64().unwrap().is_finite());
    }
}

#[test]
fn the_table_ends_with_the_fall() {
    let out = pada(&["leo", "passive", "--seconds", "1.5"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    let last = text.lines().last().unwrap();
    assert!(last.starts_with("fell after "), "{last}");
    assert!(last.contains("return"), "{last}");
    // A run too short for the fall says so.
    let out = pada(&["leo", "passive", "--seconds", "0.1"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.lines()
            .last()
            .unwrap()
            .starts_with("did not fall in 0.100 s (3 steps)"),
        "{text}"
    );
}

#[test]
fn bad_flags_name_the_valid_range() {
    assert_bad_input(
        &["leo", "passive", "--seconds", "0"],
        &["--seconds 0", "0 < seconds <= 3600"],
    );
    assert_bad_input(
        &["leo", "passive", "--seconds", "nan"],
        &["0 < seconds <= 3600"],
    );
    assert_bad_input(
        &["leo", "passive", "--seconds", "1e9"],
        &["0 < seconds <= 3600"],
    );
    assert_bad_input(
        &["leo", "passive", "--seconds", "two"],
        &["--seconds", "two"],
    );
    assert_bad_input(
        &["leo", "passive", "--substeps", "0"],
        &["--substeps", "1..=1000"],
    );
    assert_bad_input(
        &["leo", "passive", "--solver-iterations", "101"],
        &["--solver-iterations", "1..=100"],
    );
    assert_bad_input(&["leo", "passive", "--frobnicate"], &["--frobnicate"]);
    assert_bad_input(&["leo"], &["pada leo needs a subcommand", "passive"]);
    assert_bad_input(&["leo", "walk"], &["walk", "valid is passive"]);
}

#[test]
fn help_explains_the_rollout() {
    let out = pada(&["leo", "passive", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "0 V on the learned joints",
        "--seconds",
        "--json",
        "fall_time_s",
        "--substeps",
    ] {
        assert!(text.contains(needle), "help lacks {needle:?}: {text}");
    }
}

#[test]
fn a_closed_pipe_is_a_one_line_error() {
    // A pipe whose reading end is closed before pada starts: every write
    // fails, however fast pada is (closing it after the spawn raced a
    // fast run, which wrote its rollout into the pipe's buffer first).
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["leo", "passive", "--json"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .spawn()
        .expect("pada runs");
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "stderr {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: cannot write the rollout to stdout"),
        "{stderr}"
    );
}
