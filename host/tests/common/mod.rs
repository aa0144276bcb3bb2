//! What the binary's tests share: the real `pada`, run as a user runs it
//! (without a cluster's task index in its environment), the checks of its
//! exit codes and output, and the frames of a recorded telemetry stream.

#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs `pada` with `args`.
pub fn pada(args: &[&str]) -> Output {
    pada_env(args, &[])
}

/// Runs `pada` with `args` and the variables `env` set; a Slurm or
/// Kubernetes task index of the calling shell is removed.
pub fn pada_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_pada"));
    cmd.args(args).env_remove("SLURM_ARRAY_TASK_ID").env_remove("JOB_COMPLETION_INDEX");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("pada runs")
}

/// Asserts success (exit code 0) and returns stdout.
pub fn ok(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(0), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Asserts a bad-input failure: exit code 2, nothing on stdout, exactly
/// one line on stderr starting with `error:` and containing every `needle`.
pub fn assert_bad_input(args: &[&str], needles: &[&str]) {
    let out = pada(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {stderr}");
    assert!(out.stdout.is_empty(), "{args:?}: stdout {}", String::from_utf8_lossy(&out.stdout));
    assert_eq!(stderr.lines().count(), 1, "{args:?}: not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{args:?}: {stderr:?} lacks {n:?}");
    }
}

/// Frame boundaries of a COBS stream: (start, end), the end exclusive and
/// past the frame's 0x00.
pub fn frames(stream: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in stream.iter().enumerate() {
        if b == 0 {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    out
}

/// A run's JSON summary without the three measurements of its timing
/// (wall time, rate, workers), each of which must be there.
pub fn without_timing(v: &serde_json::Value) -> serde_json::Value {
    let mut v = v.clone();
    for k in ["wall_s", "env_steps_per_s", "threads"] {
        assert!(v.as_object_mut().unwrap().remove(k).is_some(), "{k} present");
    }
    v
}

/// `clean`, a recorded stream, damaged as a serial line damages one:
/// before each frame of `garbage_before` a burst of non-zero bytes ending
/// in a delimiter (line noise that looks like a frame), the frames of
/// `dropped` cut out (lost on the line), and in each frame of `corrupt` a
/// byte in the middle changed to another non-zero value (a CRC error or
/// broken COBS). Frame indices are those of [`frames`].
pub fn damaged(clean: &[u8], garbage_before: &[usize], dropped: &[usize], corrupt: &[usize]) -> Vec<u8> {
    let mut out = Vec::new();
    for (k, &(a, b)) in frames(clean).iter().enumerate() {
        if garbage_before.contains(&k) {
            out.extend((1..=37u8).map(|x| x.wrapping_mul(73) | 1));
            out.push(0);
        }
        if dropped.contains(&k) {
            continue;
        }
        let start = out.len();
        out.extend_from_slice(&clean[a..b]);
        if corrupt.contains(&k) {
            let i = start + (b - a) / 2;
            out[i] = if out[i] == 0xFF { 0x7F } else { out[i] + 1 };
        }
    }
    out
}
