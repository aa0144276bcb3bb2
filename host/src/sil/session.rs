//! The lock-step loop between the emulated board and the plant side.
//!
//! Every [`FromBoard::Idle`] says until when the board has nothing to do;
//! the [`FromBoard::Output`]s before it carry what it wrote and when. The
//! loop runs the servo-bus bytes through the [`BusEmulator`] (which
//! schedules the answers) and the telemetry through the [`Recorder`] (the
//! operator and the run protocol react to it), then advances the board's
//! clock to the first of: its timer, the next answer, the next command;
//! sends what is due at that instant, the forecasts of the answers to
//! come ([`Forecaster`]), and [`ToBoard::Advance`]. Nothing depends on
//! wall-clock time, so the same image gives the same run every time.

use super::bus::{BusEmulator, Reply};
use super::forecast::Forecaster;
use super::power_cut::{CutPlan, CutRecord, HangRecord, PowerReport, OFF_US};
use super::qemu::Emulator;
use super::replay::Record;
use super::report::{self, Facts, SilSummary};
use super::run::SilConfig;
use super::wall::{Account, WallClock};
use crate::board::{EpisodeOutcome, Phase, RunProtocol};
use crate::capture::{mode_name, Recorder};
use crate::rig::Rig;
use anyhow::{anyhow, bail, Context};
use pada_core::checkpoint::LoadOutcome;
use pada_core::safety::FaultCause;
use pada_core::wire::{self, CheckpointReport, Decoded, FrameEncoder, RunMode, StepKind, ToChip, ToHost, Warning, MAX_FRAME_LEN};
use pada_firmware::config::Robot;
use pada_firmware::sil::{
    Channel, FromBoard, ResetCause, ToBoard, CALIBRATION_INSTRUCTIONS, CHUNK_LEN, CLOCK_FRAME_LEN, CLOCK_PROTOCOL,
    CHECKPOINT_SLOT_LEN, NEVER,
};
use std::collections::VecDeque;
use std::process::ExitStatus;
use std::time::Instant;

/// When the run sets the policy and starts the first test episode, after
/// boot \[µs\] (the board's servo set-up is long done).
const FIRST_COMMAND_US: u64 = 100_000;

/// The last completed checkpoint save, as the host recorded it.
#[derive(Debug, Clone)]
struct LastSave {
    generation: u32,
    /// The run protocol then: where a boot that loads it goes on from.
    protocol: RunProtocol,
}

/// A reboot the host caused, whose boot is to be checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reboot {
    /// After `power.cuts[i]`.
    Cut(usize),
    /// After `power.hangs[i]`.
    Hang(usize),
}

/// Power cuts, saves and hangs: the plan and what happened.
struct Power {
    report: PowerReport,
    plan: CutPlan,
    /// Next of `plan.at_us`, `plan.learning` to come.
    next_at: usize,
    next_learning: usize,
    /// A timed cut decided on, at this instant \[µs\].
    due_us: Option<u64>,
    /// Timed cuts decided on but overtaken by another reboot: each comes
    /// 1 s after the next boot settles.
    deferred: u32,
    /// Learning done so far, lost learning included \[s\].
    learning_done_s: f64,
    /// The in-save cut armed for the next `SaveCheckpoint` sent.
    arm_next_save: Option<(u32, u32)>,
    /// The in-save cut sent to the board with its save.
    armed: Option<(u32, u32)>,
    last_save: Option<LastSave>,
    /// The protocol's learning time at the last save attempt \[s\].
    last_attempt_learning_s: f64,
    /// The run as it starts: what a boot without a checkpoint goes on from.
    initial: RunProtocol,
    /// Hangs to ask for \[µs\], sorted; the next to come.
    hangs_us: Vec<u64>,
    next_hang: usize,
    /// A reboot whose Boot has not come.
    awaiting_boot: Option<Reboot>,
    /// A reboot whose checkpoint outcome has not come.
    awaiting_load: Option<Reboot>,
    /// The watchdog's period on this board \[ms\] (0: none).
    watchdog_ms: u32,
}

