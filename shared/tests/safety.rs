//! The safety state machine: the whole transition table, each fault
//! detector's threshold, and configuration validation.

use pada_core::dynamixel::ErrorFlags;
use pada_core::safety::*;

const LEARN: Command = Command::Start(RunMode::Learning);
const TEST: Command = Command::Start(RunMode::Testing);
const CAUSE: FaultCause = FaultCause::WatchdogReset;

fn config() -> SafetyConfig {
    let mut c = SafetyConfig::default();
    c.soft_limits.push(SoftLimit { min: -1.0, max: 1.0 }).unwrap();
    c
}

/// A machine brought into `state` through the public API.
fn machine_in(state: State) -> Safety {
    let mut s = Safety::new(config()).unwrap();
    match state {
        State::Idle => {}
        State::Learning => {
            s.on(Event::Command(LEARN));
        }
        State::Testing => {
            s.on(Event::Command(TEST));
        }
        State::Paused => {
            s.on(Event::Command(LEARN));
            s.on(Event::Command(Command::Pause));
        }
        State::Fault(_) => {
            s.on(Event::WatchdogReset);
        }
    }
    assert_eq!(s.state(), state);
    s
}

const STATES: [State; 5] = [State::Idle, State::Learning, State::Testing, State::Paused, State::Fault(CAUSE)];
const COMMANDS: [Command; 5] = [LEARN, TEST, Command::Stop, Command::Pause, Command::ClearFault];

/// The expected result of every command in every state: the transition
/// table of the module documentation, written out.
fn expected(state: State, cmd: Command) -> (State, Outcome) {
    use Outcome::*;
    use State::*;
    let changed = |to: State| if to == state { (to, Unchanged) } else { (to, Changed) };
    match (state, cmd) {
        (Fault(_), Command::ClearFault) => (Idle, Changed),
        (Fault(_), _) => (state, Rejected(Rejection::InFault)),
        (_, Command::ClearFault) => (state, Unchanged),
        (Idle, Command::Pause) => (Idle, Rejected(Rejection::NotRunning)),
        (_, Command::Start(RunMode::Learning)) => changed(Learning),
        (_, Command::Start(RunMode::Testing)) => changed(Testing),
        (_, Command::Stop) => changed(Idle),
        (_, Command::Pause) => changed(Paused),
    }
}

#[test]
fn every_command_in_every_state() {
    let mut rows = 0;
    for state in STATES {
        for cmd in COMMANDS {
            let mut s = machine_in(state);
            let t = s.on(Event::Command(cmd));
            let (to, outcome) = expected(state, cmd);
            assert_eq!((t.from, t.to, t.outcome), (state, to, outcome), "{state:?} + {cmd:?}");
            assert_eq!(t.torque_enable, to.torque_enabled());
            assert_eq!(s.state(), to);
            assert_eq!(t.entered_fault(), None, "commands never cause a fault");
            rows += 1;
        }
    }
    assert_eq!(rows, 25);
}

#[test]
fn the_table_spelled_out() {
    // The cases a reader looks for first, independently of `expected`.
    let t = machine_in(State::Idle).on(Event::Command(LEARN));
    assert_eq!((t.to, t.torque_enable), (State::Learning, true));
    let t = machine_in(State::Learning).on(Event::Command(Command::Pause));
    assert_eq!((t.to, t.torque_enable), (State::Paused, false));
    let t = machine_in(State::Paused).on(Event::Command(TEST));
    assert_eq!((t.to, t.torque_enable), (State::Testing, true));
    let t = machine_in(State::Testing).on(Event::Command(Command::Stop));
    assert_eq!((t.to, t.torque_enable), (State::Idle, false));
    let t = machine_in(State::Fault(CAUSE)).on(Event::Command(LEARN));
    assert_eq!((t.to, t.outcome), (State::Fault(CAUSE), Outcome::Rejected(Rejection::InFault)));
    let t = machine_in(State::Fault(CAUSE)).on(Event::Command(Command::ClearFault));
    assert_eq!((t.to, t.torque_enable), (State::Idle, false));
}

#[test]
fn torque_only_while_learning_or_testing() {
    for s in STATES {
        assert_eq!(s.torque_enabled(), matches!(s, State::Learning | State::Testing), "{s:?}");
    }
}

