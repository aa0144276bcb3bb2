//! `pada run --plant` and `--plant-ranges`: learning on a plant that is
//! not the model ([`pada_sim::variation`]), and the ranges it is drawn in.

use crate::error::{usage, CliError};
use crate::experiment::tasks::TaskName;
use pada_sim::variation::{physical_pendulum_ranges, simulated_pendulum_ranges, PlantRanges, Redraw};

/// When the plant of `pada run --plant` is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PlantMode {
    /// Once per trial within the ranges: each trial's robot differs from
    /// the model its own way.
    Drawn,
    /// Anew every episode (domain randomisation, for pretraining).
    Randomised,
}

impl PlantMode {
    /// The simulator's redraw.
    pub fn redraw(self) -> Redraw {
        match self {
            PlantMode::Drawn => Redraw::PerTrial,
            PlantMode::Randomised => Redraw::PerEpisode,
        }
    }
}

/// The ranges of a built-in task, or why it has none.
pub fn task_ranges(task: TaskName) -> Result<PlantRanges, CliError> {
    match task {
        TaskName::Pendulum => Ok(simulated_pendulum_ranges()),
        TaskName::PhysicalPendulum => Ok(physical_pendulum_ranges()),
        TaskName::Leo => Err(usage(
            "--plant varies the pendulums and robots of files (--robot robot.toml); LEO's model has no differing plant yet",
        )),
    }
}

/// `base` with `--plant-ranges` over it, checked.
pub fn with_ranges_arg(base: PlantRanges, arg: Option<&str>) -> Result<PlantRanges, CliError> {
    match arg {
        Some(a) => base.with_arg(a).map_err(|e| usage(format!("--plant-ranges: {e}"))),
        None => Ok(base),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_of_the_command_line_go_over_the_tasks_and_errors_name_the_flag() {
        let r = with_ranges_arg(task_ranges(TaskName::PhysicalPendulum).unwrap(), Some("mass=1.2")).unwrap();
        assert_eq!(r.mass.lo, 1.2);
        assert_eq!(r.motor_constant, physical_pendulum_ranges().motor_constant);
        let e = with_ranges_arg(PlantRanges::MODEL, Some("mass=7")).unwrap_err().to_string();
        assert!(e.contains("--plant-ranges") && e.contains("valid is 0.2 to 5"), "{e}");
        assert!(task_ranges(TaskName::Leo).is_err());
    }
}
