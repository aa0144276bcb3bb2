//! `pada drive` against `pada servos` over a pseudo-terminal, with no
//! hardware: the PC's controller on virtual servos in lock step learns
//! what `pada run --board` learns for the same seed, torque goes off at
//! the end and on Ctrl-C, and bad input (a servo of another model, a
//! missing servo) is one line with torque off.

mod common;

use common::ok;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const PADA: &str = env!("CARGO_BIN_EXE_pada");

fn arm() -> String {
    format!("{}/../examples/robots/arm2/robot.toml", env!("CARGO_MANIFEST_DIR"))
}

/// `pada servos --port DIR/dxl --json` with `args`, started and its port
/// there.
struct Servos {
    child: Option<Child>,
    port: PathBuf,
}

impl Servos {
    fn start(dir: &Path, args: &[&str]) -> Servos {
        let port = dir.join("dxl");
        let child = Command::new(PADA)
            .args(["servos", "--port", port.to_str().unwrap(), "--json", "--seconds", "600"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("pada servos starts");
        let deadline = Instant::now() + Duration::from_secs(30);
        while std::fs::symlink_metadata(&port).is_err() {
            assert!(Instant::now() < deadline, "pada servos made no port");
            std::thread::sleep(Duration::from_millis(20));
        }
        Servos { child: Some(child), port }
    }

    fn port(&self) -> &str {
        self.port.to_str().unwrap()
    }

    /// Stops it as Ctrl-C does; its summary.
    fn stop(mut self) -> serde_json::Value {
        let child = self.child.take().unwrap();
        interrupt(&child);
        let out = child.wait_with_output().unwrap();
        let stdout = ok(&out);
        serde_json::from_str(&stdout).expect("the summary is JSON")
    }
}

impl Drop for Servos {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

fn interrupt(child: &Child) {
    let pid = rustix::process::Pid::from_child(child);
    rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
}

/// What servo `id` did, in order (`torque-on`, `torque-off`, …).
fn events(summary: &serde_json::Value, id: u64) -> Vec<String> {
    summary["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["id"] == id)
        .map(|e| e["what"].as_str().unwrap().to_string())
        .collect()
}

fn drive(args: &[&str]) -> std::process::Output {
    Command::new(PADA).arg("drive").args(args).output().expect("pada drive runs")
}

/// `pada drive --lockstep` of the pendulum on `port` for as long as it
/// takes, started, once it is learning (its telemetry log in `out` grows
/// past 20 kB).
fn start_drive_until_learning(port: &str, out: &Path) -> Child {
    let child = Command::new(PADA)
        .args(["drive", "--port", port, "--robot", "pendulum", "--lockstep", "--seconds", "100000"])
        .args(["--out", out.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let csv = out.join("telemetry.csv");
    let deadline = Instant::now() + Duration::from_secs(60);
    while std::fs::metadata(&csv).map_or(0, |m| m.len()) < 20_000 {
        assert!(Instant::now() < deadline, "pada drive did not get going");
        std::thread::sleep(Duration::from_millis(50));
    }
    child
}

/// When servo `id` first did `what` \[µs of bus time\].
fn event_at(summary: &serde_json::Value, id: u64, what: &str) -> Option<u64> {
    summary["events"].as_array().unwrap().iter().find(|e| e["id"] == id && e["what"] == what).map(|e| e["at_us"].as_u64().unwrap())
}

/// Asserts that each servo of `ids` turned torque on first and off last.
fn assert_torque_on_then_off(summary: &serde_json::Value, ids: impl IntoIterator<Item = u64>) {
    for id in ids {
        let servo = events(summary, id);
        assert_eq!(servo.first().map(String::as_str), Some("torque-on"), "servo {id}: {servo:?}");
        assert_eq!(servo.last().map(String::as_str), Some("torque-off"), "servo {id}: {servo:?}");
    }
}

/// The learning curve of the first trial in `dir`.
fn curve(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("trial-000.csv")).unwrap()
}

/// The report `pada drive` wrote in `out`.
fn drive_report(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("drive.json")).unwrap()).unwrap()
}

#[test]
fn drive_on_virtual_servos_in_lock_step_learns_as_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--lockstep"]);
    let out = dir.path().join("drive");
    let o = drive(&[
        "--port", servos.port(), "--robot", "pendulum", "--lockstep", "--board", "f405", "--algo", "pada", "--seed", "3",
        "--seconds", "30", "--out", out.to_str().unwrap(),
    ]);
    let stdout = ok(&o);
    assert!(stdout.contains("0 overruns"), "{stdout}");
    let summary = servos.stop();
    // Torque on for the episodes, off at the end.
    assert_torque_on_then_off(&summary, [1]);
    assert_eq!(summary["stats"]["damaged"], 0);

    let run = dir.path().join("run");
    ok(&common::pada(&[
        "run", "--board", "f405", "--task", "physical-pendulum", "--algo", "pada", "--seed", "3", "--seconds", "30",
        "--trials", "1", "--out", run.to_str().unwrap(),
    ]));
    let (driven, simulated) = (curve(&out), curve(&run));
    assert!(driven.lines().count() >= 3, "a test episode before and after learning: {driven}");
    assert_eq!(driven, simulated, "the learning curve over the pty is pada run --board's, episode for episode");

    let report = drive_report(&out);
    assert_eq!(report["ended"]["kind"], "done");
    assert_eq!(report["bus"]["checksum_errors"], 0);
    assert_eq!(report["bus"]["timeouts"], 0, "every request answered");
    assert!(report["clock"]["periods"].as_u64().unwrap() >= 1000, "{}", report["clock"]);
}

#[test]
fn the_arm_of_files_on_protocol_2_in_lock_step_learns_as_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let arm = arm();
    let servos = Servos::start(dir.path(), &["--robot", &arm, "--lockstep"]);
    let out = dir.path().join("drive");
    let o = drive(&[
        "--port", servos.port(), "--robot", &arm, "--lockstep", "--board", "f405", "--algo", "pada", "--seed", "1", "--seconds", "30",
        "--json", "--out", out.to_str().unwrap(),
    ]);
    let report: serde_json::Value = serde_json::from_str(&ok(&o)).expect("drive.json on stdout");
    let summary = servos.stop();
    assert_eq!(report["ended"]["kind"], "done");
    // One FAST SYNC READ (16 B out, 62 B back), Torque Enable (13 B) and one
    // SYNC WRITE of Goal PWM (20 B) a period: 111 bytes.
    assert_eq!(report["bus"]["fast_sync_read"], true);
    assert_eq!(report["bus"]["timeouts"], 0, "every request answered");
    let per_period = report["bus"]["bytes_per_period"].as_f64().unwrap();
    assert!((per_period - 111.0).abs() < 1.0, "{per_period}");
    for id in [1, 2] {
        let servo = events(&summary, id);
        assert_eq!(servo.last().map(String::as_str), Some("torque-off"), "servo {id}: {servo:?}");
    }
    assert!(summary["stats"]["sync_writes"].as_u64().unwrap() >= 1000);
    // The learning curve of `pada run --board` on the same arm: the X-series
    // servos' own units on both paths, and the operator's calls heard.
    let run = dir.path().join("run");
    ok(&common::pada(&[
        "run", "--board", "f405", "--robot", &arm, "--algo", "pada", "--seed", "1", "--seconds", "30", "--trials", "1",
        "--out", run.to_str().unwrap(),
    ]));
    assert!(curve(&out).lines().count() >= 3);
    assert_eq!(curve(&out), curve(&run), "the arm over the pty learns as pada run --board's, episode for episode");
}

/// The SO-101 of files: six STS3215s in Operating Mode 2 behind the
/// robot's simulated physics, one SYNC READ and one SYNC WRITE a period,
/// learn what `pada run --board` learns (the duty cycles in 0.1 %, the
/// held joints' P law and the 5 V supply reading on both paths).
#[test]
fn the_so101_on_feetech_servos_in_lock_step_learns_as_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let so101 = format!("{}/../examples/robots/so101", env!("CARGO_MANIFEST_DIR"));
    let servos = Servos::start(dir.path(), &["--robot", &so101, "--lockstep"]);
    let out = dir.path().join("drive");
    let o = drive(&[
        "--port", servos.port(), "--robot", &so101, "--lockstep", "--board", "f405", "--algo", "pada", "--seed", "2", "--seconds", "60",
        "--json", "--out", out.to_str().unwrap(),
    ]);
    let report: serde_json::Value = serde_json::from_str(&ok(&o)).expect("drive.json on stdout");
    let summary = servos.stop();
    assert_eq!(report["ended"]["kind"], "done");
    assert_eq!((report["bus"]["timeouts"].as_u64(), report["bus"]["checksum_errors"].as_u64()), (Some(0), Some(0)));
    assert_eq!(summary["stats"]["damaged"], 0);
    // One SYNC WRITE ends each lock-step period.
    assert_eq!(summary["stats"]["sync_writes"].as_u64(), report["clock"]["periods"].as_u64());
    assert_torque_on_then_off(&summary, 1..=6);
    let run = dir.path().join("run");
    ok(&common::pada(&[
        "run", "--board", "f405", "--robot", &so101, "--algo", "pada", "--seed", "2", "--seconds", "60", "--trials", "1", "--out",
        run.to_str().unwrap(),
    ]));
    let driven = curve(&out);
    assert!(driven.lines().count() >= 3, "a test episode before and after learning: {driven}");
    let returns: Vec<&str> = driven.lines().skip(1).map(|l| l.rsplit(',').next().unwrap()).collect();
    assert!(returns.windows(2).any(|w| w[0] != w[1]), "the arm moved between the tests: {driven}");
    assert_eq!(driven, curve(&run), "the SO-101 over the pty learns as pada run --board's, episode for episode");
}

