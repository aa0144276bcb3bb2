use pada::leo::model::*;
fn main() {
    for warm in [false, true] {
    let o = ModelOptions { substeps: 40, solver_iterations: 4, contacts: false, dry_friction: false, back_emf: false, stop_damping: false, joint_stops: false, fixed_torso: true, gravity: false, boom_force: false, ..Default::default() };
    let mut m = LeoModel::new(o, &InitialPose::REFERENCE).unwrap();
    if warm { m.physics_step().unwrap(); }
    m.set_velocities([3.0, 2.0, -2.0, -3.0, 3.0, 4.0, -4.0], [0.0; 3]);
    println!("warm={warm} before: {:?} rates {:?}", m.energy(), m.joint_state().1);
    for _ in 0..3 { m.physics_step().unwrap(); println!("after: {:?} rates {:?}", m.energy(), m.joint_state().1); }
    }
}
