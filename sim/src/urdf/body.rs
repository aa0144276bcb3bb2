//! A robot's body from its URDF, in rapier: the links and joints inserted
//! by rapier3d-urdf as one multibody with reduced coordinates (the kind
//! LEO uses), its root fixed to the world, gravity along −z (URDF's up is
//! +z), and each joint driven through its servo's motor model.
//!
//! The servo is LEO's in general form ([`pada_core::rx28::ReducedJoint`]
//! of the joint's [`pada_core::servo::DcMotor`]): the rotor's reflected
//! inertia is the DoF's armature, the back-EMF its (implicit) damping, and
//! the voltage held over the control period a constant torque `η·G·k·U/R`
//! on the two links of the joint. rapier treats armature and damping
//! implicitly, so the step can be as long as the links allow. Dry friction
//! is left out (the X-series' is an estimate: docs/reference/servos.md),
//! and so are contacts: the body has no floor and no colliders, a robot of
//! files is an arm on a fixed base.
//!
//! A joint's servo takes its command in one of two modes
//! ([`pada_core::servo::ControlMode`]): a voltage held over the period
//! (the paper's actions), or a goal angle that the servo's own position
//! loop follows ([`pada_core::servo::PositionLoop`], the STS3215's in
//! Operating_Mode 0: docs/reference/feetech.md). In position mode the loop
//! runs every sub-step at its own rate and its voltage drives the same
//! motor model, so the gear torques are the ones the loop causes.

use pada_core::limits::MAX_SERVOS;
use pada_core::robot::PerServo;
use pada_core::rx28::ReducedJoint;
use pada_core::servo::{ControlMode, PositionLoop};
use pada_robot_file::RobotFile;
use rapier3d::prelude::*;
use rapier3d::dynamics::RigidBodyAdditionalMassProps;
use rapier3d_urdf::{UrdfLoaderOptions, UrdfMultibodyOptions, UrdfRobot};
use crate::world_state::WorldState;

/// Gravity \[m/s²\], along −z.
pub const GRAVITY: f32 = 9.81;

/// The body blew up: a coordinate or a rate is no longer finite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlowUp;

/// One servo joint of the body.
#[derive(Debug, Clone)]
struct ServoJoint {
    /// The joint's link in the multibody, its DoF in the generalized
    /// coordinates.
    link: usize,
    dof: usize,
    /// The bodies the servo's torque acts between.
    child: RigidBodyHandle,
    parent: RigidBodyHandle,
    /// The URDF's unit axis in the child link's frame.
    axis: Vector,
    /// The servo's motor.
    servo: ReducedJoint,
    /// The servo's own position loop, when the joint is in position mode.
    position: Option<PositionLoop>,
}

/// A robot's body, simulated.
pub struct UrdfBody {
    world: PhysicsWorld,
    multibody: MultibodyIndex,
    joints: Vec<ServoJoint>,
    /// The world as built, before the start pose (restored at every reset).
    built: WorldState,
    start: Vec<f32>,
    substeps: u32,
    volts: PerServo,
    /// The goal angle of each joint in position mode \[rad\].
    goals: PerServo,
    /// The supply the position loops' duty cycles apply \[V\].
    supply_v: f32,
    /// The mean voltage each servo applied over the last period \[V\].
    applied: PerServo,
    /// The mean gear torque of each servo over the last period \[N·m\].
    torques: PerServo,
}

/// A robot's body as read once from its URDF, to build bodies of (one
/// per trial) without reading the file again.
#[derive(Clone)]
pub struct UrdfModel {
    urdf: UrdfRobot,
    /// The URDF name of each joint of `urdf`.
    joint_names: Vec<String>,
    /// Each robot joint's URDF axis, joint order.
    axes: Vec<[f64; 3]>,
    spec: &'static pada_core::robot::RobotSpec,
    start: Vec<f32>,
    substeps: u32,
    solver_iterations: u32,
    /// Motor constants and friction of a plant that is not its model
    /// (`None`: the model's).
    differs: Option<MotorsDiffer>,
}

/// How the servos of a plant that is not its model differ from it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct MotorsDiffer {
    /// Factor on each motor's torque constant.
    motor_constant: f32,
    /// Dry friction at each joint \[N·m\].
    friction_nm: f32,
}

