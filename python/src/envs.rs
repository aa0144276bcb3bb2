//! `pada._pada.PlantEnv`: one of pada's simulated robots stepped as
//! `pada run` steps it — the plant of the task (`pada_sim::task`),
//! the motor's levels (or continuous commands), the task's time limit —
//! for the Gymnasium environments of `pada.envs`. A robot of files (a
//! `robot.toml` and its URDF) is stepped as `pada run --robot` steps it.

use crate::check;
use pada_sim::task::{Plant, Task, TaskSpec};
use pada_sim::leo::rl::{LeoPlant, LeoTask};
use pada_sim::urdf::{RulesPlant, UrdfTask};
use pada_core::robot::{RobotSpec, Vocab};
use pada_sim::pendulum::{
    PhysicalPendulum, PhysicalPendulumTask, SimulatedPendulum, SimulatedPendulumTask,
};
use pada_core::action_space::{Levels, MAX_ACTION_DIMS};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rand_core::SeedableRng;
use rand_pcg::Pcg64;

/// The robots, by the names `pada run --task` uses, or a robot of files.
pub const KINDS: &str =
    "\"pendulum\", \"physical-pendulum\", \"leo\", or the path of a robot.toml (as `pada run --robot` takes it)";

/// One of the three plants (concrete types, so the environment is `Sync`).
pub enum AnyPlant {
    /// The simulated pendulum of Section VII.
    Pendulum(SimulatedPendulum),
    /// The model of the paper's physical pendulum.
    Physical(PhysicalPendulum),
    /// The rapier3d LEO of Section VIII.
    Leo(Box<LeoPlant>),
    /// A robot of files: its URDF in rapier3d, its robot.toml's rules.
    Urdf(Box<RulesPlant<Vocab>>, &'static RobotSpec),
}

impl AnyPlant {
    /// The plant.
    pub fn get(&mut self) -> &mut dyn Plant {
        match self {
            AnyPlant::Pendulum(p) => p,
            AnyPlant::Physical(p) => p,
            AnyPlant::Leo(p) => p.as_mut(),
            AnyPlant::Urdf(p, _) => p.as_mut(),
        }
    }
    /// The plant, shared.
    pub fn get_ref(&self) -> &dyn Plant {
        match self {
            AnyPlant::Pendulum(p) => p,
            AnyPlant::Physical(p) => p,
            AnyPlant::Leo(p) => p.as_ref(),
            AnyPlant::Urdf(p, _) => p.as_ref(),
        }
    }
}

/// Whether `robot` names a file rather than a built-in robot: as `pada run
/// --robot` tells them apart (a path has a `/` or ends in `.toml`).
fn is_path(robot: &str) -> bool {
    robot.ends_with(".toml") || robot.contains('/')
}

/// A robot of files read, checked and built as `pada run --robot` does it
/// (the host's learner profile: the state, levels and ends are the file's).
fn from_file(path: &str) -> PyResult<(TaskSpec, AnyPlant)> {
    let file = pada_robot_file::load(std::path::Path::new(path))
        .map_err(|e| PyValueError::new_err(format!("robot = {path:?}: {e}")))?;
    let task = UrdfTask::new(&file).map_err(|e| PyValueError::new_err(format!("robot = {path:?}: {e}")))?;
    Ok((task.spec().clone(), AnyPlant::Urdf(Box::new(task.plant()), file.spec)))
}

/// The task's description and a new plant, as `pada run --task kind` (or
/// `pada run --robot PATH`).
pub fn make(kind: &str) -> PyResult<(TaskSpec, AnyPlant)> {
    if is_path(kind) {
        return from_file(kind);
    }
    Ok(match kind {
        "pendulum" => {
            let t = SimulatedPendulumTask::default();
            (t.spec().clone(), AnyPlant::Pendulum(t.plant()))
        }
        "physical-pendulum" => {
            let t = PhysicalPendulumTask::default();
            (t.spec().clone(), AnyPlant::Physical(t.plant()))
        }
        "leo" => {
            let t = LeoTask::default();
            (t.spec().clone(), AnyPlant::Leo(Box::new(t.plant())))
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "robot = {other:?} is not valid: valid is {KINDS}"
            )))
        }
    })
}

/// What one step did.
#[derive(Debug, Clone, Copy)]
pub struct StepOut {
    /// The reward.
    pub reward: f32,
    /// An absorbing state (a fall): `terminated`.
    pub terminal: bool,
    /// The time limit: `truncated`.
    pub truncated: bool,
}

/// A robot and its episode bookkeeping, without Python.
pub struct Core {
    /// The task.
    pub spec: TaskSpec,
    /// The plant.
    pub plant: AnyPlant,
    /// The latest observation.
    pub obs: Vec<f32>,
    /// Steps in the episode.
    pub steps: u32,
    /// The command of the last step.
    pub command: [f32; MAX_ACTION_DIMS],
    rng: Pcg64,
}

