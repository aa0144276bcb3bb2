//! The firmware's tasks, one per concern, and the channels between them.
//!
//! ```text
//!            BUS_REQUESTS ──▶ servo_bus ──▶ USART1 (RS-485, 1 Mbps) ──▶ Dynamixel ×1…8 (Protocol 1.0 or 2.0)
//! control ◀── BUS_REPLIES ───┘
//!    │  ▲
//!    │  └── FROM_HOST ◀── telemetry_rx ◀── USART2 ◀── host
//!    ├────▶ TO_HOST ────▶ telemetry_tx ──▶ USART2 ──▶ host
//!    └────▶ WATCHDOG ───▶ watchdog ──▶ IWDG
//! ```
//!
//! `control` runs the loop at the robot's rate; it alone owns the
//! controller (agent, safety machine, fatigue counter) and the checkpoint
//! flash, so nothing else can change the weights or the torque.

use crate::board::{BoardSensors, Cycles, FlashStore, Led, ServoPort, TelemetryRx, TelemetryTx, Watchdog};
use defmt::{info, warn};
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Instant, Ticker};
use heapless::Vec;
use pada_core::checkpoint::{CheckpointStore, LoadOutcome, SaveError};
use pada_core::safety::{State, Transition};
use pada_core::wire::{self, FrameEncoder, NackReason, ToChip, ToHost, MAX_FRAME_LEN};
use pada_firmware::bus::{BusConfig, BusStats, RobotBus};
use crate::table::Ctl;
use pada_firmware::config::MAX_ROBOT_SERVOS;
use pada_core::weights::WeightStore;
use pada_firmware::control::{CheckpointError, PeriodOutput, Readings, ServoRead};
use pada_firmware::io::{ByteSink, ByteSource, CycleCounter, Sensors};
use pada_core::robot::RobotSpec;
use pada_core::servo::Drive;
use pada_firmware::timing::LoopTiming;

use crate::channels::{
    send_reliable, set_long_watchdog, Mutex, Outgoing, WatchdogRequest, FROM_HOST, TO_HOST, WATCHDOG, WATCHDOG_DONE,
};

/// What the control loop asks of the servo bus.
pub enum BusRequest {
    /// Read every servo's present state.
    Read,
    /// Apply torque enable and each servo's command.
    Write {
        /// Torque Enable for all servos.
        torque: bool,
        /// (ID, Moving Speed or Goal PWM) per servo.
        commands: Vec<(u8, Drive), MAX_ROBOT_SERVOS>,
        /// The last period overran: re-arm the servos' Bus Watchdog, which
        /// the delay may have tripped.
        rearm: bool,
    },
    /// A fault was cleared: reboot and set up again every Protocol 2.0
    /// servo that alerted (torque is off); nothing if none did.
    RebootAlerted,
}

/// The servo bus's answer to [`BusRequest::Read`].
pub struct BusReply {
    /// Per servo, in joint order.
    pub servos: [ServoRead; MAX_ROBOT_SERVOS],
    /// Counters since boot.
    pub stats: BusStats,
}

/// Control → servo bus.
pub static BUS_REQUESTS: Channel<Mutex, BusRequest, 1> = Channel::new();
/// Servo bus → control.
pub static BUS_REPLIES: Channel<Mutex, BusReply, 1> = Channel::new();
/// Servo bus → boot: the servos were told torque off (before the weight
/// table is filled, which takes about 0.7 s on the F429's 8 MiB table).
pub static SERVOS_OFF: Signal<Mutex, ()> = Signal::new();

