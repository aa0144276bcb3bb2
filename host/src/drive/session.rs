//! One `pada drive` run: the firmware's controller (`pada_firmware::control`)
//! and the firmware's bus transactions (`pada_firmware::bus::RobotBus`) on a
//! PC's serial port, with everything a board does around them.
//!
//! 1. **Boot**, as the firmware's: every servo's torque off (three times),
//!    each servo set up (it answers, it is the model the definition names,
//!    wheel or PWM mode, return delay, status return level, the Bus
//!    Watchdog), the checkpoint loaded from disk when its configuration
//!    matches. A servo that fails is bad input: torque stays off, one line
//!    says which servo and why, exit code 2.
//! 2. **Periods** on the period clock ([`super::clock`]): read every servo
//!    and the sensor device, the controller's period, write torque and
//!    commands, call the operator at an episode's end and start, then
//!    the telemetry a board sends (steps, episodes, state changes, faults,
//!    policy reports, health every second). The run protocol of `pada run
//!    --board` ([`crate::board::RunProtocol`]): a test episode, learning
//!    for the budget, a final test episode.
//! 3. **Ends**, each with every servo's torque off and the checkpoint saved
//!    and the telemetry flushed: the protocol is done; Ctrl-C (the period
//!    in progress writes torque off instead of its command); a fault of the
//!    safety machine (a silent servo, a storm of checksum errors, a
//!    hardware alert, a soft limit, overruns): torque goes off in the
//!    period it is found, then the run ends with its cause; the port goes
//!    away (an adapter pulled): nothing can reach the servos, so an X-series
//!    servo stops by its own Bus Watchdog, an RX-28 keeps its last command
//!    until its power is cut, and the line says so.

use super::clock::{ClockReport, PeriodClock};
use super::latency::Latency;
use super::port::{block_on, SerialBusPort};
use super::realtime::{Linux, Realtime, RealtimeReport};
use super::store::FileStore;
use super::telemetry::TelemetryPipe;
use crate::board::protocol::{EpisodeOutcome, RunProtocol};
use crate::board::trial::{command, table_len, with_table, BoardTrial, TableVisitor};
use crate::experiment::governed::GovernorStats;
use crate::experiment::measured::robot_mtbf_s;
use crate::experiment::{RunConfig, TrialResult};
use crate::robot_arg::RobotArg;
use crate::seed::trial_seed;
use pada_core::checkpoint::LoadOutcome;
use pada_core::episodes::is_learning_action;
use pada_core::fatigue::{FatigueCounter, PAPER_WINDOW_STEPS};
use pada_core::policy::PolicyKind;
use pada_core::profile::LearnerProfile;
use pada_core::robot::RobotRules;
use pada_core::safety::Transition;
use pada_core::servo::{Drive, ServoProtocol};
use pada_core::weights::WeightStore;
use pada_core::wire::{self, StepKind, ToChip, ToHost};
use pada_firmware::bus::{BusConfig, BusStats, OperatorCall, RobotBus, SetupError};
use pada_firmware::control::{Controller, PeriodOutput, Readings};
use pada_firmware::io::CycleCounter;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The most counted joints a run's MTBF follows (LEO's hips and knees).
const COUNTED: usize = 4;

/// What a run is.
pub struct DriveSetup {
    /// The robot.
    pub robot: RobotArg,
    /// The learner's profile (the PC's, or a board's to see what it learns).
    pub profile: LearnerProfile,
    /// Policy, learning time, seed (trial 0's), budget, switch.
    pub cfg: RunConfig,
    /// The port and its rate.
    pub port: PathBuf,
    /// Bits per second.
    pub baud: u32,
    /// Against virtual servos in lock step: no waiting for the wall clock.
    pub lock_step: bool,
    /// The checkpoint file.
    pub checkpoint: Option<PathBuf>,
    /// Table entries exported from the host's weights, imported over the
    /// fresh learner's table before the first episode (`--weights`).
    pub weights: Option<Vec<u8>>,
    /// Set by Ctrl-C.
    pub stop: Arc<AtomicBool>,
    /// The adapter's latency timer.
    pub latency: Latency,
    /// Ask for a real-time control thread (`SCHED_FIFO`, locked memory)
    /// for the periods in real time ([`super::realtime`]).
    pub realtime: bool,
}

