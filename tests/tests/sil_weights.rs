//! `pada sil --weights`: LEO's firmware on the emulated F429 boots from
//! the checkpoint of weights learned on the host (kept by the host,
//! restored at the first boot) and continues exactly as `pada run --board
//! f429-sdram --weights` continues them, episode for episode; the replay
//! of its telemetry from the same exported table agrees too.

mod common;

use pada::board::export::export;
use pada::board::exported::image_of;
use pada::board::trial::table_len;
use pada::board::{run_board_trial_from, BoardStart};
use pada::experiment::task::Task;
use pada::experiment::tasks::{visit_task, TaskName, TaskVisitor};
use pada::experiment::{run_trial_keep, RunConfig};
use pada::sil::config::SilWeights;
use pada::sil::{run, SilConfig, SilTask};
use pada::start_weights::StartWeights;
use pada_core::policy::PolicyKind;
use pada_core::profile::Board;
use std::path::Path;
use std::time::Duration;

const POLICY: PolicyKind = PolicyKind::Pada { delta: 0.5 };

/// Saves trial 0 of `seconds` of host learning on LEO to `path`.
fn learn_on_the_host(path: &Path, seconds: f64) {
    struct Learn<'a>(&'a Path, RunConfig);
    impl TaskVisitor for Learn<'_> {
        type Output = ();
        fn visit<T: Task>(self, task: &T) {
            let (_, agent, switched) = run_trial_keep(task, &self.1, 0, &|_| {}).unwrap();
            pada::weights::save(self.0, task.spec(), POLICY, switched, &agent).unwrap();
        }
    }
    let cfg = RunConfig { policy: POLICY, switch_at_s: None, mtbf_budget_s: None, seconds, trials: 1, seed: 5 };
    visit_task(TaskName::Leo, Learn(path, cfg));
}

#[test]
fn leo_on_the_f429_continues_from_host_weights_as_pada_run_board_does() {
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("leo.wts");
    learn_on_the_host(&w, 60.0);
    let robot = &pada_core::robot::leo::SPEC;
    let sim = pada::robots::sim_robot(robot).unwrap();
    let host_spec = sim.task_spec(Board::Host.profile(robot).unwrap()).unwrap();
    let profile = Board::F429Sdram.profile(robot).unwrap();
    let n = table_len(&profile, POLICY).unwrap();
    let (entries, report) = export(&StartWeights::load(&w, &host_spec, POLICY).unwrap(), &host_spec, &profile, n).unwrap();
    assert!(report.kept > 1000 && report.dropped == 0, "{report:?}");
    let seed = 1;
    let learner_seed = pada::seed::trial_seed(seed, 0);
    let image = image_of(profile, &sim, POLICY, None, learner_seed, n, &entries).unwrap();
    common::require_qemu();
    let out = dir.path().join("sil");
    let cfg = SilConfig {
        qemu: "qemu-system-arm".into(),
        elf: common::image(Board::F429Sdram.name(), &SilTask::Leo.xtask_robot()),
        task: SilTask::Leo,
        board: Board::F429Sdram,
        policy: POLICY,
        mtbf_budget_s: None,
        seconds: 10.0,
        seed,
        faults: vec![],
        power_cuts: vec![],
        hangs_s: vec![],
        save_every_s: None,
        forecast: true,
        compare: true,
        out_dir: out.clone(),
        hang_timeout: Duration::from_secs(120),
        progress: false,
        telemetry: None,
        weights: Some(SilWeights { entries: entries.clone(), image }),
    };
    let s = run(&cfg).unwrap_or_else(|e| panic!("SIL run failed: {e:#}"));
    assert!(s.passed, "{:#?}", s.checks.iter().filter(|c| !c.ok).map(|c| format!("{}: {}", c.name, c.detail)).collect::<Vec<_>>());
    assert!(s.replay.identical, "{:?}", s.replay);
    let host = s.host.as_ref().expect("the host comparison ran");
    assert_eq!(host.identical, Some(true), "{host:?}");
    assert!(host.episodes_compared >= 5, "{host:?}");
    // The comparison is `pada run --board f429-sdram --weights`'s trial 0;
    // from nothing the board's first episode has other weights.
    let rc = RunConfig { policy: POLICY, switch_at_s: None, mtbf_budget_s: None, seconds: 10.0, trials: 1, seed };
    let from = run_board_trial_from(profile, &sim, &rc, 0, BoardStart::Entries(&entries), &|_| {}).unwrap();
    let fresh = run_board_trial_from(profile, &sim, &rc, 0, BoardStart::Fresh, &|_| {}).unwrap();
    assert_eq!(Some(host.weights_checksum), Some(from.weights_checksum));
    assert_ne!(from.episodes[0].weights_checksum, fresh.episodes[0].weights_checksum);
    let csv = std::fs::read_to_string(out.join("episodes.csv")).unwrap();
    let first_sil_checksum = u32::from_str_radix(csv.lines().nth(1).unwrap().split(',').nth(4).unwrap(), 16).unwrap();
    assert_eq!(first_sil_checksum, from.episodes[0].weights_checksum, "the board did not start from the exported weights");
}