#[test]
fn ctrl_c_turns_torque_off_and_keeps_the_log() {
    let dir = tempfile::tempdir().unwrap();
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--lockstep"]);
    let out = dir.path().join("drive");
    // Until it learns, then Ctrl-C.
    let child = start_drive_until_learning(servos.port(), &out);
    let csv = out.join("telemetry.csv");
    interrupt(&child);
    let o = child.wait_with_output().unwrap();
    ok(&o);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("interrupted: torque off"), "{stderr}");
    let summary = servos.stop();
    let servo = events(&summary, 1);
    assert_eq!(servo.last().map(String::as_str), Some("torque-off"), "{servo:?}");
    let report = drive_report(&out);
    assert_eq!(report["ended"]["kind"], "interrupted");
    assert!(out.join("checkpoint.bin").is_file());
    assert!(std::fs::metadata(&csv).unwrap().len() >= 20_000);
}

/// Exit code 2, one line, every needle.
fn bad_input(o: &std::process::Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    for n in needles {
        assert!(errors[0].contains(n), "{:?} lacks {n:?}", errors[0]);
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_servo_of_another_model_and_a_missing_servo_are_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out = out.to_str().unwrap();
    // The pendulum on an XM430-W350, driven as if it were an XL430-W250.
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--servo", "XM430-W350"]);
    let o = drive(&["--port", servos.port(), "--robot", "pendulum", "--servo", "XL430-W250", "--seconds", "5", "--out", out]);
    bad_input(&o, &["servo 1", "XM430-W350", "XL430-W250", "torque is off"]);
    // The RX-28 pendulum on a bus of X-series servos: nobody answers
    // Protocol 1.0 at ID 1.
    let o = drive(&["--port", servos.port(), "--robot", "pendulum", "--seconds", "5", "--out", out]);
    bad_input(&o, &["servo 1", "does not answer", "--scan", "torque is off"]);
    let summary = servos.stop();
    assert!(events(&summary, 1).iter().all(|e| e != "torque-on"), "torque never went on: {}", summary["events"]);
    // A port that is not there.
    let o = drive(&["--port", dir.path().join("nothing").to_str().unwrap(), "--robot", "pendulum", "--out", out]);
    bad_input(&o, &["no such device"]);
}

#[test]
fn a_bus_at_another_baud_rate_is_one_line_that_names_the_rate() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    // The servos at 57 600 bps (the X series' factory rate), pada at its
    // default 1 000 000: the pty passes on the rate, and the servos hear
    // nothing they can read, as on a real bus.
    // Lock step, so that a loaded machine cannot make the run at the right
    // rate miss answers.
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--servo", "XM430-W350", "--baud", "57600", "--lockstep"]);
    let o = drive(&["--port", servos.port(), "--robot", "pendulum", "--servo", "XM430-W350", "--lockstep", "--seconds", "5", "--out", out.to_str().unwrap()]);
    bad_input(&o, &["servo 1", "does not answer at 1000000 bps", "wrong baud rate", "--scan"]);
    // At the servos' rate it runs.
    let o = drive(&[
        "--port", servos.port(), "--robot", "pendulum", "--servo", "XM430-W350", "--baud", "57600", "--lockstep", "--seconds", "2", "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = servos.stop();
    // The servos saw pada's bytes at its rate, and did not hear them.
    assert!(summary["wrong_rate_bytes"].as_u64().unwrap() > 0, "{summary}");
    assert_eq!(summary["wrong_rates"], serde_json::json!([1_000_000]), "{summary}");
}

#[test]
fn a_hardware_alert_turns_every_servos_torque_off_in_its_period_and_is_in_the_telemetry() {
    let dir = tempfile::tempdir().unwrap();
    let arm = arm();
    // The elbow's overload at 3 s of bus time (period 100 of 30 ms).
    let servos = Servos::start(dir.path(), &["--robot", &arm, "--lockstep", "--fault", "error-bits:at=3:servo=2:bits=overload"]);
    let out = dir.path().join("drive");
    let o = drive(&["--port", servos.port(), "--robot", &arm, "--lockstep", "--seconds", "30", "--out", out.to_str().unwrap()]);
    bad_input(&o, &["servo 2 (elbow)", "hardware alert", "overload", "torque is off on every servo"]);
    let summary = servos.stop();
    let at = |id: u64, what: &str| event_at(&summary, id, what);
    let alert = at(2, "alert").expect("the alert was raised");
    assert_eq!(alert, 3_000_000);
    // Servo 1 (no alert of its own) off within one period of the alert.
    let off = at(1, "torque-off").expect("servo 1's torque went off");
    assert!(off >= alert && off - alert <= 30_000, "alert at {alert} µs, servo 1 off at {off} µs");
    let csv = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    assert!(csv.lines().any(|l| l.contains(",fault,") && l.contains("hardware-alert") && l.contains("servo: 2")), "{csv}");
}

/// After a hardware alert the servo keeps its torque off until a REBOOT:
/// `pada drive` names `pada servos --reboot`, which clears it, and the
/// next run goes.
#[test]
fn a_hardware_alert_is_cleared_by_pada_servos_reboot_and_the_next_run_goes() {
    let dir = tempfile::tempdir().unwrap();
    let arm = arm();
    let servos = Servos::start(dir.path(), &["--robot", &arm, "--lockstep", "--fault", "error-bits:at=1:servo=2:bits=overheating"]);
    let out = dir.path().join("drive");
    let out = out.to_str().unwrap();
    let run = |seconds: &str| drive(&["--port", servos.port(), "--robot", &arm, "--lockstep", "--seconds", seconds, "--out", out]);
    bad_input(&run("10"), &["servo 2 (elbow)", "hardware alert", "overheating", "pada servos --reboot 2"]);
    // Still latched: the next run refuses at its set-up, with the same way out.
    bad_input(&run("2"), &["servo 2 (elbow, XL430-W250)", "hardware error", "pada servos --reboot 2"]);
    // 100 ms for an answer, not the default 5: the virtual servos are a
    // process of their own, which a loaded machine (CI's two cores) holds
    // back longer than a real servo takes to answer.
    let reboot = |id: &str| Command::new(PADA).args(["servos", "--reboot", id, "--port", servos.port(), "--timeout-ms", "100"]).output().unwrap();
    let r = reboot("2");
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(stdout.contains("servo 2 (XL430-W250) rebooted at 1000000 bps; hardware error before: overheating"), "{stdout}");
    // An ID nobody has is one line.
    bad_input(&reboot("7"), &["servo 7 does not answer at 1000000 bps", "--scan"]);
    let o = run("2");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = servos.stop();
    assert!(events(&summary, 2).iter().filter(|e| *e == "torque-on").count() >= 2, "{}", summary["events"]);
}

#[test]
fn a_storm_of_damaged_answers_faults_with_torque_off_in_its_period() {
    let dir = tempfile::tempdir().unwrap();
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--lockstep", "--fault", "corrupt:at=2:for=5:servo=1"]);
    let out = dir.path().join("drive");
    let o = drive(&["--port", servos.port(), "--robot", "pendulum", "--lockstep", "--seconds", "30", "--out", out.to_str().unwrap()]);
    bad_input(&o, &["damaged answers", "torque is off on every servo"]);
    let summary = servos.stop();
    let at = |what: &str| event_at(&summary, 1, what);
    let (corrupt, off) = (at("corrupt").expect("the fault began"), at("torque-off").expect("torque went off"));
    assert!(off >= corrupt && off - corrupt <= 30_000, "corrupted from {corrupt} µs, torque off at {off} µs");
    assert!(out.join("telemetry.csv").is_file() && out.join("checkpoint.bin").is_file());
}

#[test]
fn a_port_that_goes_away_mid_run_is_one_line_and_the_log_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let mut servos = Servos::start(dir.path(), &["--robot", "pendulum", "--lockstep"]);
    let out = dir.path().join("drive");
    let child = start_drive_until_learning(servos.port(), &out);
    // The adapter pulled: the virtual servos' process killed outright.
    let mut s = servos.child.take().unwrap();
    s.kill().unwrap();
    s.wait().unwrap();
    let o = child.wait_with_output().unwrap();
    bad_input(&o, &["went away", "power", "the checkpoint and the log are saved"]);
    for f in ["drive.json", "checkpoint.bin", "trial-000.csv"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let report = drive_report(&out);
    assert_eq!(report["ended"]["kind"], "port-gone", "{}", report["ended"]);
}

/// `pada drive --weights`: the host's weights, exported into the F405's
/// table, continue over the pty in lock step exactly as `pada run --board
/// f405 --weights` continues them.
#[test]
fn drive_from_host_weights_in_lock_step_learns_as_pada_run_board_from_them() {
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("host.wts");
    ok(&common::pada(&[
        "run", "--task", "physical-pendulum", "--algo", "pada", "--seconds", "60", "--trials", "1",
        "--out", dir.path().join("host").to_str().unwrap(), "--save-weights", w.to_str().unwrap(),
    ]));
    let servos = Servos::start(dir.path(), &["--robot", "pendulum", "--lockstep"]);
    let out = dir.path().join("drive");
    let o = drive(&[
        "--port", servos.port(), "--robot", "pendulum", "--lockstep", "--board", "f405", "--algo", "pada", "--seed", "3",
        "--seconds", "30", "--out", out.to_str().unwrap(), "--weights", w.to_str().unwrap(),
    ]);
    ok(&o);
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(said.contains("learned features of the host's exact"), "{said}");
    servos.stop();
    let (from, fresh) = (dir.path().join("run-w"), dir.path().join("run-fresh"));
    let board = |o: &Path, extra: &[&str]| {
        ok(&common::pada(&[
            &["run", "--board", "f405", "--task", "physical-pendulum", "--algo", "pada", "--seed", "3", "--seconds", "30",
            "--trials", "1", "--out", o.to_str().unwrap()][..],
            extra,
        ].concat()))
    };
    board(&from, &["--weights", w.to_str().unwrap()]);
    board(&fresh, &[]);
    assert_eq!(curve(&out), curve(&from), "the learning curve over the pty is pada run --board --weights's");
    assert_ne!(curve(&from), curve(&fresh), "the weights changed nothing");
}

/// The arm of files on two Feetech STS3215s (IDs 1 and 2, 7.4 V), its
/// shoulder calibrated 48 counts off the chain's 2048, written into `dir`.
fn sts_arm(dir: &Path) -> String {
    let urdf = format!("{}/../examples/robots/arm2/arm2.urdf", env!("CARGO_MANIFEST_DIR"));
    let toml = std::fs::read_to_string(arm())
        .unwrap()
        .replace("\"XM430-W350\"", "\"STS3215\"")
        .replace("\"XL430-W250\"", "\"STS3215\"")
        .replace("urdf = \"arm2.urdf\"", &format!("urdf = {urdf:?}"))
        .replace("supply_v = 12.0", "supply_v = 7.4")
        .replace("voltage_limit_v = 12.0", "voltage_limit_v = 7.4")
        .replacen("zero_count = 2048", "zero_count = 2000", 1);
    let path = dir.join("sts-arm.toml");
    std::fs::write(&path, toml).unwrap();
    path.to_str().unwrap().to_string()
}

/// `pada drive --lockstep --seconds SECONDS` of the STS3215 arm against
/// `pada servos --chain CHAIN --lockstep` with `faults`: its output, the
/// servos' summary and the run's directory (inside the returned tempdir).
fn drive_sts(chain: &str, faults: &[&str], seconds: &str, json: bool) -> (std::process::Output, serde_json::Value, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let robot = sts_arm(dir.path());
    let mut servos_args = vec!["--chain", chain, "--lockstep"];
    for f in faults {
        servos_args.extend(["--fault", f]);
    }
    let servos = Servos::start(dir.path(), &servos_args);
    let out = dir.path().join("drive");
    let mut args = vec!["--port", servos.port(), "--robot", &robot, "--lockstep", "--seconds", seconds, "--out", out.to_str().unwrap()];
    if json {
        args.push("--json");
    }
    let o = drive(&args);
    (o, servos.stop(), out, dir)
}

/// `pada drive` on a Feetech bus: against `pada servos`' bare STS3215
/// chain in lock step, each period is one SYNC READ and one SYNC WRITE
/// (60 bytes for two servos), the positions come back through it, and
/// torque is on for the episodes and off at the end.
#[test]
fn a_robot_of_sts3215s_runs_on_one_sync_read_and_one_sync_write_a_period() {
    let (o, summary, out, _dir) = drive_sts("sts3215:1-2", &[], "2", true);
    let report: serde_json::Value = serde_json::from_str(&ok(&o)).expect("drive.json on stdout");
    assert_eq!(report["ended"]["kind"], "done");
    let servo_lines = report["servos"].to_string();
    assert!(servo_lines.contains("servo 2 (elbow): STS3215 (model 777)"), "{servo_lines}");
    assert_eq!((report["bus"]["timeouts"].as_u64(), report["bus"]["checksum_errors"].as_u64()), (Some(0), Some(0)));
    assert_eq!(report["bus"]["fast_sync_read"], false, "no Protocol 2.0 servo");
    // SYNC READ 10 B, two answers of 14 B, SYNC WRITE 22 B.
    let per_period = report["bus"]["bytes_per_period"].as_f64().unwrap();
    assert!((per_period - 60.0).abs() < 1.0, "{per_period}");
    // The same from the encoded packets: 0.60 ms on the wire at 1 Mbaud
    // and two 50 µs Return Delays.
    assert_eq!(report["bus"]["predicted_bytes_per_period"], 60);
    assert!((report["bus"]["wire_ms_per_period"].as_f64().unwrap() - 0.70).abs() < 1e-9, "{}", report["bus"]);
    // One SYNC WRITE a period ends each of the chain's lock-step periods.
    let periods = report["clock"]["periods"].as_u64().unwrap();
    assert!(periods > 100, "{periods}");
    assert_eq!(summary["stats"]["sync_writes"].as_u64(), Some(periods));
    // The shoulder reads 48 counts (0.074 rad) from its zero, the elbow 0.
    let csv = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    let states: Vec<&str> = csv.lines().map(|l| l.split(',').collect::<Vec<_>>()).filter(|f| f[2] == "step").map(|f| f[8]).collect();
    assert!(!states.is_empty() && states.iter().all(|s| *s == "0.074 0"), "{:?}", &states[..states.len().min(5)]);
    assert_torque_on_then_off(&summary, [1, 2]);
}

/// A Feetech servo's overload (its Status bit 5, which unloads it) faults
/// the robot: every servo's torque off in that period, one line.
#[test]
fn an_sts3215_overload_turns_every_servos_torque_off_in_its_period() {
    let (o, summary, out, _dir) = drive_sts("sts3215:1-2", &["error-bits:at=1:servo=2:bits=overload"], "20", false);
    bad_input(&o, &["servo 2 (elbow)", "overload", "torque is off on every servo"]);
    let at = |id: u64, what: &str| event_at(&summary, id, what);
    let fault = at(2, "error-bits").expect("the overload was raised");
    let off = at(1, "torque-off").expect("servo 1's torque went off");
    assert!(off >= fault && off - fault <= 30_000, "overload at {fault} µs, servo 1 off at {off} µs");
    let csv = std::fs::read_to_string(out.join("telemetry.csv")).unwrap();
    assert!(csv.lines().any(|l| l.contains(",fault,") && l.contains("servo-error") && l.contains("servo: 2")), "{csv}");
}

#[test]
fn a_missing_sts3215_is_one_line_naming_it_and_torque_never_goes_on() {
    // A chain of servo 1 only.
    let (o, summary, _, _dir) = drive_sts("sts3215:1-1", &[], "2", false);
    bad_input(&o, &["servo 2 (elbow, STS3215) does not answer", "--scan", "torque is off"]);
    assert!(events(&summary, 1).iter().all(|e| e != "torque-on"), "{}", summary["events"]);
}
