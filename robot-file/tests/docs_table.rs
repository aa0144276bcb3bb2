//! docs/your-robot.md describes every field of `robot.toml` once, in one
//! table: each field the schema (src/schema.rs) reads has exactly one row,
//! and every row names a field the schema reads.

use std::collections::BTreeSet;

/// `section.field` for every field of the schema's sections, read from its
/// source (a field added to the schema without a row fails here).
fn schema_fields() -> BTreeSet<String> {
    let src = include_str!("../src/schema.rs");
    let section_of = |name: &str| match name {
        "RobotSection" => Some("robot"),
        "JointSection" => Some("joint"),
        "PointSection" => Some("point.NAME"),
        "ObserveSection" => Some("observe"),
        "ActionSection" => Some("action"),
        "UniformLevels" => Some("action.uniform_v"),
        "LearningSection" => Some("learning"),
        "RewardSection" => Some("reward"),
        "EndSection" => Some("end"),
        "ResetSection" => Some("reset"),
        "SimulationSection" => Some("simulation"),
        "PlantSection" => Some("plant"),
        _ => None,
    };
    let mut out = BTreeSet::new();
    let mut section = None;
    for line in src.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("pub struct ") {
            let name = rest.split(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
            section = section_of(name);
            if section.is_none() && name != "RobotToml" {
                panic!("schema.rs has a struct {name} this test does not map to a section");
            }
            continue;
        }
        if t == "}" {
            section = None;
        }
        if let (Some(s), Some(rest)) = (section, t.strip_prefix("pub ")) {
            if let Some((field, _)) = rest.split_once(':') {
                out.insert(format!("{s}.{}", field.trim()));
            }
        }
    }
    out
}

/// The fields the doc's table has a row for, as often as it has one.
fn doc_rows() -> Vec<String> {
    let doc = include_str!("../../docs/your-robot.md");
    doc.lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split_once('`').map(|(f, _)| f.to_string()))
        .collect()
}

#[test]
fn every_field_of_robot_toml_is_described_once_in_docs_your_robot() {
    let schema = schema_fields();
    assert!(schema.len() > 40, "the schema was not read: {schema:?}");
    let rows = doc_rows();
    let documented: BTreeSet<String> = rows.iter().cloned().collect();
    assert_eq!(documented.len(), rows.len(), "a field has two rows: {rows:?}");
    let missing: Vec<_> = schema.difference(&documented).collect();
    let unknown: Vec<_> = documented.difference(&schema).collect();
    assert!(missing.is_empty(), "fields without a row in docs/your-robot.md: {missing:?}");
    assert!(unknown.is_empty(), "rows of docs/your-robot.md for no field: {unknown:?}");
}

/// The `reward.term` row names every term the reader takes, as its error
/// for an unknown term lists them (a term added to the vocabulary without
/// a word in the table fails here).
#[test]
fn every_reward_term_is_named_in_the_table() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reacher");
    let dir = tempfile::tempdir().unwrap();
    let toml = std::fs::read_to_string(src.join("robot.toml")).unwrap().replace("term = \"distance\"", "term = \"nonsense\"");
    std::fs::write(dir.path().join("robot.toml"), toml).unwrap();
    std::fs::copy(src.join("reacher.urdf"), dir.path().join("reacher.urdf")).unwrap();
    let e = pada_robot_file::load(&dir.path().join("robot.toml")).unwrap_err().to_string();
    let valid = e.split("is not valid: ").nth(1).unwrap_or_else(|| panic!("{e}"));
    let terms: Vec<&str> = valid.split([',', ' ']).filter(|w| !w.is_empty() && *w != "or").collect();
    assert!(terms.len() >= 7 && terms.contains(&"distance_squared"), "{terms:?}");
    let doc = include_str!("../../docs/your-robot.md");
    let row = doc.lines().find(|l| l.starts_with("| `reward.term`")).expect("a reward.term row");
    for t in terms {
        assert!(row.contains(&format!("`{t}`")), "the reward.term row lacks {t}: {row}");
    }
}
