//! One pass/fail check of a software-in-the-loop run: a leaf that the
//! report and the checks' makers (the power cuts among them) both use.

use serde::Serialize;

/// A pass/fail check of the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// What is checked.
    pub name: &'static str,
    /// Whether it holds.
    pub ok: bool,
    /// The numbers behind it.
    pub detail: String,
}
