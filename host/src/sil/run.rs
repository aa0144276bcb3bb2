//! One software-in-the-loop run: the lock-step loop between the emulated
//! board and the plant side, the commands a run sends, and its results.
//!
//! # The loop
//!
//! Every [`FromBoard::Idle`] says until when the board has nothing to do and
//! how many bytes it has written. The loop takes exactly those bytes — the
//! servo bus's into the [`BusEmulator`] (which schedules the answers), the
//! telemetry's into the [`Recorder`] — then advances the board's clock to
//! the first of: its timer, the next answer, the next command; delivers what
//! is due at that instant and answers [`ToBoard::Advance`]. Nothing depends
//! on wall-clock time, so the same image gives the same run every time.
//!
//! # The run
//!
//! Like `pada run`'s trials (Section VI): a greedy test episode first
//! (commanded, `Start(Testing)`), then learning (`Start(Learning)`), with
//! the firmware's own test episode after every tenth learning episode,
//! until the learning time (learning episodes' steps × period) reaches
//! `--seconds`; then a final commanded test episode. A fault stops the
//! firmware (torque off); once its window is over the run sends
//! `ClearFault` and `Start` again, as an operator would.

use super::bus::{BusEmulator, BusStats, Reply};
use super::wall::{Account, WallClock, WallTime};
use super::fault::FaultSpec;
use crate::rig::{LeoStandIn, PendulumRig, Rig, SUPPLY_V};
use super::qemu::{Emulator, QemuSetup};
use super::replay::{replay, Record, ReplayReport};
use super::twin::{twin, TwinReport};
use crate::capture::{MessageCounts, Recorder};
use crate::experiment::{end_performance, rise_time};
use crate::pendulum::PhysicalPendulumParams;
use anyhow::{anyhow, bail, Context};
use pada_core::policy::PolicyKind;
use pada_core::wire::{
    self, Decoded, FrameEncoder, LinkStats, RunMode, StepKind, ToChip, ToHost, MAX_FRAME_LEN,
};
use pada_core::profile::{Board, LearnerProfile};
use pada_firmware::config::{Robot, DEFAULT_SEED};
use pada_firmware::sil::{
    FromBoard, ToBoard, CALIBRATION_INSTRUCTIONS, CLOCK_FRAME_LEN, CLOCK_PROTOCOL, NEVER,
};
use serde::Serialize;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

/// Seeds of the host twin besides the firmware's.
const TWIN_EXTRA_SEEDS: u64 = 7;
/// Learning time from which a run is expected to have learned \[s\].
pub const LEARNING_CHECK_S: f64 = 300.0;

/// The robots `pada sil` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum SilTask {
    /// The physical pendulum at 33 Hz (robot `physical-pendulum`) against
    /// the host's model of it.
    Pendulum,
    /// LEO (firmware robot `leo`) against a stand-in that holds its start
    /// pose (instruction counts, not learning).
    Leo,
}

impl SilTask {
    /// The firmware's robot.
    pub fn robot(self) -> Robot {
        match self {
            SilTask::Pendulum => Robot::Pendulum33,
            SilTask::Leo => Robot::Leo,
        }
    }

    /// The learner profile of the emulated board: QEMU's netduinoplus2 is
    /// an STM32F405.
    pub fn profile(self) -> LearnerProfile {
        Board::F405.profile(self.robot())
    }

    fn rig(self) -> Box<dyn Rig> {
        match self {
            SilTask::Pendulum => Box::new(PendulumRig::new(PhysicalPendulumParams::default())),
            SilTask::Leo => Box::new(LeoStandIn::new()),
        }
    }
}

/// What to run.
#[derive(Debug, Clone)]
pub struct SilConfig {
    /// `qemu-system-arm`.
    pub qemu: PathBuf,
    /// The firmware image (feature `qemu`, built for `task`'s robot).
    pub elf: PathBuf,
    /// The robot.
    pub task: SilTask,
    /// The policy the run sets (`SetPolicy`) before starting.
    pub policy: PolicyKind,
    /// Learning time to reach \[s\].
    pub seconds: f64,
    /// Faults to inject.
    pub faults: Vec<FaultSpec>,
    /// Where the telemetry, logs and summary go (created).
    pub out_dir: PathBuf,
    /// Longest wall-clock wait for the board before calling it hung.
    pub hang_timeout: Duration,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Also stream the firmware's telemetry, as it comes, to a file or a
    /// loopback TCP listener.
    pub telemetry: Option<crate::telemetry::TelemetryTarget>,
}

