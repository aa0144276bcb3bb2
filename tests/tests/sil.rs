//! Software in the loop: the firmware image in QEMU against the simulated
//! plant (`pada sil`): the pendulum on the F405's emulation
//! (netduinoplus2), LEO on the F429I-DISC1's (mps2-an386, its 8 MiB table in
//! PSRAM) and the F405's, and the example arms of files
//! (examples/robots/arm2 on Protocol 2.0, examples/robots/so101 on Feetech
//! STS3215s) on the F405's. Each test boots the real image in
//! qemu-system-arm; none is skipped when QEMU is missing.

mod common;

use pada::seed::trial_seed;
use pada::sil::fault;
use pada::sil::replay::{replay, Record};
use pada::sil::{run, SilConfig, SilSummary, SilTask};
use pada_core::policy::PolicyKind;
use pada_core::profile::Board;
use pada_core::wire::{HostDecoder, RunMode, StepKind, ToHost};
use pada_core::robot::pendulum::SPEC_33HZ;
use std::path::Path;
use std::time::Duration;

/// The master seed of every run here (`pada sil`'s default).
const SEED: u64 = 1;

struct Run {
    board: Board,
    task: SilTask,
    policy: PolicyKind,
    seconds: f64,
    faults: Vec<&'static str>,
    forecast: bool,
    compare: bool,
    mtbf_budget_s: Option<f32>,
}

impl Run {
    fn pendulum(policy: PolicyKind, seconds: f64) -> Run {
        Run { board: Board::F405, task: SilTask::Pendulum, policy, seconds, faults: vec![], forecast: true, compare: false, mtbf_budget_s: None }
    }

    fn leo(board: Board, seconds: f64) -> Run {
        Run {
            board,
            task: SilTask::Leo,
            policy: PolicyKind::Pada { delta: 0.1667 },
            seconds,
            faults: vec![],
            forecast: true,
            compare: false,
            mtbf_budget_s: None,
        }
    }

    /// The SO-101 of files (examples/robots/so101: six Feetech STS3215s),
    /// learning with PADA.
    fn so101(seconds: f64) -> Run {
        let task = SilTask::of_file(&common::root().join("examples/robots/so101/robot.toml")).unwrap_or_else(|e| panic!("{e:#}"));
        Run { board: Board::F405, task, policy: PolicyKind::Pada { delta: 0.5 }, seconds, faults: vec![], forecast: true, compare: false, mtbf_budget_s: None }
    }

    /// The example arm of files (examples/robots/arm2: two X-series
    /// servos on Protocol 2.0), learning with PADA.
    fn arm2(seconds: f64) -> Run {
        let task = SilTask::of_file(&common::root().join("examples/robots/arm2/robot.toml")).unwrap_or_else(|e| panic!("{e:#}"));
        Run { board: Board::F405, task, policy: PolicyKind::Pada { delta: 0.5 }, seconds, faults: vec![], forecast: true, compare: false, mtbf_budget_s: None }
    }

    fn config(&self, out: &Path) -> SilConfig {
        common::require_qemu();
        SilConfig {
            qemu: "qemu-system-arm".into(),
            elf: common::image(self.board.name(), &self.task.xtask_robot()),
            task: self.task,
            board: self.board,
            policy: self.policy,
            mtbf_budget_s: self.mtbf_budget_s,
            seconds: self.seconds,
            seed: SEED,
            faults: self.faults.iter().map(|f| fault::parse(f).unwrap()).collect(),
            power_cuts: vec![],
            hangs_s: vec![],
            save_every_s: None,
            forecast: self.forecast,
            compare: self.compare,
            out_dir: out.to_path_buf(),
            hang_timeout: Duration::from_secs(120),
            progress: false,
            telemetry: None,
            weights: None,
        }
    }

    fn go(&self, out: &Path) -> SilSummary {
        run(&self.config(out)).unwrap_or_else(|e| panic!("SIL run failed: {e:#}"))
    }
}

