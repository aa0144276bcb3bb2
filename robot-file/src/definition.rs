//! `robot.toml` and its URDF → pada-core's [`RobotSpec`] and
//! [`Vocabulary`]: every value checked, every error pointing at its line.
//!
//! The definition is built once per process and lives as long as it
//! (`Box::leak`): pada-core's definitions are `&'static`, as the
//! firmware's are constants.

use crate::error::{Locator, RobotFileError};
use crate::schema::{ActionSection, LearningSection, ResetSection, RewardSection, RobotSection, RobotToml, SimulationSection};
use std::ops::Range;
use crate::urdf::{servo_joint_type, Urdf};
use pada_core::agent::{SarsaParams, WeightInit};
use pada_core::limits::{MAX_ACTION_DIMS, MAX_LEVELS, MAX_ROBOT_NAME, MAX_SERVOS, MAX_STATE_DIMS};
use pada_core::policy::PolicyKind;
use pada_core::profile::{Board, TILINGS};
use pada_core::robot::hardware::{JointRange, JointSpec};
use pada_core::robot::vocabulary::{
    End, Hold, Point, Reset, RewardTerm, Signal, Vocab, Vocabulary, MAX_CHAIN, MAX_POINTS,
};
use pada_core::robot::{MotorLevels, RobotSpec, TableNeed, TorqueLaw};
use pada_core::safety::SoftLimit;
use pada_core::servo::PositionScale;
use pada_core::tile_coding::StateDim;
use pada_core::trace::TraceKind;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// A robot read from its files.
#[derive(Debug, Clone)]
pub struct RobotFile {
    /// The `robot.toml`.
    pub path: PathBuf,
    /// Its body.
    pub urdf: Urdf,
    /// The definition pada-core takes.
    pub spec: &'static RobotSpec,
    /// Physics steps per control period of the host's simulation.
    pub substeps: u32,
    /// rapier's solver iterations per physics step.
    pub solver_iterations: u32,
    /// How far the real robot may differ from this model (`[plant]`).
    pub plant: crate::plant::PlantRanges,
}

impl RobotFile {
    /// The vocabulary of the robot's rules.
    pub fn vocabulary(&self) -> &'static Vocabulary {
        // Every robot built here has one (`build`).
        self.spec.vocabulary.unwrap_or_else(|| unreachable!("a robot file's rules are its vocabulary"))
    }

    /// The learner `board` gives this robot, or why its table fits no
    /// memory of the board (an error of the file: fewer tiles or actions).
    pub fn profile(&self, board: Board) -> Result<pada_core::profile::LearnerProfile, RobotFileError> {
        board.profile(self.spec).map_err(|e| RobotFileError {
            file: self.path.clone(),
            at: None,
            field: "observe, action".into(),
            message: e.to_string(),
        })
    }

    /// The robot's rules.
    pub fn rules(&self) -> Vocab {
        // Checked when the file was read (`build`).
        Vocab::new(self.spec).unwrap_or_else(|e| unreachable!("checked at load: {e}"))
    }
}

/// Reads, checks and builds the robot of `path` (a `robot.toml`, or the
/// directory that holds it).
pub fn load(path: &Path) -> Result<RobotFile, RobotFileError> {
    let joined;
    let path = if path.is_dir() {
        joined = path.join("robot.toml");
        joined.as_path()
    } else {
        path
    };
    let text = std::fs::read_to_string(path).map_err(|e| RobotFileError {
        file: path.to_path_buf(),
        at: None,
        field: String::new(),
        message: format!("cannot read it ({e})"),
    })?;
    let at = Locator::new(path, &text);
    let toml: RobotToml = toml::from_str(&text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        let message = e.message().trim().replace('\n', "; ");
        match crate::type_error::reworded(&text, &span, &message) {
            Some((field, reworded)) => at.at(&span, field, reworded),
            None => at.at(&span, "", message),
        }
    })?;
    build(path, &at, toml)
}

/// A leaked slice: the definition lives as long as the process.
fn leak<T>(v: Vec<T>) -> &'static [T] {
    Box::leak(v.into_boxed_slice())
}

/// A finite, positive number, or the error of `field`.
fn positive(at: &Locator, v: &Spanned<f64>, field: &str, unit: &str) -> Result<f64, RobotFileError> {
    let x = *v.get_ref();
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(at.at(&v.span(), field, format!("{x} is not valid: a positive number of {unit}")))
    }
}

/// A range `[min, max]` with `min < max`, both finite.
fn range(at: &Locator, v: &Spanned<[f64; 2]>, field: &str) -> Result<[f64; 2], RobotFileError> {
    let [a, b] = *v.get_ref();
    if a.is_finite() && b.is_finite() && a < b {
        Ok([a, b])
    } else {
        Err(at.at(&v.span(), field, format!("[{a}, {b}] is not valid: [min, max] with min < max, both finite")))
    }
}

