//! The host-only run to compare a SIL run with: the firmware's own
//! controller (`pada_firmware::control::Controller`, the code inside the
//! QEMU image) driven directly on the host against the same plant model,
//! with the same run protocol (first test episode, learning, a test after
//! every tenth learning episode, final test).
//!
//! Only the bus is idealised: the servo and the encoder are read at fixed
//! offsets into the period and the voltage applies at a fixed offset,
//! close to what the emulated 1 Mbps bus gives ([`READ_AT_US`],
//! [`DRIVE_AT_US`]). The twin therefore learns like the firmware does —
//! with the chip's 64 KiB hashed weight table and the rate differenced from
//! encoder counts — and shows what the emulation itself adds: nothing but
//! bus timing. Several seeds give the spread of the configuration.

use crate::rig::{PendulumRig, Rig, SUPPLY_V};
use super::run::TestPoint;
use crate::experiment::{end_performance, rise_time};
use crate::pendulum::PhysicalPendulumParams;
use pada_core::dynamixel::table;
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::wire::{RunMode, ToChip};
use pada_core::profile::Board;
use pada_firmware::config::Robot;
use pada_firmware::control::{Controller, PeriodOutput, Readings};
use pada_firmware::pendulum::Pendulum33;
use pada_firmware::io::CycleCounter;
use rayon::prelude::*;
use serde::Serialize;

/// When the readings are taken, after the period's tick \[µs\] (the servo's
/// answer and the sensor device's, on the emulated bus: about 0.27 and
/// 0.49 ms).
pub const READ_AT_US: u64 = 400;
/// When the new voltage applies \[µs\] (after the SYNC_WRITE, about 0.6 ms).
pub const DRIVE_AT_US: u64 = 600;

/// One twin run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TwinRun {
    /// The agent's seed.
    pub seed: u64,
    /// Return of the first test episode.
    pub first_test_return: Option<f64>,
    /// Mean of the last 10 % of test returns.
    pub end_performance: Option<f64>,
    /// Rise time \[s of learning\].
    pub rise_time_s: Option<f64>,
    /// The learning curve.
    #[serde(skip)]
    pub curve: Vec<TestPoint>,
}

/// Twin runs over several seeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TwinReport {
    /// What the twin is.
    pub what: &'static str,
    /// One per seed; the first has the SIL run's seed.
    pub runs: Vec<TwinRun>,
    /// Mean end performance over the seeds.
    pub end_performance_mean: Option<f64>,
    /// Lowest.
    pub end_performance_min: Option<f64>,
    /// Highest.
    pub end_performance_max: Option<f64>,
}

fn start(ctl: &mut Controller<Box<[Q16]>, Pendulum33>, mode: RunMode) -> anyhow::Result<()> {
    ctl.command(&ToChip::Start(mode))
        .0
        .map_err(|e| anyhow::anyhow!("Start refused: {e:?}"))
}

struct NoCycles;

impl CycleCounter for NoCycles {
    fn cycles(&self) -> u32 {
        0
    }
}

/// The firmware's pendulum controller with `policy` and `seed` on the host,
/// to `seconds` of learning.
pub fn twin_run(policy: PolicyKind, seed: u64, seconds: f64) -> anyhow::Result<TwinRun> {
    let profile = Board::F405.profile(Robot::Pendulum33);
    let period = Robot::Pendulum33.spec().period_us as u64;
    let weights = profile.weights().unwrap_or(0);
    let mut ctl = Controller::<_, Pendulum33>::new(
        profile,
        PolicyKind::Sarsa,
        vec![Q16::ZERO; weights].into_boxed_slice(),
        seed,
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    // As the SIL run: SetPolicy (a fresh learner from the seed), first test.
    ctl.set_policy(policy)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    start(&mut ctl, RunMode::Testing)?;
    let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
    let mut out = PeriodOutput::default();
    let mut learning_steps = 0u64;
    let mut curve = Vec::new();
    let mut phase = 0;
    let limit = ((seconds * 4.0 + 120.0) * 1e6) as u64;
    let mut t = 0u64;
    while t < limit {
        t += period;
        let mut r = Readings {
            time_ms: (t / 1000) as u32,
            ..Readings::default()
        };
        r.servos[0].state = Some(rig.present(t + READ_AT_US, 1));
        r.encoder = Some(rig.sensors(t + READ_AT_US).0);
        ctl.period(&r, &NoCycles, &mut out);
        if let Some(&(id, speed)) = out.speeds.first() {
            let volts = table::ratio_from_moving_speed(speed) as f64 * SUPPLY_V;
            rig.drive(t + DRIVE_AT_US, id, out.torque, volts);
        }
        let Some(e) = out.episode else { continue };
        let learning_s = learning_steps as f64 * period as f64 * 1e-6;
        if e.mode == RunMode::Learning {
            learning_steps += e.length as u64;
        } else {
            curve.push(TestPoint {
                learning_time_s: learning_s,
                test_return: e.total_reward as f64,
            });
        }
        let learning_s = learning_steps as f64 * period as f64 * 1e-6;
        match phase {
            0 if e.mode == RunMode::Testing => {
                phase = 1;
                start(&mut ctl, RunMode::Learning)?;
            }
            1 if e.mode == RunMode::Learning && learning_s >= seconds - 1e-9 => {
                phase = 2;
                start(&mut ctl, RunMode::Testing)?;
            }
            2 if e.mode == RunMode::Testing => break,
            _ => {}
        }
    }
    let returns: Vec<f64> = curve.iter().map(|p| p.test_return).collect();
    let times: Vec<f64> = curve.iter().map(|p| p.learning_time_s).collect();
    Ok(TwinRun {
        seed,
        first_test_return: returns.first().copied(),
        end_performance: end_performance(&returns),
        rise_time_s: rise_time(&times, &returns),
        curve,
    })
}

/// Twin runs with `seed` and `extra` more seeds (`seed + 1 …`), in parallel.
pub fn twin(policy: PolicyKind, seed: u64, extra: u64, seconds: f64) -> anyhow::Result<TwinReport> {
    let runs = (0..=extra)
        .into_par_iter()
        .map(|k| twin_run(policy, seed.wrapping_add(k), seconds))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let ends: Vec<f64> = runs.iter().filter_map(|r| r.end_performance).collect();
    let n = ends.len() as f64;
    Ok(TwinReport {
        what:
            "the firmware's controller on the host against the same pendulum model, bus idealised",
        end_performance_mean: (n > 0.0).then(|| ends.iter().sum::<f64>() / n),
        end_performance_min: ends.iter().copied().reduce(f64::min),
        end_performance_max: ends.iter().copied().reduce(f64::max),
        runs,
    })
}