fn check_failures(s: &SilSummary) -> Vec<String> {
    s.checks.iter().filter(|c| !c.ok).map(|c| format!("{}: {}", c.name, c.detail)).collect()
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
    let s = Run::pendulum(policy, 30.0).go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    // Every frame decoded, none missing.
    assert!(s.telemetry.is_clean() && s.telemetry.frames > 1000, "{:?}", s.telemetry);
    assert_eq!(s.messages.step, s.replay.steps);
    // Same action at every step, same checksum at every episode's end.
    assert!(s.replay.identical, "{:?}", s.replay);
    assert!(s.replay.actions_compared >= 1000, "{:?}", s.replay);
    assert!(s.replay.checksums_compared >= 10, "{:?}", s.replay);
    assert_eq!(s.replay.final_checksum_firmware, s.replay.final_checksum_replay);
    assert!(s.unexpected_faults.is_empty(), "{:?}", s.unexpected_faults);
    // The board learned with trial 0's seed of the master seed.
    assert_eq!((s.seed, s.learner_seed), (SEED, trial_seed(SEED, 0)));

    // The same from the recorded stream (the one capture path), and the
    // replay notices a learning step's reward changed by 1 (a change below
    // the agent's Q16.16 resolution, or in a greedy test episode, which
    // does not learn, would change no weight).
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    // The firmware reports the policy it was set to (the wire's Policy
    // frame, which pada watch shows).
    let mut decoder = HostDecoder::new();
    let policies: Vec<pada_core::wire::PolicyReport> = decoder
        .feed(&stream)
        .filter_map(|r| match r.ok()?.msg {
            ToHost::Policy(p) => Some(p),
            _ => None,
        })
        .collect();
    // At boot (SARSA), then after the run's SetPolicy.
    assert_eq!(policies.len(), 2, "{policies:?}");
    assert_eq!(policies[0].built, PolicyKind::Sarsa);
    let last = policies.last().expect("the firmware sent a Policy frame");
    assert_eq!(last.built, policy, "{policies:?}");
    assert!(!last.switched_to_sarsa);
    let profile = Board::F405.profile(&SPEC_33HZ).unwrap();
    let seed = trial_seed(SEED, 0);
    let mut recs = records(&stream);
    assert!(replay(&profile, policy, seed, &recs).identical);
    let k = recs
        .iter()
        .position(|r| matches!(r, Record::Step(s) if s.mode == RunMode::Learning && s.kind == StepKind::Step))
        .unwrap();
    if let Record::Step(s) = &mut recs[k] {
        s.reward += 1.0;
    }
    let tampered = replay(&profile, policy, seed, &recs);
    assert!(!tampered.identical && tampered.first_checksum_mismatch.is_some(), "{tampered:?}");
    // And a wrong seed or policy is not the same agent.
    let recs = records(&stream);
    assert!(!replay(&profile, policy, seed + 1, &recs).identical);
    assert!(!replay(&profile, PolicyKind::Sarsa, seed, &recs).identical);
}

#[test]
fn a_governed_run_in_qemu_moves_its_delta_and_replays_bit_for_bit() {
    // `pada sil --algo pada --mtbf-budget B`: the firmware's wear governor
    // moves Δ while it learns; the replay takes each reported Δ where the
    // board reported it and must still give the same actions and weights.
    let dir = tempfile::tempdir().unwrap();
    let mut run = Run::pendulum(PolicyKind::Pada { delta: 0.5 }, 60.0);
    // A budget below what the full range gives on the physical pendulum
    // (≈ 5.6e7 s over 1200 actions, `pada run --board f405 --task
    // physical-pendulum --algo pada --mtbf-budget 1e7 --seconds 60`): the
    // governor starts at its floor (Δ = 0.5, one level) and relaxes to the
    // full range as the budget pays for it, so the run crosses a move.
    run.mtbf_budget_s = Some(1e7);
    let s = run.go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert!(s.replay.identical && s.replay.actions_compared >= 1000, "{:?}", s.replay);
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    let mut decoder = HostDecoder::new();
    let deltas: Vec<f32> = decoder
        .feed(&stream)
        .filter_map(|f| match f.expect("a clean recording").msg {
            ToHost::Policy(p) => p.governor.map(|g| g.parameter),
            _ => None,
        })
        .collect();
    let mut distinct = deltas.clone();
    distinct.sort_by(f32::total_cmp);
    distinct.dedup();
    assert!(distinct.len() >= 2, "the governor never moved Δ: {deltas:?}");
}

