//! Forward kinematics of a robot with a fixed base, as its URDF describes
//! it: each joint's origin (a translation, then roll–pitch–yaw about the
//! fixed x, y, z axes, URDF's convention) in its parent link's frame, and
//! a revolute joint's rotation about its axis. The chip computes a point's
//! position from the joint angles it measures; the host's simulation of the
//! same URDF (rapier) puts the link there too, and a test of the host
//! compares the two.
//!
//! `f32` and `libm`, as the rest of the chip's rules; a chain has at most
//! [`MAX_CHAIN`] joints.

/// Joints from the base to a point, at most.
pub const MAX_CHAIN: usize = 8;

/// A rotation (row-major 3×3) and a translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The rotation: `r[i][j]` is row i, column j.
    pub r: [[f32; 3]; 3],
    /// The translation \[m\].
    pub t: [f32; 3],
}

impl Pose {
    /// No rotation, no translation.
    pub const IDENTITY: Pose = Pose { r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], t: [0.0; 3] };

    /// URDF's `<origin xyz rpy>`: rotation `Rz(yaw)·Ry(pitch)·Rx(roll)`,
    /// then the translation.
    pub fn from_xyz_rpy(xyz: [f32; 3], rpy: [f32; 3]) -> Pose {
        let (sr, cr) = (libm::sinf(rpy[0]), libm::cosf(rpy[0]));
        let (sp, cp) = (libm::sinf(rpy[1]), libm::cosf(rpy[1]));
        let (sy, cy) = (libm::sinf(rpy[2]), libm::cosf(rpy[2]));
        Pose {
            r: [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ],
            t: xyz,
        }
    }

    /// A rotation by `angle` about the unit `axis` (Rodrigues).
    pub fn about_axis(axis: [f32; 3], angle: f32) -> Pose {
        let (s, c) = (libm::sinf(angle), libm::cosf(angle));
        let [x, y, z] = axis;
        let v = 1.0 - c;
        Pose {
            r: [
                [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
                [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
                [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
            ],
            t: [0.0; 3],
        }
    }

    /// `self · other`: `other`'s frame expressed through this one.
    pub fn then(&self, other: &Pose) -> Pose {
        let mut r = [[0.0f32; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = self.r[i][0] * other.r[0][j] + self.r[i][1] * other.r[1][j] + self.r[i][2] * other.r[2][j];
            }
        }
        Pose { r, t: self.apply(other.t) }
    }

    /// The point `p` of this frame in the parent frame.
    pub fn apply(&self, p: [f32; 3]) -> [f32; 3] {
        let mut out = self.t;
        for i in 0..3 {
            out[i] += self.r[i][0] * p[0] + self.r[i][1] * p[1] + self.r[i][2] * p[2];
        }
        out
    }
}

/// One URDF joint on the way from the base to a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainJoint {
    /// The joint's origin in its parent link: translation \[m\].
    pub xyz: [f32; 3],
    /// The joint's origin in its parent link: roll, pitch, yaw \[rad\].
    pub rpy: [f32; 3],
    /// The robot's joint (its index in [`crate::robot::RobotSpec::joints`])
    /// that turns here about [`axis`](Self::axis); `None` for a fixed
    /// joint.
    pub joint: Option<u8>,
    /// The unit axis of a revolute joint, in the joint's frame.
    pub axis: [f32; 3],
}

/// A point of the robot: where it is on which link, through which joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Its name (`robot.toml` names it, e.g. `tip`).
    pub name: &'static str,
    /// The joints from the base to its link, base first (at most
    /// [`MAX_CHAIN`]).
    pub chain: &'static [ChainJoint],
    /// The point in its link's frame \[m\].
    pub offset: [f32; 3],
}

impl Point {
    /// The point in the base frame for the joint angles `angles` (indexed
    /// by the robot's joints; a joint past them reads 0).
    pub fn position(&self, angles: &[f32]) -> [f32; 3] {
        let mut pose = Pose::IDENTITY;
        for link in self.chain.iter().take(MAX_CHAIN) {
            pose = pose.then(&Pose::from_xyz_rpy(link.xyz, link.rpy));
            if let Some(j) = link.joint {
                let q = angles.get(j as usize).copied().unwrap_or(0.0);
                pose = pose.then(&Pose::about_axis(link.axis, q));
            }
        }
        pose.apply(self.offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::FRAC_PI_2;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn a_planar_two_link_arm_is_where_trigonometry_puts_it() {
        // Shoulder at 0.1 m height turning about y, a 0.2 m upper arm along
        // z, the elbow about y, a 0.15 m forearm along z to the tip.
        const CHAIN: [ChainJoint; 2] = [
            ChainJoint { xyz: [0.0, 0.0, 0.1], rpy: [0.0; 3], joint: Some(0), axis: [0.0, 1.0, 0.0] },
            ChainJoint { xyz: [0.0, 0.0, 0.2], rpy: [0.0; 3], joint: Some(1), axis: [0.0, 1.0, 0.0] },
        ];
        let tip = Point { name: "tip", chain: &CHAIN, offset: [0.0, 0.0, 0.15] };
        assert!(close(tip.position(&[0.0, 0.0]), [0.0, 0.0, 0.45]));
        // A rotation about +y turns +z towards +x.
        let (a, b) = (0.3f32, -0.7f32);
        let x = 0.2 * libm::sinf(a) + 0.15 * libm::sinf(a + b);
        let z = 0.1 + 0.2 * libm::cosf(a) + 0.15 * libm::cosf(a + b);
        assert!(close(tip.position(&[a, b]), [x, 0.0, z]), "{:?}", tip.position(&[a, b]));
        assert!(close(tip.position(&[FRAC_PI_2, 0.0]), [0.35, 0.0, 0.1]));
    }

    #[test]
    fn an_origins_roll_pitch_yaw_is_urdfs() {
        // Yaw 90°: the child's x is the parent's y.
        let p = Pose::from_xyz_rpy([1.0, 0.0, 0.0], [0.0, 0.0, FRAC_PI_2]);
        assert!(close(p.apply([1.0, 0.0, 0.0]), [1.0, 1.0, 0.0]));
        // Roll 90° then yaw 90°: child's y is the parent's z.
        let p = Pose::from_xyz_rpy([0.0; 3], [FRAC_PI_2, 0.0, FRAC_PI_2]);
        assert!(close(p.apply([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        // Composition is associative with the application.
        let a = Pose::from_xyz_rpy([0.1, 0.2, 0.3], [0.3, -0.2, 0.9]);
        let b = Pose::about_axis([0.0, 0.0, 1.0], 0.4);
        let pt = [0.3, -0.1, 0.7];
        assert!(close(a.then(&b).apply(pt), a.apply(b.apply(pt))));
    }
}