/// The servo bus: boot-time set-up, then reads and writes on request, in
/// each servo's protocol ([`RobotBus`]).
#[embassy_executor::task]
pub async fn servo_bus(port: ServoPort, robot: &'static RobotSpec) -> ! {
    let mut bus = RobotBus::new(port, BusConfig::default(), robot);
    // Whatever the servos did before this boot (wheel mode keeps turning
    // at the last Moving Speed): torque off first, a few times.
    for _ in 0..3 {
        bus.stop_all().await;
    }
    SERVOS_OFF.signal(());
    for (id, result) in bus.setup().await {
        match result {
            Ok(s) => info!("servo {=u8}: model {=u16}, settings {}", id, s.model, if s.wrote { "written" } else { "ok" }),
            // The servo is refused: read as silent, so the safety machine
            // faults and torque stays off.
            Err(e) => warn!("servo {=u8}: {}", id, defmt::Debug2Format(&e)),
        }
    }
    loop {
        match BUS_REQUESTS.receive().await {
            BusRequest::Read => {
                let mut servos = [ServoRead::default(); MAX_ROBOT_SERVOS];
                bus.read(&mut servos).await;
                BUS_REPLIES.send(BusReply { servos, stats: bus.stats() }).await;
            }
            // Sent every period, so a servo that missed a packet (or
            // browned out) gets it again one period later.
            BusRequest::Write { torque, commands, rearm } => bus.write(torque, &commands, rearm).await,
            BusRequest::RebootAlerted => {
                for (id, back) in bus.reboot_alerted().await {
                    if back {
                        info!("servo {=u8}: rebooted after its hardware alert, set up again", id);
                    } else {
                        warn!("servo {=u8}: rebooted after its hardware alert, but its set-up failed: refused", id);
                    }
                }
            }
        }
    }
}

/// Frames and sends everything for the host.
#[embassy_executor::task]
pub async fn telemetry_tx(mut tx: TelemetryTx) -> ! {
    let mut encoder = FrameEncoder::new();
    let mut frame = [0u8; MAX_FRAME_LEN];
    loop {
        let out = TO_HOST.receive().await;
        for _ in 0..out.skipped {
            encoder.skip();
        }
        match encoder.encode(&out.msg, &mut frame) {
            Ok(bytes) => {
                if tx.write_all(bytes).await.is_err() {
                    warn!("telemetry: transmit error");
                }
            }
            Err(e) => warn!("telemetry: cannot encode: {}", e),
        }
    }
}

/// Decodes host commands and hands them to the control loop.
#[embassy_executor::task]
pub async fn telemetry_rx(mut rx: TelemetryRx) -> ! {
    // A whole frame: a restore's chunks are the largest commands.
    let mut decoder = wire::ChipDecoder::new();
    let mut buf = [0u8; 64];
    loop {
        let n = match rx.read(&mut buf).await {
            Ok(n) => n,
            Err(_) => {
                warn!("telemetry: receive error (overrun or framing); resynchronising");
                continue;
            }
        };
        for result in decoder.feed(&buf[..n]) {
            match result {
                Ok(frame) => FROM_HOST.send((frame.seq, frame.msg)).await,
                Err(e) => warn!("telemetry: bad command frame: {}", e),
            }
        }
    }
}

/// Feeds the independent watchdog while the control loop is alive.
#[embassy_executor::task]
pub async fn watchdog(mut wd: Watchdog, mut led: Led) -> ! {
    wd.start();
    let mut beats = 0u32;
    loop {
        match WATCHDOG.receive().await {
            WatchdogRequest::Alive => {
                wd.feed();
                beats = beats.wrapping_add(1);
                // A slow blink: the loop runs.
                led.set(beats / 16 % 2 == 0);
            }
            WatchdogRequest::Extend(long) => {
                wd.extend(long);
                WATCHDOG_DONE.signal(());
            }
        }
    }
}

/// Everything the control loop owns.
pub struct ControlLoop {
    /// The controller on the image's table (in main's static).
    pub ctl: &'static mut Ctl,
    /// Encoder and foot switches.
    pub sensors: BoardSensors,
    /// The checkpoint slots.
    pub flash: FlashStore,
    /// The cycle counter.
    pub cycles: Cycles,
    /// The CPU clock \[Hz\].
    pub cpu_hz: u32,
}

