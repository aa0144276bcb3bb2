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

/// A pseudo-terminal standing in for a USB serial adapter: its master and
/// the path of its slave, already in raw mode (set before anything is
/// written, so the line discipline passes every byte through, as `pada
/// capture` sets it through serialport). The master is close-on-exec: a
/// child holding it would keep the pty alive.
pub fn raw_pty() -> (std::os::fd::OwnedFd, String) {
    use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
    use rustix::termios::{tcgetattr, tcsetattr, OptionalActions};
    let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC).expect("openpt");
    grantpt(&master).expect("grantpt");
    unlockpt(&master).expect("unlockpt");
    let slave = ptsname(&master, Vec::new()).expect("ptsname").into_string().unwrap();
    let fd = std::fs::OpenOptions::new().read(true).write(true).open(&slave).unwrap();
    let mut t = tcgetattr(&fd).unwrap();
    t.make_raw();
    tcsetattr(&fd, OptionalActions::Now, &t).unwrap();
    (master, slave)
}

/// Plugs an adapter in at `link`: a fresh [`raw_pty`] whose slave the
/// symbolic link `link` names from now on (replaced in one rename, as
/// udev does); returns its master.
pub fn plug_at(link: &std::path::Path) -> std::fs::File {
    let (master, slave) = raw_pty();
    let tmp = link.with_extension("new");
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(&slave, &tmp).unwrap();
    std::fs::rename(&tmp, link).unwrap();
    std::fs::File::from(master)
}

/// `pada capture --file F --json [--out CSV]`, parsed.
pub fn capture_json(file: &std::path::Path, csv: Option<&std::path::Path>) -> serde_json::Value {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pada"));
    c.args(["capture", "--json", "--file"]).arg(file);
    if let Some(csv) = csv {
        c.arg("--out").arg(csv);
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}
