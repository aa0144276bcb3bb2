//! A reference trajectory of LEO from another simulator: the authors'
//! framework's CSV export of one open-loop episode (`docs/reference/
//! leo-ab.md` says how it is made), read into pada's joint order.
//!
//! The file is the framework's `exporter/csv` output with `style: line`:
//! one header line naming the columns `time[0]`, `state0[0..16]`,
//! `state1[0..16]`, `action[0..7]`, `reward[0]`, `terminal[0]`,
//! `contacts[0]` and `stanceleft[0]`, then one row per control step.
//! Lines starting with `#` before the header are provenance (commit,
//! configuration, command) and are kept. The framework's state vectors
//! are eight angles then eight filtered rates in its joint order (left
//! hip, right hip, left knee, right knee, left ankle, right ankle,
//! shoulder, torso), its action vector the seven applied voltages in the
//! same order without the torso, and its contact word the bits right toe
//! 1, right heel 2, left toe 4, left heel 8.

use std::fmt;

use crate::leo::model::{Joint, JOINTS, NUM_JOINTS};
use crate::leo::task::{learned_joints, Leg};

/// The framework's joint order of its state and action vectors: pada's
/// ([`JOINTS`]) with the shoulder last (the eighth state entry is the
/// torso).
const REFERENCE_JOINTS: [Joint; NUM_JOINTS] = {
    let mut out = JOINTS;
    let mut i = 0;
    while i + 1 < NUM_JOINTS {
        out[i] = JOINTS[i + 1];
        i += 1;
    }
    out[NUM_JOINTS - 1] = JOINTS[0];
    out
};
const _: () = assert!(matches!(JOINTS[0], Joint::Shoulder));

/// The framework's contact bits in pada's sensor order (left toe, left
/// heel, right toe, right heel).
const CONTACT_BITS: [u32; 4] = [0x04, 0x08, 0x01, 0x02];

/// Columns a reference must have, with their widths.
const COLUMNS: [(&str, usize); 8] = [
    ("time", 1),
    ("state0", 16),
    ("state1", 16),
    ("action", 7),
    ("reward", 1),
    ("terminal", 1),
    ("contacts", 1),
    ("stanceleft", 1),
];

/// The most rows a reference may have: 750 control steps are the
/// episode's 25 s timeout (§3.8); a few more are allowed for headroom.
pub const MAX_REFERENCE_STEPS: usize = 10_000;

/// The robot's state as both simulators report it after a control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeoState {
    /// Torso angle φ (rad; §3.1: φ = −pitch, falls at |φ| > 1).
    pub torso: f32,
    /// Its rate through the task's filter (rad/s).
    pub torso_rate: f32,
    /// Joint angles, pada's [`Joint`] order (rad).
    pub angles: [f32; NUM_JOINTS],
    /// Joint rates through the task's filters, [`Joint`] order (rad/s).
    pub rates: [f32; NUM_JOINTS],
}

/// One control step of the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceStep {
    /// Time at the start of the step (s since the first observation).
    pub time: f32,
    /// The state before the step.
    pub before: LeoState,
    /// The state after it.
    pub after: LeoState,
    /// The voltage every servo was commanded, [`Joint`] order (V).
    pub voltages: [f32; NUM_JOINTS],
    /// The task's reward for the step.
    pub reward: f32,
    /// The framework's terminal code: 0 none, 2 a fall (absorbing).
    pub terminal: u8,
    /// Contact sensors after the step: left toe, left heel, right toe,
    /// right heel.
    pub contacts: [bool; 4],
    /// Whether the left leg is the stance leg after the step.
    pub stance_left: bool,
}

impl ReferenceStep {
    /// The three learned voltages (stance hip, swing hip, swing knee) of
    /// this step, read off the applied ones with the stance leg the step
    /// began with.
    pub fn learned_voltages(&self, stance_left_before: bool) -> [f32; 3] {
        let stance = if stance_left_before {
            Leg::Left
        } else {
            Leg::Right
        };
        learned_joints(stance).map(|j| self.voltages[j as usize])
    }
}

/// A reference trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// The `#` lines before the header, without the `#`.
    pub provenance: Vec<String>,
    /// One entry per control step, in order.
    pub steps: Vec<ReferenceStep>,
}