/// A `ReadWeights` in progress: sent a few chunks per period.
struct WeightsJob {
    seq: u32,
    next: u32,
    end: u32,
}

/// The control loop at the robot's rate.
#[embassy_executor::task]
pub async fn control(mut cl: ControlLoop) -> ! {
    let period_us = cl.ctl.spec().period_us;
    let mut timing = LoopTiming::new(cl.cpu_hz, period_us);
    let mut readings = Readings::default();
    let mut out = PeriodOutput::default();
    let mut ticker = Ticker::every(Duration::from_micros(period_us as u64));
    align(&mut ticker, period_us);
    let mut skipped = 0u32;
    let mut drops = 0u32;
    let mut weights_job: Option<WeightsJob> = None;
    let health_every = (1_000_000 / period_us).max(1);
    let log_every = health_every * 10;
    let mut period: u32 = 0;
    info!("control loop: {} at {=u32} us, policy {}", cl.ctl.spec().name, period_us, cl.ctl.policy());

    // Sends without waiting; a full queue drops the message (counted, and
    // visible to the host as a sequence gap).
    let send = |msg: ToHost, skipped: &mut u32, drops: &mut u32| {
        match TO_HOST.try_send(Outgoing { msg, skipped: *skipped }) {
            Ok(()) => *skipped = 0,
            Err(_) => {
                *skipped += 1;
                *drops += 1;
            }
        }
    };

    loop {
        ticker.next().await;
        // The emulated boards' `--fault hang` (nothing on a real board).
        crate::board::injected_hang();
        let t0 = cl.cycles.cycles();
        period = period.wrapping_add(1);

        // Host commands.
        while let Ok((seq, cmd)) = FROM_HOST.try_receive() {
            if handle_command(&mut cl, seq, &cmd, &mut weights_job).await {
                // A flash operation or a fresh learner stalled the loop: restart the schedule
                // and do not count this period as an overrun.
                align(&mut ticker, period_us);
                readings.last_period_overran = false;
            }
        }

        // Read.
        BUS_REQUESTS.send(BusRequest::Read).await;
        let reply = BUS_REPLIES.receive().await;
        readings.servos = reply.servos;
        let bus_stats = reply.stats;
        readings.encoder = cl.sensors.encoder_count().await;
        readings.contacts = cl.sensors.contacts().await;
        readings.time_ms = Instant::now().as_millis() as u32;

        // Decide.
        let state_before = cl.ctl.state();
        cl.ctl.period(&readings, &cl.cycles, &mut out);

        // Write.
        let rearm = readings.last_period_overran;
        BUS_REQUESTS.send(BusRequest::Write { torque: out.torque, commands: out.commands.clone(), rearm }).await;

        // Time.
        let spent = cl.cycles.cycles().wrapping_sub(t0);
        let overran = timing.period(spent);
        readings.last_period_overran = overran;
        if overran {
            warn!("period {=u32} overran: {=u32} us of {=u32} us", period, timing.last_us, period_us);
        }
        if let Some(c) = out.agent_cycles {
            timing.agent_step(c);
        }

        // Report.
        for t in &out.transitions {
            report_transition(t, &cl.ctl, readings.time_ms).await;
        }
        if state_before != cl.ctl.state() && out.transitions.is_empty() {
            info!("state {} -> {}", state_before, cl.ctl.state());
        }
        if let Some(mut step) = out.step.take() {
            step.loop_us = timing.last_us;
            send(ToHost::Step(step), &mut skipped, &mut drops);
        }
        if let Some(e) = out.episode.take() {
            info!("episode {=u32} ({}): return {=f32}, {=u32} steps", e.index, e.mode, e.total_reward, e.length);
            send_reliable(ToHost::Episode(e)).await;
        }
        // The wear governor moved Δ or α, or an episode ended under it:
        // its budget, parameter and damage rate.
        if let Some(p) = out.policy.take() {
            send_reliable(ToHost::Policy(p)).await;
        }
        if let Some(job) = weights_job.as_mut() {
            if send_weights(&cl.ctl, job) {
                send_reliable(ToHost::Ack(wire::Ack { seq: job.seq })).await;
                weights_job = None;
            }
        }
        if period % health_every == 0 {
            let mut health = wire::Health {
                uptime_ms: readings.time_ms,
                servo_temps_c: Vec::new(),
                min_voltage_dv: 0,
                bus_errors: bus_stats.timeouts + bus_stats.line_errors + bus_stats.stray_packets,
                checksum_errors: bus_stats.checksum_errors,
                timeouts: bus_stats.timeouts,
                trace_drops: 0,
                weight_saturations: 0,
                overruns: timing.overruns,
                max_loop_us: timing.max_us,
                telemetry_drops: drops,
                checkpoint_erases: 0,
                saves_refused: 0,
                table_claimed: 0,
                table_slots: 0,
                claims_refused: 0,
            };
            cl.ctl.health(&mut health);
            send(ToHost::Health(health), &mut skipped, &mut drops);
        }
        if period % log_every == 0 && timing.agent_mean() > 0 {
            info!(
                "agent step: mean {=u32} cycles ({=u32} us), min {=u32}, max {=u32}; loop max {=u32} us, {=u32} overruns",
                timing.agent_mean(),
                timing.us(timing.agent_mean()),
                timing.agent_min,
                timing.agent_max,
                timing.max_us,
                timing.overruns
            );
        }

        WATCHDOG.send(WatchdogRequest::Alive).await;
    }
}

