//! The `/scene` channel: the robot drawn from the joint angles of each
//! `Step`, as a Foxglove `SceneUpdate` of line primitives.
//!
//! LEO's observation (`pada_core::robot::leo::observe`) holds the torso
//! angle φ and the stance and swing hips and knees. The stance leg starts
//! an episode on the left (the start pose) and changes at every footstep
//! (`Step::footstep`). The shoulder and the ankles are not in the
//! telemetry: they are drawn at their P laws' set points, where the held
//! joints are driven. The bodies are placed by the LEO model's own
//! forward kinematics ([`pada_sim::leo::model::assemble`]) from its anchors
//! (`pada_sim::leo::constants`), and the stance foot's heel stands on the
//! floor; at a footstep the new stance foot stays where it was, so a
//! walking robot moves forwards along x. The left leg is drawn at y =
//! +3 cm, the right at −3 cm.
//!
//! The pendulum's arm turns about the axis at the origin, θ = 0 upright,
//! to its centre of mass (`PhysicalPendulumParams::length_m`).

use pada_sim::leo::constants::{
    ANKLE_GAIN_SETPOINT, ARM_HAND, ARM_SHOULDER_ANCHOR, FOOT_ANKLE_ANCHOR, FOOT_HEEL, FOOT_TOE,
    INIT_LEFT_FOOT_POINT, SHANK_ANKLE_ANCHOR, SHANK_KNEE_ANCHOR, SHOULDER_GAIN_SETPOINT,
    THIGH_HIP_ANCHOR, THIGH_KNEE_ANCHOR, TORSO_HIP_ANCHOR, TORSO_SHOULDER_ANCHOR,
};
use pada_sim::leo::model::{assemble, Body, InitialPose};
use pada_core::robot::leo::Leg;
use pada_sim::robots::{sim_robot, Body as SimBody};
use pada_core::robot::RobotSpec;
use pada_core::wire::{Step, StepKind};

/// A point, written to 0.1 mm in the JSON (far finer than a viewer
/// shows).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3 {
    /// x \[m\] (forwards).
    pub x: f64,
    /// y \[m\] (left).
    pub y: f64,
    /// z \[m\] (up).
    pub z: f64,
}

/// A colour, 0–1 per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Opacity.
    pub a: f64,
}

/// One line strip of a scene: a body or a chain of bodies.
#[derive(Debug, Clone, PartialEq)]
pub struct Strip {
    /// What it is (`torso`, `left leg`, …).
    pub name: &'static str,
    /// Its points in order.
    pub points: Vec<Vec3>,
    /// Its colour.
    pub color: Color,
}

const TORSO: Color = Color { r: 0.25, g: 0.25, b: 0.25, a: 1.0 };
const ARM: Color = Color { r: 0.55, g: 0.35, b: 0.75, a: 1.0 };
const LEFT: Color = Color { r: 0.12, g: 0.47, b: 0.71, a: 1.0 };
const RIGHT: Color = Color { r: 1.0, g: 0.50, b: 0.05, a: 1.0 };
const FLOOR: Color = Color { r: 0.17, g: 0.63, b: 0.17, a: 1.0 };

/// Half a leg's lateral offset \[m\].
const LEG_Y: f64 = 0.03;

/// The bodies a scene draws: pada's two hand-built robots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RobotBody {
    Pendulum,
    Leo,
}

/// Draws the robot of a stream, step after step.
#[derive(Debug, Clone, Default)]
pub struct SceneBuilder {
    robot: Option<(RobotBody, &'static str)>,
    stance: Option<Leg>,
    /// World x of the stance heel.
    anchor_x: f64,
    /// World x of each heel in the last frame (left, right).
    heels: [f64; 2],
}

impl SceneBuilder {
    /// The robot is now this one (a `Hello`), or unknown.
    pub fn robot(&mut self, robot: Option<&'static RobotSpec>) {
        let body = |r| match sim_robot(r).ok()?.body {
            SimBody::Leo => Some(RobotBody::Leo),
            SimBody::Pendulum => Some(RobotBody::Pendulum),
            SimBody::Urdf(_) => None,
        };
        let robot = robot.and_then(|r| Some((body(r)?, r.name)));
        *self = SceneBuilder { robot, ..SceneBuilder::default() };
    }

    /// The scene of one step at log time `t` \[ns\] as `SceneUpdate` JSON;
    /// `None` for an unknown robot or a state too short for it.
    pub fn step(&mut self, s: &Step, t: u64) -> Option<Vec<u8>> {
        let strips = self.strips(s)?;
        Some(scene_json(&strips, t, self.robot?.1))
    }

    /// The strips of one step (also what the documentation's picture
    /// draws).
    pub fn strips(&mut self, s: &Step) -> Option<Vec<Strip>> {
        match self.robot?.0 {
            RobotBody::Leo => self.leo(s),
            RobotBody::Pendulum => pendulum(s),
        }
    }