/// Why a run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", content = "detail", rename_all = "kebab-case")]
pub enum Ended {
    /// The run protocol finished.
    Done,
    /// Ctrl-C.
    Interrupted,
    /// The safety machine faulted: torque off, the cause.
    Fault(String),
    /// The port went away.
    PortGone(String),
}

/// What a run came to.
#[derive(Debug, Serialize)]
pub struct DriveOutcome {
    /// Why it ended.
    pub ended: Ended,
    /// The learning curve and everything `pada run --board` reports.
    #[serde(skip)]
    pub trial: BoardTrial,
    /// The period clock's measurements.
    pub clock: ClockReport,
    /// What the operating system granted the control thread.
    pub realtime: RealtimeReport,
    /// The bus's counters.
    pub bus: BusReport,
    /// The set-up of every servo, one line each.
    pub servos: Vec<String>,
    /// What became of the checkpoint: loaded at the start, saved at the end.
    pub checkpoint: Vec<String>,
    /// What the telemetry carried.
    pub telemetry: super::telemetry::TelemetryReport,
}

/// The bus's counters and the bytes it carried.
#[derive(Debug, Clone, Serialize)]
pub struct BusReport {
    /// Requests, replies, timeouts, checksum errors, strays, line errors.
    pub requests: u32,
    /// Status packets received.
    pub replies: u32,
    /// Attempts without an answer.
    pub timeouts: u32,
    /// Damaged answers.
    pub checksum_errors: u32,
    /// Answers of another ID or length.
    pub stray_packets: u32,
    /// Bytes sent and received.
    pub bytes_out: u64,
    /// Bytes received.
    pub bytes_in: u64,
    /// Bytes per period, both ways (the wire time's share).
    pub bytes_per_period: f64,
    /// The bytes of a steady period counted from the packets the bus
    /// encodes (`pada_firmware::bus::timing::PeriodTraffic`), both ways.
    pub predicted_bytes_per_period: u32,
    /// Their time on the wire at the port's rate, with the servos' 50 µs
    /// Return Delay before each answer \[ms\]: the bus time stated
    /// against the period (a USB adapter's latency comes on top).
    pub wire_ms_per_period: f64,
    /// The Bus Watchdog armed on the X-series servos \[ms\] (0: none).
    pub watchdog_ms: u32,
    /// Whether the X-series servos were read with FAST SYNC READ.
    pub fast_sync_read: bool,
}

/// A run's failure that is bad input (a servo missing, of another model,
/// the wrong rate): one line, exit code 2.
#[derive(Debug)]
pub struct BadBus(pub String);

impl std::fmt::Display for BadBus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadBus {}

/// No cycle counter on the PC (the period's work is timed by the clock).
struct NoCycles;

impl CycleCounter for NoCycles {
    fn cycles(&self) -> u32 {
        0
    }
}

/// Runs the robot; the error is either bad input ([`BadBus`]) or a
/// failure.
pub fn drive(setup: &DriveSetup, telemetry: TelemetryPipe) -> anyhow::Result<DriveOutcome> {
    let n = table_len(&setup.profile, setup.cfg.policy)?;
    struct Visit<'a> {
        setup: &'a DriveSetup,
        telemetry: TelemetryPipe,
    }
    impl TableVisitor for Visit<'_> {
        type Output = DriveOutcome;
        fn visit<W: WeightStore>(self, table: W) -> anyhow::Result<DriveOutcome> {
            run(self.setup, table, self.telemetry)
        }
    }
    with_table(&setup.profile, n, Visit { setup, telemetry })
}

/// The bus timing on a PC: the answer may wait for the adapter's latency
/// timer twice (its bytes, then the next request's turnaround), plus 2 ms
/// (the ROBOTIS SDK's own allowance) and a 30-byte answer's wire time; in
/// lock step, where a loaded machine must not turn a late answer into a
/// fault, a generous 200 ms. On a pseudo-terminal (`pada servos` in real
/// time) at least [`VIRTUAL_REPLY_US`]: the answer comes from a process the
/// scheduler may hold back, and 2.3 ms faulted within seconds on a machine
/// with a load average of 5.
fn bus_config(setup: &DriveSetup) -> BusConfig {
    let byte_us = (10_000_000 / setup.baud.max(1)).max(1);
    let wire = 2 * setup.latency.ms() * 1000 + 2000 + 30 * byte_us;
    let virtual_port = std::fs::canonicalize(&setup.port).is_ok_and(|p| p.starts_with("/dev/pts"));
    let reply_timeout_us = match (setup.lock_step, virtual_port) {
        (true, _) => 200_000,
        (false, true) => wire.max(VIRTUAL_REPLY_US),
        (false, false) => wire,
    };
    BusConfig { reply_timeout_us, attempts: 2, byte_us }
}

