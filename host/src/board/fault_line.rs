//! A fault's cause as one line for a person: the servo or joint it
//! concerns, and what usually causes it. `pada drive` ends a run with it,
//! and `pada run --board` a trial; `pada run` on the host ends a trial
//! with the same words where its simulation meets a soft limit
//! ([`fault_explained`]), so a run on the host and one of the board tell
//! the same event alike.

use pada_core::episodes::EpisodeAt;
use pada_core::robot::RobotSpec;
use pada_core::safety::FaultCause;
use pada_core::wire::RunMode;

/// A fault's line: the cause with the servo or joint it concerns.
pub fn fault_line(cause: &FaultCause, spec: &RobotSpec) -> String {
    use FaultCause as F;
    let joint_of = |id: u8| spec.joints.iter().find(|j| j.id == id).map_or("?", |j| j.name);
    match *cause {
        F::ServoTimeout { servo, attempts } => {
            format!("servo {servo} ({}) did not answer {attempts} requests in a row (unplugged? no power?)", joint_of(servo))
        }
        F::ChecksumErrors { count, window_ms } => {
            format!("{count} damaged answers within {window_ms} ms: noise on the bus, a loose cable, or two servos at one ID")
        }
        F::ServoError { servo, error } => format!("servo {servo} ({}) reported {:?}", joint_of(servo), error.names().collect::<Vec<_>>()),
        F::HardwareAlert { servo, error } => format!(
            "servo {servo} ({}) raised a hardware alert: {:?} (Hardware Error Status {}); only a REBOOT clears it: `pada servos --reboot {servo} --port PORT` once the cause is gone",
            joint_of(servo),
            error.names().collect::<Vec<_>>(),
            error.0
        ),
        F::SoftLimit { joint, position } => {
            let j = spec.joints.get(joint as usize);
            let limits = j.and_then(|j| j.soft_limit).map_or(String::new(), |l| format!(" [{}, {}] rad", l.min, l.max));
            format!("joint {joint} ({}) at {position:.3} rad, past its soft limit{limits}", j.map_or("?", |j| j.name))
        }
        F::OverrunStreak { count } => format!("{count} control periods overran in a row: the PC is too slow or too loaded for the period"),
        F::WatchdogReset => "the watchdog reset the board".to_string(),
    }
}

/// Who faulted: the board's controller, or the host's simulation of the
/// robot under its board's safety rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Faulted {
    /// `pada run --board`: the firmware's controller on the host.
    Board,
    /// `pada run`: the simulated robot.
    Simulation,
}

/// What a fault `t_us` into a run means, where in the run it came
/// (`episode`: the episode in progress), and what to change: the same
/// words for the board and the host's simulation, which stop at the same
/// reading (`RobotSpec::soft_limit_fault`).
pub fn fault_explained(spec: &RobotSpec, cause: FaultCause, t_us: u64, episode: Option<EpisodeAt>, who: Faulted) -> String {
    let line = fault_line(&cause, spec);
    let when = match episode {
        Some(e) => {
            let mode = match e.mode {
                RunMode::Learning => "learning",
                RunMode::Testing => "test",
            };
            format!("at step {} of {mode} episode {}", e.steps + 1, e.index)
        }
        None => "between episodes".to_string(),
    };
    let (subject, waits) = match who {
        Faulted::Board => ("the board", "torque went off, and a board waits there for its operator to clear the fault"),
        Faulted::Simulation => (
            "the simulated robot",
            "its board would switch torque off there and wait for its operator to clear the fault, so the trial ends here as it would there",
        ),
    };
    let at = format!("{subject} faulted {:.2} s into the run, {when} ({}): {line}", t_us as f64 * 1e-6, cause.name());
    match cause {
        FaultCause::SoftLimit { .. } => format!(
            "{at}; {waits}. End an episode before a joint reaches its soft limits \
             (an [[end]] on its angle in robot.toml, inside the limits), or widen the limits if the joint can go further"
        ),
        _ => format!("{at}; {waits}"),
    }
}