/// One test episode on the learning curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TestPoint {
    /// Learning time before it \[s\].
    pub learning_time_s: f64,
    /// Its return.
    pub test_return: f64,
}

/// Distribution of the agent step's instruction count.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Instructions {
    /// Agent calls measured.
    pub calls: u64,
    /// Mean.
    pub mean: f64,
    /// Smallest.
    pub min: u32,
    /// Median.
    pub median: u32,
    /// 99th percentile.
    pub p99: u32,
    /// Largest.
    pub max: u32,
}

impl Instructions {
    fn of(mut v: Vec<u32>) -> Instructions {
        if v.is_empty() {
            return Instructions::default();
        }
        v.sort_unstable();
        let n = v.len();
        Instructions {
            calls: n as u64,
            mean: v.iter().map(|&x| x as f64).sum::<f64>() / n as f64,
            min: v[0],
            median: v[n / 2],
            p99: v[((n as f64 * 0.99) as usize).min(n - 1)],
            max: v[n - 1],
        }
    }
}

/// The agent step's instructions on the Cortex-M4 build, by call.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AgentInstructions {
    /// Learning steps (`step`: choose and update).
    pub learning_step: Instructions,
    /// Greedy test steps.
    pub test_step: Instructions,
    /// Episode starts.
    pub start: Instructions,
    /// Episode ends (time limit or absorbing).
    pub end: Instructions,
    /// Instructions stand in for cycles: QEMU counts instructions
    /// (`-icount shift=0`), not the M4's pipeline and flash wait states.
    pub note: &'static str,
}

/// What a fault did, as the plant side and the telemetry saw it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultResult {
    /// The `--fault` specification.
    pub spec: String,
    /// The first affected answer \[s, emulated time\].
    pub onset_s: Option<f64>,
    /// The servo had torque at the onset (the fault hit a running robot).
    pub torque_at_onset: bool,
    /// When the servo's torque went off after the onset \[s\].
    pub torque_off_s: Option<f64>,
    /// Onset to torque off \[ms\].
    pub latency_ms: Option<f64>,
    /// The control period \[ms\].
    pub period_ms: f64,
    /// The latency is at most one control period.
    pub within_one_period: bool,
    /// The cause the firmware reported (telemetry `Fault`).
    pub cause: Option<String>,
    /// Its details.
    pub cause_detail: Option<String>,
    /// When the `Fault` frame was sent \[s\].
    pub reported_s: Option<f64>,
    /// Torque came back on after `ClearFault` and `Start`.
    pub resumed: bool,
}

/// A pass/fail check of the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// What is checked.
    pub name: &'static str,
    /// Whether it holds.
    pub ok: bool,
    /// The numbers behind it.
    pub detail: String,
}

/// The summary of a SIL run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct SilSummary {
    /// The task.
    pub task: SilTask,
    /// The firmware's robot.
    pub robot: &'static str,
    /// The policy.
    pub policy: String,
    /// The agent's seed (the firmware's default).
    pub seed: u64,
    /// The firmware image.
    pub elf: String,
    /// What stands behind the bus.
    pub plant: String,
    /// Learning time asked for \[s\].
    pub seconds: f64,
    /// Learning time reached \[s\].
    pub learning_s: f64,
    /// Emulated time of the whole run \[s\].
    pub emulated_s: f64,
    /// Wall-clock time \[s\].
    pub wall_s: f64,
    /// Emulated seconds per wall-clock second.
    pub speedup: f64,
    /// Lock-step exchanges.
    pub exchanges: u64,
    /// Where the wall-clock time of the lock-step loop went.
    pub wall_time: WallTime,
    /// Instructions the firmware executed (outside its idle loop).
    pub instructions: u64,
    /// Learning episodes finished.
    pub learning_episodes: u64,
    /// The learning curve: every test episode.
    pub curve: Vec<TestPoint>,
    /// Return of the first test episode (before learning).
    pub first_test_return: Option<f64>,
    /// Mean of the last 10 % of test returns (Section VI).
    pub end_performance: Option<f64>,
    /// Rise time (Section VI) \[s of learning\].
    pub rise_time_s: Option<f64>,
    /// Damage J of the learned joint(s) at the end (firmware's counter).
    pub damage: Vec<f64>,
    /// Backlash re-engagements of the learned joint(s) at the end.
    pub reengagements: Vec<u32>,
    /// The agent step's instruction counts.
    pub agent_instructions: AgentInstructions,
    /// The telemetry link: frames, bytes, every kind of loss.
    pub telemetry: LinkStats,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The emulated servo bus.
    pub bus: BusStats,
    /// The bit-for-bit replay.
    pub replay: ReplayReport,
    /// The host-only runs of the same controller to compare the learning
    /// with (pendulum only).
    pub host_twin: Option<TwinReport>,
    /// The injected faults.
    pub faults: Vec<FaultResult>,
    /// Faults the firmware reported that no injection explains.
    pub unexpected_faults: Vec<String>,
    /// The checks; the run passes when all hold.
    pub checks: Vec<Check>,
    /// All checks hold.
    pub passed: bool,
}

