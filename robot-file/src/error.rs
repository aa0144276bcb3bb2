//! One error of a robot's files, in one line: the file, the line and
//! column where the value is, the field, what is wrong and what is valid.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What is wrong with a robot's files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RobotFileError {
    /// The file.
    pub file: PathBuf,
    /// Line and column (1-based) of the value, where known.
    pub at: Option<(usize, usize)>,
    /// The field, as the file spells it (`joint[1].servo`).
    pub field: String,
    /// What is wrong, and what is valid.
    pub message: String,
}

impl fmt::Display for RobotFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some((line, col)) = self.at {
            write!(f, ":{line}:{col}")?;
        }
        if self.field.is_empty() {
            write!(f, ": {}", self.message)
        } else {
            write!(f, ": {}: {}", self.field, self.message)
        }
    }
}

impl std::error::Error for RobotFileError {}

/// Builds errors that point into one file's text.
#[derive(Debug, Clone)]
pub struct Locator<'a> {
    file: &'a Path,
    text: &'a str,
}

impl<'a> Locator<'a> {
    /// Errors of `file`, whose text is `text`.
    pub fn new(file: &'a Path, text: &'a str) -> Self {
        Locator { file, text }
    }

    /// Line and column (1-based) of byte `offset`; `None` for an empty
    /// span (a default value, which has no place in the file).
    pub fn position(&self, span: &Range<usize>) -> Option<(usize, usize)> {
        if span.is_empty() && span.start == 0 {
            return None;
        }
        let before = self.text.get(..span.start.min(self.text.len()))?;
        let line = before.matches('\n').count() + 1;
        let col = before.chars().rev().take_while(|c| *c != '\n').count() + 1;
        Some((line, col))
    }

    /// An error of `field` at `span`.
    pub fn at(&self, span: &Range<usize>, field: impl Into<String>, message: impl Into<String>) -> RobotFileError {
        RobotFileError {
            file: self.file.to_path_buf(),
            at: self.position(span),
            field: field.into(),
            message: message.into(),
        }
    }

    /// An error of `field` with no place in the file.
    pub fn field(&self, field: impl Into<String>, message: impl Into<String>) -> RobotFileError {
        RobotFileError { file: self.file.to_path_buf(), at: None, field: field.into(), message: message.into() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_points_at_its_line_and_column() {
        let text = "[robot]\nname = \"x\"\nperiod_ms = -3\n";
        let l = Locator::new(Path::new("r.toml"), text);
        let start = text.find("-3").unwrap();
        let e = l.at(&(start..start + 2), "robot.period_ms", "must be positive");
        assert_eq!(e.to_string(), "r.toml:3:13: robot.period_ms: must be positive");
        assert_eq!(l.field("joint", "none").to_string(), "r.toml: joint: none");
    }
}