/// The names signals use: the joints' and the points'.
struct Names<'a> {
    joints: &'a [String],
    points: &'a [String],
}

impl Names<'_> {
    /// `NAME.KIND`: `JOINT.angle|rate`, `POINT.x|y|z|x_rate|y_rate|z_rate`.
    fn signal(&self, at: &Locator, v: &Spanned<String>, field: &str) -> Result<Signal, RobotFileError> {
        let s = v.get_ref();
        let valid = || {
            let mut names: Vec<String> = self.joints.iter().flat_map(|j| [format!("{j}.angle"), format!("{j}.rate")]).collect();
            for p in self.points {
                for a in ["x", "y", "z"] {
                    names.push(format!("{p}.{a}"));
                }
            }
            names.join(", ")
        };
        let fail = |why: &str| Err(at.at(&v.span(), field, format!("{s:?} {why}: valid are {} (and each point's x_rate, y_rate, z_rate)", valid())));
        let Some((name, kind)) = s.rsplit_once('.') else { return fail("is no signal") };
        if let Some(j) = self.joints.iter().position(|j| j == name) {
            return match kind {
                "angle" => Ok(Signal::Angle(j as u8)),
                "rate" => Ok(Signal::Rate(j as u8)),
                _ => fail("names no quantity of a joint"),
            };
        }
        if let Some(p) = self.points.iter().position(|p| p == name) {
            let axis = |a: &str| ["x", "y", "z"].iter().position(|x| *x == a).map(|i| i as u8);
            return match (axis(kind), kind.strip_suffix("_rate").and_then(axis)) {
                (Some(axis), _) => Ok(Signal::Position { point: p as u8, axis }),
                (None, Some(axis)) => Ok(Signal::Velocity { point: p as u8, axis }),
                _ => fail("names no quantity of a point"),
            };
        }
        fail("names no joint or point of the robot")
    }

    fn point(&self, at: &Locator, v: &Spanned<String>, field: &str) -> Result<u8, RobotFileError> {
        self.points.iter().position(|p| p == v.get_ref()).map(|p| p as u8).ok_or_else(|| {
            at.at(&v.span(), field, format!("{:?} is no point: valid are {}", v.get_ref(), self.points.join(", ")))
        })
    }
}

/// The checks and the conversion, section by section in the order the
/// errors are found: `[robot]`, `[[joint]]`, `[point.*]`, `[[observe]]`,
/// `[action]` with the held joints, `[learning]`, `[[reward]]`, `[[end]]`,
/// `[reset]`, `[simulation]`, and the table.
fn build(path: &Path, at: &Locator, t: RobotToml) -> Result<RobotFile, RobotFileError> {
    let robot = robot_section(path, at, &t.robot)?;
    let urdf = robot.urdf;
    let (joints, names) = joints(at, &t, &urdf, &urdf.path)?;
    let counted = counted(at, &t)?;
    let (points, point_names) = points(at, &t, &urdf, &names)?;
    let signals = Names { joints: &names, points: &point_names };
    let (observation, state) = observation(at, &t, &signals)?;
    let motor = motor(at, &t, robot.voltage_limit_v)?;
    let params = learning(at, &t.learning)?;
    let rewards = rewards(at, &t, &signals)?;
    let ends = ends(at, &t, &signals)?;
    let reset = reset(at, &t.reset)?;
    let (substeps, solver_iterations) = simulation(at, &t.simulation)?;
    let plant = crate::plant::plant(at, &t.plant)?;

    let vocabulary: &'static Vocabulary = Box::leak(Box::new(Vocabulary {
        observation: leak(observation),
        learned: leak(motor.learned.clone()),
        held: leak(motor.held),
        voltage_limit_v: robot.voltage_limit_v as f32,
        start: leak(t.joints.iter().map(|j| *j.get_ref().start_rad.get_ref() as f32).collect()),
        reset,
        points: leak(points),
        rewards: leak(rewards),
        ends: leak(ends),
    }));
    let r = &t.robot;
    let half_shift = *r.half_shift.get_ref();
    if !(8..=15).contains(&half_shift) {
        return Err(at.at(&r.half_shift.span(), "robot.half_shift", format!("{half_shift} is not valid: 8 to 15 (16-bit weights hold ±2^(shift−1))")));
    }
    let mut spec = RobotSpec {
        name: Box::leak(robot.name.into_boxed_str()),
        period_us: robot.period_us,
        episode_steps: robot.episode_steps,
        test_interval: robot.test_interval,
        state: leak(state),
        motor_dims: motor.learned.len() as u8,
        levels: motor.levels,
        action_tiles: motor.action_tiles,
        params,
        joints: leak(joints),
        counted,
        encoder: None,
        supply_nominal_v: robot.supply_v as f32,
        paper_torque: TorqueLaw::ServoStall,
        footstep_remap: None,
        half_shift,
        table: TableNeed::Claimed,
        vocabulary: Some(vocabulary),
    };
    spec.table = table(at, r, &spec)?;
    let spec: &'static RobotSpec = Box::leak(Box::new(spec));
    Vocab::check(spec, vocabulary).map_err(|e| at.field(e.param, e.to_string()))?;
    spec.params.validate().map_err(|e| at.field(format!("learning.{}", e.param), e.to_string()))?;
    spec.motor().map_err(|e| at.field("action", e.to_string()))?;
    Ok(RobotFile { path: path.to_path_buf(), urdf, spec, substeps, solver_iterations, plant })
}

