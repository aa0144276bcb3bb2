//! Power cuts and hangs in the loop (`pada sil --power-cut`, `--fault
//! hang`): what to cut and when, and what each reboot found.
//!
//! ```text
//! --power-cut at=SECONDS               a cut at that emulated time
//! --power-cut random:N[:in-save=M][:seed=K]
//!                                      N cuts at seeded random instants, M (default round(N/3)) inside saves
//! --power-cut during-save:K            a cut inside the K-th checkpoint save (1 = the first)
//! --fault hang:at=SECONDS              the control loop stops feeding the watchdog (mps2-an386)
//! ```
//!
//! A cut kills QEMU at once (SIGKILL) and keeps the checkpoint file as it is
//! at that instant; the same image boots on it after [`OFF_US`] with the
//! servos powered off meanwhile (the robot falls limp; the operator sets it
//! back, `Rig::episode_ended`). A cut inside a save is armed on the board
//! ([`pada_firmware::sil::ToBoard::CutInSave`]): the checkpoint file takes
//! the save's first `after_bytes` bytes (its erase and writes, in order)
//! and the board stops there, so the cut lands at an exact byte between the
//! erase's first and the header's last.
//!
//! Random instants: `random:N` draws its timed cuts uniformly over the
//! learning time (`--seconds`; a cut comes at the first moment the learning
//! done so far, lost learning included, passes its instant, plus a uniform
//! 0–5 s of emulated time, so cuts land in learning and test episodes and
//! between them alike; one overtaken by another cut comes 1 s after the
//! next boot) and `round(N / 3)` of them inside saves: distinct
//! save attempts among the first `seconds / save interval`, each at a
//! uniform byte of the save. With a checkpoint larger than a slot (LEO on
//! `f429-sdram`) every save is refused before flash is touched, so all N
//! are timed.

use pada_core::checkpoint::slot_len;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;
use serde::Serialize;

/// How long the power stays off at a cut \[µs\] of emulated time.
pub const OFF_US: u64 = 2_000_000;
/// The random extra delay after a random cut's learning instant \[µs\].
const RANDOM_DELAY_US: u64 = 5_000_000;

/// One `--power-cut` option.
#[derive(Debug, Clone, PartialEq)]
pub enum CutSpec {
    /// A cut at this emulated time \[s\].
    At(f64),
    /// N cuts at seeded random instants.
    Random {
        /// How many.
        n: u32,
        /// How many of them inside saves (default: a third).
        in_save: Option<u32>,
        /// The seed.
        seed: u64,
    },
    /// A cut inside the K-th save attempt (1-based).
    DuringSave(u32),
}

/// The save interval with power cuts or hangs and no `--checkpoint-every`
/// \[s of learning\] for a checkpoint that fits a flash slot.
pub const FLASH_SAVE_EVERY_S: f64 = 20.0;

/// A checkpoint streamed to the host is saved at least this many times its
/// longest save's link time apart, so that saves stop learning for at most
/// a quarter of the time spent learning and saving.
pub const LINK_TIME_FACTOR: f64 = 3.0;

/// The save interval with power cuts or hangs and no `--checkpoint-every`
/// \[s of learning\], for a checkpoint of `checkpoint_bytes` and flash
/// slots of `slot_bytes`, on a robot whose episodes last up to
/// `max_episode_s`. One that fits a slot: [`FLASH_SAVE_EVERY_S`] (an erase
/// and a write stall the loop about a second). One streamed to the host
/// (LEO on the F429): the learning loop stands still while its image
/// streams, up to [`full_save_link_s`] (a full table: about 2 minutes for
/// LEO's 8 MiB at 921 600 baud), so the interval is [`LINK_TIME_FACTOR`]
/// times that, plus two of the robot's longest episodes (a save comes up
/// to two episodes before the interval is over: `Session::maybe_save`),
/// rounded up to a whole second.
///
/// [`full_save_link_s`]: crate::capture::transfer::full_save_link_s
pub fn default_save_every_s(checkpoint_bytes: usize, slot_bytes: usize, max_episode_s: f64) -> f64 {
    if checkpoint_bytes <= slot_bytes {
        return FLASH_SAVE_EVERY_S;
    }
    let link_s = crate::capture::transfer::full_save_link_s(checkpoint_bytes.min(u32::MAX as usize) as u32);
    (LINK_TIME_FACTOR * link_s + 2.0 * max_episode_s).ceil().max(FLASH_SAVE_EVERY_S)
}