/// The state of one run.
pub struct Session<'a> {
    cfg: &'a SilConfig,
    emu: Emulator,
    rig: Box<dyn Rig>,
    bus: BusEmulator,
    forecaster: Forecaster,
    recorder: Recorder,
    decoder: wire::FrameDecoder<FromBoard, CLOCK_FRAME_LEN>,
    inbox: VecDeque<FromBoard>,
    read_buf: Vec<u8>,
    /// Frames to the board, written at once.
    outbox: Vec<u8>,
    to_board_seq: u32,
    encoder: FrameEncoder,
    now_us: u64,
    /// The horizon of the last `Advance`.
    horizon_us: u64,
    replies: Vec<Reply>,
    commands: Vec<(u64, ToChip)>,
    /// The request whose answer the board last got, and when (empty: it
    /// woke without one): what its next request follows.
    after: Option<(u64, Vec<u8>)>,
    protocol: RunProtocol,
    last_step_kind: StepKind,
    records: Vec<Record>,
    cycles: [Vec<u32>; 4],
    fault_reports: Vec<(f64, String, String)>,
    exchanges: u64,
    instructions: u64,
    booted: bool,
    wall: WallClock,
    loop_started: Instant,
    loop_s: f64,
    episodes_csv: csv::Writer<std::fs::File>,
    raw: std::io::BufWriter<std::fs::File>,
    sink: Option<crate::telemetry::TelemetrySink>,
    bar: Option<indicatif::ProgressBar>,
    power: Power,
}

impl<'a> Session<'a> {
    /// A run of `cfg` on the started emulator, with its output files.
    pub fn new(
        cfg: &'a SilConfig,
        emu: Emulator,
        rig: Box<dyn Rig>,
        bus: BusEmulator,
        sink: Option<crate::telemetry::TelemetrySink>,
    ) -> anyhow::Result<Self> {
        let out = |name: &str| cfg.out_dir.join(name);
        let csv_file = std::fs::File::create(out("telemetry.csv")).context("cannot create telemetry.csv")?;
        let recorder = Recorder::new(Some(Box::new(std::io::BufWriter::new(csv_file))))?;
        let raw = std::fs::File::create(out("telemetry.bin")).context("cannot create telemetry.bin")?;
        let mut episodes_csv = csv::Writer::from_path(out("episodes.csv")).context("cannot create episodes.csv")?;
        episodes_csv.write_record([
            "index",
            "mode",
            "return",
            "length",
            "weights_checksum",
            "walked_m",
            "learning_time_s",
            "emulated_time_s",
        ])?;
        let profile = cfg.profile();
        let ckpt = super::power_cut::checkpoint_bytes(profile.weights().unwrap_or(0), profile.format.bytes());
        let plan = CutPlan::new(&cfg.power_cuts, cfg.seconds, cfg.save_every_s.unwrap_or(f64::INFINITY), ckpt, CHECKPOINT_SLOT_LEN);
        let mut hangs_us: Vec<u64> = cfg.hangs_s.iter().map(|t| (t * 1e6).round() as u64).collect();
        hangs_us.sort_unstable();
        let protocol = RunProtocol::new(cfg.seconds, cfg.task.robot().spec().period_us);
        let power = Power {
            report: PowerReport { save_every_s: cfg.save_every_s, cuts_planned: plan.len(), ..Default::default() },
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
            initial: protocol.clone(),
            hangs_us,
            next_hang: 0,
            awaiting_boot: None,
            awaiting_load: None,
            watchdog_ms: 0,
        };
        let bar = cfg
            .progress
            .then(|| crate::progress::steps_bar((cfg.seconds * 1000.0).round() as u64, "sil: learning ms"));
        Ok(Session {
            cfg,
            emu,
            rig,
            bus,
            forecaster: Forecaster::new(cfg.forecast),
            recorder,
            decoder: wire::FrameDecoder::new(),
            inbox: VecDeque::new(),
            read_buf: vec![0; 1 << 16],
            outbox: Vec::new(),
            to_board_seq: 0,
            encoder: FrameEncoder::new(),
            now_us: 0,
            horizon_us: 0,
            replies: Vec::new(),
            commands: Vec::new(),
            after: None,
            protocol,
            last_step_kind: StepKind::Start,
            records: Vec::new(),
            cycles: Default::default(),
            fault_reports: Vec::new(),
            exchanges: 0,
            instructions: 0,
            booted: false,
            wall: WallClock::default(),
            loop_started: Instant::now(),
            loop_s: 0.0,
            episodes_csv,
            raw: std::io::BufWriter::new(raw),
            sink,
            bar,
            power,
        })
    }

