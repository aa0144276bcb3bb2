//! One telemetry path: `pada run --telemetry` streams the firmware's wire
//! frames for a host simulation, to a file or a loopback TCP listener, and
//! `pada capture` reads them like a board's.

use pada_core::wire::{HostDecoder, RunMode, ToHost};
use std::io::Read;
use std::net::TcpListener;
use std::path::Path;
use std::process::Command;

fn pada_run(out: &Path, telemetry: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pada"))
        .args([
            "run",
            "--task",
            "physical-pendulum",
            "--algo",
            "pada",
            "--trials",
            "2",
            "--seconds",
            "30",
            "--threads",
            "2",
            "--telemetry",
            telemetry,
            "--out",
        ])
        .arg(out)
        .output()
        .unwrap()
}

/// Trial 0's test returns from `pada run`'s own CSV.
fn test_returns(out: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("trial-000.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn pada_run_streams_trial_0_as_wire_frames_that_capture_reads() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("run.bin");
    let out = pada_run(&dir.path().join("run"), stream.to_str().unwrap());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let bytes = std::fs::read(&stream).unwrap();
    let mut d = HostDecoder::new();
    let msgs: Vec<ToHost> = d.feed(&bytes).map(|f| f.unwrap().msg).collect();
    assert!(d.stats().is_clean());
    assert!(matches!(msgs[0], ToHost::Hello(_)));
    let episodes: Vec<_> = msgs
        .iter()
        .filter_map(|m| match m {
            ToHost::Episode(e) => Some(*e),
            _ => None,
        })
        .collect();
    // 30 s of 3 s episodes: 10 learning episodes, a test before and after.
    assert_eq!(
        episodes
            .iter()
            .filter(|e| e.mode == RunMode::Learning)
            .count(),
        10
    );
    let tests: Vec<f64> = episodes
        .iter()
        .filter(|e| e.mode == RunMode::Testing)
        .map(|e| e.total_reward as f64)
        .collect();
    let want = test_returns(&dir.path().join("run"));
    assert_eq!(tests.len(), want.len());
    for (a, b) in tests.iter().zip(&want) {
        assert!(
            (a - b).abs() <= 1e-3 * b.abs().max(1.0),
            "stream {a} vs trial CSV {b}"
        );
    }
    // Every agent call: a start, 99 steps and an end per 100-step episode.
    let steps = msgs.iter().filter(|m| matches!(m, ToHost::Step(_))).count();
    assert_eq!(steps, episodes.len() * 101);

    let cap = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["capture", "--json", "--file"])
        .arg(&stream)
        .output()
        .unwrap();
    assert!(
        cap.status.success(),
        "{}",
        String::from_utf8_lossy(&cap.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&cap.stdout).unwrap();
    assert_eq!(json["link"]["frames"], msgs.len() as u64);
    assert_eq!(json["bad_frames"], 0);
    assert_eq!(json["link"]["seq_gaps"], 0);
    assert_eq!(json["latest"]["learning_episodes"], 10);

    // The same run to a loopback TCP listener: the same bytes.
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let reader = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut got = Vec::new();
        s.read_to_end(&mut got).unwrap();
        got
    });
    let out = pada_run(
        &dir.path().join("run-tcp"),
        &format!("tcp:127.0.0.1:{port}"),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        reader.join().unwrap() == bytes,
        "the TCP stream differs from the file"
    );
}

#[test]
fn telemetry_goes_to_loopback_only_and_bad_targets_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    for target in ["tcp:10.1.2.3:9000", "tcp:127.0.0.1", "tcp:127.0.0.1:1"] {
        let out = pada_run(&dir.path().join("x"), target);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{target}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error: --telemetry"), "{target}: {err}");
    }
}

#[test]
fn a_governed_run_streams_the_governors_delta_and_damage_rate() {
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("gov.bin");
    let out = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["run", "--algo", "lowpass", "--mtbf-budget", "2600", "--trials", "1", "--seconds", "120", "--telemetry"])
        .arg(&stream)
        .arg("--out")
        .arg(dir.path().join("run"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&stream).unwrap();
    let mut d = HostDecoder::new();
    let reports: Vec<_> = d
        .feed(&bytes)
        .filter_map(|f| match f.unwrap().msg {
            ToHost::Policy(p) => Some(p),
            _ => None,
        })
        .collect();
    // The governor's every move and its status after every episode.
    let governed: Vec<_> = reports.iter().filter_map(|p| p.governor.map(|g| (p.built, g))).collect();
    assert!(governed.len() > 40, "{} governed reports", governed.len());
    for (built, g) in &governed {
        assert_eq!(*built, pada_core::policy::PolicyKind::LowPass { alpha: g.parameter }, "the α in force");
        assert_eq!(g.budget_s, 2600.0);
        assert!(g.damage_rate.is_finite() && g.damage_rate >= 0.0);
        assert!(g.window_steps <= 1200);
    }
    let alphas: std::collections::BTreeSet<u32> = governed.iter().map(|(_, g)| g.parameter.to_bits()).collect();
    assert!(alphas.len() >= 3, "α moved over {} values", alphas.len());
    assert!(governed.iter().any(|(_, g)| g.damage_rate > 0.0));

    // `pada capture --out` writes one CSV row per frame, the report's text
    // in it.
    let csv = dir.path().join("frames.csv");
    let cap = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["capture", "--file"])
        .arg(&stream)
        .arg("--out")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(cap.status.success(), "{}", String::from_utf8_lossy(&cap.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.contains("wear governor: budget 2600 s") && text.contains("damage rate"), "{text}");
}
