use pada::leo::model::ModelOptions;
use pada::leo::*;
use rand_core::{RngCore, SeedableRng};
const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];
fn lens(sub: u32, it: usize, seqs: &[Vec<[f32;3]>], contacts: bool) -> Vec<(usize, f32, f32)> {
    let cfg = LeoConfig { model: ModelOptions { substeps: sub, solver_iterations: it, contacts, gravity: contacts, boom_force: contacts, ..Default::default() }, ..Default::default() };
    let mut env = LeoEnv::new(cfg).unwrap(); let mut rng = rand_pcg::Pcg32::seed_from_u64(0);
    seqs.iter().map(|s| { env.reset(&mut rng); let mut n = 0; let mut last = (0.0, 0.0); for a in s { n += 1; let r = env.step(*a); if r.terminal != Terminal::None { let q = env.model().state(); last = (-q.torso_pitch, r.obs.0[0] + r.obs.0[2]); break; } } (n, last.0, last.1) }).collect()
}
fn main() {
    let contacts = std::env::args().any(|a| a == "contacts");
    let mut rng = rand_pcg::Pcg32::seed_from_u64(9);
    let seqs: Vec<Vec<[f32;3]>> = (0..300).map(|_| (0..200).map(|_| [0,1,2].map(|_| LEVELS[(rng.next_u32()%7) as usize])).collect()).collect();
    let a = lens(3, 1, &seqs, contacts); let b = lens(40, 4, &seqs, contacts);
    let mut hist = std::collections::BTreeMap::new();
    for (x, y) in a.iter().zip(&b) { *hist.entry(y.0 as i64 - x.0 as i64).or_insert(0) += 1; }
    println!("len(40x4) - len(3x1) histogram: {:?}", hist);
    let phi_a = a.iter().filter(|x| x.1.abs() > 1.0).count(); let phi_b = b.iter().filter(|x| x.1.abs() > 1.0).count();
    println!("falls by torso angle: 3x1 {phi_a}/300, 40x4 {phi_b}/300");
    for i in 0..10 { println!("{:?} {:?}", a[i], b[i]); }
}
