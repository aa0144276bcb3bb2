//! Software in the loop: the firmware image in QEMU against the simulated
//! pendulum (`pada sil`). Each test boots the real image in
//! qemu-system-arm; none is skipped when QEMU is missing.

mod common;

use pada::sil::fault;
use pada::sil::replay::{replay, Record};
use pada::sil::{run, SilConfig, SilSummary, SilTask};
use pada_core::policy::PolicyKind;
use pada_core::wire::{HostDecoder, RunMode, StepKind, ToHost};
use pada_firmware::config::{Board, Robot, DEFAULT_SEED};
use std::path::Path;
use std::time::Duration;

fn sil(task: SilTask, policy: PolicyKind, seconds: f64, faults: &[&str], out: &Path) -> SilSummary {
    common::require_qemu();
    let robot = match task {
        SilTask::Pendulum => "pendulum",
        SilTask::Leo => "leo",
    };
    let cfg = SilConfig {
        qemu: "qemu-system-arm".into(),
        elf: common::image(robot),
        task,
        policy,
        seconds,
        faults: faults.iter().map(|f| fault::parse(f).unwrap()).collect(),
        out_dir: out.to_path_buf(),
        hang_timeout: Duration::from_secs(120),
        progress: false,
        telemetry: None,
    };
    run(&cfg).unwrap_or_else(|e| panic!("SIL run failed: {e:#}"))
}

fn check_failures(s: &SilSummary) -> Vec<String> {
    s.checks
        .iter()
        .filter(|c| !c.ok)
        .map(|c| format!("{}: {}", c.name, c.detail))
        .collect()
}

/// The records of a recorded telemetry stream, in order.
fn records(stream: &[u8]) -> Vec<Record> {
    let mut d = HostDecoder::new();
    let mut out = Vec::new();
    for frame in d.feed(stream) {
        match frame.expect("a clean recording").msg {
            ToHost::Step(s) => out.push(Record::Step(s)),
            ToHost::Episode(e) => out.push(Record::Episode(e)),
            _ => {}
        }
    }
    out
}

#[test]
fn the_firmware_in_qemu_replays_bit_for_bit_on_the_host_and_its_link_is_clean() {
    let dir = tempfile::tempdir().unwrap();
    let policy = PolicyKind::Pada { delta: 0.5 };
    let s = sil(SilTask::Pendulum, policy, 30.0, &[], dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    // Every frame decoded, none missing.
    assert!(
        s.telemetry.is_clean() && s.telemetry.frames > 1000,
        "{:?}",
        s.telemetry
    );
    assert_eq!(s.messages.step, s.replay.steps);
    // Same action at every step, same checksum at every episode's end.
    assert!(s.replay.identical, "{:?}", s.replay);
    assert!(s.replay.actions_compared >= 1000, "{:?}", s.replay);
    assert!(s.replay.checksums_compared >= 10, "{:?}", s.replay);
    assert_eq!(
        s.replay.final_checksum_firmware,
        s.replay.final_checksum_replay
    );
    assert!(s.unexpected_faults.is_empty(), "{:?}", s.unexpected_faults);

    // The same from the recorded stream (the one capture path), and the
    // replay notices a learning step's reward changed by 1 (a change below
    // the agent's Q16.16 resolution, or in a greedy test episode, which
    // does not learn, would change no weight).
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    // The firmware reports the policy it was set to (the wire's Policy
    // frame, which pada watch shows).
    let mut decoder = pada_core::wire::HostDecoder::new();
    let policies: Vec<pada_core::wire::PolicyReport> = decoder
        .feed(&stream)
        .filter_map(|r| match r.ok()?.msg {
            pada_core::wire::ToHost::Policy(p) => Some(p),
            _ => None,
        })
        .collect();
    // At boot (SARSA), then after the run's SetPolicy.
    assert_eq!(policies.len(), 2, "{policies:?}");
    assert_eq!(PolicyKind::from(policies[0].built), PolicyKind::Sarsa);
    let last = policies.last().expect("the firmware sent a Policy frame");
    assert_eq!(PolicyKind::from(last.built), policy, "{policies:?}");
    assert!(!last.switched_to_sarsa);
    let mut recs = records(&stream);
    assert!(replay(&Board::F405.profile(Robot::Pendulum33), policy, DEFAULT_SEED, &recs).identical);
    let k = recs
        .iter()
        .position(|r| matches!(r, Record::Step(s) if s.mode == RunMode::Learning && s.kind == StepKind::Step))
        .unwrap();
    if let Record::Step(s) = &mut recs[k] {
        s.reward += 1.0;
    }
    let tampered = replay(&Board::F405.profile(Robot::Pendulum33), policy, DEFAULT_SEED, &recs);
    assert!(
        !tampered.identical && tampered.first_checksum_mismatch.is_some(),
        "{tampered:?}"
    );
    // And a wrong seed or policy is not the same agent.
    let recs = records(&stream);
    assert!(!replay(&Board::F405.profile(Robot::Pendulum33), policy, DEFAULT_SEED + 1, &recs).identical);
    assert!(!replay(&Board::F405.profile(Robot::Pendulum33), PolicyKind::Sarsa, DEFAULT_SEED, &recs).identical);
}

#[test]
fn the_same_image_gives_the_same_run_byte_for_byte() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let sa = sil(
        SilTask::Pendulum,
        PolicyKind::Sarsa,
        6.0,
        &["drop:at=9:for=0.2"],
        a.path(),
    );
    let sb = sil(
        SilTask::Pendulum,
        PolicyKind::Sarsa,
        6.0,
        &["drop:at=9:for=0.2"],
        b.path(),
    );
    assert!(
        sa.passed && sb.passed,
        "{:#?} {:#?}",
        check_failures(&sa),
        check_failures(&sb)
    );
    for file in ["telemetry.bin", "episodes.csv"] {
        let fa = std::fs::read(a.path().join(file)).unwrap();
        let fb = std::fs::read(b.path().join(file)).unwrap();
        assert!(!fa.is_empty());
        assert!(
            fa == fb,
            "{file} differs between two runs of the same image"
        );
    }
    assert_eq!(
        (sa.exchanges, sa.instructions),
        (sb.exchanges, sb.instructions)
    );
}