/// Puts the ticker's next tick on the next multiple of the period since
/// boot. The ticks keep that phase, so a control period always starts at
/// k · period: on the emulated boards, where `pada sil`'s plant advances
/// LEO in whole control periods on those same boundaries (as `pada run
/// --board` does on the host), each period reads the robot as the
/// period's step left it. On a real board the phase is arbitrary and this
/// costs nothing.
fn align(ticker: &mut Ticker, period_us: u32) {
    let now = Instant::now().as_micros();
    let last = now - now % period_us as u64;
    // The tick after `last`: the next boundary after now.
    ticker.reset_at(Instant::from_micros(last));
}

/// Sends up to four chunks of a weights read; true when done.
fn send_weights(ctl: &Ctl, job: &mut WeightsJob) -> bool {
    let weights = ctl.weights();
    for _ in 0..4 {
        if job.next >= job.end {
            return true;
        }
        let end = (job.next + wire::WEIGHTS_PER_CHUNK as u32).min(job.end);
        let chunk = wire::WeightsChunk {
            offset: job.next,
            total: weights.len() as u32,
            weights: (job.next..end).map(|i| weights.get(i as usize).0).collect(),
        };
        if TO_HOST.try_send(Outgoing { msg: ToHost::Weights(chunk), skipped: 0 }).is_err() {
            // The link is busy: the rest next period.
            return false;
        }
        job.next = end;
    }
    job.next >= job.end
}

async fn report_transition(t: &Transition, ctl: &Ctl, time_ms: u32) {
    let step = ctl.agent_stats().steps as u32;
    info!("state {} -> {}", t.from, t.to);
    send_reliable(ToHost::State(wire::StateChange { step, from: t.from, to: t.to })).await;
    if let Some(cause) = t.entered_fault() {
        warn!("FAULT: {} — torque off", cause);
        send_reliable(ToHost::Fault(wire::Fault { step, time_ms, cause })).await;
    }
}

