//! Choosing a gearbox for the fatigue counter (Eqs. 3–7): by name from
//! pada's table (`pada_core::servo::GEARBOXES`, `docs/reference/servos.md`)
//! or from a file of the Table I fields, for `pada mtbf --gearbox` and
//! `pada.Fatigue(gearbox=…)`.
//!
//! A file is TOML (or, from Python, a dict) with the fields of
//! [`GearboxParams`], units in their names, all required, plus an optional
//! `name`, `note` and `estimate` (default false: the file's author vouches
//! for its numbers). Every value is checked by [`GearboxParams::validate`];
//! every error is one line naming the file, the field and the valid range.

use pada_core::fatigue::GearboxParams;
use pada_core::servo;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A gearbox chosen for a joint: its parameters and what reports say of it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChosenGearbox {
    /// Its name: the table's, the file's `name`, or the file's path.
    pub name: String,
    /// Where it comes from: "pada's table" or the file.
    pub source: String,
    /// Whether its last gear's geometry is an estimate (not measured).
    pub estimate: bool,
    /// The table's note on its numbers, or the file's `note`.
    pub note: String,
    /// The parameters of Eqs. 3–7 (valid).
    #[serde(skip)]
    pub params: GearboxParams,
}

impl ChosenGearbox {
    /// Table I, the RX-28's (the default everywhere).
    pub fn table_i() -> ChosenGearbox {
        Self::from_table(&servo::gearbox::RX28_GEARBOX)
    }

    /// An entry of pada's table.
    pub fn from_table(g: &servo::Gearbox) -> ChosenGearbox {
        ChosenGearbox {
            name: g.name.to_string(),
            source: "pada's table (docs/reference/servos.md)".to_string(),
            estimate: g.estimate,
            note: g.note.to_string(),
            params: g.params,
        }
    }

    /// One phrase for reports: the name and whether its geometry is an
    /// estimate.
    pub fn describe(&self) -> String {
        if self.estimate {
            format!(
                "{} (its last gear's geometry is an estimate, not a measurement: docs/reference/servos.md)",
                self.name
            )
        } else if self.params == GearboxParams::TABLE_I && self.name == "RX-28" {
            format!("{} (Table I of the paper, measured)", self.name)
        } else {
            format!("{} (from {})", self.name, self.source)
        }
    }
}

/// The fields of a gearbox file: [`GearboxParams`] with units in the
/// names, plus the optional `name`, `note` and `estimate`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearboxFile {
    /// Shown in reports (default: the file's path).
    pub name: Option<String>,
    /// Shown in JSON reports.
    pub note: Option<String>,
    /// Whether the numbers are an estimate (default false).
    pub estimate: Option<bool>,
    /// θ_bl \[rad\].
    pub theta_bl_rad: f64,
    /// k \[N·m/rad\].
    pub k_nm_per_rad: f64,
    /// d (negative).
    pub d: f64,
    /// σ'_f \[MPa\].
    pub sigma_f_mpa: f64,
    /// b \[mm\].
    pub b_mm: f64,
    /// m_n \[mm\].
    pub m_n_mm: f64,
    /// d_w \[mm\].
    pub d_w_mm: f64,
    /// Y_Fa.
    pub y_fa: f64,
    /// Y_Sa.
    pub y_sa: f64,
    /// Y_ε.
    pub y_epsilon: f64,
    /// Y_β.
    pub y_beta: f64,
    /// Teeth of the last gear (Eq. 7).
    pub teeth: u32,
}

impl GearboxFile {
    /// The checked gearbox; `origin` (the file, or "gearbox" for a dict)
    /// starts every error.
    pub fn check(self, origin: &str) -> Result<ChosenGearbox, String> {
        let params = GearboxParams {
            theta_bl_rad: self.theta_bl_rad,
            k_nm_per_rad: self.k_nm_per_rad,
            d: self.d,
            sigma_f_mpa: self.sigma_f_mpa,
            b_mm: self.b_mm,
            m_n_mm: self.m_n_mm,
            d_w_mm: self.d_w_mm,
            y_fa: self.y_fa,
            y_sa: self.y_sa,
            y_epsilon: self.y_epsilon,
            y_beta: self.y_beta,
            teeth: self.teeth,
        };
        params.validate().map_err(|e| format!("{origin}: {e}"))?;
        Ok(ChosenGearbox {
            name: self.name.unwrap_or_else(|| origin.to_string()),
            source: origin.to_string(),
            estimate: self.estimate.unwrap_or(false),
            note: self.note.unwrap_or_default(),
            params,
        })
    }
}