#[test]
fn the_same_image_gives_the_same_run_byte_for_byte_with_or_without_forecasts() {
    let dirs = [(); 3].map(|_| tempfile::tempdir().unwrap());
    let mut run = Run::pendulum(PolicyKind::Sarsa, 6.0);
    run.faults = vec!["drop:at=9:for=0.2"];
    let a = run.go(dirs[0].path());
    let b = run.go(dirs[1].path());
    run.forecast = false;
    let plain = run.go(dirs[2].path());
    for s in [&a, &b, &plain] {
        assert!(s.passed, "{:#?}", check_failures(s));
    }
    for file in ["telemetry.bin", "episodes.csv"] {
        let fa = std::fs::read(dirs[0].path().join(file)).unwrap();
        assert!(!fa.is_empty());
        for (d, what) in [(&dirs[1], "two runs of the same image"), (&dirs[2], "runs with and without forecasts")] {
            assert!(fa == std::fs::read(d.path().join(file)).unwrap(), "{file} differs between {what}");
        }
    }
    assert_eq!((a.exchanges, a.instructions), (b.exchanges, b.instructions));
    // The forecasts answer most of the bus's requests without an exchange
    // (the pendulum reads its servo and the sensor device every period).
    assert!(a.forecasts.used > 0 && plain.forecasts.used == 0, "{:?} {:?}", a.forecasts, plain.forecasts);
    assert!(a.exchanges_per_period <= 2.1, "{} exchanges per period", a.exchanges_per_period);
    assert!(plain.exchanges > a.exchanges + a.forecasts.used / 2, "{} vs {}", plain.exchanges, a.exchanges);
}

/// One fault kind: it must hit the running robot, switch torque off on
/// every servo within one control period, be reported with `cause`, and
/// learning must resume after ClearFault; the replay still matches bit for
/// bit.
fn fault_test(mut run: Run, spec: &'static str, cause: &str) {
    let dir = tempfile::tempdir().unwrap();
    run.faults = vec![spec];
    let s = run.go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    let f = &s.faults[0];
    assert!(f.torque_at_onset, "{f:?}");
    let latency = f.latency_ms.expect("torque went off");
    assert!(latency <= f.period_ms, "torque off {latency} ms after the onset, period {} ms", f.period_ms);
    assert_eq!(f.cause.as_deref(), Some(cause), "{f:?}");
    assert!(f.resumed, "{f:?}");
    assert!(s.unexpected_faults.is_empty(), "{:?}", s.unexpected_faults);
    assert!(s.replay.identical, "{:?}", s.replay);
    // The telemetry carries the Fault and the way back out of it.
    let csv = std::fs::read_to_string(dir.path().join("telemetry.csv")).unwrap();
    assert!(csv.lines().any(|l| l.contains(",fault,") && l.contains(cause)), "no Fault row");
    assert!(csv.lines().any(|l| l.contains(",state,") && l.contains("Fault(") && l.contains("-> Idle")));
}

#[test]
fn dropped_answers_fault_within_one_period_and_resume() {
    fault_test(Run::pendulum(PolicyKind::Sarsa, 9.0), "drop:at=12:for=1", "servo-timeout");
}

#[test]
fn corrupted_answers_fault_within_one_period_and_resume() {
    fault_test(Run::pendulum(PolicyKind::Sarsa, 9.0), "corrupt:at=12:for=1", "checksum-errors");
}