/// Carries out one host command; true if it stalled the loop (a flash
/// operation, or a fresh learner on a large table).
async fn handle_command(cl: &mut ControlLoop, seq: u32, cmd: &ToChip, job: &mut Option<WeightsJob>) -> bool {
    let ack = |r: Result<(), NackReason>| match r {
        Ok(()) => ToHost::Ack(wire::Ack { seq }),
        Err(reason) => ToHost::Nack(wire::Nack { seq, reason }),
    };
    let mut stalled = false;
    let result = match *cmd {
        ToChip::Ping => {
            send_reliable(ToHost::Hello(cl.ctl.hello())).await;
            send_reliable(ToHost::Policy(cl.ctl.policy_report())).await;
            Ok(())
        }
        ToChip::SaveCheckpoint => {
            if cl.ctl.torque_enabled() {
                Err(NackReason::Busy)
            } else if cl.ctl.host_keeps_checkpoint(cl.flash.capacity()) {
                // No flash slot holds it: streamed to the host, which keeps
                // it (crate::host_kept). The loop stood still meanwhile.
                stalled = true;
                match crate::host_kept::save_to_host(&mut cl.ctl).await {
                    Ok(report) => {
                        send_reliable(ToHost::Checkpoint(report)).await;
                        Ok(())
                    }
                    Err(reason) => Err(reason),
                }
            } else {
                // It fits a slot (the branch above): an erase stalls the loop.
                stalled = true;
                match with_long_watchdog(|| cl.ctl.save_checkpoint(&mut cl.flash)).await {
                    Ok(saved) => {
                        info!("checkpoint saved: generation {=u32}, slot {=u8}", saved.generation, saved.slot);
                        send_reliable(ToHost::Checkpoint(wire::CheckpointReport::Saved(saved))).await;
                        Ok(())
                    }
                    Err(CheckpointError::Busy) => Err(NackReason::Busy),
                    Err(CheckpointError::Save(SaveError::Wear(refusal))) => {
                        warn!("checkpoint save refused to spare the flash: {}", refusal);
                        send_reliable(ToHost::Checkpoint(wire::CheckpointReport::SaveFailed)).await;
                        Err(NackReason::FlashWear)
                    }
                    Err(CheckpointError::Save(SaveError::TooLarge { needed, capacity })) => {
                        warn!(
                            "checkpoint save refused ({=u32} failed since boot): it needs {=usize} bytes, a flash slot holds {=usize}",
                            cl.ctl.saves_failed(),
                            needed,
                            capacity
                        );
                        let report = wire::CheckpointReport::TooLarge { needed: needed as u32, capacity: capacity as u32 };
                        send_reliable(ToHost::Checkpoint(report)).await;
                        Err(NackReason::CheckpointFailed)
                    }
                    Err(e) => {
                        warn!("checkpoint save failed ({=u32} since boot): {}", cl.ctl.saves_failed(), defmt::Debug2Format(&e));
                        send_reliable(ToHost::Checkpoint(wire::CheckpointReport::SaveFailed)).await;
                        Err(NackReason::CheckpointFailed)
                    }
                }
            }
        }
        ToChip::LoadCheckpoint => match cl.ctl.load_checkpoint(&cl.flash) {
            Ok(outcome) => {
                log_load(&cl.ctl, outcome);
                send_reliable(ToHost::Checkpoint(wire::CheckpointReport::Load(outcome))).await;
                if let LoadOutcome::Loaded { .. } = outcome {
                    send_reliable(ToHost::Policy(cl.ctl.policy_report())).await;
                }
                match outcome {
                    LoadOutcome::Loaded { .. } => Ok(()),
                    _ => Err(NackReason::CheckpointFailed),
                }
            }
            Err(CheckpointError::Busy) => Err(NackReason::Busy),
            Err(e) => {
                warn!("checkpoint unreadable: {}", defmt::Debug2Format(&e));
                Err(NackReason::CheckpointFailed)
            }
        },
        ToChip::ReadWeights { offset, count } => {
            let total = cl.ctl.weights().len() as u32;
            match offset.checked_add(count) {
                Some(end) if end <= total => {
                    // Acknowledged once the last chunk is queued.
                    *job = Some(WeightsJob { seq, next: offset, end });
                    return false;
                }
                _ => Err(NackReason::OutOfRange),
            }
        }
        _ => {
            // A new policy starts a fresh learner: every weight is written
            // and the table's checksum recomputed. On the F429's 8 MiB LEO
            // table that is 2^21 SDRAM writes and reads, about 0.7 s at
            // 180 MHz by the estimate in firmware/README.md — longer than
            // the watchdog's normal 250 ms. The controller allows it only
            // with torque off, so the pause harms nothing; the schedule
            // restarts after it, as after a flash operation.
            let rebuilds = matches!(cmd, ToChip::SetPolicy(_)) && !cl.ctl.torque_enabled();
            // An X-series servo's alert holds its torque off until a REBOOT:
            // clearing a fault reboots the servos that alerted (the fault
            // may name the alert, or the silence of a servo refused at its
            // set-up for one).
            let reboots = matches!(cmd, ToChip::ClearFault) && matches!(cl.ctl.state(), State::Fault(_));
            let (result, transition) = if rebuilds {
                stalled = true;
                with_long_watchdog(|| cl.ctl.command(cmd)).await
            } else {
                cl.ctl.command(cmd)
            };
            if let Some(t) = transition.filter(|t| t.changed()) {
                report_transition(&t, &cl.ctl, Instant::now().as_millis() as u32).await;
            }
            if reboots && result.is_ok() {
                BUS_REQUESTS.send(BusRequest::RebootAlerted).await;
            }
            let changes_policy = matches!(cmd, ToChip::SetPolicy(_) | ToChip::SwitchToSarsa | ToChip::SetMtbfBudget(_));
            if changes_policy && result.is_ok() {
                send_reliable(ToHost::Policy(cl.ctl.policy_report())).await;
            }
            result
        }
    };
    send_reliable(ack(result)).await;
    stalled
}

