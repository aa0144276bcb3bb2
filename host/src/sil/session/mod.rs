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

mod power;

use super::bus::{BusEmulator, Reply};
use super::forecast::Forecaster;
use super::power_cut::{CutPlan, HangRecord, OFF_US};
use super::qemu::Emulator;
use super::replay::Record;
use super::report::{self, Facts, SilSummary};
use super::config::SilConfig;
use super::wall::{Account, WallClock};
use crate::board::{EpisodeOutcome, Phase, RunProtocol};
use crate::capture::{mode_name, Recorder};
use crate::checkpoint_keeper::{CheckpointKeeper, RestoreServer};
use crate::rig::Rig;
use anyhow::{anyhow, bail, Context};
use pada_core::checkpoint::LoadOutcome;
use pada_core::safety::FaultCause;
use pada_core::wire::{
    self, CheckpointReport, Decoded, FrameEncoder, RestoreDenied, RestoreOutcome, RunMode, StepKind, ToChip, ToHost, Warning,
    MAX_FRAME_LEN,
};
use power::{LastSave, Power, Reboot, TransferCut};
use pada_firmware::sil::{
    Channel, FromBoard, ToBoard, CALIBRATION_INSTRUCTIONS, CHUNK_LEN, CLOCK_FRAME_LEN, CLOCK_PROTOCOL,
    CHECKPOINT_SLOT_LEN, NEVER,
};
use std::collections::VecDeque;
use std::process::ExitStatus;
use std::time::Instant;

/// When the run sets the policy and starts the first test episode, after
/// boot \[µs\] (the board's servo set-up is long done).
const FIRST_COMMAND_US: u64 = 100_000;

/// The file in the run's directory where the host keeps a checkpoint that
/// fits no flash slot (it survives every power cut of the board).
pub const KEPT_CHECKPOINT: &str = "checkpoint.bin";

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
    /// The host's copy of a checkpoint no flash slot holds (LEO on
    /// `f429-sdram`): the board streams its saves to it and restores from
    /// it at boot ([`crate::checkpoint_keeper`]); `None` when the board's
    /// checkpoint fits its flash.
    kept: Option<HostKept>,
    /// The first boot restores exported weights (`--weights`), and the run
    /// starts with its first test episode once it has.
    from_weights: bool,
}

