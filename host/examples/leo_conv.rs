use pada::leo::model::*;
fn run(sub: u32, it: usize, emf: bool, arm: bool) -> [f32; 8] {
    let o = ModelOptions { substeps: sub, solver_iterations: it, contacts: false, gravity: false, boom_force: false, dry_friction: false, joint_stops: false, back_emf: emf, ..Default::default() };
    let mut m = LeoModel::new(o, &InitialPose::REFERENCE).unwrap();
    let _ = arm;
    for k in 0..15 {
        let u = if k % 4 < 2 { 10.7 } else { -10.7 };
        m.set_voltages([u, u, -u, u, -u, u, -u]);
        m.control_step().unwrap();
    }
    let s = m.state(); let mut x = [s.torso_pitch; 8]; x[1..].copy_from_slice(&s.angles); x
}
fn main() {
    for emf in [true, false] {
        let r = run(160, 4, emf, true);
        for (s, i) in [(1, 1), (3, 1), (6, 1), (12, 1), (3, 4), (24, 1), (48, 1), (40, 4)] {
            let x = run(s, i, emf, true);
            let e = x.iter().zip(&r).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
            println!("emf={emf} {s}x{i}: max angle err after 0.5 s {e:.4}  torso {:.4} vs {:.4}", x[0], r[0]);
        }
    }
}