/// The reply timeout of virtual servos on a pseudo-terminal in real time
/// \[µs\].
const VIRTUAL_REPLY_US: u32 = 10_000;

/// One line for a servo's set-up.
fn setup_line(robot: &RobotArg, id: u8, r: &Result<pada_firmware::bus::ServoSetup, SetupError>, baud: u32) -> String {
    let joint = robot.spec.joints.iter().find(|j| j.id == id);
    let name = joint.map_or("?", |j| j.name);
    let model = joint.map_or("?", |j| j.servo.name);
    match r {
        Ok(s) => format!("servo {id} ({name}): {model} (model {}){}, settings {}", s.model, firmware(s.firmware), if s.wrote { "written" } else { "ok" }),
        Err(SetupError::NoAnswer { .. }) => format!(
            "servo {id} ({name}, {model}) does not answer at {baud} bps (a wrong baud rate, a wrong ID, no power?): `pada servos --scan --port PORT` lists what answers"
        ),
        Err(SetupError::WrongModel { found, expected, .. }) => format!(
            "servo {id} ({name}) is a {} (model {found}); the robot {} names a {model} (model {expected}) there",
            crate::servos::scan::model_name(*found, joint.map_or(1, |j| j.servo.protocol.number())).unwrap_or("model pada does not know"),
            robot.spec.name
        ),
        Err(SetupError::Error { error, .. }) => format!("servo {id} ({name}, {model}) refused its set-up: error bits {:?}", error.names().collect::<Vec<_>>()),
        Err(SetupError::Alert { error, .. }) => format!(
            "servo {id} ({name}, {model}) has a hardware error: {:?}; only a REBOOT clears it: `pada servos --reboot {id} --port PORT` (or power it off and on)",
            error.names().collect::<Vec<_>>()
        ),
    }
}

fn firmware(v: u8) -> String {
    if v == 0 {
        String::new()
    } else {
        format!(", firmware {v}")
    }
}