/// The checkpoint the host keeps for the board, in the run's directory.
struct HostKept {
    keeper: CheckpointKeeper,
    server: RestoreServer,
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
        let mut recorder = Recorder::new(Some(Box::new(std::io::BufWriter::new(csv_file))))?;
        // telemetry.mcap: the stream's channels for Foxglove (crate::mcap).
        let mcap = crate::mcap::writer::McapFile::create(&out("telemetry.mcap")).context("cannot create telemetry.mcap")?;
        recorder.set_tap(crate::mcap::Tap::new(vec![Box::new(mcap)]));
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
        let ckpt = super::power_cut::checkpoint_bytes(profile.weights().unwrap_or(0), profile.entry_bytes());
        let plan = CutPlan::new(&cfg.power_cuts, cfg.seconds, cfg.save_every_s.unwrap_or(f64::INFINITY), ckpt, CHECKPOINT_SLOT_LEN);
        let mut hangs_us: Vec<u64> = cfg.hangs_s.iter().map(|t| (t * 1e6).round() as u64).collect();
        hangs_us.sort_unstable();
        let protocol = RunProtocol::new(cfg.seconds, cfg.task.robot().period_us);
        let power = Power::new(plan, hangs_us, cfg.save_every_s, protocol.clone());
        let kept = if ckpt > CHECKPOINT_SLOT_LEN {
            let path = out(KEPT_CHECKPOINT);
            // A run starts with a fresh board: a checkpoint an earlier run
            // left in this directory is not this run's (it is replaced, as
            // telemetry.csv is).
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(e).with_context(|| format!("cannot remove the earlier run's {}", path.display()))
                }
                _ => {}
            }
            // Exported weights: the checkpoint the board restores at its
            // first boot.
            if let Some(w) = &cfg.weights {
                crate::output::write_atomic(&path, &w.image)?;
            }
            let keeper = CheckpointKeeper::new(&path).with_context(|| format!("cannot keep a checkpoint at {}", path.display()))?;
            Some(HostKept { keeper, server: RestoreServer::new(&path) })
        } else {
            None
        };
        if cfg.weights.is_some() && kept.is_none() {
            bail!(
                "--weights on board {}: its checkpoint lives in flash, which the emulation starts erased; \
                 only a board whose checkpoint the host keeps (f429-sdram with LEO) starts from exported weights in pada sil",
                cfg.board.name()
            );
        }
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
            kept,
            from_weights: cfg.weights.is_some(),
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
        // A save or restore the run ended inside gets its row too.
        self.recorder.end()?;
        self.recorder.flush()?;
        self.recorder.close_tap().context("cannot write telemetry.mcap")?;
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
                FromBoard::Boot { protocol, robot, robot_hash, board, machine, calibration, resolution, watchdog_ms, reset } => {
                    self.on_boot(protocol, (&robot, robot_hash), &board, &machine, calibration, resolution)?;
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
        (robot, robot_hash): (&str, u32),
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
        if robot != want.name || board != want_board {
            bail!(
                "the image drives {robot} on board {board} ({machine}), the run is for {} on {want_board}: build it with `cargo xtask qemu --board {want_board} --robot {}`",
                want.name,
                self.cfg.task.xtask_robot()
            );
        }
        if robot_hash != want.definition_hash() {
            bail!(
                "the image drives another definition of {robot} (hash {robot_hash:08x}, the host's is {:08x}): rebuild it with `cargo xtask qemu --board {want_board} --robot {}`",
                want.definition_hash(),
                self.cfg.task.xtask_robot()
            );
        }
        if calibration.abs_diff(CALIBRATION_INSTRUCTIONS) > resolution as u32 + 16 {
            bail!(
                "the board's instruction counter read {calibration} for {CALIBRATION_INSTRUCTIONS} instructions (resolution {resolution}): QEMU is not counting instructions (-icount shift=0)"
            );
        }
        Ok(())
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
        let mut rest = bytes;
        while !rest.is_empty() {
            // A frame at a time (up to its 0x00): a cut decided at a frame
            // falls right after it, and what follows never arrived.
            let end = rest.iter().position(|&b| b == 0).map_or(rest.len(), |i| i + 1);
            let (piece, after) = rest.split_at(end);
            rest = after;
            std::io::Write::write_all(&mut self.raw, piece)?;
            if let Some(sink) = self.sink.as_mut() {
                sink.forward(piece);
            }
            let mut frames = Vec::new();
            self.recorder.feed(piece, at_us as f64 * 1e-6, &mut frames)?;
            for f in frames {
                self.on_frame(at_us, f)?;
            }
            if let Some(cut) = self.power.cut_now.take() {
                self.wall.add(Account::Telemetry, t0.elapsed());
                return self.transfer_cut(at_us.max(self.now_us), cut);
            }
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
                if self.kept.is_some() {
                    // Streamed to the host: cut when the stream has covered
                    // that many bytes of the image (on_checkpoint_chunk).
                    self.power.stream_armed = Some((k, after_bytes));
                } else {
                    self.power.armed = Some((k, after_bytes));
                    self.queue(&ToBoard::CutInSave { after_bytes })?;
                }
            }
        }
        for (_, cmd) in self.commands.drain(..due).collect::<Vec<_>>() {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let frame = self.encoder.encode(&cmd, &mut buf).map_err(|e| anyhow!("{e:?}"))?;
            if let ToChip::RestoreChunk(_) | ToChip::RestoreNone(_) = cmd {
                // The host's half of a restore's link time.
                self.recorder.answered(matches!(cmd, ToChip::RestoreChunk(_)) as u32, frame.len() as u64);
            }
            tele_in.extend_from_slice(frame);
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
                let outcome = EpisodeOutcome {
                    fell: self.last_step_kind == StepKind::Absorbing,
                    walked_m: self.rig.walked_m(),
                    claimed_slots: None,
                };
                self.rig.episode_ended(at_us);
                // (After the final test episode the run ends at the board's
                // next report; the firmware stays idle with torque off.)
                if e.mode == RunMode::Learning {
                    self.power.learning_done_s += e.length as f64 * self.cfg.task.robot().period_us as f64 * 1e-6;
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
            ToHost::Checkpoint(CheckpointReport::Streamed { generation, .. }) => {
                let kept = self.kept.as_ref().and_then(|k| k.keeper.kept_generation());
                if kept != Some(generation) {
                    self.power.report.streams_not_kept += 1;
                }
            }
            ToHost::CheckpointChunk(chunk) => self.on_checkpoint_chunk(&chunk)?,
            ToHost::RestoreWanted(request) => {
                if request.offset == 0 {
                    self.power.report.restores_asked += 1;
                    self.power.restore_requests = 0;
                }
                self.power.restore_requests += 1;
                if self.power.restore_cut_due() {
                    // The power fails while the board asks for this batch.
                    self.power.cut_now = Some(TransferCut::Restore { offset: request.offset });
                    return Ok(());
                }
                let Some(kept) = self.kept.as_mut() else {
                    bail!("the board asked the host for its checkpoint, but its checkpoint fits its flash");
                };
                for m in kept.server.answer(&request).messages {
                    self.command_at(at_us, m);
                }
            }
            ToHost::Restored(outcome) => {
                match outcome {
                    RestoreOutcome::Loaded { generation, .. } => self.boot_loaded(Some(generation), None),
                    RestoreOutcome::Denied(RestoreDenied::NoCheckpoint) => self.boot_loaded(None, None),
                    other => self.boot_loaded(None, Some(format!("{other:?}"))),
                }
                if std::mem::take(&mut self.from_weights) {
                    if !matches!(outcome, RestoreOutcome::Loaded { .. }) {
                        bail!("the board did not restore the exported weights at its first boot: {outcome:?}");
                    }
                    // The protocol's first run: the greedy test episode.
                    self.command_at(at_us + FIRST_COMMAND_US, ToChip::Start(RunMode::Testing));
                } else if std::mem::take(&mut self.power.start_after_restore) {
                    self.command_at(at_us + FIRST_COMMAND_US, ToChip::Start(RunMode::Learning));
                }
            }
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

    /// A chunk of a save streamed to the host: kept (a complete
    /// checkpoint is the save completed), or the armed cut inside this
    /// save falls on it (the board dies sending it).
    fn on_checkpoint_chunk(&mut self, chunk: &pada_core::checkpoint::stream::Chunk) -> anyhow::Result<()> {
        let Some(kept) = self.kept.as_mut() else {
            bail!("the board streamed a checkpoint chunk, but its checkpoint fits its flash");
        };
        if let Some((k, after_bytes)) = self.power.stream_armed {
            // The body goes in ascending order, the header last: the body
            // chunk that covers the image up to `after_bytes` is the last
            // that arrives (the last body chunk covers it all, so the cut
            // always falls before the header).
            let covered = chunk.offset as u64 + chunk.covered_len();
            if chunk.offset != 0 && covered >= after_bytes as u64 {
                self.power.stream_armed = None;
                self.power.cut_now = Some(TransferCut::Save { attempt: k, after_bytes });
            }
        }
        match kept.keeper.feed(chunk) {
            Ok(Some(k)) => {
                let p = &mut self.power;
                p.report.saves += 1;
                p.report.kept_bytes = k.bytes;
                p.report.kept_chunks = p.report.kept_chunks.max(k.chunks);
                p.report.streamed_bytes += k.encoded_bytes;
                p.last_save = Some(LastSave { generation: k.generation, protocol: self.protocol.clone() });
                self.records.push(Record::Saved);
            }
            Ok(None) => {}
            Err(e) => {
                self.power.report.chunks_refused += 1;
                if self.power.report.first_chunk_refusal.is_none() {
                    self.power.report.first_chunk_refusal = Some(e.to_string());
                }
            }
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
            power: {
                let mut power = std::mem::take(&mut self.power.report);
                power.note_transfers(self.recorder.transfers(), self.now_s());
                power
            },
        };
        report::summarize(self.cfg, facts)
    }
}