/// One fault-causing event sequence per cause.
fn fault_scenarios() -> Vec<(Vec<Event>, FaultCause)> {
    let cfg = config();
    let timeouts = vec![Event::ServoTimeout { servo: 3 }; cfg.servo_retry_budget as usize + 1];
    let checksums =
        (0..cfg.checksum_threshold as u32).map(|i| Event::ChecksumError { at_ms: 100 + i * 10 }).collect();
    let overruns = vec![Event::LoopTiming { overrun: true }; cfg.overrun_streak as usize];
    vec![
        (timeouts, FaultCause::ServoTimeout { servo: 3, attempts: cfg.servo_retry_budget + 1 }),
        (checksums, FaultCause::ChecksumErrors { count: cfg.checksum_threshold, window_ms: cfg.checksum_window_ms }),
        (
            vec![Event::ServoStatus { servo: 2, error: ErrorFlags::OVERHEATING, at_ms: 0 }],
            FaultCause::ServoError { servo: 2, error: ErrorFlags::OVERHEATING },
        ),
        (
            vec![Event::ServoStatus { servo: 2, error: ErrorFlags::OVERLOAD | ErrorFlags::RANGE, at_ms: 0 }],
            FaultCause::ServoError { servo: 2, error: ErrorFlags::OVERLOAD | ErrorFlags::RANGE },
        ),
        (
            vec![Event::ServoStatus { servo: 9, error: ErrorFlags::INPUT_VOLTAGE, at_ms: 0 }],
            FaultCause::ServoError { servo: 9, error: ErrorFlags::INPUT_VOLTAGE },
        ),
        (
            vec![Event::JointPosition { joint: 0, position: 1.5 }],
            FaultCause::SoftLimit { joint: 0, position: 1.5 },
        ),
        (overruns, FaultCause::OverrunStreak { count: cfg.overrun_streak }),
        (vec![Event::WatchdogReset], FaultCause::WatchdogReset),
    ]
}

#[test]
fn every_fault_from_every_non_fault_state_turns_torque_off() {
    for state in [State::Idle, State::Learning, State::Testing, State::Paused] {
        for (events, cause) in fault_scenarios() {
            let mut s = machine_in(state);
            let (last, before) = events.split_last().unwrap();
            for e in before {
                let t = s.on(*e);
                assert_eq!((t.to, t.outcome), (state, Outcome::Unchanged), "{state:?}: {e:?} below threshold");
            }
            let t = s.on(*last);
            assert_eq!(t.from, state);
            assert_eq!(t.to, State::Fault(cause), "{state:?}: {cause:?}");
            assert_eq!(t.outcome, Outcome::Changed);
            assert!(!t.torque_enable);
            assert_eq!(t.entered_fault(), Some(cause));
        }
    }
}

#[test]
fn in_fault_the_first_cause_is_kept() {
    for (events, _) in fault_scenarios() {
        let mut s = machine_in(State::Fault(CAUSE));
        for e in events {
            let t = s.on(e);
            assert_eq!((t.to, t.outcome, t.torque_enable), (State::Fault(CAUSE), Outcome::Unchanged, false));
            assert_eq!(t.entered_fault(), None);
        }
    }
}

#[test]
fn observations_below_thresholds_change_nothing() {
    for state in [State::Idle, State::Learning, State::Testing, State::Paused] {
        let mut s = machine_in(state);
        let events = [
            Event::ServoReply { servo: 1 },
            Event::ServoStatus { servo: 1, error: ErrorFlags::NONE, at_ms: 0 },
            Event::ServoStatus { servo: 1, error: ErrorFlags::RANGE | ErrorFlags::ANGLE_LIMIT, at_ms: 0 },
            Event::ServoStatus { servo: 1, error: ErrorFlags::INSTRUCTION, at_ms: 0 },
            Event::JointPosition { joint: 0, position: 1.0 },
            Event::JointPosition { joint: 0, position: -1.0 },
            Event::JointPosition { joint: 5, position: 100.0 }, // no limit for joint 5
            Event::LoopTiming { overrun: false },
            Event::ChecksumError { at_ms: 0 },
            Event::ServoTimeout { servo: 1 },
        ];
        for e in events {
            let t = s.on(e);
            assert_eq!((t.to, t.outcome), (state, Outcome::Unchanged), "{e:?}");
            assert_eq!(t.torque_enable, state.torque_enabled());
        }
    }
}

#[test]
fn servo_timeouts_count_consecutively_per_servo() {
    let mut s = machine_in(State::Learning);
    // Budget 2: three timeouts in a row fault, a reply in between resets.
    for _ in 0..10 {
        s.on(Event::ServoTimeout { servo: 1 });
        s.on(Event::ServoTimeout { servo: 1 });
        s.on(Event::ServoReply { servo: 1 });
        s.on(Event::ServoTimeout { servo: 2 });
        s.on(Event::ServoTimeout { servo: 2 });
        s.on(Event::ServoStatus { servo: 2, error: ErrorFlags::NONE, at_ms: 0 });
    }
    assert_eq!(s.state(), State::Learning);
    s.on(Event::ServoTimeout { servo: 1 });
    s.on(Event::ServoTimeout { servo: 2 });
    s.on(Event::ServoTimeout { servo: 1 });
    assert_eq!(s.consecutive_timeouts(1), 2);
    let t = s.on(Event::ServoTimeout { servo: 1 });
    assert_eq!(t.entered_fault(), Some(FaultCause::ServoTimeout { servo: 1, attempts: 3 }));
}

