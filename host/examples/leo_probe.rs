use pada::leo::model::*;
use pada::leo::constants::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sub: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(8);
    let it: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let opts = ModelOptions { substeps: sub, solver_iterations: it, ..Default::default() };
    let mut m = LeoModel::new(opts, &InitialPose::REFERENCE).unwrap();
    let pose = InitialPose::REFERENCE;
    let o = assemble(&pose);
    println!("assembled origins {:?}", o);
    println!("hip {:?}", m.body_point(Body::Torso, TORSO_HIP_ANCHOR));
    println!("torso com {:?}", m.body_point(Body::Torso, TORSO_COM));
    println!("left knee {:?}", m.body_point(Body::ThighLeft, THIGH_KNEE_ANCHOR));
    println!("right ankle {:?}", m.body_point(Body::ShankRight, SHANK_ANKLE_ANCHOR));
    println!("shoulder {:?}", m.body_point(Body::Torso, TORSO_SHOULDER_ANCHOR));
    println!("clear {:?}", m.foot_clearances());
    println!("state {:?}", m.state());
    println!("E {:?}", m.energy());
    let t0 = std::time::Instant::now();
    for i in 0..(30*5) {
        let tq = m.control_step();
        if i % 10 == 0 || tq.is_err() {
            let s = m.state();
            println!("t={:.2} pitch={:.3} pos={:?} q={:?} c={:?} E={:?} {:?}", m.time(), s.torso_pitch, s.torso_position, s.angles.map(|x| (x*100.0).round()/100.0), s.contacts, m.energy().total(), tq.err());
        }
        if tq.is_err() { break; }
    }
    println!("wall {:?}", t0.elapsed());
}
