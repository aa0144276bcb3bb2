use pada::leo::model::*;
use pada::leo::*;
use rand_core::{RngCore, SeedableRng};
const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];
fn cfg(sub: u32, it: usize) -> LeoConfig { LeoConfig { model: ModelOptions { substeps: sub, solver_iterations: it, ..Default::default() }, ..Default::default() } }
fn roll(c: LeoConfig, seqs: &[Vec<[f32;3]>]) -> Vec<Vec<[f32;10]>> {
    let mut env = LeoEnv::new(c).unwrap(); let mut rng = rand_pcg::Pcg32::seed_from_u64(0);
    seqs.iter().map(|s| { env.reset(&mut rng); s.iter().map(|a| env.step(*a).obs.0).collect() }).collect()
}
fn main() {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(42);
    let seqs: Vec<Vec<[f32;3]>> = (0..40).map(|_| (0..10).map(|_| [0,1,2].map(|_| LEVELS[(rng.next_u32()%7) as usize])).collect()).collect();
    let r = roll(cfg(40, 4), &seqs);
    for (s, i) in [(80, 4), (40, 8), (160, 2), (16, 2), (8, 1), (4, 1), (2, 2), (1, 4)] {
        let t = roll(cfg(s, i), &seqs);
        let mut line = format!("{s}x{i}:");
        for k in 0..10 {
            let mut se = 0.0f64; let mut ss = 0.0f64;
            for (a, b) in r.iter().zip(&t) { for d in [2,4,6,8] { se += ((a[k][d]-b[k][d]) as f64).powi(2); ss += (a[k][d] as f64 - if d==4 {0.8} else if d==8 {-1.2} else {0.0}).powi(2).max(0.0); } }
            let mut sr = 0.0f64; let mut sq = 0.0f64;
            for (a, b) in r.iter().zip(&t) { for d in [3,5,7,9] { sr += ((a[k][d]-b[k][d]) as f64).powi(2); sq += (a[k][d] as f64).powi(2); } }
            line += &format!(" k{}: {:.4}/{:.3}", k+1, (se/(40.0*4.0)).sqrt(), (sr/sq).sqrt());
        }
        println!("{line}");
    }
}
