//! A trial's result on disk, `DIR/results/NNNNNN.json`: its measurements
//! and learning curve (bit for bit, [`super::exact`]), the trial it
//! answers, the plan's hash and the trial's timing. The first line is a
//! header with the SHA-256 of the rest:
//!
//! ```text
//! pada-trial-result 1 sha256 <64 hex digits>
//! { ...JSON... }
//! ```
//!
//! A result is written to a hidden `.NNNNNN-*.partial` file in the same
//! directory and renamed into place, so a trial killed midway leaves no
//! result (at most a `.partial` file, which nothing reads).

use super::spec::{sha256_hex, Plan, TrialSpec};
use crate::experiment::{TestPoint, TrialResult};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// First word of a result file.
const MAGIC: &str = "pada-trial-result";
/// Version of the result layout.
pub const RESULT_FORMAT: u32 = 1;

/// When, where and how long a trial ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialTiming {
    /// Unix time at the trial's start \[s\].
    #[serde(with = "super::exact::f64")]
    pub started_unix_s: f64,
    /// Wall-clock time of the trial \[s\].
    #[serde(with = "super::exact::f64")]
    pub wall_s: f64,
    /// The machine that ran it.
    pub host: String,
    /// The Slurm array task (`JOB_TASK`) it ran in, if any.
    pub slurm_task: Option<String>,
}

impl TrialTiming {
    /// Unix time at the trial's end \[s\].
    pub fn finished_unix_s(&self) -> f64 {
        self.started_unix_s + self.wall_s
    }
}

/// A verified result.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredResult {
    /// The measurements, as the trial returned them.
    pub result: TrialResult,
    /// Its timing.
    pub timing: TrialTiming,
}

/// What a result file holds.
#[derive(Debug, Clone, PartialEq)]
pub enum ResultState {
    /// A result of this plan's trial whose checksum matches.
    Verified(Box<StoredResult>),
    /// No file.
    Missing,
    /// A file that is not this trial's intact result, and why.
    Corrupt(String),
}

#[derive(Serialize, Deserialize)]
struct Body {
    format: u32,
    plan: String,
    index: u32,
    spec: TrialSpec,
    #[serde(with = "StoredTrial")]
    result: TrialResult,
    timing: TrialTiming,
}

/// How a [`TrialResult`] is stored: with its curve and exact floats
/// (serde's remote derive, so the fields are checked against
/// [`TrialResult`]'s by the compiler and no copy is written by hand).
#[derive(Serialize, Deserialize)]
#[serde(remote = "TrialResult")]
struct StoredTrial {
    trial: u32,
    seed: u64,
    #[serde(with = "super::exact::f64")]
    end_performance: f64,
    #[serde(with = "super::exact::f64")]
    rise_time_s: f64,
    #[serde(with = "super::exact::f64")]
    mtbf_s: f64,
    window_reengagements: u64,
    #[serde(with = "super::exact::f64")]
    physical_mtbf_s: f64,
    physical_window_reengagements: u64,
    /// The paper's MTBF over all learning actions (absent in results
    /// written before the wear governor: NaN, unknown).
    #[serde(default = "nan", with = "super::exact::f64")]
    run_mtbf_s: f64,
    /// Each counted gearbox's MTBFs (absent in results written before
    /// them: empty, and the summary shows the robot's only).
    #[serde(default, skip_serializing_if = "Vec::is_empty", with = "super::exact::vec_f64")]
    joint_mtbf_s: Vec<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty", with = "super::exact::vec_f64")]
    physical_joint_mtbf_s: Vec<f64>,
    /// The wear governor's record, when one ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    governor: Option<crate::experiment::governed::GovernorTrial>,
    learning_steps: u64,
    test_steps: u64,
    learning_falls: u64,
    learning_episodes: u32,
    test_falls: u32,
    #[serde(with = "super::exact::opt_f64")]
    end_walked_m: Option<f64>,
    #[serde(with = "super::exact::opt_f64")]
    end_speed_m_s: Option<f64>,
    saturations: u32,
    trace_drops: u32,
    #[serde(default)]
    table: Option<pada_core::claim_table::Occupancy>,
    #[serde(with = "stored_curve")]
    curve: Vec<TestPoint>,
}

