use pada::leo::model::*;
fn main() {
    for corr in [false, true] {
        for (s, i) in [(3, 1), (6, 1), (12, 1), (160, 4)] {
            let o = ModelOptions { substeps: s, solver_iterations: i, fixed_torso: true, gravity: false, contacts: false, dry_friction: false, motor_lag_correction: corr, ..Default::default() };
            let mut m = LeoModel::new(o, &InitialPose::REFERENCE).unwrap();
            let mut v = [0.0; NUM_JOINTS]; v[0] = 10.6919; v[5] = 10.6919; m.set_voltages(v);
            let mut line = format!("corr={corr} {s}x{i}:");
            for _ in 0..3 { m.control_step().unwrap(); let (_, qd) = m.joint_state(); line += &format!(" {:.3}/{:.3}", qd[0], qd[5]); }
            println!("{line}");
        }
    }
}