/// Where the run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Waiting for the first test episode.
    FirstTest,
    /// Learning.
    Learning,
    /// Waiting for the final test episode.
    FinalTest,
    /// Finished.
    Done,
}

struct Session<'a> {
    cfg: &'a SilConfig,
    emu: Emulator,
    rig: Box<dyn Rig>,
    bus: BusEmulator,
    recorder: Recorder,
    clock_decoder: wire::FrameDecoder<FromBoard, CLOCK_FRAME_LEN>,
    clock_queue: VecDeque<FromBoard>,
    encoder: FrameEncoder,
    now_us: u64,
    bus_in: u64,
    bus_out: u64,
    tele_in: u64,
    tele_out: u64,
    replies: Vec<Reply>,
    commands: Vec<(u64, ToChip)>,
    period_us: u64,
    phase: Phase,
    learning_steps: u64,
    learning_episodes: u64,
    curve: Vec<TestPoint>,
    records: Vec<Record>,
    cycles: [Vec<u32>; 4],
    fault_reports: Vec<(f64, String, String)>,
    resumed_after: Vec<u64>,
    exchanges: u64,
    instructions: u64,
    wall: WallClock,
    loop_s: f64,
    booted: bool,
    episodes_csv: csv::Writer<std::fs::File>,
    raw: std::io::BufWriter<std::fs::File>,
    sink: Option<crate::telemetry::TelemetrySink>,
    bar: Option<indicatif::ProgressBar>,
}

/// Runs `cfg`; the summary is also written to `summary.json`.
pub fn run(cfg: &SilConfig) -> anyhow::Result<SilSummary> {
    std::fs::create_dir_all(&cfg.out_dir)
        .with_context(|| format!("cannot create {}", cfg.out_dir.display()))?;
    let out = |name: &str| cfg.out_dir.join(name);
    let setup = QemuSetup {
        qemu: cfg.qemu.clone(),
        elf: cfg.elf.clone(),
        defmt_log: out("firmware.defmt"),
        qemu_log: out("qemu.log"),
    };
    let started = Instant::now();
    let rig = cfg.task.rig();
    let bus = BusEmulator::new(rig.as_ref(), SUPPLY_V, cfg.faults.clone());
    let csv_file =
        std::fs::File::create(out("telemetry.csv")).context("cannot create telemetry.csv")?;
    let recorder = Recorder::new(Some(Box::new(std::io::BufWriter::new(csv_file))))?;
    let raw = std::fs::File::create(out("telemetry.bin")).context("cannot create telemetry.bin")?;
    let mut episodes_csv =
        csv::Writer::from_path(out("episodes.csv")).context("cannot create episodes.csv")?;
    episodes_csv.write_record([
        "index",
        "mode",
        "return",
        "length",
        "weights_checksum",
        "learning_time_s",
        "emulated_time_s",
    ])?;
    let bar = cfg.progress.then(|| {
        crate::progress::steps_bar((cfg.seconds * 1000.0).round() as u64, "sil: learning ms")
    });
    let sink = match &cfg.telemetry {
        Some(t) => Some(
            crate::telemetry::TelemetrySink::open(t).map_err(|e| anyhow!("{}", e.one_line()))?,
        ),
        None => None,
    };
    let emu = Emulator::start(&setup)?;
    let mut s = Session {
        cfg,
        emu,
        rig,
        bus,
        recorder,
        clock_decoder: wire::FrameDecoder::new(),
        clock_queue: VecDeque::new(),
        encoder: FrameEncoder::new(),
        now_us: 0,
        bus_in: 0,
        bus_out: 0,
        tele_in: 0,
        tele_out: 0,
        replies: Vec::new(),
        commands: Vec::new(),
        period_us: cfg.task.robot().spec().period_us as u64,
        phase: Phase::FirstTest,
        learning_steps: 0,
        learning_episodes: 0,
        curve: Vec::new(),
        records: Vec::new(),
        cycles: Default::default(),
        fault_reports: Vec::new(),
        resumed_after: Vec::new(),
        exchanges: 0,
        instructions: 0,
        wall: WallClock::default(),
        loop_s: 0.0,
        booted: false,
        episodes_csv,
        raw: std::io::BufWriter::new(raw),
        sink,
        bar,
    };
    let loop_started = Instant::now();
    let result = s.run_loop();
    s.loop_s = loop_started.elapsed().as_secs_f64();
    let status = s.emu.stop();
    if let Some(bar) = &s.bar {
        bar.finish_and_clear();
    }
    s.recorder.flush()?;
    s.episodes_csv.flush()?;
    std::io::Write::flush(&mut s.raw)?;
    decode_defmt(cfg, &setup);
    if let Err(e) = result {
        let how = status.map(|st| format!(" (QEMU {st})")).unwrap_or_default();
        return Err(e.context(format!(
            "SIL run stopped at {:.3} s emulated{how}; logs in {}",
            s.now_us as f64 * 1e-6,
            cfg.out_dir.display()
        )));
    }
    let summary = s.summary(started.elapsed().as_secs_f64());
    let json = serde_json::to_string_pretty(&summary)?;
    crate::output::write_atomic(&out("summary.json"), json.as_bytes())?;
    Ok(summary)
}