/// `[robot]`, checked.
struct RobotPart {
    name: String,
    urdf: Urdf,
    period_us: u32,
    episode_steps: u32,
    test_interval: u32,
    supply_v: f64,
    voltage_limit_v: f64,
}

/// `[robot]`: the name, the URDF (read), the timing and the supply.
fn robot_section(path: &Path, at: &Locator, r: &RobotSection) -> Result<RobotPart, RobotFileError> {
    // The name.
    let name = r.name.get_ref();
    if name.is_empty()
        || name.len() > MAX_ROBOT_NAME
        || !name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
    {
        return Err(at.at(
            &r.name.span(),
            "robot.name",
            format!("{name:?} is not valid: 1 to {MAX_ROBOT_NAME} lowercase letters, digits or '-'"),
        ));
    }
    if pada_core::robot::registry::find(name).is_some() {
        return Err(at.at(&r.name.span(), "robot.name", format!("{name:?} is one of pada's own robots: choose another name")));
    }
    // The body.
    let dir = path.parent().unwrap_or(Path::new("."));
    let urdf_path = dir.join(r.urdf.get_ref());
    if !urdf_path.is_file() {
        return Err(at.at(&r.urdf.span(), "robot.urdf", format!("{} is no file (the path is relative to the robot.toml)", urdf_path.display())));
    }
    let urdf = Urdf::read(&urdf_path)?;
    // Timing.
    let period_ms = positive(at, &r.period_ms, "robot.period_ms", "milliseconds")?;
    if !(1.0..=1000.0).contains(&period_ms) {
        return Err(at.at(&r.period_ms.span(), "robot.period_ms", format!("{period_ms} is not valid: 1 to 1000 ms")));
    }
    let period_us = (period_ms * 1000.0).round() as u32;
    let episode_s = positive(at, &r.episode_s, "robot.episode_s", "seconds")?;
    let episode_steps = (episode_s * 1e6 / period_us as f64).round();
    if !(1.0..=1e6).contains(&episode_steps) {
        return Err(at.at(&r.episode_s.span(), "robot.episode_s", format!("{episode_s} s is {episode_steps} control periods: valid are 1 to 1000000")));
    }
    let test_interval = *r.test_interval.get_ref();
    if test_interval == 0 {
        return Err(at.at(&r.test_interval.span(), "robot.test_interval", "0 is not valid: a test episode after every N ≥ 1 learning episodes"));
    }
    let supply_v = positive(at, &r.supply_v, "robot.supply_v", "volts")?;
    let voltage_limit_v = positive(at, &r.voltage_limit_v, "robot.voltage_limit_v", "volts")?;
    Ok(RobotPart { name: name.clone(), urdf, period_us, episode_steps: episode_steps as u32, test_interval, supply_v, voltage_limit_v })
}

