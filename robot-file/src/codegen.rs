//! A robot's definition as Rust source, for the firmware's build: statics
//! that rebuild exactly the [`RobotSpec`] the host reads from the same
//! files (every `f32` written by its bits, so the two are bit for bit the
//! same and so are their configuration hashes), the vocabulary's rules,
//! and the items the firmware's `table.rs` includes: `ThisRobot`,
//! `this_robot()` and `ROBOT`.
//!
//! Capacities are checked where the code is compiled: the statics are
//! arrays whose lengths are named constants, each asserted in a `const`
//! against pada-core's capacity for it (`pada_core::limits`, the
//! vocabulary's points and chains), and the firmware's
//! `pada_core::profile::Board::profile` of the definition runs in a
//! `const` (a table too large for the board stops the build). The reader
//! refuses such a file first; the asserts keep an edited or stale
//! generated file from reaching the chip.

use pada_core::robot::vocabulary::{ChainJoint, Point, RewardTerm, Signal, Vocabulary};
use pada_core::robot::{MotorLevels, RobotSpec, TableNeed, TorqueLaw};
use pada_core::tile_coding::StateDim;
use std::fmt::Write;

/// An `f32` exactly: its bits, with its value in a comment.
fn f(x: f32) -> String {
    format!("f32::from_bits(0x{:08x}) /* {x:?} */", x.to_bits())
}

fn f3(v: [f32; 3]) -> String {
    format!("[{}, {}, {}]", f(v[0]), f(v[1]), f(v[2]))
}

fn signal(s: &Signal) -> String {
    match *s {
        Signal::Angle(j) => format!("Signal::Angle({j})"),
        Signal::Rate(j) => format!("Signal::Rate({j})"),
        Signal::Position { point, axis } => format!("Signal::Position {{ point: {point}, axis: {axis} }}"),
        Signal::Velocity { point, axis } => format!("Signal::Velocity {{ point: {point}, axis: {axis} }}"),
    }
}

fn state_dim(d: &StateDim) -> String {
    format!("StateDim {{ min: {}, max: {}, tile_width: {}, wrap: {} }}", f(d.min), f(d.max), f(d.tile_width), d.wrap)
}

fn chain_joint(c: &ChainJoint) -> String {
    format!(
        "ChainJoint {{ xyz: {}, rpy: {}, joint: {:?}, axis: {} }}",
        f3(c.xyz),
        f3(c.rpy),
        c.joint,
        f3(c.axis)
    )
}

fn reward(r: &RewardTerm) -> String {
    match *r {
        RewardTerm::Quadratic { signal: s, target, weight, wrap } => format!(
            "RewardTerm::Quadratic {{ signal: {}, target: {}, weight: {}, wrap: {wrap} }}",
            signal(&s),
            f(target),
            f(weight)
        ),
        RewardTerm::Distance { point, target, weight } => {
            format!("RewardTerm::Distance {{ point: {point}, target: {}, weight: {} }}", f3(target), f(weight))
        }
        RewardTerm::DistanceSquared { point, target, weight } => {
            format!("RewardTerm::DistanceSquared {{ point: {point}, target: {}, weight: {} }}", f3(target), f(weight))
        }
        RewardTerm::Progress { point, axis, weight } => {
            format!("RewardTerm::Progress {{ point: {point}, axis: {axis}, weight: {} }}", f(weight))
        }
        RewardTerm::Action { weight } => format!("RewardTerm::Action {{ weight: {} }}", f(weight)),
        RewardTerm::ActionChange { weight } => format!("RewardTerm::ActionChange {{ weight: {} }}", f(weight)),
        RewardTerm::Constant { value } => format!("RewardTerm::Constant {{ value: {} }}", f(value)),
    }
}

/// The index of `name` in pada-core's servo table.
fn servo_index(name: &str) -> usize {
    pada_core::servo::SERVOS.iter().position(|s| s.name == name).unwrap_or(0)
}

