use pada::leo::*;
use pada::leo::model::ModelOptions;
use rand_core::{RngCore, SeedableRng};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let sub: u32 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(8);
    let it: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let secs: f32 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(300.0);
    let cfg = LeoConfig { model: ModelOptions { substeps: sub, solver_iterations: it, motor_lag_correction: !a.iter().any(|x| x == "nocorr"), ..Default::default() }, ..Default::default() };
    let mut env = LeoEnv::new(cfg).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
    let levels = [-10.7f32, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];
    let steps = (secs * 30.0) as usize;
    let t0 = std::time::Instant::now();
    env.reset(&mut rng);
    let (mut eps, mut len, mut lens) = (0, 0, vec![]);
    let mut ret = 0.0; let mut rets = vec![];
    let mut maxrate = 0.0f32;
    for _ in 0..steps {
        let act = [0,1,2].map(|_| levels[(rng.next_u32() % 7) as usize]);
        let r = env.step(act);
        ret += r.reward; len += 1;
        for x in [1,3,5,7,9] { maxrate = maxrate.max(r.obs.0[x].abs()); }
        if r.terminal != Terminal::None { eps += 1; lens.push(len); rets.push(ret); len = 0; ret = 0.0; env.reset(&mut rng); }
    }
    let wall = t0.elapsed().as_secs_f64();
    let ml = lens.iter().sum::<usize>() as f64 / lens.len().max(1) as f64;
    println!("sub={sub} it={it}: {secs}s sim in {wall:.3}s wall, RTF {:.0}; episodes {eps} mean len {ml:.1} steps, mean return {:.1}, falls {} blowups {} maxrate {maxrate:.1}",
        secs as f64 / wall, rets.iter().sum::<f32>() / rets.len().max(1) as f32, env.falls(), env.blow_ups());
}
