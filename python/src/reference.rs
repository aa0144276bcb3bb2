//! The references the tests and the benchmark hold the Python
//! environments against: `pada run`'s plant driven in Rust alone.

use crate::envs::{make, Core};
use pada_core::action_space::{Levels, MAX_ACTION_DIMS};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rand_core::SeedableRng;
use rand_pcg::Pcg64;
use std::time::Instant;

/// `pada run`'s environment without Python: the task's plant driven
/// through `actions` (level indices, or commands with `continuous`) as the
/// experiment runner drives it — reset at the start, after an absorbing
/// state and at the time limit. Returns one `(obs, reward, terminated,
/// truncated)` per step, for the tests.
#[pyfunction]
#[pyo3(signature = (robot, actions, continuous=false, seed=0))]
pub fn reference_rollout(
    py: Python<'_>,
    robot: &str,
    actions: Vec<Vec<f64>>,
    continuous: bool,
    seed: u64,
) -> PyResult<Vec<(Vec<f64>, f64, bool, bool)>> {
    let (spec, mut plant) = make(robot)?;
    let n = spec.state.len();
    let m = spec.motor.dims();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut obs = vec![0.0f32; n];
    let mut out = Vec::with_capacity(actions.len());
    py.detach(|| {
        plant.get().reset(&mut rng, &mut obs);
        let mut k = 0u32;
        for a in &actions {
            let mut command = [0.0f32; MAX_ACTION_DIMS];
            if continuous {
                for i in 0..m {
                    command[i] = a[i] as f32;
                }
            } else {
                let mut l = Levels::default();
                for i in 0..m {
                    l[i] = a[i] as u8;
                }
                let o = spec.motor.values(&l);
                command[..m].copy_from_slice(&o[..m]);
            }
            let s = plant.get().step(&command[..m], &mut obs);
            k += 1;
            let truncated = !s.terminal && k == spec.episode_steps;
            out.push((
                obs.iter().map(|&x| x as f64).collect(),
                s.reward as f64,
                s.terminal,
                truncated,
            ));
            if s.terminal || truncated {
                plant.get().reset(&mut rng, &mut obs);
                k = 0;
            }
        }
    });
    Ok(out)
}

/// Seconds per control step of `robot` stepped `steps` times in Rust alone
/// (no Python), with the level indices of `actions` in turn and resets at
/// episode ends: the benchmark's reference.
#[pyfunction]
pub fn bench_rust_steps(
    py: Python<'_>,
    robot: &str,
    actions: Vec<Vec<i64>>,
    steps: u64,
) -> PyResult<f64> {
    let mut core = Core::new(robot)?;
    if actions.is_empty() {
        return Err(PyValueError::new_err(
            "actions: valid is at least one action",
        ));
    }
    let levels: Vec<Levels> = actions
        .iter()
        .map(|a| core.levels_of(a))
        .collect::<PyResult<_>>()?;
    Ok(py.detach(|| {
        core.reset(Some(0));
        let t = Instant::now();
        for k in 0..steps as usize {
            let s = core.step_levels(&levels[k % levels.len()]);
            if s.terminal || s.truncated {
                core.reset(None);
            }
        }
        t.elapsed().as_secs_f64() / steps.max(1) as f64
    }))
}