/// Rust source of `spec` (a robot whose rules are its vocabulary), from
/// `origin` (named in the source's first line).
pub fn rust_source(spec: &RobotSpec, origin: &str) -> Result<String, String> {
    let Some(v) = spec.vocabulary else {
        return Err(format!("{}: a robot whose rules are code is built by its name, not from files", spec.name));
    };
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "// Generated from {origin} by pada-robot-file: do not edit.");
    let _ = writeln!(w, "#[allow(unused_imports)]\nuse pada_core::robot::vocabulary::{{ChainJoint, End, Hold, Point, Reset, RewardTerm, Signal, Vocabulary}};");
    let _ = writeln!(w, "use pada_core::robot::{{JointRange, JointSpec, MotorLevels, RobotSpec, TableNeed, TorqueLaw}};");
    let _ = writeln!(w, "use pada_core::tile_coding::StateDim;");
    let _ = writeln!(w, "use pada_core::agent::{{SarsaParams, WeightInit}};");
    let _ = writeln!(w, "use pada_core::trace::TraceKind;");
    let _ = writeln!(w, "#[allow(unused_imports)] // a robot without soft limits names none\nuse pada_core::safety::SoftLimit;\n");
    capacities(w, spec, v);

    // Joints.
    let _ = writeln!(w, "static JOINTS: [JointSpec; N_JOINTS] = [");
    for j in spec.joints {
        let limit = match j.soft_limit {
            None => "None".to_string(),
            Some(l) => format!("Some(SoftLimit {{ min: {}, max: {} }})", f(l.min), f(l.max)),
        };
        let _ = writeln!(
            w,
            "    JointSpec {{ name: {:?}, servo: &pada_core::servo::SERVOS[{}], id: {}, zero: {}, sign: {}, soft_limit: {limit} }},",
            j.name,
            servo_index(j.servo.name),
            j.id,
            j.zero,
            j.sign
        );
    }
    let _ = writeln!(w, "];");
    // State.
    let _ = writeln!(w, "static STATE: [StateDim; N_STATE] = [");
    for d in spec.state {
        let _ = writeln!(w, "    {},", state_dim(d));
    }
    let _ = writeln!(w, "];");
    // Levels.
    let levels = match spec.levels {
        MotorLevels::Listed(l) => {
            let _ = writeln!(w, "static LEVELS: [f32; N_LEVELS] = [{}];", l.iter().map(|x| f(*x)).collect::<Vec<_>>().join(", "));
            "MotorLevels::Listed(&LEVELS)".to_string()
        }
        MotorLevels::Uniform { min, max, count } => {
            format!("MotorLevels::Uniform {{ min: {}, max: {}, count: {count} }}", f(min), f(max))
        }
        MotorLevels::PerMotor(dims) => {
            for (k, l) in dims.iter().enumerate() {
                let _ = writeln!(w, "static LEVELS_{k}: [f32; {}] = [{}];", l.len(), l.iter().map(|x| f(*x)).collect::<Vec<_>>().join(", "));
            }
            let each: Vec<String> = (0..dims.len()).map(|k| format!("&LEVELS_{k}")).collect();
            let _ = writeln!(w, "static LEVELS: [&[f32]; N_MOTORS] = [{}];", each.join(", "));
            "MotorLevels::PerMotor(&LEVELS)".to_string()
        }
    };
    let tiles = match spec.action_tiles {
        None => "None".to_string(),
        Some(t) => {
            let _ = writeln!(w, "static ACTION_TILES: [f32; {}] = [{}];", t.len(), t.iter().map(|x| f(*x)).collect::<Vec<_>>().join(", "));
            "Some(&ACTION_TILES)".to_string()
        }
    };
    vocabulary(w, v);
    let p = &spec.params;
    let init = match p.init {
        pada_core::agent::WeightInit::Constant(c) => format!("WeightInit::Constant({})", f(c)),
        pada_core::agent::WeightInit::Uniform { min, max } => format!("WeightInit::Uniform {{ min: {}, max: {} }}", f(min), f(max)),
    };
    let trace = match p.trace_kind {
        pada_core::trace::TraceKind::Replacing => "TraceKind::Replacing",
        pada_core::trace::TraceKind::Accumulating => "TraceKind::Accumulating",
    };
    let table = match spec.table {
        TableNeed::Exact { weights } => format!("TableNeed::Exact {{ weights: {weights} }}"),
        TableNeed::Claimed => "TableNeed::Claimed".into(),
    };
    let torque = match spec.paper_torque {
        TorqueLaw::ServoStall => "TorqueLaw::ServoStall",
        TorqueLaw::Rule(_) => return Err("a robot of files takes its servos' stall torque".into()),
    };
    if spec.encoder.is_some() || spec.footstep_remap.is_some() {
        return Err("a robot of files has no encoder and no footstep remap".into());
    }
    let _ = writeln!(
        w,
        "static SPEC: RobotSpec = RobotSpec {{\n    name: {:?},\n    period_us: {},\n    episode_steps: {},\n    test_interval: {},\n    state: &STATE,\n    motor_dims: {},\n    levels: {levels},\n    action_tiles: {tiles},\n    params: SarsaParams {{ alpha: {}, gamma: {}, lambda: {}, epsilon: {}, trace_threshold: {}, trace_kind: {trace}, init: {init} }},\n    joints: &JOINTS,\n    counted: JointRange {{ start: {}, end: {} }},\n    encoder: None,\n    supply_nominal_v: {},\n    paper_torque: {torque},\n    footstep_remap: None,\n    half_shift: {},\n    table: {table},\n    vocabulary: Some(&VOCABULARY),\n}};",
        spec.name,
        spec.period_us,
        spec.episode_steps,
        spec.test_interval,
        spec.motor_dims,
        f(p.alpha),
        f(p.gamma),
        f(p.lambda),
        f(p.epsilon),
        f(p.trace_threshold),
        spec.counted.start,
        spec.counted.end,
        f(spec.supply_nominal_v),
        spec.half_shift,
    );
    let _ = writeln!(w, "\n/// The rules of the robot this image drives: `{}`, said in the vocabulary.", spec.name);
    let _ = writeln!(w, "pub type ThisRobot = pada_core::robot::Vocab;");
    let _ = writeln!(w, "/// The robot's rules, before its first reading.");
    let _ = writeln!(
        w,
        "pub fn this_robot() -> ThisRobot {{\n    // The definition was checked when it was generated (Vocab::check).\n    match pada_core::robot::Vocab::new(ROBOT) {{\n        Ok(rules) => rules,\n        Err(_) => unreachable!(),\n    }}\n}}"
    );
    let _ = writeln!(w, "/// The robot's definition.\npub static ROBOT: &RobotSpec = &SPEC;");
    Ok(s)
}