/// Parses the TOML text of a gearbox file; `origin` names it in errors
/// (with the line of the problem).
pub fn parse_toml(text: &str, origin: &str) -> Result<ChosenGearbox, String> {
    let file: GearboxFile = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        let msg = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
        match line {
            Some(l) => format!("{origin}, line {l}: {msg}"),
            None => format!("{origin}: {msg}"),
        }
    })?;
    file.check(origin)
}

/// Reads a gearbox file.
pub fn read_file(path: &Path) -> Result<ChosenGearbox, String> {
    let origin = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| format!("cannot read gearbox file {origin}: {e}"))?;
    parse_toml(&text, &origin)
}

/// The valid names, for errors.
fn valid_names() -> String {
    servo::gearbox::GEARBOX_NAMES.join(", ")
}

/// One gearbox: a name of pada's table (case-insensitive) or a TOML file.
pub fn resolve(spec: &str) -> Result<ChosenGearbox, String> {
    let spec = spec.trim();
    if let Ok(g) = servo::gearbox(spec) {
        return Ok(ChosenGearbox::from_table(g));
    }
    let path = Path::new(spec);
    if path.exists() || spec.ends_with(".toml") {
        return read_file(path);
    }
    Err(format!(
        "unknown gearbox \"{spec}\": valid are {}, or a TOML file of the Table I fields (docs/reference/servos.md §4)",
        valid_names()
    ))
}

/// `--gearbox A[,B,…]` for a log of `joints` columns: one gearbox for
/// every joint, or one per joint in the log's order.
pub fn resolve_list(spec: &str, joints: usize) -> Result<Vec<ChosenGearbox>, String> {
    let parts: Vec<&str> = spec.split(',').collect();
    if parts.iter().any(|p| p.trim().is_empty()) {
        return Err(format!(
            "--gearbox \"{spec}\" has an empty entry: valid is NAME|FILE, or one per joint separated by commas"
        ));
    }
    let chosen = parts.iter().map(|p| resolve(p)).collect::<Result<Vec<_>, _>>()?;
    match chosen.len() {
        1 => Ok(vec![chosen[0].clone(); joints]),
        n if n == joints => Ok(chosen),
        n => Err(format!(
            "--gearbox has {n} entries for {joints} joints: valid is one for every joint or one per joint"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE_I_TOML: &str = "theta_bl_rad = 0.01\nk_nm_per_rad = 106.0\nd = -0.262\nsigma_f_mpa = 4402.0\nb_mm = 4.0\nm_n_mm = 0.4\nd_w_mm = 18.5\ny_fa = 2.15\ny_sa = 2.0\ny_epsilon = 1.22\ny_beta = 1.0\nteeth = 45\n";

    #[test]
    fn a_file_of_table_i_is_table_i() {
        let g = parse_toml(TABLE_I_TOML, "t.toml").unwrap();
        assert_eq!(g.params, GearboxParams::TABLE_I);
        assert_eq!(g.name, "t.toml");
        assert!(!g.estimate);
    }

    #[test]
    fn errors_name_the_file_the_field_and_the_range() {
        let bad = TABLE_I_TOML.replace("b_mm = 4.0", "b_mm = -4.0");
        let e = parse_toml(&bad, "g.toml").unwrap_err();
        assert!(e.starts_with("g.toml: ") && e.contains("b_mm = -4") && e.contains("0 < b_mm"), "{e}");
        let missing = TABLE_I_TOML.replace("teeth = 45\n", "");
        let e = parse_toml(&missing, "g.toml").unwrap_err();
        assert!(e.contains("g.toml") && e.contains("teeth"), "{e}");
        let unknown = format!("{TABLE_I_TOML}teeht = 3\n");
        let e = parse_toml(&unknown, "g.toml").unwrap_err();
        assert!(e.contains("line 13") && e.contains("teeht"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        let e = resolve("XM999").unwrap_err();
        assert!(e.contains("XL330-M288") && e.contains("TOML"), "{e}");
    }

    #[test]
    fn lists_give_one_per_joint() {
        let v = resolve_list("xm430-w350", 3).unwrap();
        assert_eq!(v.len(), 3);
        assert!(v.iter().all(|g| g.name == "XM430-W350" && g.estimate));
        let v = resolve_list("RX-28, XL330-M288", 2).unwrap();
        assert_eq!((v[0].name.as_str(), v[1].name.as_str()), ("RX-28", "XL330-M288"));
        assert!(resolve_list("RX-28,RX-28", 3).unwrap_err().contains("2 entries for 3 joints"));
        assert!(resolve_list("RX-28,", 2).unwrap_err().contains("empty entry"));
    }
}