fn nan() -> f64 {
    f64::NAN
}

/// How a [`TestPoint`] is stored: with exact floats.
#[derive(Serialize, Deserialize)]
#[serde(remote = "TestPoint")]
struct StoredPoint {
    #[serde(with = "super::exact::f64")]
    learning_time_s: f64,
    learning_episodes: u32,
    #[serde(with = "super::exact::f64")]
    test_return: f64,
    #[serde(with = "super::exact::opt_f64")]
    walked_m: Option<f64>,
    fell: bool,
    #[serde(with = "super::exact::f64")]
    duration_s: f64,
    #[serde(default)]
    claimed_slots: Option<u32>,
}

/// A learning curve as a list of [`StoredPoint`]s.
mod stored_curve {
    use super::{StoredPoint, TestPoint};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// One point, stored as [`StoredPoint`] says.
    #[derive(Serialize, Deserialize)]
    #[serde(transparent)]
    struct Point(#[serde(with = "StoredPoint")] TestPoint);

    pub fn serialize<S: Serializer>(curve: &[TestPoint], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(curve.iter().map(|&p| Point(p)))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<TestPoint>, D::Error> {
        Ok(Vec::<Point>::deserialize(d)?.into_iter().map(|p| p.0).collect())
    }
}

/// The path of trial `index`'s result in the plan directory `dir`.
pub fn result_path(dir: &Path, plan: &Plan, index: u32) -> PathBuf {
    dir.join(&plan.trials[index as usize].result)
}

/// The prefix of trial `index`'s temporary files.
fn partial_prefix(index: u32) -> String {
    format!(".{index:06}-")
}

/// Removes the temporary files a killed run of trial `index` left.
pub fn remove_partials(dir: &Path, plan: &Plan, index: u32) {
    let path = result_path(dir, plan, index);
    let (Some(results), prefix) = (path.parent(), partial_prefix(index)) else {
        return;
    };
    if let Ok(entries) = std::fs::read_dir(results) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with(&prefix) && name.ends_with(".partial") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Writes trial `spec`'s result atomically; returns its path.
pub fn write(
    dir: &Path,
    plan: &Plan,
    spec: &TrialSpec,
    result: &TrialResult,
    timing: &TrialTiming,
) -> anyhow::Result<PathBuf> {
    let body = Body {
        format: RESULT_FORMAT,
        plan: plan.hash.clone(),
        index: spec.index,
        spec: spec.clone(),
        result: result.clone(),
        timing: timing.clone(),
    };
    let json = serde_json::to_string_pretty(&body)? + "\n";
    let mut bytes = format!(
        "{MAGIC} {RESULT_FORMAT} sha256 {}\n",
        sha256_hex(json.as_bytes())
    )
    .into_bytes();
    bytes.extend_from_slice(json.as_bytes());

    let path = result_path(dir, plan, spec.index);
    let results = path.parent().unwrap_or(dir);
    std::fs::create_dir_all(results)
        .with_context(|| format!("cannot create {}", results.display()))?;
    let mut tmp = tempfile::Builder::new()
        .prefix(&partial_prefix(spec.index))
        .suffix(".partial")
        .tempfile_in(results)
        .with_context(|| format!("cannot write in {}", results.display()))?;
    // Synced before the rename: on a cluster's network file system the
    // result must be whole once its name appears.
    tmp.write_all(&bytes)
        .and_then(|_| tmp.as_file().sync_all())
        .with_context(|| format!("cannot write {}", path.display()))?;
    tmp.persist(&path)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {}", path.display(), e.error))?;
    Ok(path)
}

/// Reads and verifies trial `index`'s result.
pub fn read(dir: &Path, plan: &Plan, index: u32) -> ResultState {
    let path = result_path(dir, plan, index);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return ResultState::Missing,
        Err(e) => return ResultState::Corrupt(format!("cannot read {} ({e})", path.display())),
    };
    match verify(&bytes, plan, index) {
        Ok(r) => ResultState::Verified(Box::new(r)),
        Err(why) => ResultState::Corrupt(format!("{}: {why}", path.display())),
    }
}

fn verify(bytes: &[u8], plan: &Plan, index: u32) -> Result<StoredResult, String> {
    let split = bytes
        .iter()
        .position(|&b| b == b'\n')
        .ok_or("no header line")?;
    let (header, json) = (&bytes[..split], &bytes[split + 1..]);
    let header = std::str::from_utf8(header).map_err(|_| "the header is not text")?;
    let words: Vec<&str> = header.split(' ').collect();
    let [magic, format, "sha256", sum] = words[..] else {
        return Err(format!("the header {header:?} is not a result's"));
    };
    if magic != MAGIC {
        return Err(format!("the header {header:?} is not a result's"));
    }
    if format != RESULT_FORMAT.to_string() {
        return Err(format!(
            "format {format} is not supported (valid: {RESULT_FORMAT})"
        ));
    }
    let actual = sha256_hex(json);
    if actual != sum {
        return Err(format!(
            "checksum does not match (sha256 {} in the header, {} of the content): the file was changed or cut short",
            &sum.get(..12).unwrap_or(sum),
            &actual[..12]
        ));
    }
    let body: Body =
        serde_json::from_slice(json).map_err(|e| format!("the content is not a result ({e})"))?;
    if body.plan != plan.hash {
        return Err(format!(
            "it belongs to another plan (hash {})",
            body.plan.get(..12).unwrap_or(&body.plan)
        ));
    }
    let spec = &plan.trials[index as usize];
    if body.index != index || body.spec != *spec {
        return Err(format!(
            "it answers trial {}, not {}",
            body.spec.describe(),
            spec.describe()
        ));
    }
    let result = body.result;
    if result.trial != spec.trial || result.seed != spec.trial_seed {
        return Err(format!(
            "its trial {} with seed {} is not the plan's trial {} with seed {}",
            result.trial, result.seed, spec.trial, spec.trial_seed
        ));
    }
    Ok(StoredResult {
        result,
        timing: body.timing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::tasks::TaskName;
    use crate::experiment::RunConfig;
    use crate::plan::{Experiment, ExperimentKind};
    use pada_core::policy::PolicyKind;

    fn plan() -> Plan {
        Plan::new(Experiment::new(
            ExperimentKind::Run,
            "pada run".into(),
            &[(
                TaskName::Leo,
                RunConfig {
                    policy: PolicyKind::Pada { delta: 1.0 / 6.0 },
                    switch_at_s: None,
                    mtbf_budget_s: None,
                    seconds: 60.0,
                    trials: 2,
                    seed: 9,
                },
            )],
        ))
        .unwrap()
    }

    /// A result with every awkward value: NaN, ∞, None, a long curve.
    fn result(p: &Plan) -> TrialResult {
        TrialResult {
            trial: 1,
            seed: p.trials[1].trial_seed,
            end_performance: -785.231_712_341_234_5,
            rise_time_s: f64::NAN,
            mtbf_s: f64::INFINITY,
            window_reengagements: 349,
            physical_mtbf_s: 1.0e-300,
            run_mtbf_s: f64::INFINITY,
            joint_mtbf_s: vec![f64::INFINITY, 1234.5],
            physical_joint_mtbf_s: vec![1.0e-300, f64::INFINITY],
            governor: Some(crate::experiment::governed::GovernorTrial { budget_s: 2600.0, held: true, physical_held: false, final_parameter: 0.834, mean_parameter: 0.1 + 0.2, floor_fraction: 1.0 / 3.0, moves: 7, over_budget_steps: 2 }),
            physical_window_reengagements: 7,
            learning_steps: 1800,
            test_steps: 77,
            learning_falls: 3,
            learning_episodes: 40,
            test_falls: 1,
            end_walked_m: Some(0.1 + 0.2),
            end_speed_m_s: None,
            saturations: 0,
            trace_drops: 0,
            table: Some(pada_core::claim_table::Occupancy { claimed: 3, slots: 8, refused: 1, replaced: 0, longest_probe: 2 }),
            curve: (0..50)
                .map(|i| TestPoint {
                    learning_time_s: i as f64 / 30.0,
                    learning_episodes: i,
                    test_return: -1.0 / (i as f64 + 0.7),
                    walked_m: (i % 2 == 0).then_some(i as f64 * 1e-3),
                    fell: i % 3 == 0,
                    duration_s: 25.0 - i as f64 / 7.0,
                    claimed_slots: Some(i * 3),
                })
                .collect(),
        }
    }

    fn timing() -> TrialTiming {
        TrialTiming {
            started_unix_s: 1.8e9 + 0.123,
            wall_s: 12.5,
            host: "node-7".into(),
            slurm_task: Some("42_1".into()),
        }
    }

    #[test]
    fn a_result_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let p = plan();
        let r = result(&p);
        let path = write(dir.path(), &p, &p.trials[1], &r, &timing()).unwrap();
        assert_eq!(path, dir.path().join("results/000001.json"));
        let ResultState::Verified(back) = read(dir.path(), &p, 1) else {
            panic!("{:?}", read(dir.path(), &p, 1));
        };
        assert!(back.result.rise_time_s.is_nan());
        let bits = |r: &TrialResult| {
            let mut v = vec![
                r.end_performance.to_bits(),
                r.mtbf_s.to_bits(),
                r.physical_mtbf_s.to_bits(),
            ];
            v.extend(r.curve.iter().flat_map(|c| {
                [
                    c.learning_time_s.to_bits(),
                    c.test_return.to_bits(),
                    c.duration_s.to_bits(),
                ]
            }));
            v
        };
        assert_eq!(bits(&back.result), bits(&r));
        let mut expected = r.clone();
        expected.rise_time_s = 0.0;
        let mut got = back.result.clone();
        got.rise_time_s = 0.0;
        assert_eq!(got, expected, "NaN aside, every field is equal");
        assert_eq!(back.timing, timing());
        assert_eq!(read(dir.path(), &p, 0), ResultState::Missing);
        // Only the result: no temporary file left.
        assert_eq!(
            std::fs::read_dir(dir.path().join("results"))
                .unwrap()
                .count(),
            1
        );
    }

    #[test]
    fn any_changed_byte_is_detected() {
        let dir = tempfile::tempdir().unwrap();
        let p = plan();
        let path = write(dir.path(), &p, &p.trials[1], &result(&p), &timing()).unwrap();
        let good = std::fs::read(&path).unwrap();
        // Every 97th byte of the content, flipped in its low bit.
        let header = good.iter().position(|&b| b == b'\n').unwrap() + 1;
        for at in (header..good.len()).step_by(97) {
            let mut bad = good.clone();
            bad[at] ^= 1;
            std::fs::write(&path, &bad).unwrap();
            match read(dir.path(), &p, 1) {
                ResultState::Corrupt(why) => assert!(why.contains("checksum"), "{why}"),
                other => panic!("byte {at} changed, read as {other:?}"),
            }
        }
        std::fs::write(&path, &good[..good.len() - 10]).unwrap();
        assert!(matches!(read(dir.path(), &p, 1), ResultState::Corrupt(_)));
        std::fs::write(&path, b"not a result").unwrap();
        let ResultState::Corrupt(why) = read(dir.path(), &p, 1) else {
            panic!()
        };
        assert!(why.contains("no header line"), "{why}");
        // The right file under the wrong name.
        std::fs::write(&path, &good).unwrap();
        std::fs::copy(&path, dir.path().join("results/000000.json")).unwrap();
        let ResultState::Corrupt(why) = read(dir.path(), &p, 0) else {
            panic!()
        };
        assert!(why.contains("it answers trial 1"), "{why}");
    }

    #[test]
    fn stale_partial_files_are_removed_for_their_index_only() {
        let dir = tempfile::tempdir().unwrap();
        let p = plan();
        let results = dir.path().join("results");
        std::fs::create_dir_all(&results).unwrap();
        for name in [".000001-abc.partial", ".000000-def.partial", "000000.json"] {
            std::fs::write(results.join(name), b"x").unwrap();
        }
        remove_partials(dir.path(), &p, 1);
        let mut left: Vec<String> = std::fs::read_dir(&results)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [".000000-def.partial", "000000.json"]);
    }
}