/// Parses a `--power-cut` value.
pub fn parse(spec: &str) -> Result<CutSpec, String> {
    let bad = || format!("--power-cut {spec}: expected at=SECONDS, random:N[:in-save=M][:seed=K] or during-save:K");
    if let Some(t) = spec.strip_prefix("at=") {
        let t: f64 = t.parse().map_err(|_| bad())?;
        if !(t.is_finite() && t >= 0.0) {
            return Err(format!("--power-cut {spec}: the time must be at least 0 s"));
        }
        return Ok(CutSpec::At(t));
    }
    if let Some(k) = spec.strip_prefix("during-save:") {
        let k: u32 = k.parse().map_err(|_| bad())?;
        if k == 0 {
            return Err(format!("--power-cut {spec}: saves count from 1"));
        }
        return Ok(CutSpec::DuringSave(k));
    }
    if let Some(rest) = spec.strip_prefix("random:") {
        let mut parts = rest.split(':');
        let n: u32 = parts.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
        if !(1..=10_000).contains(&n) {
            return Err(format!("--power-cut {spec}: N must be 1..=10000"));
        }
        let (mut seed, mut in_save) = (1, None);
        for p in parts {
            if let Some(m) = p.strip_prefix("in-save=") {
                let m: u32 = m.parse().map_err(|_| bad())?;
                if m > n {
                    return Err(format!("--power-cut {spec}: in-save={m} is more than the {n} cuts"));
                }
                in_save = Some(m);
            } else {
                seed = p.strip_prefix("seed=").ok_or_else(bad)?.parse().map_err(|_| bad())?;
            }
        }
        return Ok(CutSpec::Random { n, in_save, seed });
    }
    Err(bad())
}

/// Parses `hang[:at=SECONDS]` (default at 10 s); `None` if `spec` is
/// another fault.
pub fn parse_hang(spec: &str) -> Option<Result<f64, String>> {
    let rest = spec.strip_prefix("hang")?;
    if rest.is_empty() {
        return Some(Ok(10.0));
    }
    let t = rest.strip_prefix(":at=").and_then(|t| t.parse::<f64>().ok()).filter(|t| t.is_finite() && *t >= 0.0);
    Some(t.ok_or_else(|| format!("--fault {spec}: expected hang[:at=SECONDS]")))
}

/// The cuts of a run, resolved.
#[derive(Debug, Clone, Default)]
pub struct CutPlan {
    /// Cuts at emulated times \[µs\], sorted.
    pub at_us: Vec<u64>,
    /// Cuts when the learning done passes an instant \[s\], then a delay
    /// \[µs\]; sorted by instant.
    pub learning: Vec<(f64, u64)>,
    /// Cuts inside saves: (save attempt, 1-based; bytes of the save written
    /// before the cut), sorted by attempt. For a checkpoint the host keeps,
    /// the bytes are of the image the stream had covered.
    pub in_save: Vec<(u32, u32)>,
    /// For a checkpoint the host keeps: the cuts (1-based, in the order
    /// made) whose next boot is cut again inside its restore.
    pub in_restore: Vec<u32>,
}