/// Why a reference file could not be read.
#[derive(Debug, Clone, PartialEq)]
pub enum ReferenceError {
    /// No header line.
    NoHeader,
    /// A column the comparison needs is missing from the header.
    MissingColumn(String),
    /// A row does not have the header's number of fields.
    FieldCount {
        /// 1-based line number.
        line: usize,
        /// Fields in the header.
        expected: usize,
        /// Fields in the row.
        found: usize,
    },
    /// A field is not a finite number.
    BadNumber {
        /// 1-based line number.
        line: usize,
        /// The column's header name.
        column: String,
        /// The field as written.
        text: String,
    },
    /// The file has no rows after its header.
    Empty,
    /// More rows than [`MAX_REFERENCE_STEPS`].
    TooLong(usize),
    /// The time column does not advance by one control period.
    Time {
        /// 1-based line number.
        line: usize,
        /// The row's time (s).
        time: f32,
        /// The time one row per control step gives (s).
        expected: f32,
    },
}

impl fmt::Display for ReferenceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReferenceError::NoHeader => write!(
                f,
                "no header line: a reference is the framework's CSV export with `style: line`"
            ),
            ReferenceError::MissingColumn(c) => write!(
                f,
                "the header has no column `{c}` (needed: time, state0[0..16], state1[0..16], \
                 action[0..7], reward, terminal, contacts, stanceleft)"
            ),
            ReferenceError::FieldCount {
                line,
                expected,
                found,
            } => write!(
                f,
                "line {line}: {found} fields where the header has {expected}"
            ),
            ReferenceError::BadNumber { line, column, text } => write!(
                f,
                "line {line}: column `{column}` is `{text}`, not a finite number"
            ),
            ReferenceError::Empty => write!(f, "the reference has a header but no rows"),
            ReferenceError::TooLong(n) => write!(
                f,
                "the reference has {n} rows; at most {MAX_REFERENCE_STEPS} are read"
            ),
            ReferenceError::Time {
                line,
                time,
                expected,
            } => write!(
                f,
                "line {line}: time {time} s where {expected} s was expected (one row per 1/30 s \
                 control step of a single episode)"
            ),
        }
    }
}

impl std::error::Error for ReferenceError {}

/// Every reference in `dir` (its `*.csv` files, as `tests/data/leo-ab/`
/// holds them), named by file stem and sorted by name. Errors name the
/// directory or the file and why it could not be read or parsed.
pub fn references_in(dir: &std::path::Path) -> Result<Vec<(String, Reference)>, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut out = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| format!("{}: {e}", dir.display()))?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("csv") {
            continue;
        }
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let reference = Reference::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        out.push((name, reference));
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