fn run<W: WeightStore>(setup: &DriveSetup, table: W, mut tm: TelemetryPipe) -> anyhow::Result<DriveOutcome> {
    let spec = setup.robot.spec;
    let cfg = &setup.cfg;
    let rules = setup.robot.rules().map_err(|e| anyhow::Error::new(BadBus(e)))?;
    let seed = trial_seed(cfg.seed, 0);
    let mut ctl = Controller::new(rules, setup.profile, PolicyKind::Sarsa, table, seed).map_err(|e| anyhow::anyhow!("{e}"))?;

    // Boot: torque off, set-up.
    let port = SerialBusPort::open(&setup.port, setup.baud).map_err(|e| anyhow::Error::new(BadBus(e)))?;
    let mut bus = RobotBus::new(port, bus_config(setup), spec);
    for _ in 0..3 {
        block_on(bus.stop_all());
    }
    let report = block_on(bus.setup());
    let servos: Vec<String> = report.iter().map(|(id, r)| setup_line(&setup.robot, *id, r, setup.baud)).collect();
    if let Some((id, r)) = report.iter().find(|(_, r)| r.is_err()) {
        block_on(bus.stop_all());
        let _ = tm.finish();
        return Err(BadBus(format!("{}; torque is off on every servo", setup_line(&setup.robot, *id, r, setup.baud))).into());
    }
    tm.send(ToHost::Hello(ctl.hello()));

    // The checkpoint, as a board loads its flash at boot.
    let mut checkpoint_lines = Vec::new();
    let mut store = match &setup.checkpoint {
        Some(p) => Some(FileStore::open(p, ctl.checkpoint_bytes()).map_err(|e| BadBus(format!("--checkpoint {}: {e}", p.display())))?),
        None => None,
    };
    let mut resumed = false;
    if let Some(store) = store.as_mut() {
        match ctl.load_checkpoint(store) {
            Ok(outcome @ LoadOutcome::Loaded { .. }) => {
                resumed = true;
                checkpoint_lines.push(format!("loaded {} from {}: {:?}", describe_policy(ctl.policy()), store.path().display(), outcome));
                tm.send(ToHost::Checkpoint(wire::CheckpointReport::Load(outcome)));
            }
            Ok(LoadOutcome::NoCheckpoint) => checkpoint_lines.push(format!("none in {}: a fresh learner", store.path().display())),
            Ok(outcome) => {
                checkpoint_lines.push(format!("ignored ({outcome:?}) in {}: a fresh learner", store.path().display()));
                tm.send(ToHost::Warning(wire::Warning::CheckpointIgnored(outcome)));
            }
            Err(e) => checkpoint_lines.push(format!("unreadable ({e:?}): a fresh learner")),
        }
    }
    if resumed && ctl.policy() != cfg.policy {
        block_on(bus.stop_all());
        let _ = tm.finish();
        return Err(BadBus(format!(
            "--checkpoint: it learned with {} and --algo asks for {}; give the same algorithm to go on learning, or another checkpoint file",
            describe_policy(ctl.policy()),
            describe_policy(cfg.policy)
        ))
        .into());
    }

    if resumed && setup.weights.is_some() {
        block_on(bus.stop_all());
        let _ = tm.finish();
        let path = setup.checkpoint.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
        return Err(BadBus(format!(
            "--weights starts a new learner, but the checkpoint {path} holds one already: give another --checkpoint or --out"
        ))
        .into());
    }

    // The run protocol's start: a fresh learner (unless one was loaded),
    // the budget, the exported weights, the first test episode.
    for cmd in RunProtocol::start(cfg.policy) {
        if resumed && matches!(cmd, ToChip::SetPolicy(_)) {
            continue;
        }
        if let (ToChip::Start(_), Some(budget)) = (&cmd, cfg.mtbf_budget_s) {
            command(&mut ctl, ToChip::SetMtbfBudget(Some(budget)))?;
        }
        if let (ToChip::Start(_), Some(entries)) = (&cmd, &setup.weights) {
            ctl.import_entries(entries).map_err(|e| anyhow::anyhow!("the exported weights: {e}"))?;
        }
        let (result, t) = ctl.command(&cmd);
        result.map_err(|e| anyhow::anyhow!("{cmd:?} refused: {e:?}"))?;
        if let Some(t) = t {
            report_transition(&mut tm, &t, &ctl, 0);
        }
    }
    tm.send(ToHost::Policy(ctl.policy_report()));

    let period_us = spec.period_us;
    let period_s = spec.period_s();
    // The periods' thread real time (the telemetry thread, started before,
    // stays ordinary); in lock step no clock is kept, and a FIFO thread
    // running flat out would starve the machine.
    let why_not = if setup.lock_step { "lock step: the periods wait for no clock" } else { "--no-realtime" };
    let mut rt = Realtime::enter(Linux, setup.realtime && !setup.lock_step, why_not);
    let mut clock = PeriodClock::new(period_us, !setup.lock_step);
    let mut protocol = RunProtocol::new(cfg.seconds, period_us);
    let counted = spec.counted.range();
    let n_counted = counted.len().min(COUNTED);
    let window = Some(PAPER_WINDOW_STEPS);
    // Each counted joint's own servo's gearbox (Table I's for the RX-28), as
    // `pada run --board`'s trial counts.
    let fatigue = || FatigueCounter::<COUNTED>::with_gearboxes(|c| spec.gearbox(c), period_s, window);
    let mut paper = fatigue().map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut estimated = fatigue().map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut governed = GovernorStats::default();
    let switch_step = cfg.switch_at_s.map(|s| (s / period_s).round() as u64);
    let mut switched = false;
    let mut learning_actions = 0u64;
    let mut last_kind = StepKind::Start;
    let mut episodes = Vec::new();
    let mut readings = Readings::default();
    let mut out = PeriodOutput::default();
    let health_every = (1_000_000 / period_us).max(1) as u64;
    let has_sensors = spec.encoder.is_some();
    let ended = loop {
        let (k, t_us) = clock.tick();
        // 1. Read.
        block_on(bus.read(&mut readings.servos));
        if has_sensors {
            match block_on(bus.sensors()) {
                Some((count, contacts)) => {
                    readings.encoder = Some(count);
                    readings.contacts = contacts;
                }
                None => readings.encoder = None,
            }
        }
        readings.time_ms = ((if setup.lock_step { t_us } else { clock.now_us() }) / 1000) as u32;
        // 2. The controller's period.
        ctl.period(&readings, &NoCycles, &mut out);
        // Ctrl-C: this period writes torque off instead of its command.
        let interrupted = setup.stop.load(Ordering::SeqCst);
        if interrupted {
            let (_, t) = ctl.command(&ToChip::Stop);
            if let Some(t) = t.filter(|t| t.changed()) {
                let _ = out.transitions.push(t);
            }
            out.torque = false;
            for c in out.commands.iter_mut() {
                c.1 = zero(c.1);
            }
        }
        // 3. Write, and call the operator.
        block_on(bus.write(out.torque, &out.commands, readings.last_period_overran));
        let mut learning_action = false;
        if let Some(s) = &out.step {
            last_kind = s.kind;
            if s.kind == StepKind::Start {
                block_on(bus.call_operator(OperatorCall::EpisodeStarted));
            }
            learning_action = is_learning_action(s.mode, s.kind);
        }
        if out.episode.is_some() {
            block_on(bus.call_operator(OperatorCall::EpisodeEnded));
        }
        let overran = clock.done();
        readings.last_period_overran = overran;

        // 4. Count, report.
        for t in &out.transitions {
            report_transition(&mut tm, t, &ctl, readings.time_ms);
        }
        if learning_action {
            if let Some(g) = ctl.governor() {
                governed.record(g);
            }
            let mut com = [0.0f32; COUNTED];
            let mut est = [0.0f32; COUNTED];
            for (c, j) in counted.clone().enumerate().take(COUNTED) {
                // The commanded voltage in the servo's frame on the nominal
                // supply, as `pada run --board` counts it.
                let ratio = out.commands.get(j).map_or(0.0, |c| c.1.ratio());
                let volts = if out.torque { (ratio as f64 * spec.supply_nominal_v as f64) as f32 } else { 0.0 };
                com[c] = spec.paper_gear_torque(c, volts);
                est[c] = out.torques[j];
            }
            paper.update(&com).map_err(|e| anyhow::anyhow!("{e}"))?;
            estimated.update(&est).map_err(|e| anyhow::anyhow!("{e}"))?;
            learning_actions += 1;
            if !switched && switch_step.is_some_and(|s| learning_actions >= s) {
                command(&mut ctl, ToChip::SwitchToSarsa)?;
                tm.send(ToHost::Policy(ctl.policy_report()));
                switched = true;
            }
        }
        if let Some(mut step) = out.step.take() {
            step.loop_us = clock.last_work_us();
            tm.send(ToHost::Step(step));
        }
        if let Some(p) = out.policy.take() {
            tm.send(ToHost::Policy(p));
        }
        if k % health_every == health_every - 1 {
            tm.send(ToHost::Health(health(&ctl, bus.stats(), &clock, readings.time_ms, tm.dropped())));
        }
        if let Some(e) = out.episode {
            tm.send(ToHost::Episode(e));
            let outcome = EpisodeOutcome {
                fell: last_kind == StepKind::Absorbing,
                walked_m: ctl.walked_m().map(f64::from),
                claimed_slots: ctl.weights().occupancy().map(|o| o.claimed),
            };
            episodes.push(e);
            if let Some(cmd) = protocol.on_episode(&e, outcome) {
                let (result, t) = ctl.command(&cmd);
                result.map_err(|e| anyhow::anyhow!("{cmd:?} refused: {e:?}"))?;
                if let Some(t) = t {
                    report_transition(&mut tm, &t, &ctl, readings.time_ms);
                }
            }
        }
        // 5. Why it ends, if it does.
        if let Some(why) = bus.bus_mut().port_mut().gone() {
            break Ended::PortGone(why.to_string());
        }
        if interrupted {
            break Ended::Interrupted;
        }
        if let Some(cause) = ctl.state().fault() {
            break Ended::Fault(crate::board::fault_line::fault_line(&cause, spec));
        }
        if protocol.done() {
            break Ended::Done;
        }
    };

    // The way out: torque off (again: a board's Stop), the checkpoint, the
    // telemetry.
    if !matches!(ended, Ended::PortGone(_)) {
        block_on(bus.stop_all());
    }
    // Torque is off: the checkpoint and the files are written at the
    // ordinary priority.
    rt.leave();
    let (_, t) = ctl.command(&ToChip::Stop);
    if let Some(t) = t.filter(|t| t.changed()) {
        report_transition(&mut tm, &t, &ctl, readings.time_ms);
    }
    if let Some(store) = store.as_mut() {
        match ctl.save_checkpoint(store) {
            Ok(saved) => {
                checkpoint_lines.push(format!("saved to {}: generation {}, slot {}", store.path().display(), saved.generation, saved.slot));
                tm.send(ToHost::Checkpoint(wire::CheckpointReport::Saved(saved)));
            }
            Err(e) => checkpoint_lines.push(format!("the save to {} failed: {e:?}", store.path().display())),
        }
    }
    tm.send(ToHost::Health(health(&ctl, bus.stats(), &clock, readings.time_ms, tm.dropped())));

    let periods = clock.report().periods;
    let stats = bus.stats();
    let port = bus.bus_mut().port_mut();
    let (bytes_out, bytes_in) = (port.bytes_out, port.bytes_in);
    let traffic = pada_firmware::bus::timing::PeriodTraffic::of(spec, has_sensors);
    let bus_report = BusReport {
        requests: stats.requests,
        replies: stats.replies,
        timeouts: stats.timeouts,
        checksum_errors: stats.checksum_errors,
        stray_packets: stats.stray_packets,
        bytes_out,
        bytes_in,
        bytes_per_period: (bytes_out + bytes_in) as f64 / periods.max(1) as f64,
        predicted_bytes_per_period: traffic.bytes(),
        wire_ms_per_period: traffic.time_us(setup.baud, 2 * pada_firmware::bus::RETURN_DELAY as u32) / 1000.0,
        watchdog_ms: if spec.joints.iter().any(|j| j.servo.protocol == ServoProtocol::V2) { bus.watchdog_units() as u32 * 20 } else { 0 },
        fast_sync_read: bus.fast_reads() && spec.joints.iter().any(|j| j.servo.protocol == ServoProtocol::V2),
    };
    let paper_mtbf = robot_mtbf_s(&paper);
    let governor = ctl.governor().map(|g| governed.finish(g, paper_mtbf, paper_mtbf));
    let (counts, curve) = protocol.into_counts(0, seed, ctl.agent_stats(), ctl.weights().occupancy(), governor);
    // No simulation's gear torques on real servos: the board's own
    // estimate stands in.
    let result = TrialResult::measured(counts, curve, &paper, &estimated, n_counted);
    let trial = BoardTrial {
        result,
        config_hash: ctl.config_hash(),
        weights: ctl.weights().len(),
        weights_checksum: ctl.weights().checksum(),
        board_estimated_mtbf_s: robot_mtbf_s(&estimated),
        periods,
        episodes,
    };
    let telemetry = tm.finish()?;
    Ok(DriveOutcome {
        ended,
        trial,
        clock: clock.report(),
        realtime: rt.report().clone(),
        bus: bus_report,
        servos,
        checkpoint: checkpoint_lines,
        telemetry,
    })
}

