//! `pada._pada`, the Rust half of the `pada` Python package: the fatigue
//! counter of the learning core (Eqs. 3–7) and its wear governor, pada's
//! simulated robots (the pendulums of Section VII, the rapier3d LEO of
//! Section VIII) and the telemetry decoder, wrapped for Python with pyo3 on
//! the stable ABI (abi3). The Python half (`python/pada/`) builds the
//! Gymnasium wrappers and environments on these.
//!
//! Every argument is checked here and a bad one raises `ValueError` naming
//! the argument and its valid range; nothing panics across the boundary.

use pyo3::prelude::*;

mod check;
mod envs;
mod fatigue;
mod governor;
mod reference;
mod telemetry;
mod vector;

/// The module `pada._pada`.
#[pymodule]
fn _pada(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<fatigue::Fatigue>()?;
    m.add_class::<governor::WearGovernor>()?;
    m.add_class::<envs::PlantEnv>()?;
    m.add_class::<vector::LeoVectorCore>()?;
    m.add_function(wrap_pyfunction!(telemetry::read_telemetry, m)?)?;
    m.add_function(wrap_pyfunction!(reference::reference_rollout, m)?)?;
    m.add_function(wrap_pyfunction!(reference::bench_rust_steps, m)?)?;
    m.add(
        "RX28_TORQUE_PER_VOLT",
        pada_core::robot::leo::commanded_gear_torque(1.0) as f64,
    )?;
    m.add("PAPER_WINDOW_STEPS", pada_core::fatigue::PAPER_WINDOW_STEPS)?;
    m.add("MAX_BUDGET_S", pada_core::governor::MAX_BUDGET_S as f64)?;
    Ok(())
}
