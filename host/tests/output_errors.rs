//! The real `pada` binary with an output that fails: standard output a full
//! device (`> /dev/full`) or a pipe whose reader has gone (`| true`). Every
//! command must then exit non-zero with one line on stderr naming the
//! problem, never panic (exit 101). Also `pada capture`'s exit code on a
//! read error and on a directory.

mod common;

use std::fs::File;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn pada() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pada"))
}

/// A small valid telemetry stream: the recorded SIL run.
fn recording() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sil-pendulum-3s.bin")
}

fn torque_log(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("torques.csv");
    let mut csv = String::from("a,b\n");
    for k in 0..50 {
        csv.push_str(&format!("{},0.5\n", if k % 2 == 0 { 1.5 } else { -1.5 }));
    }
    std::fs::write(&p, csv).unwrap();
    p
}

/// Asserts exit code 1 and exactly one `error:` line naming standard output.
fn assert_output_error(out: &Output, what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{what}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(lines.len(), 1, "{what}: {err}");
    assert!(
        lines[0].contains("cannot write to standard output"),
        "{what}: {err}"
    );
    assert!(!err.contains("panicked"), "{what}: {err}");
}

/// The commands to try, each cheap: capture (JSON and text), mtbf, run.
fn commands(dir: &Path) -> Vec<Vec<String>> {
    let file = recording().display().to_string();
    let log = torque_log(dir).display().to_string();
    let out = dir.join("run").display().to_string();
    // Each line's words, with `@` standing for the one path (which may hold
    // spaces).
    let line = |text: &str, path: &str| text.split(' ').map(|w| if w == "@" { path.to_string() } else { w.to_string() }).collect();
    vec![
        line("capture --file @ --json", &file),
        line("mtbf --torques @", &log),
        line("mtbf --torques @ --json", &log),
        line("run --task pendulum --algo sarsa --trials 1 --seconds 30 --threads 1 --out @", &out),
    ]
}

#[test]
fn a_full_standard_output_is_one_line_and_exit_code_1_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    for args in commands(dir.path()) {
        let out = pada()
            .args(&args)
            .stdin(Stdio::null())
            .stdout(File::create("/dev/full").unwrap())
            .output()
            .unwrap();
        assert_output_error(&out, &format!("{args:?} > /dev/full"));
    }
}

#[test]
fn a_closed_pipe_is_one_line_and_exit_code_1_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    for args in commands(dir.path()) {
        // The reader is gone before the command starts (as `| true` once
        // `true` has exited): every write fails with EPIPE.
        let (reader, writer) = rustix::pipe::pipe().unwrap();
        drop(reader);
        let out = pada()
            .args(&args)
            .stdin(Stdio::null())
            .stdout(Stdio::from(writer))
            .output()
            .unwrap();
        assert_output_error(&out, &format!("{args:?} | true"));
    }
}

#[test]
fn capture_of_a_directory_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = pada()
        .args(["capture", "--json", "--file"])
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("is a directory") && err.lines().count() == 1,
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn a_read_error_ends_the_capture_with_its_summary_and_exit_code_1() {
    // Reading /proc/self/mem at offset 0 fails with EIO: a read error after
    // the file opened.
    let out = pada()
        .args(["capture", "--json", "--file", "/proc/self/mem"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        json["ended"].as_str().unwrap().starts_with("read error"),
        "{json}"
    );
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains("read error"), "{err}");
}

#[test]
fn a_stream_cut_off_at_the_end_reports_the_loss() {
    // Regression: trailing bytes without a delimiter were never
    // counted, so a 10 MB file without a zero byte reported a clean link.
    let dir = tempfile::tempdir().unwrap();
    let noise = dir.path().join("noise.bin");
    std::fs::write(&noise, vec![0x5Au8; 10 << 20]).unwrap();
    let json = common::capture_json(&noise, None);
    assert_eq!(json["link"]["truncated"], 1, "{json}");
    assert_eq!(json["bad_frames"], 1, "{json}");
    assert_eq!(json["link"]["frames"], 0);
}

#[test]
fn a_full_standard_error_does_not_make_a_command_panic() {
    // Status lines and messages go to stderr; when it cannot be written
    // there is nowhere to report that, but the command must not panic.
    let out = pada()
        .args(["capture", "--file"])
        .arg(recording())
        .stderr(File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let out = pada()
        .args(["capture", "--file", "/nonexistent"])
        .stderr(File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "bad input still exits 2");
}
