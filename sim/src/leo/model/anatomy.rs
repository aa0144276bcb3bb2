//! LEO's anatomy: the bodies and hinges of `docs`' §1.3 and §1.5 as tables,
//! the starting pose of §1.8 and the planar forward kinematics that
//! assembles it.

use rapier3d::prelude::*;

use super::super::constants::*;

/// The eight bodies of LEO (§1.3; GRL's `virtualBoom` is not needed).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// Torso with the boom folded in.
    Torso = 0,
    /// Arm (shoulder link).
    Arm,
    /// Left upper leg.
    ThighLeft,
    /// Left lower leg.
    ShankLeft,
    /// Left foot.
    FootLeft,
    /// Right upper leg.
    ThighRight,
    /// Right lower leg.
    ShankRight,
    /// Right foot.
    FootRight,
}

/// Number of bodies.
pub const NUM_BODIES: usize = 8;

/// The seven servo joints (§1.5), in the order of the robot's one
/// definition (`pada_core::robot::leo`), which the firmware's servo table
/// uses too.
pub use pada_core::robot::leo::{Joint, JOINTS, NUM_JOINTS};

/// Contact material (§1.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Material {
    Rubber,
    Foam,
}

/// Mass properties and contact spheres of one body (§1.3, §1.6).
pub(super) struct BodySpec {
    pub(super) mass: f32,
    pub(super) iyy: f32,
    pub(super) com: [f32; 2],
    pub(super) spheres: &'static [([f32; 2], f32, Material)],
}

const TORSO_SPHERES: [([f32; 2], f32, Material); 3] = [
    (TORSO_ASS_PAMPER.0, TORSO_ASS_PAMPER.1, Material::Foam),
    (
        TORSO_SHOULDER_FRONT.0,
        TORSO_SHOULDER_FRONT.1,
        Material::Foam,
    ),
    (TORSO_SHOULDER_BACK.0, TORSO_SHOULDER_BACK.1, Material::Foam),
];
const ARM_SPHERES: [([f32; 2], f32, Material); 1] = [(ARM_HAND, WHEEL_RADIUS, Material::Rubber)];
const SHANK_SPHERES: [([f32; 2], f32, Material); 1] =
    [(SHANK_KNEE_SPHERE, WHEEL_RADIUS, Material::Rubber)];
/// Toe first, heel second (the contact sensors rely on this order).
const FOOT_SPHERES: [([f32; 2], f32, Material); 2] = [
    (FOOT_TOE, WHEEL_RADIUS, Material::Rubber),
    (FOOT_HEEL, WHEEL_RADIUS, Material::Rubber),
];

const fn thigh() -> BodySpec {
    BodySpec {
        mass: THIGH_MASS,
        iyy: THIGH_IYY,
        com: THIGH_COM,
        spheres: &[],
    }
}
const fn shank() -> BodySpec {
    BodySpec {
        mass: SHANK_MASS,
        iyy: SHANK_IYY,
        com: SHANK_COM,
        spheres: &SHANK_SPHERES,
    }
}
const fn foot() -> BodySpec {
    BodySpec {
        mass: FOOT_MASS,
        iyy: FOOT_IYY,
        com: FOOT_COM,
        spheres: &FOOT_SPHERES,
    }
}

/// Bodies in [`Body`] order (§1.3, §1.6).
pub(super) const BODY_SPECS: [BodySpec; NUM_BODIES] = [
    BodySpec {
        mass: TORSO_MASS,
        iyy: TORSO_IYY,
        com: TORSO_COM,
        spheres: &TORSO_SPHERES,
    },
    BodySpec {
        mass: ARM_MASS,
        iyy: ARM_IYY,
        com: ARM_COM,
        spheres: &ARM_SPHERES,
    },
    thigh(),
    shank(),
    foot(),
    thigh(),
    shank(),
    foot(),
];

/// One hinge (§1.3 anchors, §1.5 limits and stops).
pub(super) struct JointSpec {
    pub(super) parent: Body,
    pub(super) child: Body,
    pub(super) parent_anchor: [f32; 2],
    pub(super) child_anchor: [f32; 2],
    /// The stop's spring and damper [K, D], at the joint's limits
    /// ([`joint_limits`], the robot's one definition); `None` for the
    /// unlimited shoulder.
    pub(super) stop: Option<[f32; 2]>,
}

