//! Power cuts, hangs and the watchdog in the loop (`pada sil --power-cut`,
//! `--fault hang`): the real firmware image in QEMU is killed (SIGKILL)
//! while it learns — at random instants and inside checkpoint saves —,
//! booted again on the same checkpoint file, and must load exactly the last
//! save it completed (LEO on `f429-sdram`: the one the host keeps); a
//! hung control loop on mps2-an386 must be ended by the CMSDK watchdog
//! within its period. None is skipped when QEMU is missing.

mod common;

use pada::seed::trial_seed;
use pada::sil::power_cut::{self, CutSpec};
use pada::sil::replay::{replay, Record};
use pada::sil::{run, SilConfig, SilSummary, SilTask};
use pada_core::policy::PolicyKind;
use pada_core::profile::Board;
use pada_core::wire::{CheckpointReport, HostDecoder, ToHost};
use pada_core::robot::pendulum::SPEC_33HZ;
use std::path::Path;
use std::time::Duration;

fn config(board: Board, task: SilTask, policy: PolicyKind, seconds: f64, out: &Path) -> SilConfig {
    common::require_qemu();
    SilConfig {
        qemu: "qemu-system-arm".into(),
        elf: common::image(board.name(), task.name()),
        task,
        board,
        policy,
        mtbf_budget_s: None,
        seconds,
        seed: 1,
        faults: vec![],
        power_cuts: vec![],
        hangs_s: vec![],
        save_every_s: Some(10.0),
        forecast: true,
        compare: false,
        out_dir: out.to_path_buf(),
        hang_timeout: Duration::from_secs(120),
        progress: false,
        telemetry: None,
        weights: None,
    }
}

fn go(cfg: &SilConfig) -> SilSummary {
    run(cfg).unwrap_or_else(|e| panic!("SIL run failed: {e:#}"))
}

fn failures(s: &SilSummary) -> Vec<String> {
    s.checks.iter().filter(|c| !c.ok).map(|c| format!("{}: {}", c.name, c.detail)).collect()
}

/// The replay's records from a recorded stream; with `boots`, a `Saved` at
/// every completed save and a `Boot` at every `Hello` after the first (a
/// board announces itself at every boot).
fn records(stream: &[u8], boots: bool) -> Vec<Record> {
    let mut out = Vec::new();
    let mut hellos = 0;
    for frame in HostDecoder::new().feed(stream) {
        match frame.expect("a clean recording").msg {
            ToHost::Step(s) => out.push(Record::Step(s)),
            ToHost::Episode(e) => out.push(Record::Episode(e)),
            ToHost::Checkpoint(CheckpointReport::Saved(_)) if boots => out.push(Record::Saved),
            ToHost::Hello(_) if boots => {
                hellos += 1;
                if hellos > 1 {
                    out.push(Record::Boot);
                }
            }
            _ => {}
        }
    }
    out
}

#[test]
fn power_cuts_at_random_and_inside_saves_each_boot_loads_the_last_completed_save() {
    let dir = tempfile::tempdir().unwrap();
    let policy = PolicyKind::Pada { delta: 0.5 };
    let mut cfg = config(Board::F405, SilTask::Pendulum, policy, 60.0, dir.path());
    cfg.power_cuts = vec![
        CutSpec::Random { n: 6, in_save: Some(2), seed: 5 },
        CutSpec::DuringSave(5),
        CutSpec::At(30.0),
    ];
    let s = go(&cfg);
    assert!(s.passed, "{:#?}", failures(&s));
    let p = &s.power;
    assert_eq!((p.cuts_planned, p.cuts.len()), (8, 8), "{p:#?}");
    assert_eq!(p.cuts_in_save(), 3, "{p:#?}");
    // Every boot loaded exactly the last save completed before its cut
    // (none refused, none older), and at least one had a save to load.
    assert_eq!(p.boots_ok(), 8, "{p:#?}");
    assert!(p.cuts.iter().any(|c| c.last_save.is_some() && c.loaded == Some(c.last_save)), "{p:#?}");
    assert!(p.cuts.iter().all(|c| c.refused.is_none()));
    // No more learning lost than one save interval.
    assert!(p.max_learning_lost_s() <= 10.0, "{p:#?}");
    // The replay restarted from the last save at every boot, and still
    // matched bit for bit.
    assert_eq!(s.replay.boots, 8);
    assert!(s.replay.identical, "{:?}", s.replay);

    // From the recorded stream alone: the same, with the boots marked by
    // their Hello; a replay that ignores the boots (the learner going on
    // as if never cut) does not match, so the check has teeth.
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    let profile = Board::F405.profile(&SPEC_33HZ).unwrap();
    let seed = trial_seed(1, 0);
    let with = replay(&profile, policy, seed, &records(&stream, true));
    assert!(with.identical && with.boots == 8, "{with:?}");
    let without = replay(&profile, policy, seed, &records(&stream, false));
    assert!(!without.identical, "{without:?}");
}