/// Runs a long operation (flash, a fresh learner) with the watchdog's long
/// timeout.
async fn with_long_watchdog<T>(op: impl FnOnce() -> T) -> T {
    set_long_watchdog(true).await;
    let result = op();
    set_long_watchdog(false).await;
    result
}

/// What a load found, in the log.
fn log_load(ctl: &Ctl, outcome: LoadOutcome) {
    match outcome {
        LoadOutcome::Loaded { generation, slot } => {
            let stats = ctl.agent_stats();
            info!(
                "checkpoint loaded: generation {=u32} from slot {=u8}; {=u32} episodes, {=u64} agent steps, policy {}",
                generation,
                slot,
                stats.episodes,
                stats.steps,
                ctl.policy()
            );
        }
        LoadOutcome::NoCheckpoint => info!("no checkpoint in flash; fresh learner"),
        LoadOutcome::InvalidState => match ctl.last_refusal() {
            Some(e) => warn!(
                "checkpoint ignored ({=u32} refused since boot): learner state {} out of range, valid is {}",
                ctl.checkpoints_refused(),
                e.param,
                e.valid
            ),
            None => warn!("checkpoint ignored ({=u32} refused since boot): learner state unreadable", ctl.checkpoints_refused()),
        },
        outcome => warn!("checkpoint ignored ({=u32} refused since boot): {}", ctl.checkpoints_refused(), outcome),
    }
}

/// Loads the checkpoint (weights and learner state) at boot and tells the
/// host what happened: a `Checkpoint` report when loaded, a `Warning` when
/// one was found but ignored.
pub async fn boot_checkpoint(ctl: &mut Ctl, flash: &FlashStore) {
    match ctl.load_checkpoint(flash) {
        Ok(outcome) => {
            log_load(ctl, outcome);
            match outcome {
                LoadOutcome::Loaded { .. } => {
                    send_reliable(ToHost::Checkpoint(wire::CheckpointReport::Load(outcome))).await
                }
                LoadOutcome::NoCheckpoint => {}
                _ => send_reliable(ToHost::Warning(wire::Warning::CheckpointIgnored(outcome))).await,
            }
        }
        Err(e) => warn!("checkpoint unreadable: {}", defmt::Debug2Format(&e)),
    }
}