/// Joints in [`Joint`] order.
pub(super) const JOINT_SPECS: [JointSpec; NUM_JOINTS] = [
    JointSpec {
        parent: Body::Torso,
        child: Body::Arm,
        parent_anchor: TORSO_SHOULDER_ANCHOR,
        child_anchor: ARM_SHOULDER_ANCHOR,
        stop: None,
    },
    JointSpec {
        parent: Body::Torso,
        child: Body::ThighLeft,
        parent_anchor: TORSO_HIP_ANCHOR,
        child_anchor: THIGH_HIP_ANCHOR,
        stop: Some(HIP_STOP),
    },
    JointSpec {
        parent: Body::Torso,
        child: Body::ThighRight,
        parent_anchor: TORSO_HIP_ANCHOR,
        child_anchor: THIGH_HIP_ANCHOR,
        stop: Some(HIP_STOP),
    },
    JointSpec {
        parent: Body::ThighLeft,
        child: Body::ShankLeft,
        parent_anchor: THIGH_KNEE_ANCHOR,
        child_anchor: SHANK_KNEE_ANCHOR,
        stop: Some(KNEE_STOP),
    },
    JointSpec {
        parent: Body::ThighRight,
        child: Body::ShankRight,
        parent_anchor: THIGH_KNEE_ANCHOR,
        child_anchor: SHANK_KNEE_ANCHOR,
        stop: Some(KNEE_STOP),
    },
    JointSpec {
        parent: Body::ShankLeft,
        child: Body::FootLeft,
        parent_anchor: SHANK_ANKLE_ANCHOR,
        child_anchor: FOOT_ANKLE_ANCHOR,
        stop: Some(ANKLE_STOP),
    },
    JointSpec {
        parent: Body::ShankRight,
        child: Body::FootRight,
        parent_anchor: SHANK_ANKLE_ANCHOR,
        child_anchor: FOOT_ANKLE_ANCHOR,
        stop: Some(ANKLE_STOP),
    },
];

pub use pada_core::robot::leo::joint_limits;

/// Joint `k`'s limits and its stop's [K, D], when it has a stop.
pub(super) fn limits_and_stop(k: usize) -> Option<([f32; 2], [f32; 2])> {
    joint_limits(JOINTS[k]).zip(JOINT_SPECS[k].stop)
}

/// Absolute body pitches of a starting pose (§1.8). All velocities are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialPose {
    /// Torso pitch (rad about +y).
    pub torso: f32,
    /// Arm pitch.
    pub arm: f32,
    /// Left thigh, shank, foot pitches.
    pub left: [f32; 3],
    /// Right thigh, shank, foot pitches.
    pub right: [f32; 3],
}

impl InitialPose {
    /// The reference starting pose (§1.8): left leg straight on the floor,
    /// right leg lifted with the knee bent.
    pub const REFERENCE: InitialPose = InitialPose {
        torso: INIT_TORSO_PITCH,
        arm: INIT_ARM_PITCH,
        left: INIT_LEFT_LEG_PITCH,
        right: INIT_RIGHT_LEG_PITCH,
    };

    /// Absolute pitch of each body, in [`Body`] order.
    pub fn body_pitches(&self) -> [f32; NUM_BODIES] {
        [
            self.torso,
            self.arm,
            self.left[0],
            self.left[1],
            self.left[2],
            self.right[0],
            self.right[1],
            self.right[2],
        ]
    }

    /// Hinge angles q = θ_parent − θ_child (§1.2), in [`Joint`] order.
    pub fn joint_angles(&self) -> [f32; NUM_JOINTS] {
        let p = self.body_pitches();
        JOINT_SPECS.map(|j| p[j.parent as usize] - p[j.child as usize])
    }

    /// Whether every pitch is finite.
    pub fn is_finite(&self) -> bool {
        self.body_pitches().iter().all(|x| x.is_finite())
    }
}

/// Rotates a body point (x, z) by pitch θ about +y (§1.2).
pub(super) fn rotate(theta: f32, p: [f32; 2]) -> [f32; 2] {
    let (s, c) = theta.sin_cos();
    [p[0] * c + p[1] * s, -p[0] * s + p[1] * c]
}

/// Planar forward kinematics of the assembly rule of §1.8: each child
/// anchor on its parent's anchor, then the whole robot shifted so that the
/// bottom of the left heel wheel is at the origin. Returns the world (x, z)
/// of every body's origin.
pub fn assemble(pose: &InitialPose) -> [[f32; 2]; NUM_BODIES] {
    let pitch = pose.body_pitches();
    let mut origin = [[0.0f32; 2]; NUM_BODIES];
    // Joints are listed parent-before-child.
    for j in &JOINT_SPECS {
        let (p, c) = (j.parent as usize, j.child as usize);
        let a = rotate(pitch[p], j.parent_anchor);
        let b = rotate(pitch[c], j.child_anchor);
        origin[c] = [origin[p][0] + a[0] - b[0], origin[p][1] + a[1] - b[1]];
    }
    let foot = Body::FootLeft as usize;
    let heel = rotate(pitch[foot], INIT_LEFT_FOOT_POINT);
    let shift = [origin[foot][0] + heel[0], origin[foot][1] + heel[1]];
    origin.map(|o| [o[0] - shift[0], o[1] - shift[1]])
}

/// A body's world pose from its origin (x, z) and pitch.
pub(super) fn body_pose(origin: [f32; 2], pitch: f32) -> Pose {
    Pose::from_parts(
        Vector::new(origin[0], 0.0, origin[1]),
        Rotation::from_rotation_y(pitch),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_models_stops_are_the_robot_definitions() {
        for (k, joint) in JOINTS.iter().enumerate() {
            assert_eq!(
                limits_and_stop(k).map(|(limits, _)| limits),
                pada_core::robot::leo::joint_limits(*joint),
                "{joint:?}: the simulated stop is not the definition's"
            );
        }
    }

    #[test]
    fn every_joint_with_limits_has_a_stop_and_only_those() {
        for (k, joint) in JOINTS.iter().enumerate() {
            assert_eq!(
                joint_limits(*joint).is_some(),
                JOINT_SPECS[k].stop.is_some(),
                "{joint:?}: limits and stop spring disagree"
            );
        }
    }
}