#[test]
fn answers_delayed_past_the_timeout_fault_within_one_period_and_resume() {
    fault_test(Run::pendulum(PolicyKind::Sarsa, 9.0), "delay:at=12:for=1:ms=5", "servo-timeout");
}

#[test]
fn servo_error_bits_fault_within_one_period_and_resume() {
    fault_test(Run::pendulum(PolicyKind::Sarsa, 9.0), "error-bits:at=12:for=1:bits=overheating", "servo-error");
}

/// An STS3215's overload (its Status bit 5) on the SO-101's elbow: the
/// board faults within its period, every servo's torque off, and resumes.
#[test]
fn an_sts3215_overload_faults_within_one_period_and_resumes() {
    fault_test(Run::so101(10.0), "error-bits:at=4:for=1:bits=overload:servo=3", "servo-error");
}

/// An X-series servo's hardware alert latches until a REBOOT: the board
/// faults within its period, and after the operator's ClearFault and
/// Start it reboots the servo, sets it up again and learns on.
#[test]
fn an_x_series_hardware_alert_faults_within_one_period_and_the_board_reboots_the_servo_and_resumes() {
    fault_test(Run::arm2(10.0), "error-bits:at=4:for=1:bits=overload:servo=2", "hardware-alert");
}

/// LEO's fault tests: on the F429's emulation, a servo other than 1 (the
/// right knee, ID 4; the left knee, ID 5, for the soft limit), every
/// servo's torque off within one 33 ms period.
fn leo_fault(spec: &'static str, cause: &str) {
    fault_test(Run::leo(Board::F429Sdram, 8.0), spec, cause);
}

#[test]
fn leo_dropped_answers_of_a_knee_fault_within_one_period_and_resume() {
    leo_fault("drop:at=6:for=1:servo=4", "servo-timeout");
}

#[test]
fn leo_corrupted_answers_of_a_knee_fault_within_one_period_and_resume() {
    leo_fault("corrupt:at=6:for=1:servo=4", "checksum-errors");
}

#[test]
fn leo_delayed_answers_of_a_knee_fault_within_one_period_and_resume() {
    leo_fault("delay:at=6:for=1:ms=5:servo=4", "servo-timeout");
}

#[test]
fn leo_error_bits_of_a_knee_fault_within_one_period_and_resume() {
    leo_fault("error-bits:at=6:for=1:bits=overload:servo=4", "servo-error");
}

#[test]
fn leo_knee_driven_past_its_soft_limit_faults_within_one_period_and_resumes() {
    leo_fault("past-limit:at=6:for=1:servo=5", "soft-limit");
}

#[test]
fn leo_on_the_f429_board_learns_against_the_rapier_leo_and_equals_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let mut run = Run::leo(Board::F429Sdram, 20.0);
    run.compare = true;
    let s = run.go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert_eq!((s.board, s.machine, s.weights), ("f429-sdram", "mps2-an386", 1 << 21));
    assert!(s.replay.identical, "{:?}", s.replay);
    // The same run as `pada run --board f429-sdram --seed 1`'s trial 0.
    let host = s.host.as_ref().expect("the host comparison ran");
    assert_eq!(host.identical, Some(true), "{host:?}");
    assert!(host.episodes_compared >= 10, "{host:?}");
    assert_eq!(Some(host.weights_checksum), s.replay.final_checksum_firmware);
    // The rapier LEO moves: the plant measured a distance, falls ended
    // episodes early, and the firmware saw footsteps (or the policy memory
    // would never have been mirrored).
    assert!(s.end_walked_m.is_some(), "{:?}", s.end_walked_m);
    assert!(s.learning_episodes >= 5, "{}", s.learning_episodes);
    // A period's bus traffic (seven servos, the sensor device) costs about
    // two exchanges, not nine.
    assert!(s.exchanges_per_period <= 2.5, "{} exchanges per period", s.exchanges_per_period);
    let i = &s.agent_instructions;
    // A greedy step evaluates 343 joint actions of 16 tiles each: at least
    // a few instructions per weight read.
    assert!(i.test_step.mean > 3.0 * 343.0 * 16.0, "{i:?}");
    assert!(i.learning_step.max < 180_000_000 / 30, "an agent step must fit LEO's 33 ms period at 180 MHz: {i:?}");
}

