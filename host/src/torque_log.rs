//! Reading a recorded torque log (`pada mtbf`): a CSV file with one column
//! per joint and one row per control step, torques in N·m; an optional
//! first row of joint names. Every malformed cell is reported with its
//! line and column.

use crate::error::{usage, CliError};
use std::path::Path;

/// A parsed log.
#[derive(Debug, Clone, PartialEq)]
pub struct TorqueLog {
    /// Joint names (from the header, or `joint0`, `joint1`, …).
    pub joints: Vec<String>,
    /// Rows of torques, one value per joint.
    pub rows: Vec<Vec<f32>>,
}

/// Reads and checks the log at `path`.
pub fn read(path: &Path) -> Result<TorqueLog, CliError> {
    let text = std::fs::read(path)
        .map_err(|e| usage(format!("cannot read torque log {}: {e}", path.display())))?;
    parse(&text).map_err(|e| usage(format!("{}: {e}", path.display())))
}

/// Parses CSV bytes; the error names the line, the column and the problem.
pub fn parse(bytes: &[u8]) -> Result<TorqueLog, String> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(bytes);
    let mut joints: Vec<String> = Vec::new();
    let mut rows: Vec<Vec<f32>> = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| format!("not valid CSV: {e}"))?;
        let line = record.position().map(|p| p.line()).unwrap_or(i as u64 + 1);
        if record.iter().all(|f| f.is_empty()) {
            continue;
        }
        if joints.is_empty() {
            let numeric = record.iter().filter(|f| f.parse::<f64>().is_ok()).count();
            if numeric == 0 {
                joints = record.iter().map(str::to_string).collect();
                continue;
            }
            joints = (0..record.len()).map(|j| format!("joint{j}")).collect();
        }
        if record.len() != joints.len() {
            return Err(format!(
                "line {line}: {} columns, expected {} (one torque per joint)",
                record.len(),
                joints.len()
            ));
        }
        let mut row = Vec::with_capacity(joints.len());
        for (j, field) in record.iter().enumerate() {
            let v: f32 = field.parse().map_err(|_| {
                format!(
                    "line {line}, column {} ({}): '{field}' is not a number (torque in N m)",
                    j + 1,
                    joints[j]
                )
            })?;
            if !v.is_finite() {
                return Err(format!(
                    "line {line}, column {} ({}): '{field}' is not a finite torque",
                    j + 1,
                    joints[j]
                ));
            }
            row.push(v);
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(
            "no torque rows (expected one row per control step, one column per joint)".into(),
        );
    }
    Ok(TorqueLog { joints, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_optional() {
        let a = parse(b"hip,knee\n1.5,0\n-1.5,0.2\n").unwrap();
        assert_eq!(a.joints, ["hip", "knee"]);
        assert_eq!(a.rows, vec![vec![1.5, 0.0], vec![-1.5, 0.2]]);
        let b = parse(b"1.5\n-1.5\n").unwrap();
        assert_eq!(b.joints, ["joint0"]);
        assert_eq!(b.rows.len(), 2);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse(b"hip,knee\n1.5,0\n-1.5\n").unwrap_err();
        assert!(e.contains("line 3") && e.contains("expected 2"), "{e}");
        let e = parse(b"hip,knee\n1.5,abc\n").unwrap_err();
        assert!(
            e.contains("line 2, column 2 (knee)") && e.contains("not a number"),
            "{e}"
        );
        let e = parse(b"1,NaN\n").unwrap_err();
        assert!(e.contains("not a finite torque"), "{e}");
        assert!(parse(b"hip\n").unwrap_err().contains("no torque rows"));
        assert!(parse(b"").unwrap_err().contains("no torque rows"));
    }
}
