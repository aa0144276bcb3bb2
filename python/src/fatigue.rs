//! `pada.Fatigue`: the learning core's fatigue counter (Eqs. 3–7) per
//! gearbox, fed one step's torques at a time or a whole array, with the
//! figures `pada mtbf` reports. Each gearbox is Table I's (the RX-28's)
//! unless `gearbox=` names another of pada's table, a TOML file, or gives
//! the fields as a dict.

use crate::check;
use pada_robot_file::gearbox_file::{self, ChosenGearbox, GearboxFile};
use pada_core::fatigue::{FatigueReport, JointFatigue, PAPER_WINDOW_STEPS};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

/// Most gearboxes one counter follows.
pub const MAX_COUNTED_JOINTS: i64 = 64;

/// The fatigue counter of every gearbox of a robot (Eqs. 3–7).
///
/// `Fatigue(joints, rate_hz, *, torque_per_volt=None, window=1200)`:
/// `joints` gearboxes (1–64) driven at `rate_hz` control steps per second.
/// Each step, `add(torques)` counts the backlash re-engagements of each
/// gearbox's torque (a sign change through the dead band, Eq. 3) and the
/// damage J of each (Eqs. 4–7: T_e,max → σ_max → σ_ar → N_f → 1/N_f); the
/// predicted MTBF is the elapsed time over J. With `torque_per_volt`, the
/// values given are voltages and the torque is `torque_per_volt · U` (the
/// paper's linear law). Torques are taken in `f32`, as `pada mtbf` reads a
/// log, so a log's figures are exactly `pada mtbf`'s.
#[pyclass(name = "Fatigue", module = "pada", subclass)]
pub struct Fatigue {
    joints: Vec<JointFatigue>,
    gearboxes: Vec<ChosenGearbox>,
    rate_hz: f64,
    torque_per_volt: Option<f64>,
    window: u32,
    buf: Vec<f64>,
    /// Bounds the values are clipped to before counting (an action
    /// space's, as the environment applies them), if any.
    clip: Option<(Vec<f64>, Vec<f64>)>,
}

impl Fatigue {
    /// A counter of `joints` gearboxes; the arguments checked. `gearboxes`
    /// holds one per gearbox, or is empty for Table I's everywhere.
    pub fn build(
        joints: i64,
        rate_hz: f64,
        torque_per_volt: Option<f64>,
        window: i64,
        gearboxes: Vec<ChosenGearbox>,
    ) -> PyResult<Fatigue> {
        let n = check::count("joints", joints, 1, MAX_COUNTED_JOINTS)?;
        let rate_hz = check::rate_hz("rate_hz", rate_hz)?;
        if let Some(k) = torque_per_volt {
            if !(k.is_finite() && k > 0.0) {
                return Err(check::out_of_range(
                    "torque_per_volt",
                    k,
                    "0 < torque_per_volt < inf (N m per V)",
                ));
            }
        }
        let window = check::count("window", window, 1, u32::MAX as i64)? as u32;
        let gearboxes = if gearboxes.is_empty() {
            vec![ChosenGearbox::table_i(); n]
        } else {
            gearboxes
        };
        if gearboxes.len() != n {
            return Err(PyValueError::new_err(format!(
                "gearbox: {} gearboxes for {n} joints: valid is one for every joint or one per joint",
                gearboxes.len()
            )));
        }
        let mut v = Vec::with_capacity(n);
        for g in &gearboxes {
            v.push(
                JointFatigue::new(&g.params, Some(window))
                    .map_err(|e| PyValueError::new_err(format!("window: {e}")))?,
            );
        }
        Ok(Fatigue {
            joints: v,
            gearboxes,
            rate_hz,
            torque_per_volt,
            window,
            buf: vec![0.0; n],
            clip: None,
        })
    }

    /// The gear torque counted for an input value (a torque, or a voltage
    /// with `torque_per_volt`), in `f32` as the core counts it.
    fn torque(&self, v: f64) -> f32 {
        match self.torque_per_volt {
            Some(k) => (k * v) as f32,
            None => v as f32,
        }
    }

    /// Counts one step of checked values.
    pub fn add_checked(&mut self, values: &[f64]) {
        for (j, &v) in values.iter().enumerate() {
            let t = self.torque(v);
            // Finite values only reach here; the core refuses only non-finite torques.
            let _ = self.joints[j].update(t);
        }
    }

    /// The joints.
    pub fn joints(&self) -> &[JointFatigue] {
        &self.joints
    }

    /// The control period \[s\].
    pub fn period_s(&self) -> f64 {
        1.0 / self.rate_hz
    }

