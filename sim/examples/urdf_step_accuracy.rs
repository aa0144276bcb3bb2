//! How finely must rapier step a robot of files? The body driven by the
//! same random voltages (held for a control period each, as servos hold
//! them) with several step settings, against a fine reference (64 steps a
//! period, 4 solver iterations): the largest joint-angle and tip errors
//! over 20 episodes of 200 periods.
//!
//! ```text
//! cargo run --release -p pada-sim --example urdf_step_accuracy -- examples/robots/arm2/robot.toml
//! ```

use pada_core::limits::MAX_SERVOS;
use pada_sim::urdf::{UrdfBody, UrdfModel};
use rand_core::{RngCore, SeedableRng};

fn main() -> anyhow::Result<()> {
    let path = std::env::args().nth(1).ok_or_else(|| anyhow::anyhow!("usage: urdf_step_accuracy ROBOT.toml"))?;
    let robot = pada_robot_file::load(std::path::Path::new(&path)).map_err(|e| anyhow::anyhow!("{e}"))?;
    let model = UrdfModel::load(&robot)?;
    let words = robot.vocabulary();
    let levels = robot.spec.motor().map_err(|e| anyhow::anyhow!("{e}"))?;
    let tip = words.points.first().copied();
    let run = |substeps: u32, iterations: u32| -> anyhow::Result<Vec<(Vec<f32>, Option<[f32; 3]>)>> {
        let mut body = UrdfBody::new(&model.with_steps(substeps, iterations))?;
        let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
        let mut states = Vec::new();
        for _ in 0..20 {
            body.reset()?;
            for _ in 0..200 {
                let mut volts = [0.0; MAX_SERVOS];
                for (k, j) in words.learned.iter().enumerate() {
                    let d = levels.dim(k).values();
                    volts[*j as usize] = d[rng.next_u32() as usize % d.len()];
                }
                body.set_voltages(&volts);
                body.step_period().map_err(|_| anyhow::anyhow!("blew up at {substeps} x {iterations}"))?;
                let q: Vec<f32> = body.angles()[..robot.spec.joints.len()].to_vec();
                states.push((q.clone(), tip.map(|t| t.position(&q))));
            }
        }
        Ok(states)
    };
    let reference = run(64, 4)?;
    println!("{}: against 64 physics steps x 4 solver iterations per period", robot.spec.name);
    println!("steps x iterations   max |dq| [rad]   max tip error [mm]");
    for (s, i) in [(8, 4), (4, 4), (2, 2), (1, 4), (1, 2), (1, 1)] {
        let states = run(s, i)?;
        let (mut dq, mut dp) = (0.0f32, 0.0f32);
        for ((q, p), (r, rp)) in states.iter().zip(&reference) {
            for (a, b) in q.iter().zip(r) {
                dq = dq.max((a - b).abs());
            }
            if let (Some(p), Some(rp)) = (p, rp) {
                let d = ((p[0] - rp[0]).powi(2) + (p[1] - rp[1]).powi(2) + (p[2] - rp[2]).powi(2)).sqrt();
                dp = dp.max(d);
            }
        }
        println!("{s:>5} x {i:<10}   {dq:>14.5}   {:>18.2}", dp * 1000.0);
    }
    Ok(())
}