impl CutPlan {
    /// Resolves `specs` for a run of `seconds` saving every `save_every_s`
    /// of learning a checkpoint of `checkpoint_bytes` into slots of
    /// `slot_bytes` (a larger one is never written: its cuts are timed).
    ///
    /// A checkpoint larger than a slot is the host's to keep, streamed over
    /// the telemetry link: a cut inside a save falls at a uniform byte of
    /// the image the stream has covered, and of the cuts inside transfers
    /// half (rounded down) fall inside a restore instead (at the boot after
    /// one of the other cuts, chosen at random).
    pub fn new(specs: &[CutSpec], seconds: f64, save_every_s: f64, checkpoint_bytes: usize, slot_bytes: usize) -> CutPlan {
        let mut plan = CutPlan::default();
        let host_kept = checkpoint_bytes > slot_bytes;
        // A flash save erases the slot, then writes the checkpoint.
        let save_bytes = if host_kept { checkpoint_bytes as u32 } else { (slot_bytes + checkpoint_bytes) as u32 };
        for spec in specs {
            match *spec {
                CutSpec::At(t) => plan.at_us.push((t * 1e6).round() as u64),
                CutSpec::DuringSave(k) => plan.in_save.push((k, save_bytes / 2)),
                CutSpec::Random { n, in_save, seed } => {
                    let mut rng = Pcg32::seed_from_u64(seed);
                    let mut uniform = move || rng.next_u32() as f64 / (u32::MAX as f64 + 1.0);
                    let attempts = (seconds / save_every_s).floor() as u32;
                    let third = (n as f64 / 3.0).round() as u32;
                    let n_transfer = in_save.unwrap_or(third).min(attempts);
                    let n_restore = if host_kept { n_transfer / 2 } else { 0 };
                    let n_save = n_transfer - n_restore;
                    // The boots after distinct cuts among the others.
                    let mut after: Vec<u32> = (1..=n - n_restore).collect();
                    for i in 0..n_restore as usize {
                        let last = after.len() - 1;
                        let j = i + (uniform() * (after.len() - i) as f64) as usize;
                        after.swap(i, j.min(last));
                        plan.in_restore.push(after[i]);
                    }
                    // Distinct attempts: a partial Fisher-Yates over 1..=attempts.
                    let mut pool: Vec<u32> = (1..=attempts).collect();
                    for i in 0..n_save as usize {
                        let last = pool.len() - 1;
                        let j = i + (uniform() * (pool.len() - i) as f64) as usize;
                        pool.swap(i, j.min(last));
                        plan.in_save.push((pool[i], (uniform() * save_bytes as f64) as u32));
                    }
                    for _ in n_transfer..n {
                        plan.learning.push((uniform() * seconds, (uniform() * RANDOM_DELAY_US as f64) as u64));
                    }
                }
            }
        }
        plan.at_us.sort_unstable();
        plan.learning.sort_by(|a, b| a.0.total_cmp(&b.0));
        plan.in_save.sort_unstable();
        plan.in_restore.sort_unstable();
        // Two cuts asked for the same save: the second takes the next one.
        for i in 1..plan.in_save.len() {
            if plan.in_save[i].0 <= plan.in_save[i - 1].0 {
                plan.in_save[i].0 = plan.in_save[i - 1].0 + 1;
            }
        }
        plan
    }

    /// Cuts planned.
    pub fn len(&self) -> usize {
        self.at_us.len() + self.learning.len() + self.in_save.len() + self.in_restore.len()
    }

    /// No cut planned.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Bytes a checkpoint of `weights` weights of `bytes` each takes in a slot.
pub fn checkpoint_bytes(weights: usize, bytes: usize) -> usize {
    slot_len(weights, bytes)
}

/// One power cut and the boot after it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CutRecord {
    /// When \[s\] of emulated time.
    pub at_s: f64,
    /// Inside a save (its attempt number, and the bytes written before the
    /// cut).
    pub in_save: Option<(u32, u32)>,
    /// The generation of the last save completed before the cut (none: no
    /// save yet, or none fits).
    pub last_save: Option<u32>,
    /// Learning time since that save, lost \[s\].
    pub learning_lost_s: f64,
    /// What the next boot loaded: a generation, `None` for no checkpoint;
    /// filled at its `Checkpoint` report (or its first step).
    pub loaded: Option<Option<u32>>,
    /// The boot refused a checkpoint (`CheckpointIgnored`): lost or corrupt.
    pub refused: Option<String>,
    /// Inside the restore at boot from the host, as the board asked for
    /// the batch from this image offset.
    pub in_restore: Option<u32>,
    /// The boot after this cut was itself cut, inside its restore, before
    /// it reported what it loaded: the next cut's record answers for it
    /// (the same last save).
    pub boot_cut_off: bool,
}

