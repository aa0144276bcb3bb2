use pada::leo::model::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let sub: u32 = a[1].parse().unwrap(); let it: usize = a[2].parse().unwrap(); let scale: f32 = a[3].parse().unwrap();
    let o = ModelOptions { substeps: sub, solver_iterations: it, contacts: false, dry_friction: false, back_emf: false, stop_damping: false, joint_stops: a.get(4).map_or(true, |x| x != "nostops"), fixed_torso: true, ..Default::default() };
    let mut m = LeoModel::new(o, &InitialPose::REFERENCE).unwrap();
    m.set_velocities([3.0, 2.0, -2.0, -3.0, 3.0, 4.0, -4.0].map(|x| x * scale), [0.0; 3]);
    let e0 = m.energy();
    println!("E0 {:?}", e0);
    let mut minmax = (f32::MAX, f32::MIN);
    for k in 0..300 {
        m.control_step().unwrap();
        let e = m.energy(); let (q, _) = m.joint_state();
        minmax.0 = minmax.0.min(e.total()-e0.total()); minmax.1 = minmax.1.max(e.total()-e0.total());
        if k % 30 == 0 { println!("t={:.1} dE={:.5} KE={:.4} q={:?}", m.time(), e.total()-e0.total(), e.kinetic, q.map(|x| (x*100.0).round()/100.0)); }
    }
    println!("range {:?}", minmax);
}
