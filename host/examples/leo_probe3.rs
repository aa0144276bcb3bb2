use pada::leo::*;
use pada::leo::model::ModelOptions;
use rand_core::{RngCore, SeedableRng};
fn main() {
    let cfg = LeoConfig { model: ModelOptions { substeps: 2, solver_iterations: 2, ..Default::default() }, ..Default::default() };
    let levels = [-10.7f32, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    let mut worst = 0.0f32; let mut lens = (0, 0);
    for trial in 0..50 {
        let acts: Vec<[f32;3]> = (0..40).map(|_| [0,1,2].map(|_| levels[(rng.next_u32() % 7) as usize])).collect();
        let mut fresh = LeoEnv::new(cfg).unwrap();
        let mut used = LeoEnv::new(cfg).unwrap();
        // wear `used` out: random episode
        for _ in 0..(trial % 5 + 1) { used.reset(&mut rng); loop { let a=[0,1,2].map(|_| levels[(rng.next_u32() % 7) as usize]); if used.step(a).terminal != Terminal::None { break; } } }
        let o1 = fresh.reset(&mut rng); let o2 = used.reset(&mut rng);
        if trial < 3 { println!("{:?}\n{:?}", o1.0, o2.0); }
        let mut d = o1.0.iter().zip(o2.0.iter()).map(|(a,b)| (a-b).abs()).fold(0.0, f32::max);
        let mut l = (0, 0);
        for (i, a) in acts.iter().enumerate() {
            let r1 = fresh.step(*a); let r2 = used.step(*a);
            if i < 5 { d = d.max(r1.obs.0.iter().zip(r2.obs.0.iter()).map(|(a,b)| (a-b).abs()).fold(0.0, f32::max)); }
            if r1.terminal == Terminal::None { l.0 += 1; } if r2.terminal == Terminal::None { l.1 += 1; }
        }
        worst = worst.max(d); lens.0 += l.0; lens.1 += l.1;
    }
    println!("max obs diff over first 5 steps: {worst}; total lens fresh {} reused {}", lens.0, lens.1);
}
