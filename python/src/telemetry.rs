//! `pada.read_telemetry`: a recorded telemetry stream (`pada run
//! --telemetry FILE`, a board's raw serial output) decoded by the host's
//! capture decoder (`pada_telemetry::capture::Recorder`, the one `pada capture`
//! uses), so its frame and loss counts are `pada capture --json`'s.

use pada_telemetry::capture::{mode_name, step_kind_name, Recorder};
use pada_core::wire::ToHost;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Decodes the stream at `path`; returns a dict of plain lists (the Python
/// side turns them into numpy arrays) and `summary_json`, the link and
/// message counts as `pada capture --json` writes them.
#[pyfunction]
pub fn read_telemetry<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    if path.is_dir() {
        return Err(PyValueError::new_err(format!(
            "path = {} is a directory: valid is a recorded telemetry stream file",
            path.display()
        )));
    }
    let bytes = std::fs::read(&path)
        .map_err(|e| PyOSError::new_err(format!("path = {}: cannot read: {e}", path.display())))?;
    let (rec, frames) = py.detach(|| {
        let mut rec = Recorder::new(None).expect("no CSV to write");
        let mut frames = Vec::new();
        let _ = rec.feed(&bytes, 0.0, &mut frames);
        let _ = rec.finish(0.0);
        // A save or restore the file ends inside is listed as unfinished.
        let _ = rec.end();
        (rec, frames)
    });
    let d = PyDict::new(py);
    let (
        mut step,
        mut time_ms,
        mut episode,
        mut mode,
        mut kind,
        mut action,
        mut reward,
        mut td,
        mut explored,
    ) = (
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
    );
    let (mut state, mut output, mut damage, mut reeng, mut loop_us) =
        (vec![], vec![], vec![], vec![], vec![]);
    let (mut e_index, mut e_mode, mut e_return, mut e_length, mut e_checksum) =
        (vec![], vec![], vec![], vec![], vec![]);
    for f in &frames {
        match &f.msg {
            ToHost::Step(s) => {
                step.push(s.step);
                time_ms.push(s.time_ms);
                episode.push(s.episode);
                mode.push(mode_name(s.mode));
                kind.push(step_kind_name(s.kind));
                action.push(s.action);
                reward.push(s.reward as f64);
                td.push(s.td_error as f64 / 65536.0);
                explored.push(s.explored);
                state.push(s.state.iter().map(|&x| x as f64).collect::<Vec<_>>());
                output.push(s.output.iter().map(|&x| x as f64).collect::<Vec<_>>());
                damage.push(s.joints.iter().map(|j| j.damage).collect::<Vec<_>>());
                reeng.push(s.joints.iter().map(|j| j.reengagements).collect::<Vec<_>>());
                loop_us.push(s.loop_us);
            }
            ToHost::Episode(e) => {
                e_index.push(e.index);
                e_mode.push(mode_name(e.mode));
                e_return.push(e.total_reward as f64);
                e_length.push(e.length);
                e_checksum.push(e.weights_checksum);
            }
            _ => {}
        }
    }
    let steps = PyDict::new(py);
    steps.set_item("step", step)?;
    steps.set_item("time_ms", time_ms)?;
    steps.set_item("episode", episode)?;
    steps.set_item("mode", mode)?;
    steps.set_item("kind", kind)?;
    steps.set_item("action", action)?;
    steps.set_item("reward", reward)?;
    steps.set_item("td_error", td)?;
    steps.set_item("explored", explored)?;
    steps.set_item("state", state)?;
    steps.set_item("output", output)?;
    steps.set_item("damage", damage)?;
    steps.set_item("reengagements", reeng)?;
    steps.set_item("loop_us", loop_us)?;
    let episodes = PyDict::new(py);
    episodes.set_item("index", e_index)?;
    episodes.set_item("mode", e_mode)?;
    episodes.set_item("return", e_return)?;
    episodes.set_item("length", e_length)?;
    episodes.set_item("weights_checksum", e_checksum)?;
    d.set_item("steps", steps)?;
    d.set_item("episodes", episodes)?;
    let stats = rec.stats();
    let summary = serde_json::json!({
        "link": stats,
        "bad_frames": stats.bad_frames(),
        "messages": rec.counts(),
        // One per checkpoint save and restore, as pada capture's CSV rows.
        "checkpoints": rec.transfers(),
    });
    d.set_item("summary_json", summary.to_string())?;
    Ok(d)
}