/// The lengths of the definition's arrays as named constants, each
/// asserted against the capacity that bounds it, so that the compiler
/// refuses a definition the chip cannot hold.
fn capacities(w: &mut String, spec: &RobotSpec, v: &Vocabulary) {
    let levels = match spec.levels {
        MotorLevels::Listed(l) => l.len(),
        MotorLevels::Uniform { count, .. } => count as usize,
        MotorLevels::PerMotor(dims) => dims.iter().map(|l| l.len()).max().unwrap_or(0),
    };
    let gearboxes = spec.counted.end.saturating_sub(spec.counted.start) as usize;
    let _ = writeln!(w, "// Capacities: each length, and pada-core's room for it.");
    let consts: [(&str, usize, &str, &str); 7] = [
        ("N_JOINTS", spec.joints.len(), "pada_core::limits::MAX_SERVOS", "joints (servos on the bus)"),
        ("N_STATE", spec.state.len(), "pada_core::limits::MAX_STATE_DIMS", "observed state dimensions"),
        ("N_MOTORS", spec.motor_dims as usize, "pada_core::limits::MAX_ACTION_DIMS", "learned motor dimensions"),
        ("N_LEVELS", levels, "pada_core::limits::MAX_LEVELS", "levels of an action dimension"),
        ("N_GEARBOXES", gearboxes, "pada_core::limits::MAX_GEARBOXES", "counted gearboxes"),
        ("N_NAME", spec.name.len(), "pada_core::limits::MAX_ROBOT_NAME", "bytes of the robot's name"),
        ("N_POINTS", v.points.len(), "pada_core::robot::vocabulary::MAX_POINTS", "points"),
    ];
    for (name, n, cap, what) in consts {
        let _ = writeln!(w, "const {name}: usize = {n};");
        let message = format!("{}: more {what} than pada-core holds", spec.name);
        let _ = writeln!(w, "const _: () = assert!({name} <= {cap}, {message:?});");
    }
    for (k, p) in v.points.iter().enumerate() {
        let _ = writeln!(w, "const N_CHAIN_{k}: usize = {};", p.chain.len());
        let message = format!("{}: point {} hangs on more joints than pada-core follows", spec.name, p.name);
        let _ = writeln!(w, "const _: () = assert!(N_CHAIN_{k} <= pada_core::robot::vocabulary::MAX_CHAIN, {message:?});");
    }
    let _ = writeln!(w);
}

