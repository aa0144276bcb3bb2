//! Power cuts, saves and hangs in the lock-step loop: the plan and what
//! happened, when a cut or a save is due, and each reboot the host causes,
//! checked at the board's next boot (what it loaded, where the run goes on
//! from).

use super::{Session, FIRST_COMMAND_US};
use crate::board::RunProtocol;
use crate::sil::power_cut::{CutPlan, CutRecord, PowerReport, OFF_US};
use crate::sil::replay::Record;
use crate::sil::wall::Account;
use anyhow::{bail, Context};
use pada_core::wire::{self, FrameEncoder, RunMode, StepKind, ToChip};
use pada_firmware::sil::{ResetCause, ToBoard};

/// The last completed checkpoint save, as the host recorded it.
#[derive(Debug, Clone)]
pub(super) struct LastSave {
    pub(super) generation: u32,
    /// The run protocol then: where a boot that loads it goes on from.
    pub(super) protocol: RunProtocol,
}

/// A cut inside a checkpoint transfer with the host (a board whose
/// checkpoint fits no flash): decided while a telemetry frame is taken,
/// made once the frame is done.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum TransferCut {
    /// Inside save attempt `attempt`, at the chunk that reached
    /// `after_bytes` of the image (that chunk and the rest never arrive).
    Save {
        /// The save attempt (1-based).
        attempt: u32,
        /// Image bytes the stream had covered.
        after_bytes: u32,
    },
    /// Inside the restore at boot, as the board asked for the batch from
    /// `offset`.
    Restore {
        /// The offset asked for.
        offset: u32,
    },
}

/// A reboot the host caused, whose boot is to be checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Reboot {
    /// After `power.cuts[i]`.
    Cut(usize),
    /// After `power.hangs[i]`.
    Hang(usize),
}

/// Power cuts, saves and hangs: the plan and what happened.
pub(super) struct Power {
    pub(super) report: PowerReport,
    pub(super) plan: CutPlan,
    /// Next of `plan.at_us`, `plan.learning` to come.
    pub(super) next_at: usize,
    pub(super) next_learning: usize,
    /// A timed cut decided on, at this instant \[µs\].
    pub(super) due_us: Option<u64>,
    /// Timed cuts decided on but overtaken by another reboot: each comes
    /// 1 s after the next boot settles.
    pub(super) deferred: u32,
    /// Learning done so far, lost learning included \[s\].
    pub(super) learning_done_s: f64,
    /// The in-save cut armed for the next `SaveCheckpoint` sent.
    pub(super) arm_next_save: Option<(u32, u32)>,
    /// The in-save cut sent to the board with its save.
    pub(super) armed: Option<(u32, u32)>,
    pub(super) last_save: Option<LastSave>,
    /// The protocol's learning time at the last save attempt \[s\].
    pub(super) last_attempt_learning_s: f64,
    /// The run as it starts: what a boot without a checkpoint goes on from.
    pub(super) initial: RunProtocol,
    /// Hangs to ask for \[µs\], sorted; the next to come.
    pub(super) hangs_us: Vec<u64>,
    pub(super) next_hang: usize,
    /// A reboot whose Boot has not come.
    pub(super) awaiting_boot: Option<Reboot>,
    /// A reboot whose checkpoint outcome has not come.
    pub(super) awaiting_load: Option<Reboot>,
    /// The watchdog's period on this board \[ms\] (0: none).
    pub(super) watchdog_ms: u32,
    /// A cut inside a save streamed to the host, armed for the stream of
    /// this save attempt: (attempt, image bytes covered).
    pub(super) stream_armed: Option<(u32, u32)>,
    /// A transfer cut to make once the frame being taken is done.
    pub(super) cut_now: Option<TransferCut>,
    /// The boot's restore is to be cut at its [`RESTORE_CUT_REQUEST`]-th
    /// request.
    pub(super) restore_cut_armed: bool,
    /// Requests of the restore in progress.
    pub(super) restore_requests: u32,
    /// The run goes on (`Start`) once the board reports its restore.
    pub(super) start_after_restore: bool,
}

/// The request of a restore at which an armed restore cut falls: the
/// second, when the header and the first body chunks have arrived and
/// some of the table is written.
pub(super) const RESTORE_CUT_REQUEST: u32 = 2;

impl Power {
    /// Nothing happened yet: cuts as `plan` says, hangs at `hangs_us`
    /// (sorted), saves every `save_every_s` of learning, a run that starts
    /// as `initial`.
    pub(super) fn new(plan: CutPlan, hangs_us: Vec<u64>, save_every_s: Option<f64>, initial: RunProtocol) -> Power {
        Power {
        report: PowerReport { save_every_s: save_every_s, cuts_planned: plan.len(), ..Default::default() },
        plan,
        next_at: 0,
        next_learning: 0,
        due_us: None,
        deferred: 0,
        learning_done_s: 0.0,
        arm_next_save: None,
        armed: None,
        last_save: None,
        last_attempt_learning_s: 0.0,
        initial,
        hangs_us,
        next_hang: 0,
        awaiting_boot: None,
        awaiting_load: None,
        watchdog_ms: 0,
        stream_armed: None,
        cut_now: None,
        restore_cut_armed: false,
        restore_requests: 0,
        start_after_restore: false,
        }
    }
}

