//! `pada drive` and `pada servos` in real time ask for a real-time thread
//! (SCHED_FIFO, locked memory) and say what they were granted: granted
//! where the process may (root, CAP_SYS_NICE), refused with the reason and
//! the fix in a child without the capabilities, and the run goes on either
//! way; `--no-realtime` asks nothing.

mod common;

use common::ok;
use rustix::process::{getrlimit, setrlimit, Resource, Rlimit};
use rustix::thread::CapabilitySet;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const PADA: &str = env!("CARGO_BIN_EXE_pada");

/// `pada` with `args`; `without_rights`: in a child that has neither
/// CAP_SYS_NICE nor CAP_IPC_LOCK (dropped from its bounding set, so that
/// root loses them at exec), no real-time priority limit and 64 KiB of
/// locked memory at most.
fn pada(args: &[&str], without_rights: bool) -> Command {
    let mut cmd = Command::new(PADA);
    cmd.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    if without_rights {
        // SAFETY: between fork and exec only system calls are made (prctl,
        // setrlimit), no allocation and no lock.
        unsafe {
            cmd.pre_exec(|| {
                for cap in [CapabilitySet::SYS_NICE, CapabilitySet::IPC_LOCK] {
                    // Refused (EPERM) without CAP_SETPCAP: then the process
                    // had neither capability to lose.
                    let _ = rustix::thread::remove_capability_from_bounding_set(cap);
                }
                setrlimit(Resource::Rtprio, Rlimit { current: Some(0), maximum: Some(0) })?;
                setrlimit(Resource::Memlock, Rlimit { current: Some(64 << 10), maximum: Some(64 << 10) })?;
                Ok(())
            });
        }
    }
    cmd
}

/// Whether this process may have a SCHED_FIFO thread at 49 and lock its
/// memory (what a child with its rights is granted).
fn rights() -> (bool, bool) {
    let caps = rustix::thread::capabilities(None).expect("capget").effective;
    let rtprio = getrlimit(Resource::Rtprio).current.is_none_or(|r| r >= 49);
    let memlock = getrlimit(Resource::Memlock).current.is_none();
    (caps.contains(CapabilitySet::SYS_NICE) || rtprio, caps.contains(CapabilitySet::IPC_LOCK) || memlock)
}