    /// The emulated time \[s\].
    pub fn now_s(&self) -> f64 {
        self.now_us as f64 * 1e-6
    }

    /// Ends QEMU.
    pub fn stop(&mut self) -> Option<ExitStatus> {
        self.loop_s = self.loop_started.elapsed().as_secs_f64();
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        self.emu.stop()
    }

    /// Writes out the recorded files.
    pub fn flush(&mut self) -> anyhow::Result<()> {
        self.recorder.flush()?;
        self.episodes_csv.flush()?;
        std::io::Write::flush(&mut self.raw)?;
        Ok(())
    }

    /// The emulated time after which the run gives up: generous room for
    /// resets between episodes (LEO learning to walk spends up to four
    /// times its learning time falling and being set up again), test
    /// episodes and faults.
    fn time_limit_us(&self) -> u64 {
        let fault_end = self.cfg.faults.iter().map(|f| f.end_us).max().unwrap_or(0);
        // Every cut or hang may lose a save interval of learning (or all of
        // it, with no saves) and costs its time off.
        let reboots = (self.power.plan.len() + self.power.hangs_us.len()) as f64;
        let per_reboot = OFF_US as f64 * 1e-6 + 10.0 * self.cfg.save_every_s.unwrap_or(self.cfg.seconds).min(self.cfg.seconds);
        ((self.cfg.seconds * 10.0 + 120.0 + reboots * per_reboot) * 1e6) as u64 + fault_end
    }

    fn next_message(&mut self) -> anyhow::Result<FromBoard> {
        loop {
            if let Some(m) = self.inbox.pop_front() {
                return Ok(m);
            }
            let (emu, buf, timeout) = (&mut self.emu, &mut self.read_buf, self.cfg.hang_timeout);
            let n = self.wall.time(Account::Board, || emu.receive(buf, timeout))?;
            for r in self.decoder.feed(&self.read_buf[..n]) {
                match r {
                    Ok(frame) => self.inbox.push_back(frame.msg),
                    Err(e) => bail!("damaged clock frame from the board: {e:?}"),
                }
            }
        }
    }

    fn queue(&mut self, msg: &ToBoard) -> anyhow::Result<()> {
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        let frame = wire::encode_frame(msg, self.to_board_seq, &mut buf).map_err(|e| anyhow!("{e:?}"))?;
        self.to_board_seq = self.to_board_seq.wrapping_add(1);
        self.outbox.extend_from_slice(frame);
        Ok(())
    }

    fn send_queued(&mut self) -> anyhow::Result<()> {
        let bytes = std::mem::take(&mut self.outbox);
        self.emu.send(&bytes)?;
        self.outbox = bytes;
        self.outbox.clear();
        Ok(())
    }

    /// Sends `bytes` on `channel`, due at the next `Advance`.
    fn queue_input(&mut self, channel: Channel, bytes: &[u8]) -> anyhow::Result<()> {
        for piece in bytes.chunks(CHUNK_LEN) {
            let bytes = heapless::Vec::from_slice(piece).map_err(|_| anyhow!("a chunk longer than {CHUNK_LEN}"))?;
            self.queue(&ToBoard::Input { channel, bytes })?;
        }
        Ok(())
    }

    fn command_at(&mut self, t_us: u64, cmd: ToChip) {
        let i = self.commands.partition_point(|(t, _)| *t <= t_us);
        self.commands.insert(i, (t_us, cmd));
    }