impl CutRecord {
    /// The boot loaded exactly the last completed save (or, with none,
    /// found no checkpoint); a boot cut off in its restore is answered for
    /// by the next.
    pub fn loaded_last_save(&self) -> bool {
        self.boot_cut_off || (self.refused.is_none() && self.loaded == Some(self.last_save))
    }
}

/// One injected hang and the watchdog reset that ended it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HangRecord {
    /// When the host asked for it \[s\].
    pub asked_s: f64,
    /// When the control loop hung (its next period) \[s\].
    pub hung_s: Option<f64>,
    /// Emulated time from the watchdog's last feed to the reset \[ms\].
    pub reset_after_feed_ms: Option<f64>,
    /// The watchdog's period \[ms\].
    pub watchdog_ms: u32,
    /// When the chip reset \[s\].
    pub reset_s: Option<f64>,
    /// When every servo had torque off after the reset \[s\].
    pub torque_off_s: Option<f64>,
    /// From the reset to every servo's torque off \[ms\].
    pub torque_off_ms: Option<f64>,
    /// The reset cause the firmware reported.
    pub cause: Option<String>,
    /// The generation the boot loaded (`Some(None)`: no checkpoint).
    pub loaded: Option<Option<u32>>,
    /// The generation of the last save before the hang.
    pub last_save: Option<u32>,
    /// Learning episodes completed after the reset.
    pub episodes_after: u32,
}

impl HangRecord {
    /// Ended by the watchdog within its period, torque off within one
    /// control period, cause reported, the last save loaded, learning on.
    pub fn ok(&self, period_ms: f64) -> bool {
        self.reset_after_feed_ms.is_some_and(|t| t <= self.watchdog_ms as f64)
            && self.torque_off_ms.is_some_and(|t| t <= period_ms)
            && self.cause.is_some()
            && self.loaded == Some(self.last_save)
            && self.episodes_after > 0
    }
}

/// Everything about the run's power cuts, saves and hangs.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct PowerReport {
    /// Learning time between saves \[s\] (none: no saves).
    pub save_every_s: Option<f64>,
    /// Save attempts (`SaveCheckpoint` sent).
    pub save_attempts: u32,
    /// Saves completed (`Checkpoint(Saved)`).
    pub saves: u32,
    /// Saves refused: the checkpoint is larger than a slot.
    pub saves_too_large: u32,
    /// Other failed saves (wear budget, store).
    pub saves_failed: u32,
    /// The more worn sector's erases, from the last `Saved`.
    pub max_erases: u32,
    /// Erases the ten-year budget allows after the board's operating time.
    pub erases_allowed: f64,
    /// Cuts planned.
    pub cuts_planned: usize,
    /// Every cut and its boot.
    pub cuts: Vec<CutRecord>,
    /// Every hang.
    pub hangs: Vec<HangRecord>,
    /// Restores the board asked the host for (a checkpoint the host keeps).
    pub restores_asked: u32,
    /// Bytes of the last image the host kept.
    pub kept_bytes: u64,
    /// The most chunks a kept checkpoint took.
    pub kept_chunks: u32,
    /// Encoded chunk bytes of every kept checkpoint (what the link carried
    /// for them, before framing).
    pub streamed_bytes: u64,
    /// Chunks the keeper refused (out of order, corrupt, stale, …).
    pub chunks_refused: u32,
    /// The first refusal, in one line.
    pub first_chunk_refusal: Option<String>,
    /// `Streamed` reports whose checkpoint the host did not keep.
    pub streams_not_kept: u32,
    /// Seconds the saves streamed to the host held the telemetry link
    /// (`telemetry.csv`'s `checkpoint-save` rows): the control loop stands
    /// still meanwhile. QEMU gives a stream no emulated time; a real board's
    /// link does.
    pub save_link_s: f64,
    /// Seconds the restores from the host held the link (`checkpoint-restore`
    /// rows; the round trip of each request comes on top): the board waits
    /// at boot meanwhile.
    pub restore_link_s: f64,
    /// The share of the run a real board spends with learning stopped by
    /// those transfers: their link time over the emulated time plus it.
    pub paused_fraction: f64,
}

