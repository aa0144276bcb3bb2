//! `pada._pada.WearGovernor`: the learning core's wear governor
//! (`pada_core::governor`, the rule behind `pada run --mtbf-budget`) with
//! the fatigue counters that feed it, for `PadaWrapper(mtbf_budget=…)`.

use crate::check;
use crate::fatigue::Fatigue;
use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::fatigue::{GearboxParams, PAPER_WINDOW_STEPS};
use pada_core::governor::{Governor, GovernorConfig, Restricts, GOVERNED_JOINTS, MAX_BUDGET_S};
use pada_core::policy::PolicyKind;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Moves PADA's Δ (Eq. 9) or the low-pass α (Eq. 8) so that the predicted
/// MTBF (Eqs. 3–7) over the last 1200 actions stays at or above a budget.
///
/// `WearGovernor(mtbf_budget, rate_hz, *, joints, levels, worst_torque,
/// restricts="delta")`: `levels` is the number of action levels per
/// dimension the Δ ladder steps over (Δ = k/(levels−1)); `worst_torque`
/// the largest gear torque one action can command \[N m\]. `observe(torques)`
/// counts one action's gear torques and returns the new Δ or α when the
/// governor moved, else `None`. The rule is the core's, bit for bit the one
/// of `pada run --mtbf-budget`.
#[pyclass(name = "WearGovernor", module = "pada")]
pub struct WearGovernor {
    governor: Governor,
    fatigue: Fatigue,
    before: Vec<u64>,
}

#[pymethods]
impl WearGovernor {
    #[new]
    #[pyo3(signature = (mtbf_budget, rate_hz, *, joints, levels, worst_torque, restricts="delta"))]
    fn new(
        mtbf_budget: f64,
        rate_hz: f64,
        joints: i64,
        levels: i64,
        worst_torque: f64,
        restricts: &str,
    ) -> PyResult<Self> {
        if !(mtbf_budget.is_finite() && mtbf_budget > 0.0 && mtbf_budget <= MAX_BUDGET_S as f64) {
            return Err(check::out_of_range(
                "mtbf_budget",
                mtbf_budget,
                "0 < mtbf_budget <= 1e10 (s)",
            ));
        }
        let rate_hz = check::rate_hz("rate_hz", rate_hz)?;
        let n = check::count("joints", joints, 1, GOVERNED_JOINTS as i64)?;
        let levels = check::count("levels", levels, 2, 255)?;
        if !(worst_torque.is_finite() && worst_torque > 0.0) {
            return Err(check::out_of_range(
                "worst_torque",
                worst_torque,
                "0 < worst_torque < inf (N m)",
            ));
        }
        let kind = match restricts {
            "delta" => PolicyKind::Pada { delta: 1.0 },
            "alpha" => PolicyKind::LowPass { alpha: 1.0 },
            other => {
                return Err(PyValueError::new_err(format!(
                    "restricts = {other:?} is not valid: valid is \"delta\" (PADA, Eq. 9) or \"alpha\" (low-pass, Eq. 8)"
                )))
            }
        };
        let dim = ActionDim::uniform(-1.0, 1.0, levels)
            .map_err(|e| PyValueError::new_err(format!("levels: {e}")))?;
        let motor =
            ActionSpace::new(&[dim]).map_err(|e| PyValueError::new_err(format!("levels: {e}")))?;
        let config = GovernorConfig {
            budget_s: mtbf_budget as f32,
            period_s: 1.0 / rate_hz,
            gearbox: GearboxParams::TABLE_I,
            worst_torque_nm: worst_torque as f32,
            joints: n as u8,
        };
        let governor = Governor::new(&kind, &motor, &config)
            .map_err(|e| PyValueError::new_err(format!("mtbf_budget: {e}")))?;
        let fatigue = Fatigue::build(n as i64, rate_hz, None, PAPER_WINDOW_STEPS as i64, Vec::new())?;
        Ok(WearGovernor {
            governor,
            fatigue,
            before: vec![0; n],
        })
    }

    /// One action's gear torques (one per gearbox, N m): counts them and
    /// returns the new Δ or α if the governor moved, else `None`.
    fn observe(&mut self, torques: &Bound<'_, PyAny>) -> PyResult<Option<f32>> {
        self.fatigue.read_step("torques", torques)?;
        for (b, j) in self.before.iter_mut().zip(self.fatigue.joints()) {
            *b = j.damage_raw();
        }
        self.fatigue.add_buffered();
        let mut inc = [0u64; GOVERNED_JOINTS];
        for (k, j) in self.fatigue.joints().iter().enumerate() {
            inc[k] = j.damage_raw() - self.before[k];
        }
        Ok(self.governor.observe(&inc))
    }

    /// The Δ or α in force.
    #[getter]
    fn parameter(&self) -> f32 {
        self.governor.parameter()
    }

    /// The rung in force (0 the most restrictive).
    #[getter]
    fn rung(&self) -> u8 {
        self.governor.rung()
    }

    /// "delta" or "alpha".
    #[getter]
    fn restricts(&self) -> &'static str {
        match self.governor.restricts() {
            Restricts::Delta => "delta",
            Restricts::Alpha => "alpha",
        }
    }

    /// What the governor reports: budget, parameter, rung, moves, the
    /// window's MTBF and the actions over budget.
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.governor.status();
        let d = PyDict::new(py);
        d.set_item("mtbf_budget", self.governor.budget_s() as f64)?;
        d.set_item("restricts", self.restricts())?;
        d.set_item("parameter", s.parameter)?;
        d.set_item("rung", s.rung)?;
        d.set_item("moves", s.moves)?;
        d.set_item("window_mtbf_s", s.window_mtbf_s)?;
        d.set_item("over_budget_steps", self.governor.state().over_budget_steps)?;
        d.set_item("robot_mtbf_s", self.fatigue.robot_mtbf_s())?;
        Ok(d)
    }
}