    /// Runs until the run protocol is done (or fails).
    pub fn run_loop(&mut self) -> anyhow::Result<()> {
        self.loop_started = Instant::now();
        loop {
            match self.next_message()? {
                FromBoard::Boot { protocol, robot, board, machine, calibration, resolution, watchdog_ms, reset } => {
                    self.on_boot(protocol, robot, &board, &machine, calibration, resolution)?;
                    self.power.watchdog_ms = watchdog_ms;
                    self.after_boot(reset)?;
                }
                FromBoard::PowerCut { now_us } => {
                    let armed = self.power.armed.take();
                    if armed.is_none() {
                        bail!("the board stopped at a power cut the host did not arm");
                    }
                    self.power_cut(now_us.max(self.now_us), armed)?;
                }
                FromBoard::Output { channel: Channel::Bus, at_us, answered, bytes } => self.on_bus(at_us, answered, &bytes)?,
                FromBoard::Output { channel: Channel::Telemetry, at_us, bytes, .. } => self.on_telemetry(at_us, &bytes)?,
                FromBoard::Idle { now_us, until_us, instructions } => {
                    if self.on_idle(now_us, until_us, instructions)? {
                        return Ok(());
                    }
                }
            }
        }
    }

    fn on_boot(
        &mut self,
        protocol: u16,
        robot: u8,
        board: &str,
        machine: &str,
        calibration: u32,
        resolution: u16,
    ) -> anyhow::Result<()> {
        if protocol != CLOCK_PROTOCOL {
            bail!("the board speaks clock protocol {protocol}, this host {CLOCK_PROTOCOL}: rebuild one of them");
        }
        let want = self.cfg.task.robot();
        let want_board = self.cfg.board.name();
        if robot != want.code() || board != want_board {
            let name = Robot::from_code(robot).map(|r| r.name()).unwrap_or("an unknown robot");
            bail!(
                "the image drives {name} on board {board} ({machine}), the run is for {} on {want_board}: build it with `cargo xtask qemu --board {want_board} --robot {}`",
                want.name(),
                self.cfg.task.name()
            );
        }
        if calibration.abs_diff(CALIBRATION_INSTRUCTIONS) > resolution as u32 + 16 {
            bail!(
                "the board's instruction counter read {calibration} for {CALIBRATION_INSTRUCTIONS} instructions (resolution {resolution}): QEMU is not counting instructions (-icount shift=0)"
            );
        }
        Ok(())
    }