/// `[[joint]]`: each joint's URDF joint, servo, ID, calibration and soft
/// limit; the joints' URDF names, in joint order.
fn joints(at: &Locator, t: &RobotToml, urdf: &Urdf, urdf_path: &Path) -> Result<(Vec<JointSpec>, Vec<String>), RobotFileError> {
    if t.joints.is_empty() || t.joints.len() > MAX_SERVOS {
        return Err(at.field("joint", format!("{} joints: valid are 1 to {MAX_SERVOS} [[joint]] tables", t.joints.len())));
    }
    let moving: Vec<String> = urdf.moving_joints().map(|j| j.name.clone()).collect();
    let mut joints = Vec::new();
    let mut names = Vec::new();
    for (i, js) in t.joints.iter().enumerate() {
        let j = js.get_ref();
        let f = |field: &str| format!("joint[{i}].{field}");
        let Some(u) = urdf.joint(j.urdf.get_ref()) else {
            return Err(at.at(&j.urdf.span(), f("urdf"), format!("{:?} is no joint of {}: its moving joints are {}", j.urdf.get_ref(), urdf_path.display(), moving.join(", "))));
        };
        servo_joint_type(&u.joint_type).map_err(|why| at.at(&j.urdf.span(), f("urdf"), format!("{:?} is a {:?} joint: {why}", u.name, u.joint_type)))?;
        if names.contains(j.urdf.get_ref()) {
            return Err(at.at(&j.urdf.span(), f("urdf"), format!("{:?} has a servo already", u.name)));
        }
        let servo = pada_core::servo::servo(j.servo.get_ref()).map_err(|e| at.at(&j.servo.span(), f("servo"), e.to_string()))?;
        let id = *j.id.get_ref();
        if id > 252 {
            return Err(at.at(&j.id.span(), f("id"), format!("{id} is not valid: a bus ID is 0 to 252")));
        }
        if joints.iter().any(|k: &JointSpec| k.id == id) {
            return Err(at.at(&j.id.span(), f("id"), format!("{id} is another joint's ID: each servo has its own")));
        }
        let sign = *j.sign.get_ref();
        if sign != 1 && sign != -1 {
            return Err(at.at(&j.sign.span(), f("sign"), format!("{sign} is not valid: 1 or -1")));
        }
        let zero = *j.zero_count.get_ref();
        let last = match servo.encoding.position {
            PositionScale::Span { max, .. } => max as u32,
            PositionScale::Turns { per_turn } => per_turn.saturating_sub(1),
        };
        if zero as u32 > last {
            return Err(at.at(
                &j.zero_count.span(),
                f("zero_count"),
                format!("{zero} is not valid: a position count of the {}'s encoder, 0 to {last}", servo.name),
            ));
        }
        let soft_limit = match &j.soft_limit_rad {
            None => None,
            Some(l) => {
                let [min, max] = range(at, l, &f("soft_limit_rad"))?;
                // A revolute joint stops at its URDF limits (rapier holds
                // it there): a soft limit past them is never reached.
                let stop = &u.limit;
                let revolute = matches!(u.joint_type, urdf_rs::JointType::Revolute) && stop.lower < stop.upper;
                if revolute && (min < stop.lower || max > stop.upper) {
                    return Err(at.at(
                        &l.span(),
                        f("soft_limit_rad"),
                        format!(
                            "[{min}, {max}] is not valid: within the URDF joint {:?}'s limits [{}, {}] rad (the joint cannot go further)",
                            u.name, stop.lower, stop.upper
                        ),
                    ));
                }
                Some(SoftLimit { min: min as f32, max: max as f32 })
            }
        };
        let start = *j.start_rad.get_ref();
        let inside = soft_limit.map_or(start.is_finite(), |l| l.fault(i as u8, start as f32).is_none());
        if !inside {
            let valid = soft_limit.map_or("a finite angle in radians".to_string(), |l| format!("within the joint's soft_limit_rad [{}, {}]", l.min, l.max));
            return Err(at.at(&j.start_rad.span(), f("start_rad"), format!("{start} is not valid: {valid} (the robot would fault at its first reading)")));
        }
        names.push(u.name.clone());
        joints.push(JointSpec {
            name: Box::leak(u.name.clone().into_boxed_str()),
            servo,
            id,
            zero,
            sign,
            soft_limit,
        });
    }
    if let Some(missing) = moving.iter().find(|m| !names.contains(m)) {
        return Err(at.field("joint", format!("the URDF's joint {missing:?} moves, but no [[joint]] names a servo for it (urdf = {missing:?})")));
    }
    // The safety machine takes soft limits up to the first joint without
    // one (pada_firmware's `soft_limits`).
    if let Some(k) = joints.iter().position(|j| j.soft_limit.is_none()) {
        if let Some(later) = joints[k..].iter().position(|j| j.soft_limit.is_some()) {
            return Err(at.at(
                &t.joints[k + later].get_ref().urdf.span(),
                format!("joint[{}].soft_limit_rad", k + later),
                "the joints with soft limits come first in joint order (the safety machine takes them in order)",
            ));
        }
    }
    Ok((joints, names))
}

/// The counted gearboxes: a run of joints.
fn counted(at: &Locator, t: &RobotToml) -> Result<JointRange, RobotFileError> {
    let counted: Vec<usize> =
        t.joints.iter().enumerate().filter(|(_, j)| j.get_ref().counted.unwrap_or(j.get_ref().learned)).map(|(i, _)| i).collect();
    match (counted.first(), counted.last()) {
        (Some(&a), Some(&b)) if b - a + 1 == counted.len() && counted.len() <= pada_core::limits::MAX_GEARBOXES => {
            Ok(JointRange { start: a as u8, end: b as u8 + 1 })
        }
        (None, _) => Err(at.field("joint", "no joint is counted: set counted = true on the joints whose gearbox wear counts")),
        _ => Err(at.field(
            "joint",
            format!("the counted joints {counted:?} must follow each other in joint order, at most {} of them", pada_core::limits::MAX_GEARBOXES),
        )),
    }
}

