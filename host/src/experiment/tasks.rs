//! The tasks the command line knows, by name. A new task (LEO) adds a
//! variant here and an arm in [`visit_task`]; everything else is generic.

use crate::experiment::task::Task;
use crate::leo::rl::LeoTask;
use crate::pendulum::{PhysicalPendulumTask, SimulatedPendulumTask};
use std::fmt;

/// A task name on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TaskName {
    /// The simulated inverted pendulum of Section VII.
    Pendulum,
    /// The model of the physical pendulum of the paper's experiment.
    PhysicalPendulum,
    /// The LEO biped walking (Section VIII).
    Leo,
}

impl fmt::Display for TaskName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TaskName::Pendulum => "pendulum",
            TaskName::PhysicalPendulum => "physical-pendulum",
            TaskName::Leo => "leo",
        })
    }
}

/// Something done with a task of any type (a generic closure).
pub trait TaskVisitor {
    /// The result.
    type Output;
    /// Does it with `task`.
    fn visit<T: Task>(self, task: &T) -> Self::Output;
}

/// Builds the named task with its default constants and hands it to `v`.
pub fn visit_task<V: TaskVisitor>(name: TaskName, v: V) -> V::Output {
    match name {
        TaskName::Pendulum => v.visit(&SimulatedPendulumTask::default()),
        TaskName::PhysicalPendulum => v.visit(&PhysicalPendulumTask::default()),
        TaskName::Leo => v.visit(&LeoTask::default()),
    }
}
