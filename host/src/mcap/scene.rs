//! The `/scene` channel: the robot drawn from the joint angles of each
//! `Step`, as a Foxglove `SceneUpdate` of line primitives.
//!
//! LEO's observation (`pada_core::robot::leo::observe`) holds the torso
//! angle φ and the stance and swing hips and knees. The stance leg starts
//! an episode on the left (the start pose) and changes at every footstep
//! (`Step::footstep`). The shoulder and the ankles are not in the
//! telemetry: they are drawn at their P laws' set points, where the held
//! joints are driven. The bodies are placed by the LEO model's own
//! forward kinematics ([`crate::leo::model::assemble`]) from its anchors
//! (`crate::leo::constants`), and the stance foot's heel stands on the
//! floor; at a footstep the new stance foot stays where it was, so a
//! walking robot moves forwards along x. The left leg is drawn at y =
//! +3 cm, the right at −3 cm.
//!
//! The pendulum's arm turns about the axis at the origin, θ = 0 upright,
//! to its centre of mass (`PhysicalPendulumParams::length_m`).

use super::channels::json;
use crate::leo::constants::{
    ANKLE_GAIN_SETPOINT, ARM_HAND, ARM_SHOULDER_ANCHOR, FOOT_ANKLE_ANCHOR, FOOT_HEEL, FOOT_TOE,
    INIT_LEFT_FOOT_POINT, SHANK_ANKLE_ANCHOR, SHANK_KNEE_ANCHOR, SHOULDER_GAIN_SETPOINT,
    THIGH_HIP_ANCHOR, THIGH_KNEE_ANCHOR, TORSO_HIP_ANCHOR, TORSO_SHOULDER_ANCHOR,
};
use crate::leo::model::{assemble, Body, InitialPose};
use pada_core::robot::leo::Leg;
use pada_core::robot::Robot;
use pada_core::wire::{Step, StepKind};
use serde::Serialize;

/// A point or vector, rounded to 0.1 mm when serialized (shorter JSON;
/// far finer than a viewer shows).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Vec3 {
    #[serde(serialize_with = "tenth_mm")]
    /// x \[m\] (forwards).
    pub x: f64,
    /// y \[m\] (left).
    #[serde(serialize_with = "tenth_mm")]
    pub y: f64,
    /// z \[m\] (up).
    #[serde(serialize_with = "tenth_mm")]
    pub z: f64,
}

fn tenth_mm<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64((v * 1e4).round() / 1e4)
}

/// A colour, 0–1 per channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
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

#[derive(Debug, Clone, Copy, Serialize)]
struct Quat {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Debug, Clone, Copy, Serialize)]
struct Pose {
    position: Vec3,
    orientation: Quat,
}

const IDENTITY: Pose = Pose {
    position: Vec3 { x: 0.0, y: 0.0, z: 0.0 },
    orientation: Quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
};

/// Foxglove's `Time` and `Duration`.
#[derive(Debug, Clone, Copy, Serialize)]
struct Time {
    sec: u64,
    nsec: u32,
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

#[derive(Serialize)]
struct Line<'a> {
    #[serde(rename = "type")]
    kind: u8,
    pose: Pose,
    thickness: f64,
    scale_invariant: bool,
    points: &'a [Vec3],
    color: Color,
    colors: [Color; 0],
    indices: [u32; 0],
}

#[derive(Serialize)]
struct KeyValue<'a> {
    key: &'a str,
    value: &'a str,
}

#[derive(Serialize)]
struct Entity<'a> {
    timestamp: Time,
    frame_id: &'a str,
    id: &'a str,
    lifetime: Time,
    frame_locked: bool,
    metadata: Vec<KeyValue<'a>>,
    arrows: [u8; 0],
    cubes: [u8; 0],
    spheres: [u8; 0],
    cylinders: [u8; 0],
    lines: Vec<Line<'a>>,
    triangles: [u8; 0],
    texts: [u8; 0],
    models: [u8; 0],
}

#[derive(Serialize)]
struct SceneUpdate<'a> {
    deletions: [u8; 0],
    entities: [Entity<'a>; 1],
}

const TORSO: Color = Color { r: 0.25, g: 0.25, b: 0.25, a: 1.0 };
const ARM: Color = Color { r: 0.55, g: 0.35, b: 0.75, a: 1.0 };
const LEFT: Color = Color { r: 0.12, g: 0.47, b: 0.71, a: 1.0 };
const RIGHT: Color = Color { r: 1.0, g: 0.50, b: 0.05, a: 1.0 };
const FLOOR: Color = Color { r: 0.17, g: 0.63, b: 0.17, a: 1.0 };

/// Half a leg's lateral offset \[m\].
const LEG_Y: f64 = 0.03;

/// Draws the robot of a stream, step after step.
#[derive(Debug, Clone, Default)]
pub struct SceneBuilder {
    robot: Option<Robot>,
    stance: Option<Leg>,
    /// World x of the stance heel.
    anchor_x: f64,
    /// World x of each heel in the last frame (left, right).
    heels: [f64; 2],
}

impl SceneBuilder {
    /// The robot is now this one (a `Hello`), or unknown.
    pub fn robot(&mut self, robot: Option<Robot>) {
        *self = SceneBuilder { robot, ..SceneBuilder::default() };
    }

    /// The scene of one step at log time `t` \[ns\] as `SceneUpdate` JSON;
    /// `None` for an unknown robot or a state too short for it.
    pub fn step(&mut self, s: &Step, t: u64) -> Option<Vec<u8>> {
        let strips = self.strips(s)?;
        Some(scene_json(&strips, t, self.robot?))
    }

    /// The strips of one step (also what the documentation's picture
    /// draws).
    pub fn strips(&mut self, s: &Step) -> Option<Vec<Strip>> {
        match self.robot? {
            Robot::Leo => self.leo(s),
            Robot::Pendulum33 | Robot::Pendulum20 => pendulum(s),
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
    let l = crate::pendulum::PhysicalPendulumParams::default().length_m;
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

fn scene_json(strips: &[Strip], t: u64, robot: Robot) -> Vec<u8> {
    let lines = strips
        .iter()
        .map(|s| Line {
            kind: 0,
            pose: IDENTITY,
            thickness: if s.name == "floor" { 0.004 } else { 0.012 },
            scale_invariant: false,
            points: &s.points,
            color: s.color,
            colors: [],
            indices: [],
        })
        .collect();
    let time = Time { sec: t / 1_000_000_000, nsec: (t % 1_000_000_000) as u32 };
    json(&SceneUpdate {
        deletions: [],
        entities: [Entity {
            timestamp: time,
            frame_id: "world",
            id: robot.name(),
            lifetime: Time { sec: 0, nsec: 0 },
            frame_locked: false,
            metadata: vec![KeyValue { key: "robot", value: robot.name() }],
            arrows: [],
            cubes: [],
            spheres: [],
            cylinders: [],
            lines,
            triangles: [],
            texts: [],
            models: [],
        }],
    })
}