impl UrdfModel {
    /// The same body with `draw`'s masses (every link's mass and inertia
    /// times its factor), motor constants and dry friction
    /// ([`crate::variation`]).
    pub fn varied(&self, draw: &crate::variation::PlantDraw) -> UrdfModel {
        let mut m = self.clone();
        if draw.mass != 1.0 {
            let f = draw.mass as f32;
            for link in &mut m.urdf.links {
                let added = link.body.mass_properties().additional_local_mprops.as_deref().cloned();
                if let Some(RigidBodyAdditionalMassProps::MassProps(mut p)) = added {
                    p.inv_mass /= f;
                    p.inv_principal_inertia /= f;
                    link.body.set_additional_mass_properties(p, false);
                }
            }
        }
        m.differs = Some(MotorsDiffer { motor_constant: draw.motor_constant as f32, friction_nm: draw.friction_nm as f32 });
        m
    }

    /// The robot's definition.
    pub fn spec(&self) -> &'static pada_core::robot::RobotSpec {
        self.spec
    }

    /// The same body stepped `substeps` times a period with
    /// `solver_iterations` (for studies of the step's accuracy).
    pub fn with_steps(&self, substeps: u32, solver_iterations: u32) -> UrdfModel {
        UrdfModel { substeps, solver_iterations, ..self.clone() }
    }

    /// The body of `robot`, read from its URDF and checked by building it
    /// once.
    pub fn load(robot: &RobotFile) -> anyhow::Result<UrdfModel> {
        let options = UrdfLoaderOptions {
            make_roots_fixed: true,
            // A servo's torque must act whenever it is applied: a body
            // asleep would ignore it.
            rigid_body_blueprint: RigidBodyBuilder::dynamic().can_sleep(false),
            create_colliders_from_collision_shapes: false,
            create_colliders_from_visual_shapes: false,
            ..UrdfLoaderOptions::default()
        };
        let (urdf, description) = UrdfRobot::from_file(&robot.urdf.path, options, None)
            .map_err(|e| anyhow::anyhow!("{}: rapier3d-urdf cannot load it: {e}", robot.urdf.path.display()))?;
        let joint_names = urdf.joints.iter().map(|j| description.joints[j.urdf_joint_index].name.clone()).collect();
        let axes = robot
            .spec
            .joints
            .iter()
            .map(|spec| description.joints.iter().find(|j| j.name == spec.name).map_or([1.0, 0.0, 0.0], |j| j.axis.xyz.0))
            .collect();
        let model = UrdfModel {
            urdf,
            joint_names,
            axes,
            spec: robot.spec,
            start: robot.vocabulary().start.to_vec(),
            substeps: robot.substeps,
            solver_iterations: robot.solver_iterations,
            differs: None,
        };
        UrdfBody::new(&model).map_err(|e| anyhow::anyhow!("{}: {e}", robot.urdf.path.display()))?;
        Ok(model)
    }
}