#[test]
fn leo_runs_on_the_f405_board_too() {
    let dir = tempfile::tempdir().unwrap();
    let s = Run::leo(Board::F405, 10.0).go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert_eq!((s.board, s.machine, s.weights), ("f405", "netduinoplus2", 1 << 15));
    assert!(s.replay.identical && s.replay.checksums_compared >= 3, "{:?}", s.replay);
}

#[test]
fn an_image_for_another_robot_is_refused_with_what_to_build() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = Run::pendulum(PolicyKind::Sarsa, 1.0).config(dir.path());
    // The F405's pendulum image, for a LEO run on the F405.
    cfg.task = SilTask::Leo;
    let e = format!("{:#}", run(&cfg).map(|_| ()).unwrap_err());
    assert!(e.contains("drives physical-pendulum") && e.contains("cargo xtask qemu --board f405 --robot leo"), "{e}");
}

#[test]
fn a_robot_of_files_in_qemu_replays_bit_for_bit_and_equals_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let mut run = Run::arm2(30.0);
    run.compare = true;
    let s = run.go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert_eq!((s.robot, s.board, s.machine), ("arm2", "f405", "netduinoplus2"));
    // The image's agent, replayed on the host.
    assert!(s.replay.identical && s.replay.actions_compared >= 500 && s.replay.checksums_compared >= 3, "{:?}", s.replay);
    // The same run as `pada run --board f405 --robot examples/robots/arm2/robot.toml --seed 1`'s
    // trial 0: every episode and the final weights.
    let host = s.host.as_ref().expect("the host comparison ran");
    assert_eq!(host.identical, Some(true), "{host:?}");
    assert!(host.episodes_compared >= 5, "{host:?}");
    assert_eq!(Some(host.weights_checksum), s.replay.final_checksum_firmware);
    // The image generated from the files says it learns what the host
    // builds from them: its Hello's configuration hash.
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    let hello = HostDecoder::new()
        .feed(&stream)
        .into_iter()
        .find_map(|f| match f.ok()?.msg {
            ToHost::Hello(h) => Some(h),
            _ => None,
        })
        .expect("the image says Hello");
    let profile = run.config(dir.path()).profile();
    let task = run.task.sim().unwrap().task_spec(profile).unwrap();
    let host_agent = pada::experiment::build_agent(&task, run.policy).unwrap();
    assert_eq!(hello.config_hash, pada_core::profile::config_hash(&profile, &host_agent), "{hello:?}");
    assert_eq!((hello.robot.as_str(), hello.robot_hash), ("arm2", run.task.robot().definition_hash()));
}

/// The SO-101 of files: six Feetech STS3215s on the emulated bus (one SYNC
/// READ and one SYNC WRITE a period, Operating Mode 2's duty cycles)
/// learn in QEMU what `pada run --board f405 --robot
/// examples/robots/so101/robot.toml --seed 1` learns.
#[test]
fn the_so101_on_feetech_servos_in_qemu_replays_bit_for_bit_and_equals_pada_run_board() {
    let dir = tempfile::tempdir().unwrap();
    let mut run = Run::so101(20.0);
    run.compare = true;
    let s = run.go(dir.path());
    assert!(s.passed, "{:#?}", check_failures(&s));
    assert_eq!((s.robot, s.board), ("so101", "f405"));
    assert!(s.replay.identical && s.replay.actions_compared >= 500, "{:?}", s.replay);
    let host = s.host.as_ref().expect("the host comparison ran");
    assert_eq!(host.identical, Some(true), "{host:?}");
    assert!(host.episodes_compared >= 5, "{host:?}");
    assert_eq!(Some(host.weights_checksum), s.replay.final_checksum_firmware);
}