impl PowerReport {
    /// Takes the link time of the run's checkpoint transfers (the
    /// recorder's, one per save and restore) over `emulated_s` of run.
    pub fn note_transfers(&mut self, transfers: &[crate::capture::transfer::Transfer], emulated_s: f64) {
        use crate::capture::transfer::Direction;
        // (A fold from +0: an empty f64 sum is -0, which summary.json would show.)
        let sum = |d: Direction| transfers.iter().filter(|t| t.direction == d).fold(0.0, |a, t| a + t.link_s);
        self.save_link_s = sum(Direction::Save);
        self.restore_link_s = sum(Direction::Restore);
        let paused = self.save_link_s + self.restore_link_s;
        self.paused_fraction = if paused > 0.0 { paused / (emulated_s + paused) } else { 0.0 };
    }

    /// Cuts inside a save.
    pub fn cuts_in_save(&self) -> usize {
        self.cuts.iter().filter(|c| c.in_save.is_some()).count()
    }

    /// Cuts inside a restore from the host.
    pub fn cuts_in_restore(&self) -> usize {
        self.cuts.iter().filter(|c| c.in_restore.is_some()).count()
    }

    /// Boots that loaded the last completed save.
    pub fn boots_ok(&self) -> usize {
        self.cuts.iter().filter(|c| c.loaded_last_save()).count()
    }

