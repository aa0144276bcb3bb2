//! toml's own errors of a value's type or length (`invalid type: string
//! "2", expected u8`, `invalid length 2, expected an array of length 3`)
//! said as every other error of a robot's files is: the field as the file
//! spells it (`joint[1].id`), the value as written, and the valid values.
//! The field is found from the error's place in the text: the key on its
//! line and the table above it.

use std::collections::BTreeMap;
use std::ops::Range;

/// The field at byte `offset` of `text` (`joint[1].id`, `robot.period_ms`,
/// `point.tip.offset_m`), if a `key = value` line holds it.
pub fn field_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("");
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    if key.is_empty() || key.starts_with('[') || key.starts_with('#') {
        return None;
    }
    let mut table = None;
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for l in text[..line_start].lines() {
        let l = l.trim();
        if let Some(name) = l.strip_prefix("[[").and_then(|r| r.split_once("]]")).map(|(n, _)| n.trim()) {
            let n = seen.entry(name.to_string()).or_insert(0);
            table = Some(format!("{name}[{n}]"));
            *n += 1;
        } else if let Some(name) = l.strip_prefix('[').and_then(|r| r.split_once(']')).map(|(n, _)| n.trim()) {
            table = Some(name.to_string());
        }
    }
    Some(match table {
        Some(t) => format!("{t}.{key}"),
        None => key.to_string(),
    })
}

/// The valid values of `field` (as [`field_at`] names it), where a field
/// has more to say than its type.
fn valid_of(field: &str) -> Option<&'static str> {
    let key = field.rsplit('.').next().unwrap_or(field);
    Some(match key {
        "id" => "a bus ID, an integer from 0 to 252",
        "zero_count" => "the servo's position count at joint angle 0, an integer within its encoder's counts (0 to 4095 on the X series, 0 to 1023 on the RX-28 and MX-28)",
        "sign" => "1 or -1",
        "soft_limit_rad" => "[min, max] in radians, min < max, within the URDF joint's limits",
        "range" => "[min, max], min < max",
        "initial_weights" => "[min, max], two numbers",
        "target_m" => "[x, y, z] in metres, three numbers",
        "offset_m" => "[x, y, z] in metres on the link, three numbers",
        "levels_v" => "a list of 2 to 16 increasing voltages, [-2.0, 0.0, 2.0]",
        "count" => "an integer from 2 to 16",
        "test_interval" => "an integer, 1 or more",
        "half_shift" => "an integer from 8 to 15",
        "substeps" => "an integer from 1 to 1000",
        "solver_iterations" => "an integer from 1 to 64",
        "learned" | "counted" | "wrap" => "true or false",
        "name" | "urdf" | "servo" | "signal" | "link" | "term" | "point" | "axis" | "table" => "a string in double quotes",
        _ => return None,
    })
}

/// What toml's `expected …` asks for, in the file's words.
fn valid_of_type(message: &str) -> Option<String> {
    let expected = message.rsplit_once("expected ")?.1.trim();
    Some(match expected {
        "u8" => "an integer from 0 to 255".into(),
        "u16" => "an integer from 0 to 65535".into(),
        "u32" => "an integer from 0 to 4294967295".into(),
        "i8" => "an integer from -128 to 127".into(),
        "f64" => "a number".into(),
        "a boolean" => "true or false".into(),
        "a string" => "a string in double quotes".into(),
        other => match other.strip_prefix("an array of length ") {
            Some(n) => format!("an array of {n} numbers"),
            None => return None,
        },
    })
}

/// toml's error `message` at `span` of `text` in the file's words, if it
/// is a type or length error of a field's value.
pub fn reworded(text: &str, span: &Range<usize>, message: &str) -> Option<(String, String)> {
    if !(message.starts_with("invalid type") || message.starts_with("invalid value") || message.starts_with("invalid length")) {
        return None;
    }
    let field = field_at(text, span.start)?;
    let valid = valid_of(&field).map(str::to_string).or_else(|| valid_of_type(message))?;
    let value = text.get(span.clone()).unwrap_or("").trim();
    let value = if value.chars().count() > 40 { format!("{}…", value.chars().take(40).collect::<String>()) } else { value.to_string() };
    Some((field, format!("{value} is not valid: {valid}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_is_the_key_of_the_line_in_its_table() {
        let text = "[robot]\nname = \"a\"\n\n[[joint]]\nid = 1\n\n[[joint]]\nid = \"2\"\n\n[point.tip]\noffset_m = [0.0]\n";
        let at = |needle: &str| field_at(text, text.find(needle).unwrap());
        assert_eq!(at("\"a\"").as_deref(), Some("robot.name"));
        assert_eq!(at("1\n").as_deref(), Some("joint[0].id"));
        assert_eq!(at("\"2\"").as_deref(), Some("joint[1].id"));
        assert_eq!(at("[0.0]").as_deref(), Some("point.tip.offset_m"));
        assert_eq!(at("[[joint]]"), None);
    }
}
