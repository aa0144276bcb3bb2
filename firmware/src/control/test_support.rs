//! What the controller's tests share: a cycle counter, the F405's
//! learners and tables, healthy readings, starting and stopping, and the
//! crude pendulum that the replay and checkpoint tests run.

use super::*;
use crate::config::Board;
use crate::io::CycleCounter;
pub(super) use pada_core::robot::leo::{self, Leo};
pub(super) use pada_core::robot::pendulum::{Pendulum, SPEC_20HZ, SPEC_33HZ};
use pada_core::robot::RobotSpec;
use core::cell::Cell;
use core::f32::consts::PI;
use pada_core::checkpoint;
use pada_core::dynamixel::table::PresentState;
use pada_core::fixed::Q16;
use pada_core::robot::pendulum::EXACT_WEIGHTS as WEIGHTS;
use pada_core::safety::RunMode;
use pada_core::wire;

/// A cycle counter that advances 1000 cycles at every read.
pub(super) struct Clock(pub(super) Cell<u32>);

impl CycleCounter for Clock {
    fn cycles(&self) -> u32 {
        let c = self.0.get();
        self.0.set(c + 1000);
        c
    }
}

/// The F405's learner for `robot`.
pub(super) fn profile(robot: &'static RobotSpec) -> LearnerProfile {
    Board::F405.profile(robot).unwrap()
}

/// The F405's pendulum table (exact).
pub(super) fn table() -> Box<[Q16]> {
    vec![Q16::ZERO; WEIGHTS].into_boxed_slice()
}

/// A chip's LEO table on the heap: a claim table of 16-bit weights and
/// 16-bit tags (as `crate::table` lays it out in CCM or SDRAM).
pub(super) type LeoTable = pada_core::claim_table::ClaimTable<
    pada_core::weights::Half<Box<[i16]>, { pada_core::robot::leo::HALF_SHIFT as u32 }>,
    pada_core::claim_table::Tags16<Box<[u16]>>,
>;

/// A chip's LEO claim table of `n` slots.
pub(super) fn leo_table_of(n: usize) -> LeoTable {
    let weights = pada_core::weights::Half::new(vec![0i16; n].into_boxed_slice());
    pada_core::claim_table::ClaimTable::new(weights, pada_core::claim_table::Tags16(vec![0u16; n].into_boxed_slice()))
        .unwrap()
}

/// LEO's claim table in the F405's CCM alone (2^14 slots of 16-bit weight
/// and tag, 64 KiB): a table whose checkpoint fits a 128 KiB flash sector.
pub(super) fn ccm_leo_profile() -> LearnerProfile {
    let p = profile(&leo::SPEC);
    p.with_hashed_table(pada_core::tile_coding::Layout::Claimed, 14, p.format, 2)
}

/// The F405's LEO table: 2^15 hashed 16-bit weights (as `crate::table`
/// lays them out in CCM).
pub(super) fn leo_table() -> pada_core::weights::Half<Box<[i16]>, { pada_core::robot::leo::HALF_SHIFT as u32 }> {
    pada_core::weights::Half::new(vec![0i16; profile(&leo::SPEC).weights().unwrap()].into_boxed_slice())
}

/// A healthy pendulum reading: the servo answers, the encoder at `counts`.
pub(super) fn pendulum_readings(counts: u16, time_ms: u32) -> Readings {
    let mut r = Readings { encoder: Some(counts), time_ms, ..Readings::default() };
    r.servos[0].state = Some(PresentState { position: 512, speed: 0, load: 0, voltage: 120, temperature: 35 }.into());
    r
}

pub(super) fn start<W: pada_core::weights::WeightStore, R: RobotRules>(c: &mut Controller<W, R>, mode: RunMode) {
    let (result, t) = c.command(&wire::ToChip::Start(mode));
    assert_eq!(result, Ok(()));
    assert!(t.unwrap().torque_enable);
}

// -----------------------------------------------------------------------
// Saved learning
// -----------------------------------------------------------------------

pub(super) type Store = pada_core::checkpoint::RamStore<{ checkpoint::slot_len(WEIGHTS, 4) }>;

/// `periods` periods of the crude pendulum of the replay test, from
/// period `k0`; the Step records.
pub(super) fn run_pendulum(c: &mut Controller<Box<[Q16]>, Pendulum>, angle: &mut f32, k0: u32, periods: u32) -> std::vec::Vec<wire::Step> {
    let clock = Clock(Cell::new(0));
    let mut out = PeriodOutput::default();
    let mut steps = std::vec::Vec::new();
    for k in k0..k0 + periods {
        let counts = (*angle / (2.0 * PI) * 4096.0).round() as i64;
        c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
        if let Some(s) = out.step.take() {
            steps.push(s);
        }
        let u = c.applied[0];
        *angle += 0.02 * u - 0.05 * libm::sinf(*angle);
    }
    steps
}

pub(super) fn stop(c: &mut Controller<Box<[Q16]>, Pendulum>) {
    assert_eq!(c.command(&wire::ToChip::Stop).0, Ok(()));
    let mut out = PeriodOutput::default();
    c.period(&pendulum_readings(0, 0), &Clock(Cell::new(0)), &mut out);
    assert!(!out.torque);
}

// -----------------------------------------------------------------------
// Learning on a wear budget
// -----------------------------------------------------------------------

/// The budget the governed tests hold: on the crude pendulum of
/// `run_pendulum`, tight enough that the governor moves Δ both ways.
pub(super) const TEST_BUDGET_S: f32 = 2.0e8;

/// A governed run's records in the order the board sends them.
pub(super) enum Sent {
    Step(wire::Step),
    Policy(wire::PolicyReport),
}

pub(super) fn run_governed(c: &mut Controller<Box<[Q16]>, Pendulum>, angle: &mut f32, periods: u32) -> std::vec::Vec<Sent> {
    let clock = Clock(Cell::new(0));
    let mut out = PeriodOutput::default();
    let mut sent = std::vec::Vec::new();
    for k in 0..periods {
        let counts = (*angle / (2.0 * PI) * 4096.0).round() as i64;
        c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
        if let Some(s) = out.step.take() {
            sent.push(Sent::Step(s));
        }
        if let Some(p) = out.policy.take() {
            sent.push(Sent::Policy(p));
        }
        let u = c.applied[0];
        *angle += 0.02 * u - 0.05 * libm::sinf(*angle);
    }
    sent
}