/// `defmt-print` turns the firmware's binary log into text, if installed.
fn decode_defmt(cfg: &SilConfig, setup: &QemuSetup) {
    let Ok(input) = std::fs::File::open(&setup.defmt_log) else {
        return;
    };
    let Ok(output) = std::fs::File::create(cfg.out_dir.join("firmware.log")) else {
        return;
    };
    let ok = std::process::Command::new("defmt-print")
        .arg("-e")
        .arg(&cfg.elf)
        .stdin(input)
        .stdout(output)
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        let _ = std::fs::write(
            cfg.out_dir.join("firmware.log"),
            format!(
                "defmt-print (cargo install defmt-print) was not found or failed; decode the log with\n  defmt-print -e {} < {}\n",
                cfg.elf.display(),
                setup.defmt_log.display()
            ),
        );
    }
}

impl Session<'_> {
    fn now_s(&self) -> f64 {
        self.now_us as f64 * 1e-6
    }

    fn learning_time_s(&self) -> f64 {
        self.learning_steps as f64 * self.period_us as f64 * 1e-6
    }

    /// The emulated time after which the run gives up: generous room for
    /// resets between episodes, test episodes and faults.
    fn time_limit_us(&self) -> u64 {
        let fault_end = self.cfg.faults.iter().map(|f| f.end_us).max().unwrap_or(0);
        ((self.cfg.seconds * 4.0 + 120.0) * 1e6) as u64 + fault_end
    }

    fn next_clock(&mut self) -> anyhow::Result<FromBoard> {
        loop {
            if let Some(m) = self.clock_queue.pop_front() {
                return Ok(m);
            }
            let (rx, timeout) = (&self.emu.clock_rx, self.cfg.hang_timeout);
            let chunk = match self.wall.time(Account::Board, || rx.recv_timeout(timeout)) {
                Ok(c) => c,
                Err(RecvTimeoutError::Timeout) => {
                    if let Some(st) = self.emu.exited() {
                        bail!("QEMU exited ({st}): the firmware stopped (a panic or fault is in firmware.log)");
                    }
                    bail!(
                        "the board sent nothing for {} s of wall-clock time: hung",
                        self.cfg.hang_timeout.as_secs()
                    )
                }
                Err(RecvTimeoutError::Disconnected) => {
                    std::thread::sleep(Duration::from_millis(50));
                    let st = self
                        .emu
                        .exited()
                        .map(|s| s.to_string())
                        .unwrap_or_else(|| "still running".into());
                    bail!("the board closed its clock channel (QEMU {st}): the firmware stopped (see firmware.log)")
                }
            };
            for r in self.clock_decoder.feed(&chunk) {
                match r {
                    Ok(frame) => self.clock_queue.push_back(frame.msg),
                    Err(e) => bail!("damaged clock frame from the board: {e:?}"),
                }
            }
        }
    }

    fn take(&mut self, telemetry: bool, want: u64) -> anyhow::Result<Vec<u8>> {
        let mut got = Vec::new();
        loop {
            let have = if telemetry { self.tele_in } else { self.bus_in };
            if have >= want {
                if have > want {
                    bail!("the board wrote more than it counted ({have} > {want})");
                }
                return Ok(got);
            }
            let rx = if telemetry {
                &self.emu.telemetry_rx
            } else {
                &self.emu.bus_rx
            };
            let timeout = self.cfg.hang_timeout;
            let chunk = self.wall.time(Account::Board, || rx.recv_timeout(timeout)).map_err(|_| {
                anyhow!(
                    "{} bytes the board counted never arrived",
                    if telemetry { "telemetry" } else { "bus" }
                )
            })?;
            if telemetry {
                self.tele_in += chunk.len() as u64;
            } else {
                self.bus_in += chunk.len() as u64;
            }
            got.extend_from_slice(&chunk);
        }
    }

    fn command_at(&mut self, t_us: u64, cmd: ToChip) {
        let i = self.commands.partition_point(|(t, _)| *t <= t_us);
        self.commands.insert(i, (t_us, cmd));
    }

    fn run_loop(&mut self) -> anyhow::Result<()> {
        loop {
            match self.next_clock()? {
                FromBoard::Boot {
                    protocol,
                    robot,
                    calibration,
                } => {
                    if protocol != CLOCK_PROTOCOL {
                        bail!("the board speaks clock protocol {protocol}, this host {CLOCK_PROTOCOL}: rebuild one of them");
                    }
                    let want = self.cfg.task.robot();
                    if robot != want.code() {
                        let name = Robot::from_code(robot)
                            .map(|r| r.name())
                            .unwrap_or("unknown");
                        bail!(
                            "the image drives {name}, the run is for {}: build it with `cargo xtask qemu --robot {}`",
                            want.name(),
                            if want == Robot::Leo { "leo" } else { "pendulum" }
                        );
                    }
                    if calibration.abs_diff(CALIBRATION_INSTRUCTIONS) > 16 {
                        bail!(
                            "the board's instruction counter read {calibration} for {CALIBRATION_INSTRUCTIONS} instructions: QEMU is not counting instructions (-icount shift=0)"
                        );
                    }
                    self.booted = true;
                    // A fresh learner with the run's policy, then the first
                    // test episode.
                    self.command_at(100_000, ToChip::SetPolicy(self.cfg.policy));
                    self.command_at(200_000, ToChip::Start(RunMode::Testing));
                }
                FromBoard::Idle {
                    now_us,
                    until_us,
                    bus_tx,
                    telemetry_tx,
                    instructions,
                } => {
                    if !self.booted {
                        bail!("the board went idle before it booted");
                    }
                    if now_us != self.now_us {
                        bail!(
                            "the board's clock ({now_us} us) is not the host's ({} us)",
                            self.now_us
                        );
                    }
                    self.instructions = instructions;
                    self.exchanges += 1;
                    let bus_bytes = self.take(false, bus_tx)?;
                    if !bus_bytes.is_empty() {
                        let (bus, rig, now) = (&mut self.bus, self.rig.as_mut(), self.now_us);
                        let replies = self.wall.time(Account::Plant, || bus.receive(now, &bus_bytes, rig));
                        self.replies.extend(replies);
                        self.replies.sort_by_key(|r| r.at_us);
                    }
                    let tele_bytes = self.take(true, telemetry_tx)?;
                    if !tele_bytes.is_empty() {
                        let t0 = Instant::now();
                        std::io::Write::write_all(&mut self.raw, &tele_bytes)?;
                        if let Some(sink) = self.sink.as_mut() {
                            sink.forward(&tele_bytes);
                        }
                        let mut frames = Vec::new();
                        self.recorder.feed(&tele_bytes, self.now_s(), &mut frames)?;
                        for f in frames {
                            self.on_frame(f)?;
                        }
                        let spent = t0.elapsed();
                        self.wall.add(Account::Telemetry, spent);
                    }
                    if self.phase == Phase::Done {
                        return Ok(());
                    }
                    if self.now_us > self.time_limit_us() {
                        bail!(
                            "learning time {:.1} s of {} s not reached within {:.0} s of emulated time",
                            self.learning_time_s(),
                            self.cfg.seconds,
                            self.time_limit_us() as f64 * 1e-6
                        );
                    }
                    let next_reply = self.replies.first().map_or(NEVER, |r| r.at_us);
                    let next_command = self.commands.first().map_or(NEVER, |c| c.0);
                    let next = until_us.min(next_reply).min(next_command).max(self.now_us);
                    if next == NEVER {
                        bail!("the board waits for nothing and nothing is scheduled: it would sleep forever");
                    }
                    let due = self.replies.partition_point(|r| r.at_us <= next);
                    let mut bus_out = Vec::new();
                    for r in self.replies.drain(..due) {
                        bus_out.extend_from_slice(&r.bytes);
                    }
                    if !bus_out.is_empty() {
                        self.bus_out += bus_out.len() as u64;
                        self.emu.send_bus(&bus_out)?;
                    }
                    let due = self.commands.partition_point(|c| c.0 <= next);
                    let mut tele_out = Vec::new();
                    for (_, cmd) in self.commands.drain(..due) {
                        let mut buf = [0u8; MAX_FRAME_LEN];
                        let frame = self
                            .encoder
                            .encode(&cmd, &mut buf)
                            .map_err(|e| anyhow!("{e:?}"))?;
                        tele_out.extend_from_slice(frame);
                    }
                    if !tele_out.is_empty() {
                        self.tele_out += tele_out.len() as u64;
                        self.emu.send_telemetry(&tele_out)?;
                    }
                    self.now_us = next;
                    let advance = ToBoard::Advance {
                        now_us: next,
                        bus_rx: self.bus_out,
                        telemetry_rx: self.tele_out,
                    };
                    let mut buf = [0u8; CLOCK_FRAME_LEN];
                    let frame = wire::encode_frame(&advance, self.exchanges as u32, &mut buf)
                        .map_err(|e| anyhow!("{e:?}"))?;
                    self.emu.send_clock(frame)?;
                }
            }
        }
    }

    fn on_frame(&mut self, frame: Decoded<ToHost>) -> anyhow::Result<()> {
        match frame.msg {
            ToHost::Step(step) => {
                let k = match (step.kind, step.mode) {
                    (StepKind::Start, _) => 2,
                    (StepKind::Absorbing | StepKind::Timeout, _) => 3,
                    (StepKind::Step, RunMode::Learning) => 0,
                    (StepKind::Step, RunMode::Testing) => 1,
                };
                self.cycles[k].push(step.agent_cycles);
                self.records.push(Record::Step(step));
            }
            ToHost::Episode(e) => {
                let learning = e.mode == RunMode::Learning;
                if learning {
                    self.learning_steps += e.length as u64;
                    self.learning_episodes += 1;
                } else {
                    self.curve.push(TestPoint {
                        learning_time_s: self.learning_time_s(),
                        test_return: e.total_reward as f64,
                    });
                }
                self.episodes_csv.write_record([
                    e.index.to_string(),
                    crate::capture::mode_name(e.mode).to_string(),
                    e.total_reward.to_string(),
                    e.length.to_string(),
                    format!("{:08x}", e.weights_checksum),
                    format!("{:.3}", self.learning_time_s()),
                    format!("{:.3}", self.now_s()),
                ])?;
                self.records.push(Record::Episode(e));
                if let Some(bar) = &self.bar {
                    bar.set_position((self.learning_time_s() * 1000.0) as u64);
                }
                match self.phase {
                    Phase::FirstTest if !learning => {
                        self.phase = Phase::Learning;
                        self.command_at(self.now_us, ToChip::Start(RunMode::Learning));
                    }
                    Phase::Learning
                        if learning && self.learning_time_s() >= self.cfg.seconds - 1e-9 =>
                    {
                        self.phase = Phase::FinalTest;
                        self.command_at(self.now_us, ToChip::Start(RunMode::Testing));
                    }
                    Phase::FinalTest if !learning => {
                        self.phase = Phase::Done;
                        self.command_at(self.now_us, ToChip::Stop);
                    }
                    _ => {}
                }
            }
            ToHost::Fault(f) => {
                let (name, detail) = crate::capture::describe(&ToHost::Fault(f));
                let _ = name;
                self.fault_reports
                    .push((self.now_s(), f.cause.name().to_string(), detail));
                // Resume once every fault window that is open now is over.
                let resume_from = self
                    .cfg
                    .faults
                    .iter()
                    .filter(|w| w.start_us <= self.now_us)
                    .map(|w| w.end_us)
                    .max()
                    .unwrap_or(0)
                    .max(self.now_us);
                let mode = if self.phase == Phase::Learning {
                    RunMode::Learning
                } else {
                    RunMode::Testing
                };
                self.command_at(resume_from + 100_000, ToChip::ClearFault);
                self.command_at(resume_from + 200_000, ToChip::Start(mode));
                self.resumed_after.push(resume_from);
            }
            _ => {}
        }
        Ok(())
    }

    fn summary(&mut self, wall_s: f64) -> SilSummary {
        let cfg = self.cfg;
        let returns: Vec<f64> = self.curve.iter().map(|p| p.test_return).collect();
        let times: Vec<f64> = self.curve.iter().map(|p| p.learning_time_s).collect();
        let replay = replay(&cfg.task.profile(), cfg.policy, DEFAULT_SEED, &self.records);
        let period_ms = self.period_us as f64 * 1e-3;
        let mut faults = Vec::new();
        let mut explained = vec![false; self.fault_reports.len()];
        for (spec, trace) in self.bus.faults() {
            let onset_s = trace.onset_us.map(|t| t as f64 * 1e-6);
            let torque_off_s = trace.torque_off_us.map(|t| t as f64 * 1e-6);
            let latency_ms = match (trace.onset_us, trace.torque_off_us) {
                (Some(a), Some(b)) => Some((b - a) as f64 * 1e-3),
                _ => None,
            };
            // The firmware's report: the first Fault sent after the onset.
            let report = trace.onset_us.and_then(|on| {
                self.fault_reports
                    .iter()
                    .enumerate()
                    .find(|(_, r)| r.0 * 1e6 >= on as f64 - 1.0)
            });
            if let Some((i, _)) = report {
                explained[i] = true;
            }
            faults.push(FaultResult {
                spec: spec.to_string(),
                onset_s,
                torque_at_onset: trace.torque_at_onset,
                torque_off_s,
                latency_ms,
                period_ms,
                within_one_period: latency_ms.is_some_and(|l| l <= period_ms),
                cause: report.map(|(_, r)| r.1.clone()),
                cause_detail: report.map(|(_, r)| r.2.clone()),
                reported_s: report.map(|(_, r)| r.0),
                resumed: trace.torque_on_again_us.is_some(),
            });
        }
        let unexpected_faults: Vec<String> = self
            .fault_reports
            .iter()
            .zip(&explained)
            .filter(|(_, e)| !**e)
            .map(|(r, _)| format!("{:.3} s: {}", r.0, r.2))
            .collect();
        let link = self.recorder.stats();
        let latest = self.recorder.latest().clone();
        let mut checks = vec![
            Check {
                name: "telemetry: every frame decoded, no sequence gap",
                ok: link.is_clean() && link.frames > 0,
                detail: format!(
                    "{} frames, {} bytes; crc {} cobs {} oversize {} short {} undecodable {} non-canonical {}; gaps {} ({} frames missed, {} resyncs)",
                    link.frames,
                    link.bytes,
                    link.crc_errors,
                    link.cobs_errors,
                    link.oversize,
                    link.too_short,
                    link.decode_errors,
                    link.noncanonical,
                    link.seq_gaps,
                    link.frames_missed,
                    link.seq_resyncs
                ),
            },
            Check {
                name: "replay: same action at every step and same weight checksums, bit for bit",
                ok: replay.identical,
                detail: format!(
                    "{} agent calls, {} actions and {} checksums compared; final checksum firmware {} replay {}{}",
                    replay.steps,
                    replay.actions_compared,
                    replay.checksums_compared,
                    replay.final_checksum_firmware.map(|c| format!("{c:08x}")).unwrap_or("-".into()),
                    replay.final_checksum_replay.map(|c| format!("{c:08x}")).unwrap_or("-".into()),
                    replay
                        .first_action_mismatch
                        .map(|m| format!("; first action mismatch at step {}: {} vs {}", m.0, m.1, m.2))
                        .unwrap_or_default()
                ),
            },
            Check {
                name: "learning time reached and a final test episode run",
                ok: self.phase == Phase::Done,
                detail: format!("{:.1} s of {} s", self.learning_time_s(), cfg.seconds),
            },
            Check {
                name: "no fault without an injected cause",
                ok: unexpected_faults.is_empty(),
                detail: if unexpected_faults.is_empty() { "none".into() } else { unexpected_faults.join("; ") },
            },
        ];
        for f in &faults {
            checks.push(Check {
                name: "fault: hit with torque on, torque off within one control period, cause reported, resumed",
                ok: f.torque_at_onset && f.within_one_period && f.cause.is_some() && f.resumed,
                detail: format!(
                    "{}: onset {} (torque {}) torque off {} latency {} (period {} ms), cause {}, resumed {}",
                    f.spec,
                    f.onset_s.map(|t| format!("{t:.4} s")).unwrap_or("never".into()),
                    if f.torque_at_onset { "on" } else { "off" },
                    f.torque_off_s.map(|t| format!("{t:.4} s")).unwrap_or("never".into()),
                    f.latency_ms.map(|t| format!("{t:.2} ms")).unwrap_or("-".into()),
                    f.period_ms,
                    f.cause.as_deref().unwrap_or("none"),
                    f.resumed
                ),
            });
        }
        let end = end_performance(&returns);
        let host_twin = match cfg.task {
            SilTask::Pendulum => {
                match twin(cfg.policy, DEFAULT_SEED, TWIN_EXTRA_SEEDS, cfg.seconds) {
                    Ok(t) => Some(t),
                    Err(e) => {
                        checks.push(Check {
                            name: "host twin",
                            ok: false,
                            detail: format!("{e:#}"),
                        });
                        None
                    }
                }
            }
            SilTask::Leo => None,
        };
        if cfg.task == SilTask::Pendulum && cfg.seconds >= LEARNING_CHECK_S {
            let first = returns.first().copied();
            let twin_text = host_twin
                .as_ref()
                .and_then(|t| {
                    Some((
                        t.end_performance_mean?,
                        t.end_performance_min?,
                        t.end_performance_max?,
                    ))
                })
                .map(|(m, lo, hi)| format!("; host twin {m:.0} (seeds: {lo:.0} .. {hi:.0})"))
                .unwrap_or_default();
            checks.push(Check {
                name: "learned: end performance above the first test return",
                ok: matches!((first, end), (Some(f), Some(e)) if e > f),
                detail: format!(
                    "first {} end {}{twin_text}",
                    first.map(|v| format!("{v:.0}")).unwrap_or("-".into()),
                    end.map(|v| format!("{v:.0}")).unwrap_or("-".into())
                ),
            });
        }
        if let Some(sink) = self.sink.take() {
            let (ok, detail) = match sink.finish() {
                Ok(t) => (true, format!("{} bytes to {}", t.bytes, t.target)),
                Err(e) => (false, format!("{e:#}")),
            };
            checks.push(Check {
                name: "telemetry forwarded (--telemetry)",
                ok,
                detail,
            });
        }
        let passed = checks.iter().all(|c| c.ok);
        SilSummary {
            task: cfg.task,
            robot: cfg.task.robot().name(),
            policy: crate::experiment::algo::label(&cfg.policy),
            seed: DEFAULT_SEED,
            elf: cfg.elf.display().to_string(),
            plant: self.rig.describe(),
            seconds: cfg.seconds,
            learning_s: self.learning_time_s(),
            emulated_s: self.now_s(),
            wall_s,
            speedup: if wall_s > 0.0 { self.now_s() / wall_s } else { 0.0 },
            exchanges: self.exchanges,
            wall_time: self.wall.report(self.loop_s),
            instructions: self.instructions,
            learning_episodes: self.learning_episodes,
            first_test_return: returns.first().copied(),
            end_performance: end,
            rise_time_s: rise_time(&times, &returns),
            curve: std::mem::take(&mut self.curve),
            damage: latest.damage,
            reengagements: latest.reengagements,
            agent_instructions: AgentInstructions {
                learning_step: Instructions::of(std::mem::take(&mut self.cycles[0])),
                test_step: Instructions::of(std::mem::take(&mut self.cycles[1])),
                start: Instructions::of(std::mem::take(&mut self.cycles[2])),
                end: Instructions::of(std::mem::take(&mut self.cycles[3])),
                note: "instructions executed (QEMU -icount shift=0), counted around the agent call by the board's counter",
            },
            telemetry: link,
            messages: self.recorder.counts(),
            bus: self.bus.stats(),
            replay,
            host_twin,
            faults,
            unexpected_faults,
            checks,
            passed,
        }
    }
}