impl Core {
    /// A robot of `kind`.
    pub fn new(kind: &str) -> PyResult<Core> {
        let (spec, plant) = make(kind)?;
        let n = spec.state.len();
        Ok(Core {
            spec,
            plant,
            obs: vec![0.0; n],
            steps: 0,
            command: [0.0; MAX_ACTION_DIMS],
            rng: Pcg64::seed_from_u64(0),
        })
    }

    /// Starts an episode; `seed` reseeds the plant's generator (the
    /// pendulums and LEO start from fixed poses, as in `pada run`).
    pub fn reset(&mut self, seed: Option<u64>) {
        if let Some(s) = seed {
            self.rng = Pcg64::seed_from_u64(s);
        }
        let n = self.spec.state.len();
        self.plant.get().reset(&mut self.rng, &mut self.obs[..n]);
        self.steps = 0;
    }

    /// One control period with `command` (one value per motor dimension).
    pub fn step_command(&mut self, command: &[f32]) -> StepOut {
        let n = self.spec.state.len();
        let m = self.spec.motor.dims();
        self.command[..m].copy_from_slice(&command[..m]);
        let s = self.plant.get().step(&command[..m], &mut self.obs[..n]);
        self.steps += 1;
        // A fault (a joint past its soft limit) ends the episode, as `pada
        // run --robot` ends its trial there; `PlantEnv.fault` names it.
        let terminal = s.terminal || self.plant.get_ref().fault().is_some();
        StepOut {
            reward: s.reward,
            terminal,
            truncated: !terminal && self.steps >= self.spec.episode_steps,
        }
    }

    /// One control period with the motor's levels.
    pub fn step_levels(&mut self, levels: &Levels) -> StepOut {
        let out = self.spec.motor.values(levels);
        let m = self.spec.motor.dims();
        let mut c = [0.0f32; MAX_ACTION_DIMS];
        c[..m].copy_from_slice(&out[..m]);
        self.step_command(&c[..m])
    }

    /// The paper's gear torques of the last step (from the command).
    pub fn commanded_torques(&self) -> Vec<f64> {
        let m = self.spec.motor.dims();
        let t = self.plant.get_ref().commanded_torques(&self.command[..m]);
        t[..self.spec.gearboxes].iter().map(|&x| x as f64).collect()
    }

    /// The simulation's gear torques of the last step.
    pub fn gearbox_torques(&self) -> Vec<f64> {
        let m = self.spec.motor.dims();
        let t = self.plant.get_ref().gearbox_torques(&self.command[..m]);
        t[..self.spec.gearboxes].iter().map(|&x| x as f64).collect()
    }

    /// Checks discrete `action` values (one level index per motor
    /// dimension) into levels.
    pub fn levels_of(&self, action: &[i64]) -> PyResult<Levels> {
        let m = self.spec.motor.dims();
        let mut levels = Levels::default();
        for (i, &a) in action.iter().enumerate().take(m) {
            let n = self.spec.motor.dim(i).len() as i64;
            if !(0..n).contains(&a) {
                return Err(check::out_of_range(
                    &format!("action[{i}]"),
                    a,
                    &format!("0 <= action[{i}] < {n}"),
                ));
            }
            levels[i] = a as u8;
        }
        Ok(levels)
    }

    /// Checks continuous `action` values against the motor's range.
    pub fn command_of(&self, action: &[f64]) -> PyResult<[f32; MAX_ACTION_DIMS]> {
        let mut c = [0.0f32; MAX_ACTION_DIMS];
        for (i, &a) in action.iter().enumerate() {
            let d = self.spec.motor.dim(i);
            if !(a.is_finite() && a >= d.min() as f64 && a <= d.max() as f64) {
                return Err(check::out_of_range(
                    &format!("action[{i}]"),
                    a,
                    &format!(
                        "{} <= action[{i}] <= {} (the motor's range)",
                        d.min(),
                        d.max()
                    ),
                ));
            }
            c[i] = a as f32;
        }
        Ok(c)
    }
}

/// A pada robot for Gymnasium (`pada.envs`): `PlantEnv(robot,
/// continuous=False)` with `robot` "pendulum" (Section VII's simulated
/// pendulum), "physical-pendulum" (the paper's physical pendulum's model)
/// or "leo" (the rapier3d LEO, Section VIII).
#[pyclass(module = "pada")]
pub struct PlantEnv {
    core: Core,
    continuous: bool,
    ints: Vec<i64>,
    floats: Vec<f64>,
}

fn tuple_of<'py>(py: Python<'py>, v: &[f32]) -> PyResult<Bound<'py, PyTuple>> {
    PyTuple::new(py, v.iter().map(|&x| x as f64))
}