    /// The most learning one cut lost \[s\].
    pub fn max_learning_lost_s(&self) -> f64 {
        self.cuts.iter().map(|c| c.learning_lost_s).fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_bad_ones_say_why() {
        assert_eq!(parse("at=12.5"), Ok(CutSpec::At(12.5)));
        assert_eq!(parse("random:30"), Ok(CutSpec::Random { n: 30, in_save: None, seed: 1 }));
        assert_eq!(parse("random:30:seed=7"), Ok(CutSpec::Random { n: 30, in_save: None, seed: 7 }));
        assert_eq!(parse("random:30:in-save=5:seed=7"), Ok(CutSpec::Random { n: 30, in_save: Some(5), seed: 7 }));
        assert_eq!(parse("during-save:3"), Ok(CutSpec::DuringSave(3)));
        for bad in ["at=-1", "random:0", "during-save:0", "now", "random:3:salt=1", "random:3:in-save=4"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_hang("hang:at=20"), Some(Ok(20.0)));
        assert_eq!(parse_hang("hang"), Some(Ok(10.0)));
        assert!(parse_hang("hang:when=2").unwrap().is_err());
        assert_eq!(parse_hang("drop:at=2"), None);
    }

    #[test]
    fn the_paused_fraction_is_the_transfers_link_time_over_the_run_with_it() {
        use crate::capture::transfer::{Direction, Transfer};
        let t = |direction, link_s| Transfer {
            direction,
            generation: Some(1),
            bytes: 8,
            chunks: 1,
            requests: 0,
            board_bytes: 0,
            host_bytes: 0,
            link_s,
            outcome: "streamed".into(),
            reported: true,
            reported_chunks: Some(1),
            started_s: 0.0,
            ended_s: 0.0,
        };
        let mut p = PowerReport::default();
        p.note_transfers(&[], 100.0);
        // No transfer: +0 s (an empty float sum is -0, printed as such).
        assert_eq!((p.save_link_s.to_bits(), p.paused_fraction), (0f64.to_bits(), 0.0));
        p.note_transfers(&[t(Direction::Save, 30.0), t(Direction::Restore, 50.0), t(Direction::Save, 20.0)], 300.0);
        assert_eq!((p.save_link_s, p.restore_link_s, p.paused_fraction), (50.0, 50.0, 0.25));
    }

    #[test]
    fn the_default_save_interval_follows_the_images_link_time() {
        use crate::capture::transfer::full_save_link_s;
        // A checkpoint in flash: 20 s, whatever the robot.
        assert_eq!(default_save_every_s(100_368, 131_072, 3.0), FLASH_SAVE_EVERY_S);
        // LEO on f429-sdram (its image, 25 s episodes): three full saves'
        // link time between two saves even when one comes two episodes
        // early, so saves stop learning at most a quarter of the time.
        let profile = pada_core::profile::Board::F429Sdram.profile(&pada_core::robot::leo::SPEC).unwrap();
        let image = checkpoint_bytes(profile.weights().unwrap(), profile.entry_bytes());
        let spec = &pada_core::robot::leo::SPEC;
        let episode_s = spec.episode_steps as f64 * spec.period_us as f64 * 1e-6;
        let every = default_save_every_s(image, 131_072, episode_s);
        let link = full_save_link_s(image as u32);
        eprintln!("LEO f429-sdram: a full save {link:.1} s on the link, default interval {every} s");
        assert!(every - 2.0 * episode_s >= LINK_TIME_FACTOR * link, "{every} s for {link} s saves");
        assert!(every - 2.0 * episode_s < LINK_TIME_FACTOR * link + 1.0);
        assert_eq!(every, every.round(), "whole seconds");
        // `pada sil --help` names it.
        let help = crate::commands::sil::checkpoint_every_help();
        assert!(help.contains(&format!("LEO on f429-sdram: {every} s")), "{help}");
    }

    #[test]
    fn a_random_plan_puts_a_third_inside_distinct_saves_and_is_seeded() {
        let specs = [CutSpec::Random { n: 30, in_save: None, seed: 3 }];
        let p = CutPlan::new(&specs, 600.0, 20.0, 100_368, 131_072);
        assert_eq!(p.len(), 30);
        assert_eq!(p.in_save.len(), 10);
        assert!(p.in_save.iter().all(|&(k, b)| (1..=30).contains(&k) && b < 131_072 + 100_368));
        assert!(p.learning.iter().all(|&(t, d)| (0.0..600.0).contains(&t) && d < RANDOM_DELAY_US));
        let again = CutPlan::new(&specs, 600.0, 20.0, 100_368, 131_072);
        assert_eq!((p.learning.clone(), p.in_save.clone()), (again.learning, again.in_save));
        // A checkpoint that no slot holds is the host's: of the cuts inside
        // transfers, half fall inside a restore, after a distinct other cut.
        let leo = CutPlan::new(&[CutSpec::Random { n: 5, in_save: None, seed: 1 }], 60.0, 20.0, 8_389_136, 131_072);
        let five = CutPlan::new(&[CutSpec::Random { n: 30, in_save: Some(5), seed: 1 }], 600.0, 20.0, 100_368, 131_072);
        assert_eq!((five.learning.len(), five.in_save.len(), five.in_restore.len()), (25, 5, 0));
        assert_eq!((leo.learning.len(), leo.in_save.len(), leo.in_restore.len()), (3, 1, 1));
        assert!(leo.in_save.iter().all(|&(k, b)| (1..=3).contains(&k) && b < 8_389_136));
        assert!(leo.in_restore.iter().all(|&c| (1..=4).contains(&c)));
        let many = CutPlan::new(&[CutSpec::Random { n: 20, in_save: Some(8), seed: 4 }], 7333.0, 300.0, 8_389_664, 131_072);
        assert_eq!((many.learning.len(), many.in_save.len(), many.in_restore.len(), many.len()), (12, 4, 4, 20));
        let mut distinct = many.in_restore.clone();
        distinct.dedup();
        assert_eq!(distinct, many.in_restore);
    }
}

/// The checks of a run's cuts, saves and hangs (none without them).
pub fn checks(p: &mut PowerReport, period_ms: f64, emulated_s: f64, checkpoint_fits: bool) -> Vec<super::check::Check> {
    use super::check::Check;
    let mut checks = Vec::new();
    p.erases_allowed = pada_core::checkpoint::WearBudget::STM32F4.allowed(emulated_s as u64) as f64;
    let lost: Vec<f64> = p.cuts.iter().map(|c| c.learning_lost_s).collect();
    let mean_lost = if lost.is_empty() { 0.0 } else { lost.iter().sum::<f64>() / lost.len() as f64 };
    if p.cuts_planned > 0 {
        let refused = p.cuts.iter().filter(|c| c.refused.is_some()).count();
        checks.push(Check {
            name: "power cuts: every planned cut made, every boot loaded the last completed save",
            ok: p.cuts.len() == p.cuts_planned && p.boots_ok() == p.cuts.len(),
            detail: format!(
                "{} of {} cuts made ({} inside a save, {} inside a restore from the host); {} of {} boots loaded the last completed save; {} refused a checkpoint (lost or corrupt){}",
                p.cuts.len(),
                p.cuts_planned,
                p.cuts_in_save(),
                p.cuts_in_restore(),
                p.boots_ok(),
                p.cuts.len(),
                refused,
                p.cuts
                    .iter()
                    .find(|c| !c.loaded_last_save())
                    .map(|c| format!("; first bad boot after the cut at {:.3} s: last save {:?}, loaded {:?}, refused {:?}", c.at_s, c.last_save, c.loaded, c.refused))
                    .unwrap_or_default()
            ),
        });
        if let Some(every) = p.save_every_s {
            checks.push(Check {
                name: "power cuts: learning lost per cut at most one save interval",
                ok: p.max_learning_lost_s() <= every + 1e-9,
                detail: format!(
                    "mean {mean_lost:.2} s, max {:.2} s of learning lost per cut; saves every {every} s{}",
                    p.max_learning_lost_s(),
                    if checkpoint_fits { "" } else { " (streamed to the host, which keeps them)" }
                ),
            });
        }
    }
    if !checkpoint_fits && (p.save_attempts > 0 || p.restores_asked > 0) {
        checks.push(Check {
            name: "checkpoints kept by the host: every save streamed whole was kept, no chunk refused",
            ok: p.chunks_refused == 0 && p.streams_not_kept == 0 && p.saves_too_large == 0,
            detail: format!(
                "{} of {} save attempts kept ({} cut off inside), last image {} bytes in up to {} chunks, {} encoded bytes streamed for them; {} restores asked; saves held the 921,600-baud link {:.1} s, restores {:.1} s: learning stopped {:.1} % of the run; {} chunks refused{}; {} streams reported but not kept",
                p.saves,
                p.save_attempts,
                p.cuts_in_save(),
                p.kept_bytes,
                p.kept_chunks,
                p.streamed_bytes,
                p.restores_asked,
                p.save_link_s,
                p.restore_link_s,
                p.paused_fraction * 100.0,
                p.chunks_refused,
                p.first_chunk_refusal.as_deref().map(|r| format!(" (first: {r})")).unwrap_or_default(),
                p.streams_not_kept
            ),
        });
    }
    if p.saves > 0 && checkpoint_fits {
        checks.push(Check {
            name: "flash: erases within the ten-year wear budget, no save failed",
            ok: (p.max_erases as f64) <= p.erases_allowed && p.saves_failed == 0,
            detail: format!(
                "{} saves of {} attempts; the more worn sector erased {} times, {} allowed after {:.0} s of operation; {} failed",
                p.saves, p.save_attempts, p.max_erases, p.erases_allowed, emulated_s, p.saves_failed
            ),
        });
    }
    for h in &p.hangs {
        checks.push(Check {
            name: "hang: reset by the watchdog within its period, torque off on every servo within one control period, cause reported, last save loaded, learning resumed",
            ok: h.ok(period_ms),
            detail: format!(
                "asked at {:.3} s, hung {}, reset {} after the last feed (period {} ms), torque off {} after the reset (period {period_ms} ms), cause {}, loaded {:?} (last save {:?}), {} learning episodes after",
                h.asked_s,
                h.hung_s.map(|t| format!("{t:.3} s")).unwrap_or("never".into()),
                h.reset_after_feed_ms.map(|t| format!("{t:.3} ms")).unwrap_or("never".into()),
                h.watchdog_ms,
                h.torque_off_ms.map(|t| format!("{t:.3} ms")).unwrap_or("never".into()),
                h.cause.as_deref().unwrap_or("none"),
                h.loaded,
                h.last_save,
                h.episodes_after
            ),
        });
    }
    checks
}