    /// After a Boot's checks: configure the board and start (or resume) the
    /// run; a reboot the host did not cause ends the run.
    fn after_boot(&mut self, reset: ResetCause) -> anyhow::Result<()> {
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
                self.reboot_at(reset_us.max(self.now_us));
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
            // watchdog reset in Fault, which the Fault report clears).
            if matches!(reboot, Some(Reboot::Cut(_))) {
                self.command_at(self.now_us + FIRST_COMMAND_US, ToChip::Start(RunMode::Learning));
            }
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
    fn reboot_at(&mut self, now_us: u64) {
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
        self.recorder.restarted();
        self.records.push(Record::Boot);
    }

    /// Cuts the power at `at_us` (`in_save`: the save attempt and the
    /// bytes it wrote) and boots the board again after [`OFF_US`].
    fn power_cut(&mut self, at_us: u64, in_save: Option<(u32, u32)>) -> anyhow::Result<()> {
        self.wall.time(Account::Board, || self.emu.power_cycle())?;
        let saved_s = self.power.last_save.as_ref().map_or(0.0, |s| s.protocol.learning_time_s());
        self.power.report.cuts.push(CutRecord {
            at_s: at_us as f64 * 1e-6,
            in_save,
            last_save: self.power.last_save.as_ref().map(|s| s.generation),
            learning_lost_s: self.protocol.learning_time_s() - saved_s,
            loaded: None,
            refused: None,
        });
        let (rig, bus) = (self.rig.as_mut(), &mut self.bus);
        self.wall.time(Account::Plant, || {
            rig.advance_to(at_us);
            // The robot falls limp; the operator sets it back.
            bus.power_off(at_us, rig);
            rig.episode_ended(at_us);
        });
        self.now_us = at_us;
        self.reboot_at(at_us + OFF_US);
        self.power.awaiting_boot = Some(Reboot::Cut(self.power.report.cuts.len() - 1));
        Ok(())
    }

    /// What a boot after a reboot found in flash: `loaded` (a generation,
    /// or none), `refused` (a checkpoint it ignored).
    fn boot_loaded(&mut self, loaded: Option<u32>, refused: Option<String>) {
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
    fn cut_due(&mut self, next: u64) -> Option<u64> {
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
    fn maybe_save(&mut self, at_us: u64) {
        let Some(every) = self.cfg.save_every_s else { return };
        let spec = self.cfg.task.robot().spec();
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

    fn on_bus(&mut self, at_us: u64, answered: bool, bytes: &[u8]) -> anyhow::Result<()> {
        if let Some((t, key)) = self.after.take() {
            if t == at_us {
                self.forecaster.observe(&key, bytes);
            }
        }
        let (bus, rig) = (&mut self.bus, self.rig.as_mut());
        let replies = self.wall.time(Account::Plant, || bus.receive(at_us, bytes, rig));
        if answered {
            self.forecaster.confirm(at_us, bytes, &replies).map_err(|e| anyhow!(e))?;
            let at = replies[0].at_us;
            self.now_us = at;
            self.after = Some((at, bytes.to_vec()));
        } else {
            self.replies.extend(replies);
            self.replies.sort_by_key(|r| r.at_us);
        }
        Ok(())
    }

    fn on_telemetry(&mut self, at_us: u64, bytes: &[u8]) -> anyhow::Result<()> {
        let t0 = Instant::now();
        std::io::Write::write_all(&mut self.raw, bytes)?;
        if let Some(sink) = self.sink.as_mut() {
            sink.forward(bytes);
        }
        let mut frames = Vec::new();
        self.recorder.feed(bytes, at_us as f64 * 1e-6, &mut frames)?;
        for f in frames {
            self.on_frame(at_us, f)?;
        }
        self.wall.add(Account::Telemetry, t0.elapsed());
        Ok(())
    }

    /// Takes the board's report; true when the run is over.
    fn on_idle(&mut self, now_us: u64, until_us: u64, instructions: u64) -> anyhow::Result<bool> {
        if !self.booted {
            bail!("the board went idle before it booted");
        }
        // The board may have let its timers fire on its own, up to the
        // horizon (pada_firmware::sil, "Forecasts").
        if now_us < self.now_us || now_us > self.horizon_us {
            bail!(
                "the board's clock ({now_us} us) is outside what the host allowed ({} .. {} us)",
                self.now_us,
                self.horizon_us
            );
        }
        self.now_us = now_us;
        self.instructions = instructions;
        self.exchanges += 1;
        self.forecaster.void();
        if self.protocol.done() {
            return Ok(true);
        }
        if self.now_us > self.time_limit_us() {
            bail!(
                "learning time {:.1} s of {} s not reached within {:.0} s of emulated time",
                self.protocol.learning_time_s(),
                self.cfg.seconds,
                self.time_limit_us() as f64 * 1e-6
            );
        }
        let next_reply = self.replies.first().map_or(NEVER, |r| r.at_us);
        let next_command = self.commands.first().map_or(NEVER, |c| c.0);
        let next_hang = match self.power.hangs_us.get(self.power.next_hang) {
            Some(&t) if self.power.awaiting_boot.is_none() && self.power.awaiting_load.is_none() => t,
            _ => NEVER,
        };
        let next = until_us.min(next_reply).min(next_command).min(next_hang).max(self.now_us);
        if next == NEVER {
            bail!("the board waits for nothing and nothing is scheduled: it would sleep forever");
        }
        if let Some(t) = self.cut_due(next) {
            self.power.due_us = None;
            self.power_cut(t.max(self.now_us), None)?;
            return Ok(false);
        }
        if next >= next_hang {
            self.power.next_hang += 1;
            self.power.report.hangs.push(HangRecord {
                asked_s: next as f64 * 1e-6,
                hung_s: None,
                reset_after_feed_ms: None,
                watchdog_ms: self.power.watchdog_ms,
                reset_s: None,
                torque_off_s: None,
                torque_off_ms: None,
                cause: None,
                loaded: None,
                last_save: self.power.last_save.as_ref().map(|s| s.generation),
                episodes_after: 0,
            });
            self.power.awaiting_boot = Some(Reboot::Hang(self.power.report.hangs.len() - 1));
            self.queue(&ToBoard::Hang)?;
        }
        let due = self.replies.partition_point(|r| r.at_us <= next);
        let mut bus_in = Vec::new();
        let mut key = Vec::new();
        for r in self.replies.drain(..due) {
            bus_in.extend_from_slice(&r.bytes);
            key = r.request;
        }
        self.queue_input(Channel::Bus, &bus_in)?;
        let due = self.commands.partition_point(|c| c.0 <= next);
        let mut tele_in = Vec::new();
        if self.commands[..due].iter().any(|c| c.1 == ToChip::SaveCheckpoint) {
            if let Some((k, after_bytes)) = self.power.arm_next_save.take() {
                self.power.armed = Some((k, after_bytes));
                self.queue(&ToBoard::CutInSave { after_bytes })?;
            }
        }
        for (_, cmd) in self.commands.drain(..due).collect::<Vec<_>>() {
            let mut buf = [0u8; MAX_FRAME_LEN];
            tele_in.extend_from_slice(self.encoder.encode(&cmd, &mut buf).map_err(|e| anyhow!("{e:?}"))?);
        }
        self.queue_input(Channel::Telemetry, &tele_in)?;
        self.now_us = next;
        let horizon = self.commands.first().map_or(NEVER, |c| c.0).min(self.replies.first().map_or(NEVER, |r| r.at_us));
        self.horizon_us = horizon;
        if self.replies.is_empty() {
            let (forecaster, bus, rig) = (&mut self.forecaster, &self.bus, self.rig.as_mut());
            let chain = self.wall.time(Account::Plant, || {
                // Nothing the board does from now can come before now.
                rig.advance_to(next);
                forecaster.plan(bus, rig, next, &key, horizon)
            });
            for f in chain {
                let request = heapless::Vec::from_slice(&f.request).map_err(|_| anyhow!("a forecast request too long"))?;
                let reply = heapless::Vec::from_slice(&f.reply.bytes).map_err(|_| anyhow!("a forecast answer too long"))?;
                self.queue(&ToBoard::Forecast { request_at_us: f.request_at_us, request, reply_at_us: f.reply.at_us, reply })?;
            }
        }
        self.after = Some((next, key));
        self.queue(&ToBoard::Advance { now_us: next, horizon_us: horizon })?;
        self.send_queued()?;
        Ok(false)
    }

    fn on_frame(&mut self, at_us: u64, frame: Decoded<ToHost>) -> anyhow::Result<()> {
        match frame.msg {
            ToHost::Step(step) => {
                let k = match (step.kind, step.mode) {
                    (StepKind::Start, _) => 2,
                    (StepKind::Absorbing | StepKind::Timeout, _) => 3,
                    (StepKind::Step, RunMode::Learning) => 0,
                    (StepKind::Step, RunMode::Testing) => 1,
                };
                self.cycles[k].push(step.agent_cycles);
                self.last_step_kind = step.kind;
                // A boot that reported no checkpoint before its first step
                // found none.
                self.boot_loaded(None, None);
                if step.kind == StepKind::Start {
                    // The firmware started an episode: the operator lets go.
                    self.rig.episode_started(at_us);
                }
                self.records.push(Record::Step(step));
            }
            ToHost::Episode(e) => {
                // The firmware reports the episode's end and waits: the
                // operator sets the robot up again (rig::leo).
                let outcome = EpisodeOutcome { fell: self.last_step_kind == StepKind::Absorbing, walked_m: self.rig.walked_m() };
                self.rig.episode_ended(at_us);
                // (After the final test episode the run ends at the board's
                // next report; the firmware stays idle with torque off.)
                if e.mode == RunMode::Learning {
                    self.power.learning_done_s += e.length as f64 * self.cfg.task.robot().spec().period_us as f64 * 1e-6;
                    if let Some(h) = self.power.report.hangs.last_mut().filter(|h| h.reset_s.is_some()) {
                        h.episodes_after += 1;
                    }
                }
                if let Some(cmd) = self.protocol.on_episode(&e, outcome) {
                    self.command_at(at_us, cmd);
                } else if e.mode == RunMode::Learning && self.protocol.phase() == Phase::Learning {
                    self.maybe_save(at_us);
                }
                self.episodes_csv.write_record([
                    e.index.to_string(),
                    mode_name(e.mode).to_string(),
                    e.total_reward.to_string(),
                    e.length.to_string(),
                    format!("{:08x}", e.weights_checksum),
                    outcome.walked_m.map(|w| format!("{w:.4}")).unwrap_or_default(),
                    format!("{:.3}", self.protocol.learning_time_s()),
                    format!("{:.3}", at_us as f64 * 1e-6),
                ])?;
                self.records.push(Record::Episode(e));
                if let Some(bar) = &self.bar {
                    bar.set_position((self.protocol.learning_time_s() * 1000.0) as u64);
                }
            }
            ToHost::Policy(p) => {
                // The governor's Δ or α in force from the next decision on
                // (the firmware reports a move after the period's Step).
                if let Some(g) = p.governor {
                    self.records.push(Record::Restriction(g.parameter));
                }
            }
            ToHost::Checkpoint(CheckpointReport::Saved(saved)) => {
                let p = &mut self.power;
                p.report.saves += 1;
                p.report.max_erases = p.report.max_erases.max(saved.erases);
                p.last_save = Some(LastSave { generation: saved.generation, protocol: self.protocol.clone() });
                self.records.push(Record::Saved);
            }
            ToHost::Checkpoint(CheckpointReport::TooLarge { .. }) => self.power.report.saves_too_large += 1,
            ToHost::Checkpoint(CheckpointReport::SaveFailed) => self.power.report.saves_failed += 1,
            ToHost::Checkpoint(CheckpointReport::Load(LoadOutcome::Loaded { generation, .. })) => {
                self.boot_loaded(Some(generation), None)
            }
            ToHost::Warning(Warning::CheckpointIgnored(outcome)) => self.boot_loaded(None, Some(format!("{outcome:?}"))),
            ToHost::Fault(f) => {
                let (_, detail) = crate::capture::describe(&ToHost::Fault(f));
                let hang = self.power.report.hangs.iter_mut().rev().find(|h| h.reset_s.is_some() && h.cause.is_none());
                match (f.cause, hang) {
                    (FaultCause::WatchdogReset, Some(h)) => {
                        // The reset the hang caused: reported at boot, after
                        // the servos were told torque off.
                        h.cause = Some(f.cause.name().to_string());
                        let reset_us = h.reset_s.map_or(0, |t| (t * 1e6).round() as u64);
                        let off = self.bus.all_off_since();
                        h.torque_off_s = off.map(|t| t as f64 * 1e-6);
                        h.torque_off_ms = off.map(|t| t.saturating_sub(reset_us) as f64 * 1e-3);
                        self.boot_loaded(None, None);
                    }
                    _ => self.fault_reports.push((at_us as f64 * 1e-6, f.cause.name().to_string(), detail)),
                }
                // Torque is off; a walking robot may be on the floor: the
                // operator sets it up and holds it.
                self.rig.episode_ended(at_us);
                // Resume once every fault window that is open now is over.
                let resume_from = self
                    .cfg
                    .faults
                    .iter()
                    .filter(|w| w.start_us <= at_us)
                    .map(|w| w.end_us)
                    .max()
                    .unwrap_or(0)
                    .max(at_us);
                let mode = if self.protocol.phase() == Phase::Learning { RunMode::Learning } else { RunMode::Testing };
                self.command_at(resume_from + 100_000, ToChip::ClearFault);
                self.command_at(resume_from + 200_000, ToChip::Start(mode));
            }
            _ => {}
        }
        Ok(())
    }

    /// The run's summary (runs the replay and the host comparison).
    pub fn summary(&mut self, wall_s: f64) -> SilSummary {
        let facts = Facts {
            emulated_s: self.now_s(),
            wall_s,
            loop_s: self.loop_s,
            wall_time: self.wall.report(self.loop_s),
            exchanges: self.exchanges,
            instructions: self.instructions,
            forecasts: self.forecaster.stats(),
            records: std::mem::take(&mut self.records),
            cycles: std::mem::take(&mut self.cycles),
            fault_reports: std::mem::take(&mut self.fault_reports),
            protocol: self.protocol.clone(),
            plant: self.rig.describe(),
            bus: &self.bus,
            link: self.recorder.stats(),
            messages: self.recorder.counts(),
            latest: self.recorder.latest().clone(),
            sink: self.sink.take(),
            power: std::mem::take(&mut self.power.report),
        };
        report::summarize(self.cfg, facts)
    }
}
