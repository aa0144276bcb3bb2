use pada::leo::model::*;
fn main() {
    let opts = ModelOptions { substeps: 2, solver_iterations: 2, ..Default::default() };
    let n = 2000;
    let mut m = LeoModel::new(opts, &InitialPose::REFERENCE).unwrap();
    m.control_step().unwrap();
    let snap = m.snapshot();
    let t = std::time::Instant::now();
    for _ in 0..n { m.restore(&snap); }
    let restore = t.elapsed().as_secs_f64() / n as f64;
    let t = std::time::Instant::now();
    for _ in 0..n { std::hint::black_box(m.snapshot()); }
    let snapt = t.elapsed().as_secs_f64() / n as f64;
    let t = std::time::Instant::now();
    for _ in 0..n { m.reset(&InitialPose::REFERENCE).unwrap(); }
    let reset = t.elapsed().as_secs_f64() / n as f64;
    let t = std::time::Instant::now();
    for _ in 0..n/10 { m.restore(&snap); for _ in 0..10 { m.control_step().unwrap(); } }
    let step = t.elapsed().as_secs_f64() / n as f64;
    println!("restore {:.1} us, snapshot {:.1} us, reset {:.1} us, control step {:.1} us", restore*1e6, snapt*1e6, reset*1e6, step*1e6);
}