impl UrdfBody {
    /// A body of `model`, at rest in its start pose.
    pub fn new(model: &UrdfModel) -> anyhow::Result<UrdfBody> {
        let UrdfModel { urdf, joint_names, axes, spec, start, substeps, solver_iterations, differs } = model.clone();
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -GRAVITY);
        world.integration_parameters.dt = spec.period_s() as f32 / substeps as f32;
        world.integration_parameters.num_solver_iterations = solver_iterations as usize;
        let handles = urdf.insert_using_multibody_joints(
            &mut world.bodies,
            &mut world.colliders,
            &mut world.multibody_joints,
            UrdfMultibodyOptions::DISABLE_SELF_CONTACTS,
        );
        let mut joints = Vec::new();
        let mut multibody = None;
        for (spec, axis) in spec.joints.iter().zip(&axes) {
            let k = joint_names
                .iter()
                .position(|n| n == spec.name)
                .ok_or_else(|| anyhow::anyhow!("rapier3d-urdf kept no joint {:?}", spec.name))?;
            let h = &handles.joints[k];
            let link = world
                .multibody_joints
                .rigid_body_link(h.link2)
                .ok_or_else(|| anyhow::anyhow!("joint {:?} is not in the multibody", spec.name))?;
            if *multibody.get_or_insert(link.multibody) != link.multibody {
                anyhow::bail!("the robot is not one tree");
            }
            let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt().max(1e-12);
            joints.push(ServoJoint {
                link: link.id,
                dof: 0,
                child: h.link2,
                parent: h.link1,
                axis: Vector::new((axis[0] / n) as f32, (axis[1] / n) as f32, (axis[2] / n) as f32),
                servo: match differs {
                    None => spec.servo.motor().to_rx28().reduced(),
                    Some(d) => {
                        let mut motor = spec.servo.motor();
                        motor.torque_constant_nm_per_a *= d.motor_constant;
                        motor.to_rx28().reduced()
                    }
                },
                position: None,
            });
        }
        let multibody = multibody.ok_or_else(|| anyhow::anyhow!("the robot has no servo joint"))?;
        let mb = world.multibody_joints.get_multibody_mut(multibody).ok_or_else(|| anyhow::anyhow!("no multibody"))?;
        mb.forward_kinematics(&world.bodies, true);
        // The servo model per DoF; no other damping (rapier's default on
        // angular DoFs is removed) and no friction loss.
        mb.damping_mut().fill(0.0);
        mb.armature_mut().fill(0.0);
        mb.frictions_mut().fill(0.0);
        for j in &mut joints {
            j.dof = mb.link(j.link).ok_or_else(|| anyhow::anyhow!("no link"))?.assembly_id();
            mb.damping_mut()[j.dof] = j.servo.damping;
            mb.armature_mut()[j.dof] = j.servo.armature;
            if let Some(d) = differs {
                mb.frictions_mut()[j.dof] = d.friction_nm;
            }
        }
        let built = WorldState::of(&world);
        let mut body = UrdfBody {
            world,
            multibody,
            joints,
            built,
            start: start.clone(),
            substeps,
            volts: [0.0; MAX_SERVOS],
            goals: [0.0; MAX_SERVOS],
            supply_v: spec.supply_nominal_v,
            applied: [0.0; MAX_SERVOS],
            torques: [0.0; MAX_SERVOS],
        };
        body.reset_to(&start)?;
        Ok(body)
    }

    fn multibody(&self) -> &Multibody {
        // The index was checked when the body was built.
        &self.world.multibody_joints[self.multibody]
    }

    /// Back in the start pose, at rest, 0 V.
    pub fn reset(&mut self) -> anyhow::Result<()> {
        let start = self.start.clone();
        self.reset_to(&start)
    }

    /// At `angles` (one per servo joint), at rest, 0 V.
    pub fn reset_to(&mut self, angles: &[f32]) -> anyhow::Result<()> {
        self.built.restore(&mut self.world);
        self.volts = [0.0; MAX_SERVOS];
        self.applied = [0.0; MAX_SERVOS];
        self.torques = [0.0; MAX_SERVOS];
        // A position-mode joint holds where it starts.
        self.goals = [0.0; MAX_SERVOS];
        for (k, (j, q)) in self.joints.iter_mut().zip(angles).enumerate() {
            if let Some(l) = &mut j.position {
                l.reset();
                self.goals[k] = *q;
            }
        }
        let w = &mut self.world;
        let mb = w.multibody_joints.get_multibody_mut(self.multibody).ok_or_else(|| anyhow::anyhow!("no multibody"))?;
        for (j, q) in self.joints.iter().zip(angles) {
            mb.link_mut(j.link).ok_or_else(|| anyhow::anyhow!("no link"))?.joint.apply_displacement(&[*q]);
        }
        mb.generalized_velocity_mut().fill(0.0);
        mb.forward_kinematics(&w.bodies, false);
        mb.update_rigid_bodies(&mut w.bodies, true);
        Ok(())
    }

    /// The voltage each servo applies from now on (held until the next
    /// call, as a servo holds its command over the period). A joint in
    /// position mode ignores it.
    pub fn set_voltages(&mut self, volts: &PerServo) {
        self.volts = *volts;
    }

    /// How joint `joint`'s servo takes its command from now on; a joint
    /// switched to position mode holds its present angle until
    /// [`UrdfBody::set_goals`]. False when there is no such joint.
    pub fn set_control_mode(&mut self, joint: usize, mode: ControlMode) -> bool {
        let q = self.angles();
        let Some(j) = self.joints.get_mut(joint) else { return false };
        j.position = match mode {
            ControlMode::Voltage => None,
            ControlMode::Position(spec) => Some(PositionLoop::new(spec)),
        };
        self.goals[joint] = q[joint];
        true
    }

    /// The supply the position loops apply their duty cycles to \[V\]
    /// (the robot's `supply_v` until set).
    pub fn set_supply(&mut self, supply_v: f32) {
        self.supply_v = supply_v;
    }

    /// The goal angle of each joint in position mode from now on \[rad\]
    /// (the others ignore theirs).
    pub fn set_goals(&mut self, goals: &PerServo) {
        self.goals = *goals;
    }

    /// One control period: the physics steps with the held voltages.
    pub fn step_period(&mut self) -> Result<(), BlowUp> {
        let mut sum = [0.0f32; MAX_SERVOS];
        let mut applied = [0.0f32; MAX_SERVOS];
        let dt = self.world.integration_parameters.dt;
        let looped = self.joints.iter().any(|j| j.position.is_some());
        for _ in 0..self.substeps {
            let before = self.rates();
            // Each servo's voltage over this sub-step: the held command, or
            // what its position loop makes of the goal and the angle now.
            let mut volts = self.volts;
            if looped {
                let q = self.angles();
                for (k, j) in self.joints.iter_mut().enumerate() {
                    if let Some(l) = &mut j.position {
                        volts[k] = l.step(self.goals[k], q[k], self.supply_v, dt);
                    }
                }
            }
            for k in 0..MAX_SERVOS {
                applied[k] += volts[k];
            }
            for (k, j) in self.joints.iter().enumerate() {
                let tau = j.servo.voltage_torque(volts[k]);
                let axis = self.world.bodies[j.child].rotation() * j.axis;
                self.world.bodies[j.child].reset_torques(false);
                self.world.bodies[j.child].add_torque(axis * tau, false);
            }
            // A parent may be another joint's child: its reaction torques
            // go on after every child's own torque is set.
            for (k, j) in self.joints.iter().enumerate() {
                let tau = j.servo.voltage_torque(volts[k]);
                let axis = self.world.bodies[j.child].rotation() * j.axis;
                if self.world.bodies[j.parent].is_dynamic() {
                    self.world.bodies[j.parent].add_torque(-axis * tau, false);
                }
            }
            self.world.step();
            let after = self.rates();
            for (k, j) in self.joints.iter().enumerate() {
                // The torque the gears carry: the motor's, less its back-EMF
                // and the rotor's inertia.
                sum[k] += j.servo.joint_torque(volts[k], after[k], (after[k] - before[k]) / dt);
            }
            if !after.iter().all(|x| x.is_finite()) {
                return Err(BlowUp);
            }
        }
        for k in 0..MAX_SERVOS {
            self.torques[k] = sum[k] / self.substeps as f32;
            self.applied[k] = applied[k] / self.substeps as f32;
        }
        Ok(())
    }

    /// The mean voltage each servo applied over the last period \[V\]:
    /// the held command, or its position loop's output.
    pub fn applied_voltages(&self) -> PerServo {
        self.applied
    }

    /// The joint angles \[rad\], joint order (0 past the joints).
    pub fn angles(&self) -> PerServo {
        let mut q = [0.0; MAX_SERVOS];
        let mb = self.multibody();
        for (k, j) in self.joints.iter().enumerate() {
            // A revolute joint's coordinate is its angle about the joint
            // frame's axis (rapier3d-urdf aligns it with the URDF's).
            q[k] = mb.link(j.link).map_or(f32::NAN, |l| l.joint.coords()[3]);
        }
        q
    }

    /// The joint rates \[rad/s\], joint order.
    pub fn rates(&self) -> PerServo {
        let mut qd = [0.0; MAX_SERVOS];
        let v = self.multibody().generalized_velocity();
        for (k, j) in self.joints.iter().enumerate() {
            qd[k] = v[j.dof];
        }
        qd
    }

    /// The mean torque on each servo's gears over the last period \[N·m\].
    pub fn gear_torques(&self) -> PerServo {
        self.torques
    }

    /// The world position of a point `offset` of the link that servo joint
    /// `joint` moves (its child link) \[m\].
    pub fn link_point(&self, joint: usize, offset: [f32; 3]) -> Option<[f32; 3]> {
        let j = self.joints.get(joint)?;
        let p = self.world.bodies[j.child].position() * Vector::new(offset[0], offset[1], offset[2]);
        Some([p.x, p.y, p.z])
    }
}