/// One fault kind: it must hit the running robot, switch torque off within
/// one control period (30 ms), be reported with `cause`, and learning must
/// resume after ClearFault; the replay still matches bit for bit.
fn fault_test(spec: &str, cause: &str) {
    let dir = tempfile::tempdir().unwrap();
    let s = sil(
        SilTask::Pendulum,
        PolicyKind::Sarsa,
        9.0,
        &[spec],
        dir.path(),
    );
    assert!(s.passed, "{:#?}", check_failures(&s));
    let f = &s.faults[0];
    assert!(f.torque_at_onset, "{f:?}");
    let latency = f.latency_ms.expect("torque went off");
    assert!(
        latency <= f.period_ms,
        "torque off {latency} ms after the onset, period {} ms",
        f.period_ms
    );
    assert_eq!(f.cause.as_deref(), Some(cause), "{f:?}");
    assert!(f.resumed, "{f:?}");
    assert!(s.unexpected_faults.is_empty(), "{:?}", s.unexpected_faults);
    assert!(s.replay.identical, "{:?}", s.replay);
    // The telemetry carries the Fault and the way back out of it.
    let csv = std::fs::read_to_string(dir.path().join("telemetry.csv")).unwrap();
    assert!(
        csv.lines()
            .any(|l| l.contains(",fault,") && l.contains(cause)),
        "no Fault row"
    );
    assert!(csv
        .lines()
        .any(|l| l.contains(",state,") && l.contains("Fault(") && l.contains("-> Idle")));
}

#[test]
fn dropped_answers_fault_within_one_period_and_resume() {
    fault_test("drop:at=12:for=1", "servo-timeout");
}

#[test]
fn corrupted_answers_fault_within_one_period_and_resume() {
    fault_test("corrupt:at=12:for=1", "checksum-errors");
}

#[test]
fn answers_delayed_past_the_timeout_fault_within_one_period_and_resume() {
    fault_test("delay:at=12:for=1:ms=5", "servo-timeout");
}

#[test]
fn servo_error_bits_fault_within_one_period_and_resume() {
    fault_test("error-bits:at=12:for=1:bits=overheating", "servo-error");
}

#[test]
fn leo_image_runs_in_qemu_and_its_agent_step_is_counted() {
    let dir = tempfile::tempdir().unwrap();
    let s = sil(
        SilTask::Leo,
        PolicyKind::Pada { delta: 0.5 },
        25.0,
        &[],
        dir.path(),
    );
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert!(s.replay.identical, "{:?}", s.replay);
    let i = &s.agent_instructions;
    assert!(i.learning_step.calls >= 700, "{i:?}");
    // A greedy step evaluates 343 joint actions of 16 tiles each: at least
    // a few instructions per weight read.
    assert!(i.test_step.mean > 3.0 * 343.0 * 16.0, "{i:?}");
    assert!(
        i.learning_step.max < 168_000_000 / 30,
        "an agent step must fit LEO's 33 ms period at 168 MHz: {i:?}"
    );
}
