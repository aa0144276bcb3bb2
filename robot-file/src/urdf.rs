//! The robot's body as its URDF describes it (read by `urdf-rs`, the
//! parser rapier3d-urdf uses): its joints, their types and origins, and the
//! chain of joints from the fixed base to any link.

use crate::error::RobotFileError;
use pada_core::robot::vocabulary::ChainJoint;
use std::path::{Path, PathBuf};
use urdf_rs::{Joint, JointType, Robot};

/// A URDF, read and checked: one root link, and a tree of joints.
#[derive(Debug, Clone)]
pub struct Urdf {
    /// Where it was read from.
    pub path: PathBuf,
    /// What urdf-rs read.
    pub robot: Robot,
}

impl Urdf {
    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<Urdf, RobotFileError> {
        let err = |message: String| RobotFileError { file: path.to_path_buf(), at: None, field: String::new(), message };
        let text = std::fs::read_to_string(path).map_err(|e| err(format!("cannot read it ({e})")))?;
        let robot = urdf_rs::read_from_string(&text).map_err(|e| err(format!("not a URDF urdf-rs reads: {e}")))?;
        let urdf = Urdf { path: path.to_path_buf(), robot };
        urdf.root().map_err(err)?;
        for j in &urdf.robot.joints {
            for (end, link) in [("parent", &j.parent.link), ("child", &j.child.link)] {
                if !urdf.robot.links.iter().any(|l| &l.name == link) {
                    return Err(err(format!("joint {:?}'s {end} link {link:?} is no link of the URDF", j.name)));
                }
            }
        }
        Ok(urdf)
    }

    /// The one link that is no joint's child: the fixed base.
    pub fn root(&self) -> Result<&str, String> {
        let roots: Vec<&str> = self
            .robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|l| !self.robot.joints.iter().any(|j| j.child.link == *l))
            .collect();
        match roots.as_slice() {
            [one] => Ok(one),
            [] => Err("every link is a joint's child: the URDF has no root".into()),
            many => Err(format!("the URDF has {} root links ({}): a robot is one tree", many.len(), many.join(", "))),
        }
    }

    /// The joint called `name`.
    pub fn joint(&self, name: &str) -> Option<&Joint> {
        self.robot.joints.iter().find(|j| j.name == name)
    }

    /// The joints that move (every type but `fixed`).
    pub fn moving_joints(&self) -> impl Iterator<Item = &Joint> {
        self.robot.joints.iter().filter(|j| !matches!(j.joint_type, JointType::Fixed))
    }

    /// Whether a link of this name exists.
    pub fn has_link(&self, name: &str) -> bool {
        self.robot.links.iter().any(|l| l.name == name)
    }

    /// The joints from the root to `link`, root first.
    pub fn chain_to(&self, link: &str) -> Vec<&Joint> {
        let mut chain = Vec::new();
        let mut at = link;
        // A tree has at most as many joints on a path as it has joints.
        while let Some(j) = self.robot.joints.iter().find(|j| j.child.link == at) {
            chain.push(j);
            at = &j.parent.link;
            if chain.len() > self.robot.joints.len() {
                break;
            }
        }
        chain.reverse();
        chain
    }

    /// The chain of `link` as forward kinematics takes it: each joint's
    /// origin and unit axis, and for a moving joint its index among the
    /// robot's joints (`index_of` maps a URDF joint name to it).
    pub fn kinematic_chain(&self, link: &str, index_of: impl Fn(&str) -> Option<u8>) -> Vec<ChainJoint> {
        self.chain_to(link)
            .into_iter()
            .map(|j| {
                let [x, y, z] = j.axis.xyz.0;
                let n = (x * x + y * y + z * z).sqrt();
                let axis = if n > 0.0 { [x / n, y / n, z / n] } else { [1.0, 0.0, 0.0] };
                ChainJoint {
                    xyz: j.origin.xyz.0.map(|v| v as f32),
                    rpy: j.origin.rpy.0.map(|v| v as f32),
                    joint: match j.joint_type {
                        JointType::Fixed => None,
                        _ => index_of(&j.name),
                    },
                    axis: axis.map(|v| v as f32),
                }
            })
            .collect()
    }
}

/// Why a joint of this type cannot be a servo's, if it cannot.
pub fn servo_joint_type(t: &JointType) -> Result<(), &'static str> {
    match t {
        JointType::Revolute | JointType::Continuous => Ok(()),
        JointType::Fixed => Err("a fixed joint does not move"),
        JointType::Prismatic => Err("a prismatic joint slides; a servo turns (revolute or continuous)"),
        JointType::Floating => Err("a floating joint has six degrees of freedom; a servo turns one (revolute or continuous)"),
        JointType::Planar => Err("a planar joint has three degrees of freedom; a servo turns one (revolute or continuous)"),
        JointType::Spherical => Err("a spherical joint has three degrees of freedom; a servo turns one (revolute or continuous)"),
    }
}
