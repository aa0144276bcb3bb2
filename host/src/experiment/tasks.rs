//! The tasks the command line knows, by name. A new task adds a variant
//! to [`TaskName`] (in the registry, [`crate::robots`]) and an arm in
//! [`visit_task`]; everything else is generic.

use crate::experiment::task::Task;
use crate::leo::rl::LeoTask;
use crate::pendulum::{PhysicalPendulumTask, SimulatedPendulumTask};

/// A task name on the command line (the registry's, [`crate::robots`]).
pub use crate::robots::TaskName;

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