/// `[point.NAME]`: each point's kinematic chain; the points' names.
fn points(at: &Locator, t: &RobotToml, urdf: &Urdf, names: &[String]) -> Result<(Vec<Point>, Vec<String>), RobotFileError> {
    if t.points.len() > MAX_POINTS {
        return Err(at.field("point", format!("{} points: at most {MAX_POINTS}", t.points.len())));
    }
    let point_names: Vec<String> = t.points.keys().cloned().collect();
    let index_of = |n: &str| names.iter().position(|m| m == n).map(|k| k as u8);
    let mut points = Vec::new();
    for (pname, p) in &t.points {
        let link = p.get_ref().link.get_ref();
        if !urdf.has_link(link) {
            let links: Vec<&str> = urdf.robot.links.iter().map(|l| l.name.as_str()).collect();
            return Err(at.at(&p.get_ref().link.span(), format!("point.{pname}.link"), format!("{link:?} is no link of the URDF: its links are {}", links.join(", "))));
        }
        let chain = urdf.kinematic_chain(link, index_of);
        if chain.len() > MAX_CHAIN {
            return Err(at.at(&p.get_ref().link.span(), format!("point.{pname}.link"), format!("{} joints from the base: at most {MAX_CHAIN}", chain.len())));
        }
        points.push(Point {
            name: Box::leak(pname.clone().into_boxed_str()),
            chain: leak(chain),
            offset: p.get_ref().offset_m.map(|v| v as f32),
        });
    }
    Ok((points, point_names))
}

/// `[[observe]]`: the signals and the tile coder's dimensions.
fn observation(at: &Locator, t: &RobotToml, signals: &Names) -> Result<(Vec<Signal>, Vec<StateDim>), RobotFileError> {
    if t.observe.is_empty() || t.observe.len() > MAX_STATE_DIMS - MAX_ACTION_DIMS {
        return Err(at.field(
            "observe",
            format!("{} dimensions: valid are 1 to {} (the tile coder's {MAX_STATE_DIMS}, less room for a Markov policy's own)", t.observe.len(), MAX_STATE_DIMS - MAX_ACTION_DIMS),
        ));
    }
    let mut observation = Vec::new();
    let mut state = Vec::new();
    for (i, o) in t.observe.iter().enumerate() {
        let o = o.get_ref();
        observation.push(signals.signal(at, &o.signal, &format!("observe[{i}].signal"))?);
        let [min, max] = range(at, &o.range, &format!("observe[{i}].range"))?;
        let tile = positive(at, &o.tile, &format!("observe[{i}].tile"), "the signal's unit")?;
        let dim = StateDim { min: min as f32, max: max as f32, tile_width: tile as f32, wrap: o.wrap };
        dim.validate().map_err(|e| at.at(&o.tile.span(), format!("observe[{i}]"), e.to_string()))?;
        state.push(dim);
    }
    Ok((observation, state))
}

/// The motor: the learned joints, their levels and action tiles, and the
/// held joints' P laws.
struct Motor {
    learned: Vec<u8>,
    levels: MotorLevels,
    action_tiles: Option<&'static [f32]>,
    held: Vec<Hold>,
}

/// `[action]` and the joints' `learned` and `hold_*` fields.
fn motor(at: &Locator, t: &RobotToml, voltage_limit_v: f64) -> Result<Motor, RobotFileError> {
    let learned: Vec<u8> = t.joints.iter().enumerate().filter(|(_, j)| j.get_ref().learned).map(|(i, _)| i as u8).collect();
    if learned.is_empty() || learned.len() > MAX_ACTION_DIMS {
        return Err(at.field("joint", format!("{} learned joints: valid are 1 to {MAX_ACTION_DIMS}", learned.len())));
    }
    let levels = levels_of(at, t, &learned, voltage_limit_v)?;
    let action_tiles = match t.action.get_ref().tile_v {
        None => None,
        Some(w) if w.is_finite() && w > 0.0 => Some(leak(vec![w as f32; learned.len()])),
        Some(w) => return Err(at.at(&t.action.span(), "action.tile_v", format!("{w} is not valid: a positive width in volts"))),
    };
    let mut held = Vec::new();
    for (i, js) in t.joints.iter().enumerate() {
        let j = js.get_ref();
        match (&j.hold_gain_v_per_rad, j.learned) {
            (Some(g), false) => {
                let gain = positive(at, g, &format!("joint[{i}].hold_gain_v_per_rad"), "volts per radian")?;
                held.push(Hold { joint: i as u8, target: j.hold_target_rad.unwrap_or(*j.start_rad.get_ref()) as f32, gain_v_per_rad: gain as f32 });
            }
            (Some(g), true) => return Err(at.at(&g.span(), format!("joint[{i}].hold_gain_v_per_rad"), "a learned joint is not held: set learned = false to hold it")),
            (None, false) => return Err(at.at(&j.urdf.span(), format!("joint[{i}]"), "a joint the learner does not drive needs hold_gain_v_per_rad (its P law)")),
            (None, true) => {}
        }
    }
    Ok(Motor { learned, levels, action_tiles, held })
}