fn vocabulary(w: &mut String, v: &Vocabulary) {
    let _ = writeln!(w, "static OBSERVATION: [Signal; N_STATE] = [{}];", v.observation.iter().map(signal).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "static LEARNED: [u8; N_MOTORS] = {:?};", v.learned);
    let _ = writeln!(w, "static HELD: [Hold; {}] = [", v.held.len());
    for h in v.held {
        let _ = writeln!(w, "    Hold {{ joint: {}, target: {}, gain_v_per_rad: {} }},", h.joint, f(h.target), f(h.gain_v_per_rad));
    }
    let _ = writeln!(w, "];");
    let _ = writeln!(w, "static START: [f32; {}] = [{}];", v.start.len(), v.start.iter().map(|x| f(*x)).collect::<Vec<_>>().join(", "));
    for (k, p) in v.points.iter().enumerate() {
        let _ = writeln!(w, "static CHAIN_{k}: [ChainJoint; N_CHAIN_{k}] = [");
        for c in p.chain {
            let _ = writeln!(w, "    {},", chain_joint(c));
        }
        let _ = writeln!(w, "];");
    }
    let _ = writeln!(w, "static POINTS: [Point; N_POINTS] = [");
    for (k, p) in v.points.iter().enumerate() {
        let Point { name, offset, .. } = p;
        let _ = writeln!(w, "    Point {{ name: {name:?}, chain: &CHAIN_{k}, offset: {} }},", f3(*offset));
    }
    let _ = writeln!(w, "];");
    let _ = writeln!(w, "static REWARDS: [RewardTerm; {}] = [", v.rewards.len());
    for r in v.rewards {
        let _ = writeln!(w, "    {},", reward(r));
    }
    let _ = writeln!(w, "];");
    let _ = writeln!(w, "static ENDS: [End; {}] = [", v.ends.len());
    for e in v.ends {
        let _ = writeln!(w, "    End {{ signal: {}, min: {}, max: {}, reward: {} }},", signal(&e.signal), f(e.min), f(e.max), f(e.reward));
    }
    let _ = writeln!(w, "];");
    let r = &v.reset;
    let _ = writeln!(
        w,
        "static VOCABULARY: Vocabulary = Vocabulary {{\n    observation: &OBSERVATION,\n    learned: &LEARNED,\n    held: &HELD,\n    voltage_limit_v: {},\n    start: &START,\n    reset: Reset {{ gain_v_per_rad: {}, tolerance_rad: {}, still_rad_s: {}, settle_us: {}, timeout_us: {} }},\n    points: &POINTS,\n    rewards: &REWARDS,\n    ends: &ENDS,\n}};",
        f(v.voltage_limit_v),
        f(r.gain_v_per_rad),
        f(r.tolerance_rad),
        f(r.still_rad_s),
        r.settle_us,
        r.timeout_us
    );
}
