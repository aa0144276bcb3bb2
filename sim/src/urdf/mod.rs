//! A robot of the user's own, from its `robot.toml` and URDF
//! (`pada_robot_file`): its body in rapier ([`UrdfBody`], inserted by
//! rapier3d-urdf as multibody joints), the plant of the experiment runner
//! that drives it through the robot's rules ([`RulesPlant`], [`UrdfTask`]),
//! and the rig behind a board's servos ([`UrdfRig`]).

mod body;
mod plant;
mod rig;
#[cfg(test)]
mod tests;

pub use body::{BlowUp, UrdfBody, UrdfModel, GRAVITY};
pub use plant::{RulesPlant, UrdfTask};
pub use rig::{UrdfOnRig, UrdfRig};
