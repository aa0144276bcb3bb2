//! `pada._pada.LeoVectorCore`: n LEOs stepped in parallel threads (rayon)
//! with the GIL released, for `pada.envs.LeoVector`.

use crate::check;
use crate::envs::{Core, StepOut};
use pada_core::action_space::MAX_ACTION_DIMS;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;

/// Most environments of one vector.
pub const MAX_ENVS: i64 = 1024;

/// n LEO environments; an environment whose episode ended is reset in the
/// same step (Gymnasium's same-step autoreset), its last observation kept
/// for `final_obs`.
#[pyclass(module = "pada")]
pub struct LeoVectorCore {
    envs: Vec<Core>,
    continuous: bool,
    obs_dim: usize,
    act_dim: usize,
    gearboxes: usize,
}

/// What `step` returns: observations, rewards, ends, last observations of
/// ended episodes, commanded torques (all flat, env-major).
type StepBytes<'py> = (
    Bound<'py, PyBytes>,
    Vec<f64>,
    Vec<bool>,
    Vec<bool>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
);

fn f32_bytes<'py>(py: Python<'py>, v: impl Iterator<Item = f32>) -> Bound<'py, PyBytes> {
    let b: Vec<u8> = v.flat_map(|x| x.to_ne_bytes()).collect();
    PyBytes::new(py, &b)
}

/// One environment's step: its result, its last observation if the
/// episode ended (then it is reset), and the commanded torques.
type Stepped = (StepOut, Vec<f32>, Vec<f64>);

fn step_one(e: &mut Core, c: &[f32; MAX_ACTION_DIMS], m: usize, obs_dim: usize) -> Stepped {
    let s = e.step_command(&c[..m]);
    let torques = e.commanded_torques();
    let last = if s.terminal || s.truncated {
        let last = e.obs.clone();
        e.reset(None);
        last
    } else {
        vec![f32::NAN; obs_dim]
    };
    (s, last, torques)
}

#[pymethods]
impl LeoVectorCore {
    #[new]
    #[pyo3(signature = (n, robot="leo", continuous=false))]
    fn new(py: Python<'_>, n: i64, robot: &str, continuous: bool) -> PyResult<Self> {
        let n = check::count("n", n, 1, MAX_ENVS)?;
        let envs = py.detach(|| {
            (0..n)
                .into_par_iter()
                .map(|_| Core::new(robot))
                .collect::<PyResult<Vec<_>>>()
        })?;
        let obs_dim = envs[0].spec.state.len();
        let act_dim = envs[0].spec.motor.dims();
        let gearboxes = envs[0].spec.gearboxes;
        Ok(LeoVectorCore {
            envs,
            continuous,
            obs_dim,
            act_dim,
            gearboxes,
        })
    }

    /// Resets every environment (environment i with `seed + i` when a seed
    /// is given); returns the observations as native `f32` bytes.
    #[pyo3(signature = (seed=None))]
    fn reset<'py>(&mut self, py: Python<'py>, seed: Option<u64>) -> Bound<'py, PyBytes> {
        for (i, e) in self.envs.iter_mut().enumerate() {
            e.reset(seed.map(|s| s.wrapping_add(i as u64)));
        }
        f32_bytes(py, self.envs.iter().flat_map(|e| e.obs.iter().copied()))
    }

    /// One step of every environment: `actions` holds n × action-dimension
    /// values, env-major (level indices, or voltages with `continuous`).
    fn step<'py>(&mut self, py: Python<'py>, actions: Vec<f64>) -> PyResult<StepBytes<'py>> {
        let (n, m) = (self.envs.len(), self.act_dim);
        if actions.len() != n * m {
            return Err(PyValueError::new_err(format!(
                "actions has {} values, expected {n} x {m} (one action per environment)",
                actions.len()
            )));
        }
        // Check every action before stepping any environment.
        let mut commands = Vec::with_capacity(n);
        for (e, a) in self.envs.iter().zip(actions.chunks_exact(m)) {
            let c: [f32; MAX_ACTION_DIMS] = if self.continuous {
                e.command_of(a)?
            } else {
                let mut ints = [0i64; MAX_ACTION_DIMS];
                for (i, &x) in a.iter().enumerate() {
                    if x.fract() != 0.0 || !x.is_finite() {
                        return Err(check::out_of_range(
                            &format!("actions[{i}]"),
                            x,
                            "an integer level index",
                        ));
                    }
                    ints[i] = x as i64;
                }
                let l = e.levels_of(&ints[..m])?;
                let o = e.spec.motor.values(&l);
                let mut c = [0.0; MAX_ACTION_DIMS];
                c[..m].copy_from_slice(&o[..m]);
                c
            };
            commands.push(c);
        }
        let obs_dim = self.obs_dim;
        // The calling thread steps environment 0 itself while rayon's pool
        // steps the others: one environment needs no hand-off, n need n − 1.
        let results: Vec<Stepped> = py.detach(|| {
            let mut results: Vec<Option<Stepped>> = (0..n).map(|_| None).collect();
            let (first_env, rest_envs) = self.envs.split_first_mut().expect("n >= 1");
            let (first_res, rest_res) = results.split_first_mut().expect("n >= 1");
            rayon::in_place_scope(|s| {
                for ((e, c), r) in rest_envs
                    .iter_mut()
                    .zip(&commands[1..])
                    .zip(rest_res.iter_mut())
                {
                    s.spawn(move |_| *r = Some(step_one(e, c, m, obs_dim)));
                }
                *first_res = Some(step_one(first_env, &commands[0], m, obs_dim));
            });
            results
                .into_iter()
                .map(|r| r.expect("every environment stepped"))
                .collect()
        });
        let obs = f32_bytes(py, self.envs.iter().flat_map(|e| e.obs.iter().copied()));
        let last = f32_bytes(py, results.iter().flat_map(|r| r.1.iter().copied()));
        let torques: Vec<u8> = results
            .iter()
            .flat_map(|r| r.2.iter().flat_map(|x| x.to_ne_bytes()))
            .collect();
        Ok((
            obs,
            results.iter().map(|r| r.0.reward as f64).collect(),
            results.iter().map(|r| r.0.terminal).collect(),
            results.iter().map(|r| r.0.truncated).collect(),
            last,
            PyBytes::new(py, &torques),
        ))
    }

    /// Environments.
    #[getter]
    fn n(&self) -> usize {
        self.envs.len()
    }

    /// Observation dimensions.
    #[getter]
    fn obs_dim(&self) -> usize {
        self.obs_dim
    }

    /// Gearboxes per environment.
    #[getter]
    fn gearboxes(&self) -> usize {
        self.gearboxes
    }
}
