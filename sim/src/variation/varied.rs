//! A task whose plants differ from its model ([`Varied`]): each plant is
//! drawn within the ranges once per trial (a robot that is not its model)
//! or anew every episode (domain randomisation, for pretraining).
//!
//! Reproducible: a plant's draws come from its own generator, seeded by
//! one number of the trial's generator at the trial's first reset, so a
//! seed repeats its plants whichever thread runs the trial.

use super::{PlantDraw, PlantRanges};
use crate::task::{Plant, Step, Task, TaskSpec};
use pada_core::action_space::{Output, MAX_ACTION_DIMS};
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::VecDeque;
use std::sync::Arc;

/// A task that can build its plant with other physical constants.
pub trait Vary: Task + Send + Sync + 'static {
    /// A plant of `draw`'s masses, motor constants and friction, reading
    /// its joints through `draw`'s sensor (noise seeded by `seed`). The
    /// command delay is [`VariedPlant`]'s.
    fn plant_with(&self, draw: &PlantDraw, seed: u64) -> Self::Plant;
}

/// When a [`Varied`] task's plant is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Redraw {
    /// Once per trial: each trial's robot differs from the model its own way.
    PerTrial,
    /// At every episode (domain randomisation).
    PerEpisode,
}

/// `T` on plants drawn within `ranges`.
pub struct Varied<T> {
    task: Arc<T>,
    ranges: PlantRanges,
    redraw: Redraw,
}

impl<T: Vary> Varied<T> {
    /// `task` on plants drawn within `ranges`, `redraw` deciding when.
    pub fn new(task: T, ranges: PlantRanges, redraw: Redraw) -> Varied<T> {
        Varied { task: Arc::new(task), ranges, redraw }
    }

    /// The ranges.
    pub fn ranges(&self) -> &PlantRanges {
        &self.ranges
    }

    /// When plants are drawn.
    pub fn redraw(&self) -> Redraw {
        self.redraw
    }
}

impl<T: Vary> Task for Varied<T> {
    type Plant = VariedPlant<T>;

    fn spec(&self) -> &TaskSpec {
        self.task.spec()
    }

    fn plant(&self) -> VariedPlant<T> {
        VariedPlant {
            task: Arc::clone(&self.task),
            ranges: self.ranges,
            redraw: self.redraw,
            rng: None,
            inner: None,
            draw: PlantDraw::MODEL,
            late: VecDeque::new(),
            applied: [0.0; MAX_ACTION_DIMS],
        }
    }
}

/// A plant of `T` drawn within the ranges, its commands delayed by the
/// drawn number of control periods.
pub struct VariedPlant<T: Vary> {
    task: Arc<T>,
    ranges: PlantRanges,
    redraw: Redraw,
    /// The plant's own generator (seeded at the first reset).
    rng: Option<Pcg64>,
    inner: Option<T::Plant>,
    draw: PlantDraw,
    /// Commands on their way to the motor, oldest first.
    late: VecDeque<Output>,
    /// The command the motor applied in the last step.
    applied: Output,
}

impl<T: Vary> VariedPlant<T> {
    /// The plant drawn for the current episode (the model's before the
    /// first reset).
    pub fn draw(&self) -> &PlantDraw {
        &self.draw
    }
}

impl<T: Vary> Plant for VariedPlant<T> {
    fn reset(&mut self, rng: &mut dyn RngCore, obs: &mut [f32]) {
        let own = self.rng.get_or_insert_with(|| Pcg64::seed_from_u64(rng.next_u64()));
        if self.inner.is_none() || self.redraw == Redraw::PerEpisode {
            self.draw = PlantDraw::draw(&self.ranges, own);
            let seed = own.next_u64();
            self.inner = Some(self.task.plant_with(&self.draw, seed));
        }
        // The commands in flight are dropped with the episode: the motor
        // starts at rest.
        self.late.clear();
        self.late.extend(std::iter::repeat_n([0.0; MAX_ACTION_DIMS], self.draw.delay_periods as usize));
        self.applied = [0.0; MAX_ACTION_DIMS];
        if let Some(p) = self.inner.as_mut() {
            p.reset(rng, obs);
        }
    }

    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step {
        let mut now: Output = [0.0; MAX_ACTION_DIMS];
        let n = command.len().min(MAX_ACTION_DIMS);
        now[..n].copy_from_slice(&command[..n]);
        self.late.push_back(now);
        self.applied = self.late.pop_front().unwrap_or(now);
        let inner = self.inner.as_mut().expect("reset before the first step");
        inner.step(&self.applied[..n], obs)
    }

    fn gearbox_torques(&self, command: &[f32]) -> Output {
        let n = command.len().min(MAX_ACTION_DIMS);
        self.inner.as_ref().map_or([0.0; MAX_ACTION_DIMS], |p| p.gearbox_torques(&self.applied[..n]))
    }

    fn commanded_torques(&self, command: &[f32]) -> Output {
        let n = command.len().min(MAX_ACTION_DIMS);
        self.inner.as_ref().map_or([0.0; MAX_ACTION_DIMS], |p| p.commanded_torques(&self.applied[..n]))
    }

    fn fault(&self) -> Option<pada_core::safety::FaultCause> {
        self.inner.as_ref().and_then(|p| p.fault())
    }

    fn walked_distance_m(&self) -> Option<f64> {
        self.inner.as_ref().and_then(|p| p.walked_distance_m())
    }

    fn footstep(&self) -> bool {
        self.inner.as_ref().is_some_and(|p| p.footstep())
    }
}