#[test]
fn a_hung_control_loop_on_mps2_is_reset_by_the_watchdog_within_its_period() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = config(Board::F429Sdram, SilTask::Pendulum, PolicyKind::Sarsa, 40.0, dir.path());
    // One hang before the first save (the board starts afresh), two after.
    cfg.hangs_s = vec![20.0, 110.0, 170.0];
    let s = go(&cfg);
    assert!(s.passed, "{:#?}", failures(&s));
    assert_eq!(s.power.hangs.len(), 3);
    for h in &s.power.hangs {
        assert_eq!(h.watchdog_ms, 250);
        let after = h.reset_after_feed_ms.unwrap();
        assert!(after > 240.0 && after <= 250.0, "{h:?}");
        assert!(h.torque_off_ms.unwrap() <= 30.0, "{h:?}");
        assert_eq!(h.cause.as_deref(), Some("watchdog-reset"));
        assert_eq!(h.loaded, Some(h.last_save), "{h:?}");
        assert!(h.episodes_after > 0);
    }
    assert!(s.power.hangs.iter().any(|h| h.last_save.is_some()), "{:#?}", s.power.hangs);
    assert_eq!(s.replay.boots, 3);
    assert!(s.unexpected_faults.is_empty(), "{:?}", s.unexpected_faults);
}

#[test]
fn leo_on_f429_resumes_every_cut_from_the_checkpoint_the_host_keeps() {
    // LEO's 8 MiB table fits no flash slot: the board streams its saves to
    // the host, which keeps them in the run's checkpoint.bin, and asks for
    // the kept one at every boot. Three cuts: one timed, one inside a save
    // stream, one inside the restore at a boot.
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = config(Board::F429Sdram, SilTask::Leo, PolicyKind::Pada { delta: 0.1667 }, 20.0, dir.path());
    cfg.power_cuts = vec![CutSpec::Random { n: 3, in_save: Some(2), seed: 1 }];
    cfg.save_every_s = Some(5.0);
    let s = go(&cfg);
    assert!(s.passed, "{:#?}", failures(&s));
    let p = &s.power;
    assert_eq!((p.cuts.len(), p.cuts_in_save(), p.cuts_in_restore()), (3, 1, 1), "{p:#?}");
    assert!(p.saves > 0 && p.saves_too_large == 0 && p.chunks_refused == 0, "{p:#?}");
    // Every boot resumed from the last checkpoint the host kept before its
    // cut (the one cut off in its restore: by the boot after it).
    assert!(p.cuts.iter().all(|c| c.loaded_last_save()), "{p:#?}");
    assert!(p.cuts.iter().any(|c| c.last_save.is_some() && c.loaded == Some(c.last_save)), "{p:#?}");
    assert!(p.cuts.iter().all(|c| c.learning_lost_s <= 5.0 + 1e-9), "{p:#?}");
    assert!(s.replay.identical && s.replay.boots == 3, "{:?}", s.replay);
    // The file survived the cuts whole: the last save kept.
    let kept = pada::checkpoint_keeper::read_kept(&dir.path().join("checkpoint.bin")).unwrap();
    assert_eq!(kept.image().len() as u64, p.kept_bytes);
    // Each restore that loaded asked once per batch of 24 chunks (protocol
    // 9; once per 3 before, 21 848 round trips for a full LEO table),
    // counted from the raw stream: the CSV has one row per restore.
    let stream = std::fs::read(dir.path().join("telemetry.bin")).unwrap();
    let mut rec = pada::capture::Recorder::new(None).unwrap();
    rec.feed(&stream, 0.0, &mut Vec::new()).unwrap();
    rec.end().unwrap();
    let loaded: Vec<_> = rec
        .transfers()
        .iter()
        .filter(|t| t.direction == pada::capture::transfer::Direction::Restore && t.outcome == "loaded")
        .collect();
    assert!(!loaded.is_empty(), "{:#?}", rec.transfers());
    for t in loaded {
        assert!(t.chunks > 24 && t.requests == t.chunks.div_ceil(24), "{t:?}");
    }
    let csv = std::fs::read_to_string(dir.path().join("telemetry.csv")).unwrap();
    let rows = csv.lines().filter(|l| l.contains(",checkpoint-restore,")).count();
    assert_eq!(rows as u32, p.restores_asked, "one row per restore");
}

#[test]
fn the_plan_and_the_hang_spec_parse() {
    assert_eq!(power_cut::parse("random:30:in-save=5:seed=9"), Ok(CutSpec::Random { n: 30, in_save: Some(5), seed: 9 }));
    assert_eq!(power_cut::parse_hang("hang:at=12"), Some(Ok(12.0)));
}
