use pada::leo::model::ModelOptions;
use pada::leo::*;
use rand_core::{RngCore, SeedableRng};
const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let sub: u32 = a[1].parse().unwrap(); let it: usize = a[2].parse().unwrap(); let eps: usize = a[3].parse().unwrap();
    let freq: f32 = a.get(4).map_or(25.0, |x| x.parse().unwrap());
    let zeta: f32 = a.get(5).map_or(0.8, |x| x.parse().unwrap());
    let cfg = LeoConfig { model: ModelOptions { substeps: sub, solver_iterations: it, contact_frequency: freq, contact_damping_ratio: zeta, back_emf: !a.iter().any(|x| x=="noemf"), joint_stops: !a.iter().any(|x| x=="nostops"), dry_friction: !a.iter().any(|x| x=="nofric"), ..Default::default() }, ..Default::default() };
    let mut env = LeoEnv::new(cfg).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(5);
    let mut lens = vec![];
    for _ in 0..eps { env.reset(&mut rng); let mut n = 0; loop { n += 1; let a = [0,1,2].map(|_| LEVELS[(rng.next_u32()%7) as usize]); if env.step(a).terminal != Terminal::None { break; } } lens.push(n as f64); }
    let m = lens.iter().sum::<f64>() / eps as f64; let sd = (lens.iter().map(|x| (x-m)*(x-m)).sum::<f64>() / eps as f64).sqrt();
    println!("{sub}x{it} f={freq} z={zeta} {:?}: mean len {m:.2} ± {:.2} (sd {sd:.1})", a.get(6..).unwrap_or(&[]), sd / (eps as f64).sqrt());
}