/// `[learning]`: SARSA(λ)'s parameters, each error at its line.
fn learning(at: &Locator, l: &LearningSection) -> Result<SarsaParams, RobotFileError> {
    let [w0, w1] = *l.initial_weights.get_ref();
    let params = SarsaParams {
        alpha: *l.alpha.get_ref() as f32,
        gamma: *l.gamma.get_ref() as f32,
        lambda: *l.lambda.get_ref() as f32,
        epsilon: *l.epsilon.get_ref() as f32,
        trace_threshold: *l.trace_threshold.get_ref() as f32,
        trace_kind: TraceKind::Replacing,
        init: if w0 == w1 { WeightInit::Constant(w0 as f32) } else { WeightInit::Uniform { min: w0 as f32, max: w1 as f32 } },
    };
    if let Err(e) = params.validate() {
        let span = match e.param {
            "alpha" => l.alpha.span(),
            "gamma" => l.gamma.span(),
            "lambda" => l.lambda.span(),
            "epsilon" => l.epsilon.span(),
            "trace_threshold" => l.trace_threshold.span(),
            _ => l.initial_weights.span(),
        };
        return Err(at.at(&span, format!("learning.{}", e.param), e.to_string()));
    }
    Ok(params)
}

/// `[[reward]]`: at least one term, every number finite.
fn rewards(at: &Locator, t: &RobotToml, signals: &Names) -> Result<Vec<RewardTerm>, RobotFileError> {
    let mut rewards = Vec::new();
    for (i, rs) in t.rewards.iter().enumerate() {
        let term = reward_term(at, signals, rs.get_ref(), i)?;
        if !reward_finite(Some(&term)) {
            return Err(at.at(&rs.span(), format!("reward[{i}]"), "its numbers must be finite"));
        }
        rewards.push(term);
    }
    if rewards.is_empty() {
        return Err(at.field("reward", "no [[reward]]: the learner needs at least one term to learn from"));
    }
    Ok(rewards)
}

/// `[[end]]`: the limits that end an episode.
fn ends(at: &Locator, t: &RobotToml, signals: &Names) -> Result<Vec<End>, RobotFileError> {
    let mut ends = Vec::new();
    for (i, e) in t.ends.iter().enumerate() {
        let e = e.get_ref();
        let [min, max] = range(at, &e.range, &format!("end[{i}].range"))?;
        ends.push(End { signal: signals.signal(at, &e.signal, &format!("end[{i}].signal"))?, min: min as f32, max: max as f32, reward: e.reward as f32 });
    }
    Ok(ends)
}

/// `[reset]`: every value positive.
fn reset(at: &Locator, rs: &ResetSection) -> Result<Reset, RobotFileError> {
    let reset = Reset {
        gain_v_per_rad: rs.gain_v_per_rad as f32,
        tolerance_rad: rs.tolerance_rad as f32,
        still_rad_s: rs.still_rad_s as f32,
        settle_us: (rs.settle_s * 1e6).round().clamp(0.0, u32::MAX as f64) as u32,
        timeout_us: (rs.timeout_s * 1e6).round().clamp(0.0, u32::MAX as f64) as u32,
    };
    if [rs.gain_v_per_rad, rs.tolerance_rad, rs.still_rad_s, rs.settle_s, rs.timeout_s].iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(at.field("reset", "gain_v_per_rad, tolerance_rad, still_rad_s, settle_s and timeout_s must be positive"));
    }
    Ok(reset)
}

/// `[simulation]`: physics steps per control period and solver iterations.
fn simulation(at: &Locator, s: &SimulationSection) -> Result<(u32, u32), RobotFileError> {
    let substeps = *s.substeps.get_ref();
    if !(1..=1000).contains(&substeps) {
        return Err(at.at(&s.substeps.span(), "simulation.substeps", format!("{substeps} is not valid: 1 to 1000 physics steps per control period")));
    }
    let solver_iterations = *s.solver_iterations.get_ref();
    if !(1..=64).contains(&solver_iterations) {
        return Err(at.at(&s.solver_iterations.span(), "simulation.solver_iterations", format!("{solver_iterations} is not valid: 1 to 64")));
    }
    Ok((substeps, solver_iterations))
}