impl Power {
    /// Whether the restore request just counted is where the armed restore
    /// cut falls (then it is disarmed).
    pub(super) fn restore_cut_due(&mut self) -> bool {
        let due = self.restore_cut_armed && self.restore_requests == RESTORE_CUT_REQUEST;
        if due {
            self.restore_cut_armed = false;
        }
        due
    }
}

impl Session<'_> {
    /// Cuts the power inside a checkpoint transfer with the host.
    pub(super) fn transfer_cut(&mut self, at_us: u64, cut: TransferCut) -> anyhow::Result<()> {
        match cut {
            TransferCut::Save { attempt, after_bytes } => self.power_cut(at_us, Some((attempt, after_bytes))),
            TransferCut::Restore { offset } => {
                self.power_cut(at_us, None)?;
                if let Some(c) = self.power.report.cuts.last_mut() {
                    c.in_restore = Some(offset);
                }
                Ok(())
            }
        }
    }

    /// After a Boot's checks: configure the board and start (or resume) the
    /// run; a reboot the host did not cause ends the run.
    pub(super) fn after_boot(&mut self, reset: ResetCause) -> anyhow::Result<()> {
        let reboot = self.power.awaiting_boot.take();
        match (self.booted, reboot, reset) {
            (false, None, ResetCause::PowerOn) => {}
            (true, Some(Reboot::Cut(_)), ResetCause::PowerOn) => {}
            (true, Some(Reboot::Hang(i)), ResetCause::Watchdog { fed_at_us, hung_at_us, since_feed_ns }) => {
                let reset_us = hung_at_us.max(fed_at_us) + since_feed_ns / 1000;
                let h = &mut self.power.report.hangs[i];
                h.hung_s = Some(hung_at_us as f64 * 1e-6);
                h.reset_after_feed_ms = Some(since_feed_ns as f64 * 1e-6);
                h.reset_s = Some(reset_us as f64 * 1e-6);
                // The servos keep their last command while the chip is hung.
                self.wall.time(Account::Plant, || self.rig.advance_to(reset_us));
                self.bus.watch_torque_off(reset_us);
                self.reboot_at(reset_us.max(self.now_us))?;
            }
            (_, reboot, reset) => bail!(
                "the board booted unexpectedly ({reset:?}; the host expected {}): a reset nobody caused",
                match reboot {
                    Some(Reboot::Cut(_)) => "a power-on after its power cut",
                    Some(Reboot::Hang(_)) => "a watchdog reset after its hang",
                    None => "no reset",
                }
            ),
        }
        let first = !self.booted;
        self.booted = true;
        self.power.awaiting_load = reboot;
        self.queue(&ToBoard::Configure { seed: self.cfg.learner_seed(), now_us: self.now_us })?;
        self.send_queued()?;
        if !first && self.power.last_save.is_some() {
            // The board loads the last save and waits, torque off (after a
            // watchdog reset in Fault, which the Fault report clears). A
            // board restoring from the host goes on once it reports the
            // restore (which takes as long as its table is large).
            if matches!(reboot, Some(Reboot::Cut(_))) {
                if self.kept.is_some() {
                    self.power.start_after_restore = true;
                } else {
                    self.command_at(self.now_us + FIRST_COMMAND_US, ToChip::Start(RunMode::Learning));
                }
            }
            return Ok(());
        }
        if first && self.from_weights {
            // The board restores the exported weights' checkpoint (policy,
            // budget and table in it) and starts once it reports that.
            return Ok(());
        }
        // A first boot, or a reboot with no save to load: the run starts
        // again (after a watchdog reset the board is in Fault; the Fault
        // report clears it).
        let base = self.now_us;
        // A fresh learner with the run's policy, then the first test episode.
        // As `pada run --board`: the budget after the policy, before the
        // first run (torque off).
        let mut k = 0;
        for cmd in RunProtocol::start(self.cfg.policy) {
            if let (ToChip::Start(_), Some(budget)) = (&cmd, self.cfg.mtbf_budget_s) {
                k += 1;
                self.command_at(base + FIRST_COMMAND_US * k, ToChip::SetMtbfBudget(Some(budget)));
            }
            k += 1;
            self.command_at(base + FIRST_COMMAND_US * k, cmd);
        }
        Ok(())
    }

    /// The board's state is gone (a power cut or a reset) and it boots
    /// again at `now_us`: the run goes on from the last completed save (or
    /// from the start, with none), as the board will.
    fn reboot_at(&mut self, now_us: u64) -> anyhow::Result<()> {
        self.now_us = now_us;
        self.horizon_us = now_us;
        self.protocol = match &self.power.last_save {
            Some(s) => s.protocol.clone(),
            None => self.power.initial.clone(),
        };
        self.power.last_attempt_learning_s = self.protocol.learning_time_s();
        if self.power.due_us.take().is_some() {
            self.power.deferred += 1;
        }
        self.power.armed = None;
        self.commands.clear();
        self.replies.clear();
        self.forecaster.void();
        self.after = None;
        self.inbox.clear();
        self.decoder = wire::FrameDecoder::new();
        self.to_board_seq = 0;
        self.encoder = FrameEncoder::new();
        self.last_step_kind = StepKind::Start;
        self.recorder.restarted().context("cannot write telemetry.csv")?;
        self.records.push(Record::Boot);
        Ok(())
    }

    /// Cuts the power at `at_us` (`in_save`: the save attempt and the
    /// bytes it wrote) and boots the board again after [`OFF_US`].
    pub(super) fn power_cut(&mut self, at_us: u64, in_save: Option<(u32, u32)>) -> anyhow::Result<()> {
        self.wall.time(Account::Board, || self.emu.power_cycle())?;
        // A boot cut off before it reported what it loaded: the next boot,
        // which finds the same last save, answers for it.
        if let Some(Reboot::Cut(i)) = self.power.awaiting_load.take() {
            self.power.report.cuts[i].boot_cut_off = true;
        }
        self.power.stream_armed = None;
        self.power.start_after_restore = false;
        let saved_s = self.power.last_save.as_ref().map_or(0.0, |s| s.protocol.learning_time_s());
        self.power.report.cuts.push(CutRecord {
            at_s: at_us as f64 * 1e-6,
            in_save,
            last_save: self.power.last_save.as_ref().map(|s| s.generation),
            learning_lost_s: self.protocol.learning_time_s() - saved_s,
            loaded: None,
            refused: None,
            in_restore: None,
            boot_cut_off: false,
        });
        // The restore at the boot after this cut is to be cut too.
        let made = self.power.report.cuts.len() as u32;
        self.power.restore_cut_armed = self.power.plan.in_restore.contains(&made);
        let (rig, bus) = (self.rig.as_mut(), &mut self.bus);
        self.wall.time(Account::Plant, || {
            rig.advance_to(at_us);
            // The robot falls limp; the operator sets it back.
            bus.power_off(at_us, rig);
            rig.episode_ended(at_us);
        });
        self.now_us = at_us;
        self.reboot_at(at_us + OFF_US)?;
        self.power.awaiting_boot = Some(Reboot::Cut(self.power.report.cuts.len() - 1));
        Ok(())
    }

    /// What a boot after a reboot found in flash: `loaded` (a generation,
    /// or none), `refused` (a checkpoint it ignored).
    pub(super) fn boot_loaded(&mut self, loaded: Option<u32>, refused: Option<String>) {
        let Some(reboot) = self.power.awaiting_load.take() else { return };
        match reboot {
            Reboot::Cut(i) => {
                let c = &mut self.power.report.cuts[i];
                c.loaded = Some(loaded);
                c.refused = refused;
            }
            Reboot::Hang(i) => self.power.report.hangs[i].loaded = Some(loaded),
        }
    }

    /// Whether a timed cut is due by `next` (deciding the next one when
    /// its learning instant has passed).
    pub(super) fn cut_due(&mut self, next: u64) -> Option<u64> {
        let p = &mut self.power;
        if p.awaiting_boot.is_some() || p.awaiting_load.is_some() || !self.booted {
            return None;
        }
        if p.due_us.is_none() {
            if p.deferred > 0 {
                p.deferred -= 1;
                p.due_us = Some(self.now_us + 1_000_000);
            } else if let Some(&t) = p.plan.at_us.get(p.next_at) {
                p.next_at += 1;
                p.due_us = Some(t.max(self.now_us));
            } else if let Some(&(instant, delay)) = p.plan.learning.get(p.next_learning) {
                if p.learning_done_s >= instant {
                    p.next_learning += 1;
                    p.due_us = Some(self.now_us + delay);
                }
            }
        }
        p.due_us.filter(|&t| t <= next)
    }

    /// After a learning episode: a save when the next two learning
    /// episodes could take the learning since the last save past the
    /// interval (two: the board's own test episode may come first, and no
    /// save is made before it, so the next chance may be one episode later;
    /// torque off for it: `Pause`, `SaveCheckpoint`, `Start`).
    pub(super) fn maybe_save(&mut self, at_us: u64) {
        let Some(every) = self.cfg.save_every_s else { return };
        let spec = self.cfg.task.robot();
        let max_episode_s = spec.episode_steps as f64 * spec.period_us as f64 * 1e-6;
        let since = self.protocol.learning_time_s() - self.power.last_attempt_learning_s;
        let test_next = spec.test_interval > 0 && self.protocol.learning_episodes() % spec.test_interval == 0;
        if since <= 0.0 || since + 2.0 * max_episode_s <= every || test_next {
            return;
        }
        self.power.last_attempt_learning_s = self.protocol.learning_time_s();
        let p = &mut self.power;
        p.report.save_attempts += 1;
        let k = p.report.save_attempts;
        p.arm_next_save = p.plan.in_save.iter().find(|c| c.0 == k).copied();
        self.command_at(at_us, ToChip::Pause);
        self.command_at(at_us, ToChip::SaveCheckpoint);
        self.command_at(at_us, ToChip::Start(RunMode::Learning));
    }
}