/// Reads `m` action values from a Python object (sequence or number).
fn read_action<T: for<'a, 'py> FromPyObject<'a, 'py>>(
    obj: &Bound<'_, PyAny>,
    m: usize,
    out: &mut Vec<T>,
) -> PyResult<()> {
    out.clear();
    if let Ok(len) = obj.len() {
        if len != m {
            return Err(PyValueError::new_err(format!(
                "action has {len} values, expected {m} (one per motor dimension)"
            )));
        }
        for item in obj.try_iter()? {
            out.push(
                item?
                    .extract::<T>()
                    .map_err(|_| PyValueError::new_err("action: every value must be a number"))?,
            );
        }
    } else {
        if m != 1 {
            return Err(PyValueError::new_err(format!(
                "action is one number, expected {m} values (one per motor dimension)"
            )));
        }
        out.push(
            obj.extract::<T>()
                .map_err(|_| PyValueError::new_err("action must be a number"))?,
        );
    }
    Ok(())
}

#[pymethods]
impl PlantEnv {
    #[new]
    #[pyo3(signature = (robot, continuous=false))]
    fn new(robot: &str, continuous: bool) -> PyResult<Self> {
        Ok(PlantEnv {
            core: Core::new(robot)?,
            continuous,
            ints: Vec::new(),
            floats: Vec::new(),
        })
    }

    /// The task: `name`, `control_period_s`, `episode_steps`, `gearboxes`,
    /// `levels` (the motor's values per dimension), `state_low`/`state_high`
    /// (the tile coder's ranges) and `state_wraps`.
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.core.spec;
        let d = PyDict::new(py);
        d.set_item("name", s.name)?;
        d.set_item("title", s.title)?;
        d.set_item("control_period_s", s.control_period_s)?;
        d.set_item("episode_steps", s.episode_steps)?;
        d.set_item("gearboxes", s.gearboxes)?;
        d.set_item("worst_torque", s.worst_torque_nm as f64)?;
        let levels: Vec<Vec<f64>> = (0..s.motor.dims())
            .map(|i| s.motor.dim(i).values().iter().map(|&v| v as f64).collect())
            .collect();
        d.set_item("levels", levels)?;
        d.set_item(
            "state_low",
            s.state.iter().map(|x| x.min as f64).collect::<Vec<_>>(),
        )?;
        d.set_item(
            "state_high",
            s.state.iter().map(|x| x.max as f64).collect::<Vec<_>>(),
        )?;
        d.set_item(
            "state_wraps",
            s.state.iter().map(|x| x.wrap).collect::<Vec<_>>(),
        )?;
        d.set_item("torque_note", s.torque_note)?;
        Ok(d)
    }

    /// Starts an episode; returns the first observation.
    #[pyo3(signature = (seed=None))]
    fn reset<'py>(&mut self, py: Python<'py>, seed: Option<u64>) -> PyResult<Bound<'py, PyTuple>> {
        self.core.reset(seed);
        tuple_of(py, &self.core.obs)
    }

    /// One control step: returns `(obs, reward, terminated, truncated)`.
    /// The action is one level index per motor dimension (a number for one
    /// dimension), or with `continuous` the commands themselves (torque or
    /// voltage, within the motor's range).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let m = self.core.spec.motor.dims();
        let out = if self.continuous {
            let mut v = std::mem::take(&mut self.floats);
            let r = read_action(action, m, &mut v).and_then(|_| self.core.command_of(&v));
            self.floats = v;
            let c = r?;
            self.core.step_command(&c[..m])
        } else {
            let mut v = std::mem::take(&mut self.ints);
            let r = read_action(action, m, &mut v).and_then(|_| self.core.levels_of(&v));
            self.ints = v;
            let l = r?;
            self.core.step_levels(&l)
        };
        let obs = tuple_of(py, &self.core.obs)?;
        PyTuple::new(
            py,
            [
                obs.into_any(),
                (out.reward as f64).into_pyobject(py)?.into_any(),
                pyo3::types::PyBool::new(py, out.terminal)
                    .to_owned()
                    .into_any(),
                pyo3::types::PyBool::new(py, out.truncated)
                    .to_owned()
                    .into_any(),
            ],
        )
    }

    /// The paper's gear torques of the last step, per gearbox \[N m\]
    /// (from the commanded action: `pada run`'s `mtbf_s`).
    fn commanded_torques(&self) -> Vec<f64> {
        self.core.commanded_torques()
    }

    /// The simulation's gear torques of the last step, per gearbox \[N m\]
    /// (`pada run`'s `physical_mtbf_s`).
    fn gearbox_torques(&self) -> Vec<f64> {
        self.core.gearbox_torques()
    }

    /// The fault of the last step (a joint past its soft limit), as
    /// `"soft-limit: joint shoulder (servo id 1)"`, else `None`.
    fn fault(&self) -> Option<String> {
        let joints = match &self.core.plant {
            AnyPlant::Urdf(_, robot) => robot.joints,
            _ => &[],
        };
        self.core.plant.get_ref().fault().map(|f| {
            match f.joint().and_then(|j| joints.get(j as usize)) {
                Some(j) => format!("{}: joint {} (servo id {})", f.name(), j.name, j.id),
                None => f.name().to_string(),
            }
        })
    }

    /// Walked distance in the episode \[m\] (LEO), else `None`.
    fn walked_distance_m(&self) -> Option<f64> {
        self.core.plant.get_ref().walked_distance_m()
    }
}