/// The table: exact where it fits an F405 (or where asked for), else a
/// claim table.
fn table(at: &Locator, r: &RobotSection, spec: &RobotSpec) -> Result<TableNeed, RobotFileError> {
    // An observation with more features than an exact table can index
    // (past 2^32 weights) still learns in a claim table.
    let exact = spec.exact_table_len::<TILINGS>(PolicyKind::Sarsa);
    let fits_f405 = exact.as_ref().is_ok_and(|&weights| Board::F405.profile(RobotSpec { table: TableNeed::Exact { weights }, ..*spec }.leaked()).is_ok());
    let span = r.table.as_ref().map(|s| s.span()).unwrap_or(0..0);
    match (r.table.as_ref().map(|s| s.get_ref().as_str()), exact) {
        (None, Ok(weights)) if fits_f405 => Ok(TableNeed::Exact { weights }),
        (None, _) | (Some("claim"), _) => Ok(TableNeed::Claimed),
        (Some("exact"), Ok(weights)) => Ok(TableNeed::Exact { weights }),
        (Some("exact"), Err(e)) => Err(at.at(&span, "robot.table", format!("\"exact\" is not valid for this observation ({e}): claim, or coarser tiles"))),
        (Some(other), _) => Err(at.at(&span, "robot.table", format!("{other:?} is not valid: exact or claim"))),
    }
}

trait Leaked {
    fn leaked(self) -> &'static Self;
}

impl Leaked for RobotSpec {
    /// A provisional definition for a check (leaked: small, once per load).
    fn leaked(self) -> &'static Self {
        Box::leak(Box::new(self))
    }
}

fn reward_finite(term: Option<&RewardTerm>) -> bool {
    match term {
        Some(RewardTerm::Quadratic { target, weight, .. }) => target.is_finite() && weight.is_finite(),
        Some(RewardTerm::Distance { target, weight, .. }) | Some(RewardTerm::DistanceSquared { target, weight, .. }) => {
            target.iter().all(|v| v.is_finite()) && weight.is_finite()
        }
        Some(RewardTerm::Progress { weight, .. }) | Some(RewardTerm::Action { weight }) | Some(RewardTerm::ActionChange { weight }) => weight.is_finite(),
        Some(RewardTerm::Constant { value }) => value.is_finite(),
        None => true,
    }
}

/// `[action]`: `levels_v` (increasing, 2 to 16) or `uniform_v`, within the
/// voltage limit.
fn motor_levels(at: &Locator, a: &Spanned<ActionSection>, limit: f64) -> Result<MotorLevels, RobotFileError> {
    let s = a.span();
    let in_limit = |v: f64| v.is_finite() && v.abs() <= limit + 1e-9;
    match (&a.get_ref().levels_v, &a.get_ref().uniform_v) {
        (Some(levels), None) => Ok(MotorLevels::Listed(leak(listed_levels(at, &s, "action.levels_v", levels, limit)?))),
        (None, Some(u)) => {
            if !((2..=MAX_LEVELS as u8).contains(&u.count) && u.min < u.max && in_limit(u.min) && in_limit(u.max)) {
                return Err(at.at(&s, "action.uniform_v", format!("min {} max {} count {} is not valid: min < max within ±{limit} V, 2 to {MAX_LEVELS} levels", u.min, u.max, u.count)));
            }
            Ok(MotorLevels::Uniform { min: u.min as f32, max: u.max as f32, count: u.count })
        }
        _ => Err(at.at(&s, "action", "give either levels_v = [...] or uniform_v = { min, max, count }")),
    }
}

/// A list of levels: 2 to 16 increasing voltages within the limit.
fn listed_levels(at: &Locator, span: &Range<usize>, field: &str, levels: &[f64], limit: f64) -> Result<Vec<f32>, RobotFileError> {
    let in_limit = |v: f64| v.is_finite() && v.abs() <= limit + 1e-9;
    let ok = (2..=MAX_LEVELS).contains(&levels.len()) && levels.windows(2).all(|w| w[0] < w[1]) && levels.iter().all(|v| in_limit(*v));
    if !ok {
        return Err(at.at(span, field, format!("{levels:?} is not valid: 2 to {MAX_LEVELS} increasing voltages within ±voltage_limit_v ({limit} V)")));
    }
    Ok(levels.iter().map(|v| *v as f32).collect())
}

