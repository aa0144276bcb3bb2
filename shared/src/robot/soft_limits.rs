//! A robot's soft limits, checked the same way wherever it runs. On the
//! board the safety machine sees every joint reading and faults past a
//! soft limit (torque off, until an operator clears it); the host's
//! simulation of a robot asks [`RobotSpec::soft_limit_fault`] of every
//! simulated reading and ends the run there too. Both go through
//! [`crate::safety::SoftLimit::fault`], joint by joint in joint order, so
//! the same reading faults on both with the same cause.

use super::RobotSpec;
use crate::safety::FaultCause;

impl RobotSpec {
    /// The fault the safety machine raises at these joint readings (in
    /// joint order, `None` for a servo that did not answer): the first
    /// joint past its soft limit, or whose reading is not finite.
    pub fn soft_limit_fault(&self, angles: &[Option<f32>]) -> Option<FaultCause> {
        self.joints.iter().zip(angles).enumerate().find_map(|(i, (joint, angle))| {
            let (limit, angle) = (joint.soft_limit?, (*angle)?);
            limit.fault(i as u8, angle)
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use crate::robot::{leo, pendulum};
    use std::vec::Vec;
    use crate::safety::{Event, FaultCause, Safety, SafetyConfig, SoftLimit};

    #[test]
    fn the_first_joint_past_its_limit_faults_as_the_safety_machine_does() {
        let spec = &leo::SPEC;
        let limits: heapless::Vec<SoftLimit, 8> = spec.joints.iter().map_while(|j| j.soft_limit).collect();
        let inside: Vec<Option<f32>> = limits.iter().map(|l| Some(0.5 * (l.min + l.max))).collect();
        assert_eq!(spec.soft_limit_fault(&inside), None);
        for (k, past) in [(2usize, limits[2].max + 0.01), (4, limits[4].min - 0.01), (1, f32::NAN)] {
            let mut angles = inside.clone();
            angles[k] = Some(past);
            // A later joint past its limit too: the first is the cause.
            angles[5] = Some(limits[5].max + 1.0);
            let fault = spec.soft_limit_fault(&angles).unwrap();
            let mut safety = Safety::new(SafetyConfig { soft_limits: limits.clone(), ..SafetyConfig::default() }).unwrap();
            let board = angles.iter().enumerate().find_map(|(j, a)| {
                safety.on(Event::JointPosition { joint: j as u8, position: a.unwrap() }).entered_fault()
            });
            match (fault, board) {
                (FaultCause::SoftLimit { joint, position }, Some(FaultCause::SoftLimit { joint: j, position: p })) => {
                    assert_eq!((joint, j), (k as u8, k as u8));
                    assert!(position.to_bits() == p.to_bits());
                }
                other => panic!("{other:?}"),
            }
        }
        // A servo that did not answer is no reading; a joint without
        // limits never faults.
        let mut angles = inside.clone();
        angles[2] = None;
        assert_eq!(spec.soft_limit_fault(&angles), None);
        assert_eq!(pendulum::SPEC_33HZ.soft_limit_fault(&[Some(100.0)]), None);
    }
}