    fn leo(&mut self, s: &Step) -> Option<Vec<Strip>> {
        let x = s.state.as_slice();
        if x.len() < pada_core::robot::leo::OBS_DIM {
            return None;
        }
        if s.kind == StepKind::Start || self.stance.is_none() {
            *self = SceneBuilder { robot: self.robot, ..SceneBuilder::default() };
            self.stance = Some(Leg::Left);
        } else if s.footstep {
            let new = self.stance.unwrap_or(Leg::Left).other();
            self.anchor_x = self.heels[new as usize];
            self.stance = Some(new);
        }
        let stance = self.stance.unwrap_or(Leg::Left);
        let [phi, _, hip_st, _, hip_sw, _, knee_st, _, knee_sw, _] =
            std::array::from_fn(|i| x[i]);
        let torso = -phi;
        let ankle = ANKLE_GAIN_SETPOINT[1];
        let leg = |hip: f32, knee: f32| {
            let thigh = torso - hip;
            let shank = thigh - knee;
            [thigh, shank, shank - ankle]
        };
        let (st, sw) = (leg(hip_st, knee_st), leg(hip_sw, knee_sw));
        let (left, right) = match stance {
            Leg::Left => (st, sw),
            Leg::Right => (sw, st),
        };
        let pose = InitialPose { torso, arm: torso - SHOULDER_GAIN_SETPOINT[1], left, right };
        let pitch = pose.body_pitches();
        let origin = assemble(&pose);
        let at = |b: Body, p: [f32; 2]| -> [f64; 2] {
            let (sn, c) = (pitch[b as usize] as f64).sin_cos();
            let o = origin[b as usize];
            let (px, pz) = (p[0] as f64, p[1] as f64);
            [o[0] as f64 + px * c + pz * sn, o[1] as f64 - px * sn + pz * c]
        };
        // The stance heel on the floor at anchor_x.
        let heel = |foot: Body| at(foot, INIT_LEFT_FOOT_POINT);
        let (hl, hr) = (heel(Body::FootLeft), heel(Body::FootRight));
        let h = if stance == Leg::Left { hl } else { hr };
        let shift = [self.anchor_x - h[0], -h[1]];
        self.heels = [hl[0] + shift[0], hr[0] + shift[0]];
        let p = |b: Body, pt: [f32; 2], y: f64| {
            let w = at(b, pt);
            Vec3 { x: w[0] + shift[0], y, z: w[1] + shift[1] }
        };
        let leg_strip = |name, thigh, shank, foot, y, color| Strip {
            name,
            points: vec![
                p(thigh, THIGH_HIP_ANCHOR, y),
                p(thigh, THIGH_KNEE_ANCHOR, y),
                p(shank, SHANK_KNEE_ANCHOR, y),
                p(shank, SHANK_ANKLE_ANCHOR, y),
                p(foot, FOOT_ANKLE_ANCHOR, y),
                p(foot, FOOT_HEEL, y),
                p(foot, FOOT_TOE, y),
                p(foot, FOOT_ANKLE_ANCHOR, y),
            ],
            color,
        };
        let floor_x = self.anchor_x;
        Some(vec![
            Strip {
                name: "floor",
                points: vec![
                    Vec3 { x: floor_x - 0.4, y: 0.0, z: 0.0 },
                    Vec3 { x: floor_x + 0.4, y: 0.0, z: 0.0 },
                ],
                color: FLOOR,
            },
            leg_strip("left leg", Body::ThighLeft, Body::ShankLeft, Body::FootLeft, LEG_Y, LEFT),
            leg_strip("right leg", Body::ThighRight, Body::ShankRight, Body::FootRight, -LEG_Y, RIGHT),
            Strip {
                name: "torso",
                points: vec![p(Body::Torso, TORSO_HIP_ANCHOR, 0.0), p(Body::Torso, TORSO_SHOULDER_ANCHOR, 0.0)],
                color: TORSO,
            },
            Strip {
                name: "arm",
                points: vec![p(Body::Arm, ARM_SHOULDER_ANCHOR, 0.0), p(Body::Arm, ARM_HAND, 0.0)],
                color: ARM,
            },
        ])
    }
}

fn pendulum(s: &Step) -> Option<Vec<Strip>> {
    let theta = *s.state.first()? as f64;
    let l = pada_sim::pendulum::PhysicalPendulumParams::default().length_m;
    let tip = Vec3 { x: l * theta.sin(), y: 0.0, z: l * theta.cos() };
    let origin = Vec3 { x: 0.0, y: 0.0, z: 0.0 };
    Some(vec![
        Strip {
            name: "base",
            points: vec![Vec3 { x: -0.5 * l, y: 0.0, z: -1.2 * l }, origin, Vec3 { x: 0.5 * l, y: 0.0, z: -1.2 * l }],
            color: TORSO,
        },
        Strip { name: "arm", points: vec![origin, tip], color: RIGHT },
    ])
}

/// The `SceneUpdate` JSON of one frame, written directly: it is most of a
/// recording's bytes, and serde's map serialisation and float formatting
/// were most of the cost of `--mcap` (docs/foxglove.md, "Costs"). The
/// Python test validates it against the schema.
fn scene_json(strips: &[Strip], t: u64, name: &str) -> Vec<u8> {
    use std::io::Write as _;
    let mut v = Vec::with_capacity(256 + strips.len() * 400);
    let (sec, nsec) = (t / 1_000_000_000, t % 1_000_000_000);
    let _ = write!(
        v,
        r#"{{"deletions":[],"entities":[{{"timestamp":{{"sec":{sec},"nsec":{nsec}}},"frame_id":"world","id":"{name}","lifetime":{{"sec":0,"nsec":0}},"frame_locked":false,"metadata":[{{"key":"robot","value":"{name}"}}],"arrows":[],"cubes":[],"spheres":[],"cylinders":[],"lines":["#
    );
    for (i, s) in strips.iter().enumerate() {
        if i > 0 {
            v.push(b',');
        }
        let thickness = if s.name == "floor" { "0.004" } else { "0.012" };
        let _ = write!(
            v,
            r#"{{"type":0,"pose":{{"position":{{"x":0,"y":0,"z":0}},"orientation":{{"x":0,"y":0,"z":0,"w":1}}}},"thickness":{thickness},"scale_invariant":false,"points":["#
        );
        for (k, p) in s.points.iter().enumerate() {
            if k > 0 {
                v.push(b',');
            }
            v.extend_from_slice(br#"{"x":"#);
            tenth_mm(&mut v, p.x);
            v.extend_from_slice(br#","y":"#);
            tenth_mm(&mut v, p.y);
            v.extend_from_slice(br#","z":"#);
            tenth_mm(&mut v, p.z);
            v.push(b'}');
        }
        let c = s.color;
        let _ = write!(v, r#"],"color":{{"r":{},"g":{},"b":{},"a":{}}},"colors":[],"indices":[]}}"#, c.r, c.g, c.b, c.a);
    }
    v.extend_from_slice(br#"],"triangles":[],"texts":[],"models":[]}]}"#);
    v
}

/// Writes metres as a JSON number to 0.1 mm (integer arithmetic; a value
/// that is not finite, which the kinematics cannot give, is written 0).
fn tenth_mm(v: &mut Vec<u8>, m: f64) {
    use std::io::Write as _;
    let n = if m.is_finite() { (m * 1e4).round().clamp(-1e15, 1e15) as i64 } else { 0 };
    if n < 0 {
        v.push(b'-');
    }
    let a = n.unsigned_abs();
    let _ = write!(v, "{}.{:04}", a / 10_000, a % 10_000);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metres_to_a_tenth_of_a_millimetre() {
        for (m, s) in [(0.0, "0.0000"), (0.12345, "0.1235"), (-0.0405, "-0.0405"), (1.5, "1.5000"), (-0.00004, "0.0000"), (f64::NAN, "0.0000")] {
            let mut v = Vec::new();
            tenth_mm(&mut v, m);
            assert_eq!(String::from_utf8(v).unwrap(), s, "{m}");
        }
    }

    #[test]
    fn a_leo_step_is_drawn_as_five_strips_of_valid_json() {
        let mut b = SceneBuilder::default();
        b.robot(Some(&pada_core::robot::leo::SPEC));
        let mut s = Step {
            step: 0, time_ms: 1500, episode: 0, mode: pada_core::wire::RunMode::Learning, kind: StepKind::Start,
            state: heapless::Vec::new(), action: 0, output: heapless::Vec::new(), reward: 0.0, td_error: 0,
            explored: false, footstep: false, joints: heapless::Vec::new(), loop_us: 0, agent_cycles: 0,
        };
        assert!(b.step(&s, 0).is_none(), "a state too short is not drawn");
        for x in [-0.1f32, 0.0, 0.1, 0.0, 0.82, 0.0, 0.0, 0.0, -1.27, 0.0] {
            s.state.push(x).unwrap();
        }
        let json = b.step(&s, 1_500_000_000).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        let e = &v["entities"][0];
        assert_eq!(e["timestamp"]["sec"], 1);
        assert_eq!(e["timestamp"]["nsec"], 500_000_000);
        let lines = e["lines"].as_array().unwrap();
        assert_eq!(lines.len(), 5);
        // The stance (left) heel's wheel on the floor: its centre one
        // wheel radius (3.5 mm) up.
        let left = &lines[1]["points"];
        let heel_z = left[5]["z"].as_f64().unwrap() as f32;
        assert!((heel_z - pada_sim::leo::constants::WHEEL_RADIUS).abs() < 2e-4, "{left}");
        // The thigh is the model's: hip to knee anchor.
        let thigh = left[0]["z"].as_f64().unwrap() - left[1]["z"].as_f64().unwrap();
        let want = (pada_sim::leo::constants::THIGH_HIP_ANCHOR[1] - pada_sim::leo::constants::THIGH_KNEE_ANCHOR[1]) as f64;
        assert!((thigh - want).abs() < 2e-4, "{thigh} {want}");
        // The hips of both legs meet at the torso's hip anchor.
        assert_eq!(lines[1]["points"][0]["x"], lines[2]["points"][0]["x"]);
    }
}