/// The levels of the learned joints: `[action]`'s for all, or, where a
/// learned joint gives its own `levels_v`, a list per motor dimension
/// (`[action]`'s for the joints that give none).
fn levels_of(at: &Locator, t: &RobotToml, learned: &[u8], limit: f64) -> Result<MotorLevels, RobotFileError> {
    for (i, js) in t.joints.iter().enumerate() {
        let j = js.get_ref();
        if let (Some(l), false) = (&j.levels_v, j.learned) {
            return Err(at.at(&l.span(), format!("joint[{i}].levels_v"), "a held joint has no levels of its own: set learned = true, or leave levels_v out"));
        }
    }
    if learned.iter().all(|&k| t.joints[k as usize].get_ref().levels_v.is_none()) {
        return motor_levels(at, &t.action, limit);
    }
    let mut each = Vec::new();
    for &k in learned {
        let values = match &t.joints[k as usize].get_ref().levels_v {
            Some(l) => listed_levels(at, &l.span(), &format!("joint[{k}].levels_v"), l.get_ref(), limit)?,
            None => match motor_levels(at, &t.action, limit)? {
                MotorLevels::Listed(l) => l.to_vec(),
                MotorLevels::Uniform { min, max, count } => pada_core::action_space::ActionDim::uniform(min, max, count as usize)
                    .map_err(|e| at.at(&t.action.span(), "action.uniform_v", e.to_string()))?
                    .values()
                    .to_vec(),
                MotorLevels::PerMotor(_) => unreachable!("[action] gives one list"),
            },
        };
        each.push(leak(values));
    }
    Ok(MotorLevels::PerMotor(leak(each)))
}

/// One `[[reward]]`: its `term` and exactly the fields that term takes.
fn reward_term(at: &Locator, names: &Names, r: &RewardSection, i: usize) -> Result<RewardTerm, RobotFileError> {
    let f = |field: &str| format!("reward[{i}].{field}");
    let term = r.term.get_ref().as_str();
    let span: Range<usize> = r.term.span();
    let given = [
        ("signal", r.signal.is_some()),
        ("target", r.target.is_some()),
        ("wrap", r.wrap.is_some()),
        ("point", r.point.is_some()),
        ("target_m", r.target_m.is_some()),
        ("axis", r.axis.is_some()),
        ("weight", r.weight.is_some()),
        ("value", r.value.is_some()),
    ];
    let takes: &[&str] = match term {
        "quadratic" => &["signal", "target", "wrap", "weight"],
        "distance" | "distance_squared" => &["point", "target_m", "weight"],
        "progress" => &["point", "axis", "weight"],
        "action" | "action_change" => &["weight"],
        "constant" => &["value"],
        other => {
            return Err(at.at(&span, f("term"), format!("{other:?} is not valid: quadratic, distance, distance_squared, progress, action, action_change or constant")))
        }
    };
    if let Some((extra, _)) = given.iter().find(|(name, set)| *set && !takes.contains(name)) {
        return Err(at.at(&span, f(extra), format!("a {term} term takes {}, not {extra}", takes.join(", "))));
    }
    let need = |field: &str, v: Option<f64>| v.ok_or_else(|| at.at(&span, f(field), format!("a {term} term needs {field}")));
    let need_name = |field: &str, v: &Option<Spanned<String>>| {
        v.clone().ok_or_else(|| at.at(&span, f(field), format!("a {term} term needs {field}")))
    };
    Ok(match term {
        "quadratic" => RewardTerm::Quadratic {
            signal: names.signal(at, &need_name("signal", &r.signal)?, &f("signal"))?,
            target: r.target.unwrap_or(0.0) as f32,
            weight: need("weight", r.weight)? as f32,
            wrap: r.wrap.unwrap_or(false),
        },
        "distance" => RewardTerm::Distance {
            point: names.point(at, &need_name("point", &r.point)?, &f("point"))?,
            target: r.target_m.ok_or_else(|| at.at(&span, f("target_m"), "a distance term needs target_m = [x, y, z]"))?.map(|v| v as f32),
            weight: need("weight", r.weight)? as f32,
        },
        "distance_squared" => RewardTerm::DistanceSquared {
            point: names.point(at, &need_name("point", &r.point)?, &f("point"))?,
            target: r.target_m.ok_or_else(|| at.at(&span, f("target_m"), "a distance_squared term needs target_m = [x, y, z]"))?.map(|v| v as f32),
            weight: need("weight", r.weight)? as f32,
        },
        "progress" => {
            let axis = need_name("axis", &r.axis)?;
            RewardTerm::Progress {
                point: names.point(at, &need_name("point", &r.point)?, &f("point"))?,
                axis: match axis.get_ref().as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    other => return Err(at.at(&axis.span(), f("axis"), format!("{other:?} is not valid: x, y or z"))),
                },
                weight: need("weight", r.weight)? as f32,
            }
        }
        "action" => RewardTerm::Action { weight: need("weight", r.weight)? as f32 },
        "action_change" => RewardTerm::ActionChange { weight: need("weight", r.weight)? as f32 },
        _ => RewardTerm::Constant { value: need("value", r.value)? as f32 },
    })
}