#[test]
fn checksum_errors_fault_only_within_the_window() {
    let mut s = machine_in(State::Learning);
    // 5 per 1000 ms: errors 300 ms apart never make 5 within a second.
    for i in 0..50u32 {
        let t = s.on(Event::ChecksumError { at_ms: i * 300 });
        assert_eq!(t.to, State::Learning, "error {i}");
    }
    // Four close together after that, plus the servo's own CHECKSUM bit.
    for i in 0..4u32 {
        assert_eq!(s.on(Event::ChecksumError { at_ms: 20_000 + i }).to, State::Learning);
    }
    let t = s.on(Event::ServoStatus { servo: 4, error: ErrorFlags::CHECKSUM, at_ms: 20_010 });
    assert_eq!(t.entered_fault(), Some(FaultCause::ChecksumErrors { count: 5, window_ms: 1000 }));
}

#[test]
fn checksum_window_survives_clock_wrap() {
    let mut s = machine_in(State::Testing);
    for i in 0..5u32 {
        s.on(Event::ChecksumError { at_ms: (u32::MAX - 2).wrapping_add(i) });
    }
    assert!(matches!(s.state(), State::Fault(FaultCause::ChecksumErrors { .. })));
}

#[test]
fn overrun_streak_resets_on_time() {
    let mut s = machine_in(State::Learning);
    for _ in 0..20 {
        s.on(Event::LoopTiming { overrun: true });
        s.on(Event::LoopTiming { overrun: true });
        s.on(Event::LoopTiming { overrun: false });
    }
    assert_eq!(s.state(), State::Learning);
    assert_eq!(s.overrun_streak(), 0);
}

#[test]
fn non_finite_positions_are_out_of_limits() {
    for p in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0001] {
        let mut s = machine_in(State::Learning);
        let t = s.on(Event::JointPosition { joint: 0, position: p });
        assert!(matches!(t.entered_fault(), Some(FaultCause::SoftLimit { joint: 0, .. })), "{p}");
    }
}

#[test]
fn clear_fault_resets_the_counters() {
    let mut s = machine_in(State::Learning);
    s.on(Event::ServoTimeout { servo: 1 });
    s.on(Event::ServoTimeout { servo: 1 });
    s.on(Event::LoopTiming { overrun: true });
    s.on(Event::LoopTiming { overrun: true });
    for i in 0..4 {
        s.on(Event::ChecksumError { at_ms: i });
    }
    s.on(Event::WatchdogReset);
    s.on(Event::Command(Command::ClearFault));
    assert_eq!(s.state(), State::Idle);
    s.on(Event::Command(LEARN));
    // None of the earlier counts carry over.
    s.on(Event::ServoTimeout { servo: 1 });
    s.on(Event::LoopTiming { overrun: true });
    s.on(Event::ChecksumError { at_ms: 5 });
    assert_eq!(s.state(), State::Learning);
}

#[test]
fn fault_cause_names_and_joints() {
    let names: Vec<&str> = fault_scenarios().iter().map(|(_, c)| c.name()).collect();
    assert!(names.contains(&"servo-timeout") && names.contains(&"watchdog-reset"));
    assert_eq!(FaultCause::SoftLimit { joint: 2, position: 0.0 }.joint(), Some(2));
    assert_eq!(FaultCause::ServoError { servo: 7, error: ErrorFlags::OVERLOAD }.joint(), Some(7));
    assert_eq!(FaultCause::OverrunStreak { count: 3 }.joint(), None);
}

#[test]
fn config_validation_names_the_parameter() {
    let bad = |f: fn(&mut SafetyConfig)| {
        let mut c = SafetyConfig::default();
        f(&mut c);
        Safety::new(c).unwrap_err().param
    };
    assert!(Safety::new(SafetyConfig::default()).is_ok());
    assert_eq!(bad(|c| c.servo_retry_budget = 17), "servo_retry_budget");
    assert_eq!(bad(|c| c.checksum_threshold = 0), "checksum_threshold");
    assert_eq!(bad(|c| c.checksum_threshold = 33), "checksum_threshold");
    assert_eq!(bad(|c| c.checksum_window_ms = 0), "checksum_window_ms");
    assert_eq!(bad(|c| c.servo_fault_mask = ErrorFlags::OVERHEATING), "servo_fault_mask");
    assert_eq!(bad(|c| c.servo_fault_mask = ErrorFlags(0xFF)), "servo_fault_mask");
    assert_eq!(bad(|c| c.overrun_streak = 0), "overrun_streak");
    assert_eq!(bad(|c| c.soft_limits.push(SoftLimit { min: 1.0, max: 1.0 }).unwrap()), "soft_limits.max");
    assert_eq!(bad(|c| c.soft_limits.push(SoftLimit { min: f32::NAN, max: 1.0 }).unwrap()), "soft_limits.min");
    let mut c = SafetyConfig::default();
    c.soft_limits.push(SoftLimit { min: 0.0, max: 1.0 }).unwrap();
    c.soft_limits.push(SoftLimit { min: 0.0, max: f32::INFINITY }).unwrap();
    assert_eq!(Safety::new(c).unwrap_err().index, Some(1));
    // Every fault bit may be added to the mask.
    let c = SafetyConfig { servo_fault_mask: ErrorFlags::ALL, ..Default::default() };
    assert!(Safety::new(c).is_ok());
}
