//! A fault's cause as one line for a person: the servo or joint it
//! concerns, and what usually causes it. `pada drive` ends a run with it,
//! and `pada run --board` a trial.

/// A fault's line: the cause with the servo or joint it concerns.
pub fn fault_line(cause: &pada_core::safety::FaultCause, spec: &pada_core::robot::RobotSpec) -> String {
    use pada_core::safety::FaultCause as F;
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