    /// Robot MTBF (weakest gearbox) over the whole run.
    pub fn robot_mtbf_s(&self) -> f64 {
        let p = self.period_s();
        self.joints
            .iter()
            .map(|j| j.mtbf_s(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Reads one step's values from a Python object into the buffer.
    pub fn read_step(&mut self, name: &str, obj: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.joints.len();
        let what = if self.torque_per_volt.is_some() {
            "one voltage per gearbox, V"
        } else {
            "one torque per gearbox, N m"
        };
        let mut buf = std::mem::take(&mut self.buf);
        let r = check::finite_values(name, obj, n, what, &mut buf);
        if let Some((lo, hi)) = &self.clip {
            for ((v, l), h) in buf.iter_mut().zip(lo).zip(hi) {
                *v = v.clamp(*l, *h);
            }
        }
        self.buf = buf;
        r
    }

    /// Counts the step in the buffer.
    pub fn add_buffered(&mut self) {
        let buf = std::mem::take(&mut self.buf);
        self.add_checked(&buf);
        self.buf = buf;
    }
}

/// One gearbox from Python: a name of pada's table or a TOML file's path
/// (a str), or the Table I fields (a dict).
fn one_gearbox(obj: &Bound<'_, PyAny>) -> PyResult<ChosenGearbox> {
    if let Ok(s) = obj.cast::<PyString>() {
        let spec = s.to_cow()?;
        return gearbox_file::resolve(&spec).map_err(|e| PyValueError::new_err(format!("gearbox: {e}")));
    }
    if obj.cast::<PyDict>().is_ok() {
        let json: String = obj
            .py()
            .import("json")?
            .call_method1("dumps", (obj,))?
            .extract()?;
        let file: GearboxFile = serde_json::from_str(&json)
            .map_err(|e| PyValueError::new_err(format!("gearbox: {e}")))?;
        return file
            .check("gearbox")
            .map_err(PyValueError::new_err);
    }
    Err(PyValueError::new_err(format!(
        "gearbox: {} is not a gearbox: valid is a name of pada's table, a TOML file, or a dict of the Table I fields",
        obj.get_type().name()?
    )))
}

/// `gearbox=`: `None` (Table I everywhere), one gearbox for every joint, or
/// a list/tuple of one per joint.
pub fn gearboxes_from_py(obj: Option<&Bound<'_, PyAny>>, joints: i64) -> PyResult<Vec<ChosenGearbox>> {
    let Some(obj) = obj else { return Ok(Vec::new()) };
    if obj.is_none() {
        return Ok(Vec::new());
    }
    let items: Vec<Bound<'_, PyAny>> = if let Ok(l) = obj.cast::<PyList>() {
        l.iter().collect()
    } else if let Ok(t) = obj.cast::<PyTuple>() {
        t.iter().collect()
    } else {
        let g = one_gearbox(obj)?;
        let n = joints.max(0) as usize;
        return Ok(vec![g; n]);
    };
    items.iter().map(one_gearbox).collect()
}

fn reports(f: &Fatigue) -> Vec<FatigueReport> {
    let p = f.period_s();
    f.joints.iter().map(|j| j.report(p)).collect()
}

#[pymethods]
impl Fatigue {
    #[new]
    #[pyo3(signature = (joints, rate_hz, *, torque_per_volt=None, window=PAPER_WINDOW_STEPS as i64, gearbox=None))]
    fn new(
        joints: i64,
        rate_hz: f64,
        torque_per_volt: Option<f64>,
        window: i64,
        gearbox: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let gearboxes = gearboxes_from_py(gearbox, joints)?;
        Fatigue::build(joints, rate_hz, torque_per_volt, window, gearboxes)
    }

    /// Each gearbox's name (Table I's is "RX-28").
    #[getter]
    fn gearbox(&self) -> Vec<String> {
        self.gearboxes.iter().map(|g| g.name.clone()).collect()
    }

    /// Per gearbox, whether its last gear's geometry is an estimate (then so
    /// is its MTBF; docs/reference/servos.md).
    #[getter]
    fn gearbox_estimate(&self) -> Vec<bool> {
        self.gearboxes.iter().map(|g| g.estimate).collect()
    }

    /// Counts one control step: `torques` holds one value per gearbox (a
    /// number when there is one gearbox). A wrong length or a NaN raises
    /// `ValueError` and counts nothing.
    fn add(&mut self, torques: &Bound<'_, PyAny>) -> PyResult<()> {
        self.read_step("torques", torques)?;
        self.add_buffered();
        Ok(())
    }

    /// Counts `rows` steps from `data`, native-endian `f64` bytes of a
    /// C-contiguous `(rows, joints)` array (what `Fatigue.add_many` passes).
    fn _add_f64_bytes(&mut self, data: &[u8], rows: usize) -> PyResult<()> {
        let n = self.joints.len();
        if data.len() != rows * n * 8 {
            return Err(PyValueError::new_err(format!(
                "torques: {} bytes for {rows} rows of {n} float64 values",
                data.len()
            )));
        }
        let values: Vec<f64> = data
            .chunks_exact(8)
            .map(|c| f64::from_ne_bytes(c.try_into().expect("8 bytes")))
            .collect();
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "torques[{}, {}] = {} is not finite: valid is a finite number (nothing was counted)",
                i / n,
                i % n,
                values[i]
            )));
        }
        for row in values.chunks_exact(n) {
            self.add_checked(row);
        }
        Ok(())
    }

    /// Clips every value to `[low, high]` (per gearbox) before counting, as
    /// an environment clips its actions; `None` turns clipping off.
    #[pyo3(signature = (low=None, high=None))]
    fn set_clip(&mut self, low: Option<Vec<f64>>, high: Option<Vec<f64>>) -> PyResult<()> {
        let n = self.joints.len();
        self.clip = match (low, high) {
            (None, None) => None,
            (Some(l), Some(h))
                if l.len() == n && h.len() == n && l.iter().zip(&h).all(|(a, b)| a <= b) =>
            {
                Some((l, h))
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "low, high: valid is two lists of {n} numbers with low <= high, or neither"
                )))
            }
        };
        Ok(())
    }

    /// `add(torques)`, then writes `damage`, `mtbf_s` (per gearbox) and
    /// `robot_mtbf_s` into the dict `info` (what `MtbfWrapper` adds to
    /// every step's info).
    fn add_to_info(
        &mut self,
        torques: &Bound<'_, PyAny>,
        info: &Bound<'_, PyDict>,
    ) -> PyResult<()> {
        self.read_step("torques", torques)?;
        self.add_buffered();
        let p = self.period_s();
        let py = info.py();
        let damage = pyo3::types::PyList::new(py, self.joints.iter().map(|j| j.damage()))?;
        let mtbf = pyo3::types::PyList::new(py, self.joints.iter().map(|j| j.mtbf_s(p)))?;
        info.set_item(pyo3::intern!(py, "damage"), damage)?;
        info.set_item(pyo3::intern!(py, "mtbf_s"), mtbf)?;
        info.set_item(pyo3::intern!(py, "robot_mtbf_s"), self.robot_mtbf_s())?;
        Ok(())
    }

    /// Starts over: no steps, no damage.
    fn reset(&mut self) {
        for j in &mut self.joints {
            j.reset();
        }
    }

    /// Gearboxes counted.
    #[getter]
    fn joints_count(&self) -> usize {
        self.joints.len()
    }

    /// Control rate \[Hz\].
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// The window of the paper's MTBF \[steps\].
    #[getter]
    fn window(&self) -> u32 {
        self.window
    }

    /// Steps counted.
    #[getter]
    fn steps(&self) -> u64 {
        self.joints[0].steps()
    }

    /// Damage J per gearbox so far (Eq. 7).
    #[getter]
    fn damage(&self) -> Vec<f64> {
        self.joints.iter().map(|j| j.damage()).collect()
    }

    /// Predicted MTBF per gearbox so far \[s\] (`inf` without damage).
    #[getter]
    fn mtbf_s(&self) -> Vec<f64> {
        let p = self.period_s();
        self.joints.iter().map(|j| j.mtbf_s(p)).collect()
    }

    /// The robot's predicted MTBF so far: its weakest gearbox's \[s\].
    #[getter(robot_mtbf_s)]
    fn robot_mtbf_s_py(&self) -> f64 {
        self.robot_mtbf_s()
    }

    /// What `pada mtbf` reports, as a dict: `steps`, `rate_hz`,
    /// `window_steps`; per gearbox the lists `reengagements`, `damage`,
    /// `mtbf_s` (whole run) and `window_reengagements`, `window_damage`,
    /// `window_mtbf_s` (the first `window` steps, the paper's MTBF); and the
    /// robot's `robot_mtbf_s` and `robot_window_mtbf_s` (weakest gearbox).
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = reports(self);
        let d = PyDict::new(py);
        d.set_item("steps", self.joints[0].steps())?;
        d.set_item("rate_hz", self.rate_hz)?;
        d.set_item("window_steps", self.window)?;
        d.set_item(
            "reengagements",
            r.iter().map(|x| x.reengagements).collect::<Vec<_>>(),
        )?;
        d.set_item("damage", r.iter().map(|x| x.damage).collect::<Vec<_>>())?;
        d.set_item("mtbf_s", r.iter().map(|x| x.mtbf_s).collect::<Vec<_>>())?;
        let w = |f: fn(&pada_core::fatigue::WindowReport) -> f64| -> Vec<f64> {
            r.iter().map(|x| x.window.as_ref().map_or(0.0, f)).collect()
        };
        d.set_item(
            "window_reengagements",
            r.iter()
                .map(|x| x.window.map_or(0, |w| w.reengagements))
                .collect::<Vec<_>>(),
        )?;
        d.set_item("window_damage", w(|w| w.damage))?;
        let wm: Vec<f64> = r
            .iter()
            .map(|x| x.window.map_or(f64::INFINITY, |w| w.mtbf_s))
            .collect();
        d.set_item(
            "robot_window_mtbf_s",
            wm.iter().copied().fold(f64::INFINITY, f64::min),
        )?;
        d.set_item("window_mtbf_s", wm)?;
        d.set_item("robot_mtbf_s", self.robot_mtbf_s())?;
        d.set_item("gearbox", self.gearbox())?;
        d.set_item("gearbox_estimate", self.gearbox_estimate())?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Fatigue(joints={}, rate_hz={}, steps={}, robot_mtbf_s={})",
            self.joints.len(),
            self.rate_hz,
            self.joints[0].steps(),
            self.robot_mtbf_s()
        )
    }
}
