//! Weights learned on the host, continued on a board: the board's
//! learner started from the exported entries (`pada run --board B
//! --weights`) equals, bit for bit, the board booting from the checkpoint
//! image of those entries (the firmware's restore at boot: the file the
//! host keeps for it, the flash slot), on the F405's hashed 16-bit table
//! and the F429's claim table; a board from exported weights learns
//! otherwise than one from nothing; and the image is one the host's
//! checkpoint keeper serves to a board of that configuration.

mod common;
use common::{ok, pada};
use pada::board::export::export;
use pada::board::exported::image_of;
use pada::board::trial::table_len;
use pada::board::{run_board_trial_from, BoardStart};
use pada::experiment::RunConfig;
use pada::robots::sim_robot;
use pada::start_weights::StartWeights;
use pada_core::policy::PolicyKind;
use pada_core::profile::Board;

/// Host weights of `task` after `seconds` of PADA, saved by `pada run`.
fn host_weights(dir: &std::path::Path, task: &str, seconds: &str) -> std::path::PathBuf {
    let w = dir.join(format!("{task}.wts"));
    ok(&pada(&[
        "run", "--task", task, "--algo", "pada", "--trials", "1", "--seconds", seconds, "--threads", "1",
        "--out", dir.join(task).to_str().unwrap(), "--save-weights", w.to_str().unwrap(),
    ]));
    w
}

/// Board `board`'s trial 0 of `robot` from the exported weights, by both
/// paths, and from nothing; the two exported ones must be equal.
fn continue_on(board: Board, robot: &'static pada_core::robot::RobotSpec, weights: &std::path::Path, seconds: f64) {
    let sim = sim_robot(robot).unwrap();
    let policy = PolicyKind::Pada { delta: 0.5 };
    let host_spec = sim.task_spec(Board::Host.profile(robot).unwrap()).unwrap();
    let start = StartWeights::load(weights, &host_spec, policy).unwrap();
    let profile = board.profile(robot).unwrap();
    let n = table_len(&profile, policy).unwrap();
    let (entries, report) = export(&start, &host_spec, &profile, n).unwrap();
    assert!(report.kept > 0 && report.kept + report.dropped == report.learned, "{report:?}");
    let cfg = RunConfig { policy, switch_at_s: None, mtbf_budget_s: None, seconds, trials: 1, seed: 3 };
    let seed = pada::seed::trial_seed(cfg.seed, 0);
    let image = image_of(profile, &sim, policy, None, seed, n, &entries).unwrap();
    let none = |_| {};
    let imported = run_board_trial_from(profile, &sim, &cfg, 0, BoardStart::Entries(&entries), &none).unwrap();
    let booted = run_board_trial_from(profile, &sim, &cfg, 0, BoardStart::Checkpoint(&image), &none).unwrap();
    let fresh = run_board_trial_from(profile, &sim, &cfg, 0, BoardStart::Fresh, &none).unwrap();
    assert!(!imported.episodes.is_empty());
    assert_eq!(imported.episodes, booted.episodes, "{}: the episodes differ", board.name());
    assert_eq!(imported.weights_checksum, booted.weights_checksum);
    assert_eq!(imported, booted, "{}: the trials differ", board.name());
    assert_ne!(imported.episodes[0].weights_checksum, fresh.episodes[0].weights_checksum, "{}: the exported weights did not arrive", board.name());
    // The image is what the host keeps for a board whose checkpoint fits
    // no flash: its keeper reads it back for the board's configuration.
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("checkpoint.bin");
    std::fs::write(&kept, &image).unwrap();
    let restore = pada::checkpoint_keeper::restore_for(&kept, imported.config_hash, image.len() as u64, None).unwrap();
    assert_eq!(restore.image(), &image[..]);
    assert!(pada::checkpoint_keeper::restore_for(&kept, imported.config_hash ^ 1, image.len() as u64, None).is_err());
}

#[test]
fn leo_continues_from_host_weights_on_the_f405_and_the_f429_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let w = host_weights(dir.path(), "leo", "20");
    continue_on(Board::F405, &pada_core::robot::leo::SPEC, &w, 10.0);
    continue_on(Board::F429Sdram, &pada_core::robot::leo::SPEC, &w, 10.0);
}

#[test]
fn the_physical_pendulum_continues_from_host_weights_on_the_f405_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let w = host_weights(dir.path(), "physical-pendulum", "60");
    continue_on(Board::F405, &pada_core::robot::pendulum::SPEC_33HZ, &w, 30.0);
}