/// `pada servos` in real time on `dir/dxl`, its port there.
fn servos(dir: &Path, extra: &[&str], without_rights: bool) -> Child {
    let port = dir.join("dxl");
    let mut args = vec!["servos", "--port", port.to_str().unwrap(), "--robot", "pendulum", "--json", "--seconds", "60"];
    args.extend_from_slice(extra);
    let child = pada(&args, without_rights).spawn().expect("pada servos starts");
    let deadline = Instant::now() + Duration::from_secs(30);
    while std::fs::symlink_metadata(&port).is_err() {
        assert!(Instant::now() < deadline, "pada servos made no port");
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

fn interrupt(child: &Child) {
    rustix::process::kill_process(rustix::process::Pid::from_child(child), rustix::process::Signal::INT).expect("SIGINT");
}

/// Stops `child` as Ctrl-C does after `after`; its output.
fn stop_after(child: Child, after: Duration) -> Output {
    std::thread::sleep(after);
    interrupt(&child);
    child.wait_with_output().unwrap()
}

/// A drive that ended as a run ends: Ctrl-C (exit 0), or a fault of the
/// safety machine (exit 2), which a busy machine may cause in a run at the
/// ordinary priority: the run went on either way. Its stdout.
fn ran(o: &Output) -> String {
    let stderr = String::from_utf8_lossy(&o.stderr);
    match o.status.code() {
        Some(0) => {}
        Some(2) => assert!(stderr.contains("error: fault:"), "not a fault: {stderr}"),
        c => panic!("exit {c:?}: {stderr}"),
    }
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s).unwrap_or_else(|e| panic!("{e}: {s}"))
}

#[test]
fn pada_servos_in_real_time_is_granted_what_its_rights_allow_and_says_what_was_refused() {
    let (fifo, lock) = rights();
    let dir = tempfile::tempdir().unwrap();
    let summary = json(&ok(&stop_after(servos(dir.path(), &[], false), Duration::from_millis(500))));
    let rt = &summary["realtime"];
    assert_eq!(rt["priority"]["status"], if fifo { "granted" } else { "refused" }, "{rt}");
    if lock {
        assert_eq!(rt["locked_memory"]["status"], "granted", "{rt}");
    }

    let dir = tempfile::tempdir().unwrap();
    let out = stop_after(servos(dir.path(), &[], true), Duration::from_millis(500));
    let summary = json(&ok(&out));
    let rt = &summary["realtime"];
    assert_eq!(rt["priority"]["status"], "refused", "{rt}");
    let why = rt["priority"]["detail"].as_str().unwrap();
    assert!(why.starts_with("SCHED_FIFO 49: Operation not permitted") && why.contains("cap_sys_nice"), "{why}");
    assert_eq!(rt["locked_memory"]["status"], "refused", "{rt}");
    assert!(rt["locked_memory"]["detail"].as_str().unwrap().contains("RLIMIT_MEMLOCK 64 KiB"), "{rt}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("servos: real time: priority: refused (SCHED_FIFO 49: Operation not permitted"), "{stderr}");
    assert_eq!(summary["ended"], "interrupted", "the servos served on without it");

    // Lock step waits for the client: nothing asked.
    let dir = tempfile::tempdir().unwrap();
    let summary = json(&ok(&stop_after(servos(dir.path(), &["--lockstep"], false), Duration::from_millis(200))));
    assert_eq!(summary["realtime"]["priority"]["status"], "not-asked", "{}", summary["realtime"]);
}

/// `pada drive` of the pendulum in real time on `port` into `out` for a
/// couple of seconds, stopped by Ctrl-C.
fn drive(port: &Path, out: &Path, extra: &[&str], without_rights: bool) -> Output {
    let mut args = vec!["drive", "--port", port.to_str().unwrap(), "--robot", "pendulum", "--seconds", "100000", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let child = pada(&args, without_rights).spawn().expect("pada drive starts");
    stop_after(child, Duration::from_secs(3))
}

#[test]
fn pada_drive_without_the_rights_goes_on_and_says_what_was_refused_and_no_realtime_asks_nothing() {
    let (fifo, _) = rights();
    let dir = tempfile::tempdir().unwrap();
    let servos = servos(dir.path(), &[], false);
    let port = dir.path().join("dxl");

    let refused = dir.path().join("refused");
    let o = drive(&port, &refused, &[], true);
    let stdout = ran(&o);
    assert!(stdout.contains("real time: priority refused, locked memory refused, CPU affinity not asked"), "{stdout}");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("drive: real time: priority: refused (SCHED_FIFO 49: Operation not permitted"), "{stderr}");
    let report = json(&std::fs::read_to_string(refused.join("drive.json")).unwrap());
    assert!(["interrupted", "fault"].contains(&report["ended"]["kind"].as_str().unwrap()), "{}", report["ended"]);
    assert!(report["clock"]["periods"].as_u64().unwrap() >= 1, "it ran on: {}", report["clock"]);
    let summary = json(&std::fs::read_to_string(refused.join("summary.json")).unwrap());
    assert_eq!(summary["realtime"], report["realtime"], "summary.json says it too");
    assert_eq!(summary["realtime"]["priority"]["status"], "refused");
    assert_eq!(summary["realtime"]["locked_memory"]["status"], "refused");
    assert_eq!(summary["trials"], 1, "pada run --board's summary is kept: {summary}");
    assert!(summary["board_per_trial"].is_array(), "{summary}");

    let asked = dir.path().join("asked");
    let report_of = |d: &Path| json(&std::fs::read_to_string(d.join("drive.json")).unwrap());
    ran(&drive(&port, &asked, &[], false));
    assert_eq!(report_of(&asked)["realtime"]["priority"]["status"], if fifo { "granted" } else { "refused" });

    let off = dir.path().join("off");
    ran(&drive(&port, &off, &["--no-realtime"], false));
    let rt = &report_of(&off)["realtime"];
    assert_eq!(rt["priority"], json(r#"{"status": "not-asked", "detail": "--no-realtime"}"#));
    assert_eq!(rt["locked_memory"]["status"], "not-asked");
    ok(&stop_after(servos, Duration::ZERO));
}