/// The zero command of a servo's kind.
fn zero(d: Drive) -> Drive {
    d.zeroed()
}

/// The policy as the command line names it.
fn describe_policy(p: PolicyKind) -> String {
    crate::experiment::algo::label(&p)
}

/// A state change (and a fault) into the telemetry, as the firmware
/// reports them.
fn report_transition<W: WeightStore, R: RobotRules>(tm: &mut TelemetryPipe, t: &Transition, ctl: &Controller<W, R>, time_ms: u32) {
    let step = ctl.agent_stats().steps as u32;
    tm.send(ToHost::State(wire::StateChange { step, from: t.from, to: t.to }));
    if let Some(cause) = t.entered_fault() {
        tm.send(ToHost::Fault(wire::Fault { step, time_ms, cause }));
    }
}

/// A board's periodic `Health`.
fn health<W: WeightStore, R: RobotRules>(ctl: &Controller<W, R>, bus: BusStats, clock: &PeriodClock, time_ms: u32, drops: u32) -> wire::Health {
    let mut h = wire::Health {
        uptime_ms: time_ms,
        bus_errors: bus.timeouts + bus.line_errors + bus.stray_packets,
        checksum_errors: bus.checksum_errors,
        timeouts: bus.timeouts,
        overruns: clock.overruns(),
        max_loop_us: clock.max_work_us(),
        telemetry_drops: drops,
        ..wire::Health::default()
    };
    ctl.health(&mut h);
    h
}