impl Reference {
    /// Parses a reference file's text (see the module's documentation).
    pub fn parse(text: &str) -> Result<Reference, ReferenceError> {
        let mut provenance = Vec::new();
        let mut lines = text.lines().enumerate();
        let header = loop {
            match lines.next() {
                None => return Err(ReferenceError::NoHeader),
                Some((_, l)) if l.trim().is_empty() => continue,
                Some((_, l)) if l.trim_start().starts_with('#') => {
                    provenance.push(l.trim_start()[1..].trim().to_string());
                }
                Some((_, l)) => break l,
            }
        };
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let mut start = [0usize; COLUMNS.len()];
        for (c, &(name, width)) in COLUMNS.iter().enumerate() {
            for j in 0..width {
                let want = format!("{name}[{j}]");
                let at = names
                    .iter()
                    .position(|n| *n == want)
                    .ok_or(ReferenceError::MissingColumn(want))?;
                if j == 0 {
                    start[c] = at;
                } else if at != start[c] + j {
                    return Err(ReferenceError::MissingColumn(format!(
                        "{name}[{j}] right after {name}[{}]",
                        j - 1
                    )));
                }
            }
        }
        let mut steps = Vec::new();
        for (index, line) in lines {
            let number = index + 1;
            if line.trim().is_empty() || line.trim_start().starts_with('#') {
                continue;
            }
            if steps.len() == MAX_REFERENCE_STEPS {
                return Err(ReferenceError::TooLong(steps.len() + 1));
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != names.len() {
                return Err(ReferenceError::FieldCount {
                    line: number,
                    expected: names.len(),
                    found: fields.len(),
                });
            }
            let value = |c: usize, j: usize| -> Result<f32, ReferenceError> {
                let at = start[c] + j;
                fields[at]
                    .parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| ReferenceError::BadNumber {
                        line: number,
                        column: names[at].to_string(),
                        text: fields[at].to_string(),
                    })
            };
            let state = |c: usize| -> Result<LeoState, ReferenceError> {
                let mut angles = [0.0; NUM_JOINTS];
                let mut rates = [0.0; NUM_JOINTS];
                for (k, joint) in REFERENCE_JOINTS.iter().enumerate() {
                    angles[*joint as usize] = value(c, k)?;
                    rates[*joint as usize] = value(c, 8 + k)?;
                }
                Ok(LeoState {
                    torso: value(c, 7)?,
                    torso_rate: value(c, 15)?,
                    angles,
                    rates,
                })
            };
            let mut voltages = [0.0; NUM_JOINTS];
            for (k, joint) in REFERENCE_JOINTS.iter().enumerate() {
                voltages[*joint as usize] = value(3, k)?;
            }
            let word = value(6, 0)? as u32;
            let time = value(0, 0)?;
            let expected = steps.len() as f32 / 30.0;
            if (time - expected).abs() > 1e-3 {
                return Err(ReferenceError::Time {
                    line: number,
                    time,
                    expected,
                });
            }
            steps.push(ReferenceStep {
                time,
                before: state(1)?,
                after: state(2)?,
                voltages,
                reward: value(4, 0)?,
                terminal: value(5, 0)? as u8,
                contacts: CONTACT_BITS.map(|b| word & b != 0),
                stance_left: value(7, 0)? != 0.0,
            });
        }
        if steps.is_empty() {
            return Err(ReferenceError::Empty);
        }
        Ok(Reference { provenance, steps })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> String {
        let mut h = vec!["time[0]".to_string()];
        for (name, width) in &COLUMNS[1..] {
            for j in 0..*width {
                h.push(format!("{name}[{j}]"));
            }
        }
        h.join(", ")
    }

    fn row(time: f32) -> String {
        let mut v = vec![format!("{time:.6}")];
        v.extend((0..16).map(|i| format!("{:.6}", i as f32 * 0.01)));
        v.extend((0..16).map(|i| format!("{:.6}", i as f32 * 0.02)));
        v.extend((0..7).map(|i| format!("{:.6}", i as f32)));
        v.extend(["-1.0", "0", "5", "1"].map(String::from));
        v.join(", ")
    }

    #[test]
    fn a_reference_is_read_into_pada_order() {
        let text = format!(
            "# commit x\n{}\n{}\n{}\n",
            header(),
            row(0.0),
            row(1.0 / 30.0)
        );
        let r = Reference::parse(&text).unwrap();
        assert_eq!(r.provenance, vec!["commit x".to_string()]);
        assert_eq!(r.steps.len(), 2);
        let s = &r.steps[1];
        // The framework's first joint is the left hip, its seventh the
        // shoulder, its eighth state entry the torso.
        assert_eq!(s.before.angles[Joint::HipLeft as usize], 0.0);
        assert_eq!(s.before.angles[Joint::Shoulder as usize], 0.06);
        assert_eq!(s.before.torso, 0.07);
        assert_eq!(s.after.rates[Joint::HipRight as usize], 0.18);
        assert_eq!(s.voltages[Joint::Shoulder as usize], 6.0);
        assert_eq!(s.voltages[Joint::AnkleRight as usize], 5.0);
        // 5 = right toe + left toe.
        assert_eq!(s.contacts, [true, false, true, false]);
        assert!(s.stance_left);
        // Stance left: stance hip = left hip (0 V), swing hip = right hip
        // (1 V), swing knee = right knee (3 V).
        assert_eq!(s.learned_voltages(true), [0.0, 1.0, 3.0]);
        assert_eq!(s.learned_voltages(false), [1.0, 0.0, 2.0]);
    }

    #[test]
    fn bad_references_are_refused_with_the_line_and_column() {
        assert_eq!(Reference::parse(""), Err(ReferenceError::NoHeader));
        assert_eq!(
            Reference::parse(&format!("{}\n", header())),
            Err(ReferenceError::Empty)
        );
        let e = Reference::parse("time[0], state0[0]\n0, 1\n").unwrap_err();
        assert!(matches!(e, ReferenceError::MissingColumn(_)), "{e}");
        let bad = row(0.0).replacen("0.010000", "nan", 1);
        let e = Reference::parse(&format!("{}\n{bad}\n", header())).unwrap_err();
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("state0[1]"),
            "{e}"
        );
        let e = Reference::parse(&format!("{}\n{}\n", header(), "1, 2")).unwrap_err();
        assert!(
            matches!(e, ReferenceError::FieldCount { line: 2, .. }),
            "{e}"
        );
        let e = Reference::parse(&format!("{}\n{}\n", header(), row(0.5))).unwrap_err();
        assert!(matches!(e, ReferenceError::Time { line: 2, .. }), "{e}");
    }
}
