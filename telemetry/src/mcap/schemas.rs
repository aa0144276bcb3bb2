//! The JSON Schemas of the channels ([`super::channels::Topic`]): encoding
//! `jsonschema`, which Foxglove reads without a plugin. pada's own records
//! are flat objects of numbers, strings and booleans (what a plot panel
//! picks from); the scene is Foxglove's `foxglove.SceneUpdate`, written
//! here from its published field list.

use super::channels::Topic;
use serde_json::{json, Map, Value};
use std::sync::OnceLock;

/// A field's JSON type.
#[derive(Clone, Copy)]
enum T {
    Int,
    Num,
    NumOrNull,
    IntOrNull,
    Str,
    Bool,
    Nums,
    Ints,
}

fn ty(t: T) -> Value {
    match t {
        T::Int => json!({"type": "integer"}),
        T::Num => json!({"type": "number"}),
        T::NumOrNull => json!({"type": ["number", "null"]}),
        T::IntOrNull => json!({"type": ["integer", "null"]}),
        T::Str => json!({"type": "string"}),
        T::Bool => json!({"type": "boolean"}),
        T::Nums => json!({"type": "array", "items": {"type": "number"}}),
        T::Ints => json!({"type": "array", "items": {"type": "integer"}}),
    }
}

/// A flat object schema: every field required, no others.
fn object(title: &str, description: &str, fields: &[(&str, T)]) -> String {
    let mut props = Map::new();
    for (name, t) in fields {
        props.insert(name.to_string(), ty(*t));
    }
    let required: Vec<&str> = fields.iter().map(|f| f.0).collect();
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": title,
        "description": description,
        "type": "object",
        "properties": props,
        "required": required,
        "additionalProperties": false,
    })
    .to_string()
}

const LINK_FIELDS: &[(&str, T)] = &[
    ("event", T::Str),
    ("detail", T::Str),
    ("bad_frames", T::Int),
    ("frames", T::Int),
    ("bytes", T::Int),
    ("crc_errors", T::Int),
    ("cobs_errors", T::Int),
    ("oversize", T::Int),
    ("too_short", T::Int),
    ("decode_errors", T::Int),
    ("noncanonical", T::Int),
    ("truncated", T::Int),
    ("seq_gaps", T::Int),
    ("frames_missed", T::Int),
    ("seq_resyncs", T::Int),
];

fn build(topic: Topic) -> (&'static str, String) {
    match topic {
        Topic::Hello => ("pada.Hello", object("pada.Hello", "Who is talking: the board's protocol, configuration and dimensions", &[
            ("protocol", T::Int), ("config_hash", T::Int), ("config_hash_hex", T::Str), ("weight_count", T::Int),
            ("period_us", T::Int), ("state_dims", T::Int), ("joints", T::Int), ("robot", T::Str),
        ])),
        Topic::Step => ("pada.Step", object("pada.Step", "One control step of the learner", &[
            ("step", T::Int), ("time_ms", T::Int), ("episode", T::Int), ("mode", T::Str), ("kind", T::Str),
            ("state", T::Nums), ("action", T::Int), ("output", T::Nums), ("reward", T::Num), ("td_error", T::Num),
            ("explored", T::Bool), ("footstep", T::Bool), ("gearboxes", T::Int), ("loop_us", T::Int), ("agent_cycles", T::Int),
        ])),
        Topic::Fatigue(_) => ("pada.Fatigue", object("pada.Fatigue", "Fatigue of one gearbox after a control step (Section IV)", &[
            ("step", T::Int), ("gearbox", T::Int), ("damage", T::Num), ("reengagements", T::Int),
        ])),
        Topic::Episode => ("pada.Episode", object("pada.Episode", "One finished episode", &[
            ("index", T::Int), ("mode", T::Str), ("total_reward", T::Num), ("length", T::Int), ("weights_checksum", T::Int),
        ])),
        Topic::Health => ("pada.Health", object("pada.Health", "The board's periodic health; counters are totals since boot", &[
            ("uptime_ms", T::Int), ("servo_temps_c", T::Ints), ("max_servo_temp_c", T::Int), ("min_voltage_dv", T::Int),
            ("bus_errors", T::Int), ("checksum_errors", T::Int), ("timeouts", T::Int), ("trace_drops", T::Int),
            ("weight_saturations", T::Int), ("overruns", T::Int), ("max_loop_us", T::Int), ("telemetry_drops", T::Int),
            ("checkpoint_erases", T::Int), ("saves_refused", T::Int),
            ("table_claimed", T::Int), ("table_slots", T::Int), ("claims_refused", T::Int),
        ])),
        Topic::Claims => ("pada.Claims", object("pada.Claims", "The claim table's occupancy", &[
            ("claimed", T::Int), ("slots", T::Int), ("fraction", T::Num), ("claims_refused", T::Int),
        ])),
        Topic::SafetyState => ("pada.StateChange", object("pada.StateChange", "A safety state change", &[
            ("step", T::Int), ("from", T::Str), ("to", T::Str), ("to_fault", T::Bool),
        ])),
        Topic::SafetyFault => ("pada.Fault", object("pada.Fault", "The board entered Fault; torque is off", &[
            ("step", T::Int), ("time_ms", T::Int), ("cause", T::Str), ("detail", T::Str),
        ])),
        Topic::Policy => ("pada.Policy", object("pada.Policy", "The action policy in force", &[
            ("step", T::Int), ("policy", T::Str), ("built", T::Str), ("switched_to_sarsa", T::Bool), ("governed", T::Bool),
        ])),
        Topic::Governor => ("pada.Governor", object("pada.Governor", "The wear governor's status", &[
            ("step", T::Int), ("budget_s", T::Num), ("restricts", T::Str), ("parameter", T::Num), ("rung", T::Int),
            ("rungs", T::Int), ("window_steps", T::Int), ("damage_rate", T::Num), ("window_mtbf_s", T::NumOrNull),
            ("moves", T::Int), ("over_budget_steps", T::Int),
        ])),
        Topic::Event => ("pada.Event", object("pada.Event", "A checkpoint report, log, warning, weights, ack or nack", &[
            ("kind", T::Str), ("detail", T::Str),
        ])),
        Topic::Link => ("pada.Link", object("pada.Link", "The link's counters after a lost frame, a sequence gap, a health report or the end", LINK_FIELDS)),
        Topic::Scene => ("foxglove.SceneUpdate", scene_update()),
        Topic::Checkpoint => ("pada.Checkpoint", object("pada.Checkpoint", "One save or restore of a checkpoint the host keeps, from its chunks, requests and report", &[
            ("direction", T::Str), ("generation", T::IntOrNull), ("bytes", T::Int), ("chunks", T::Int), ("requests", T::Int),
            ("board_bytes", T::Int), ("host_bytes", T::Int), ("link_s", T::Num), ("outcome", T::Str), ("reported", T::Bool),
            ("reported_chunks", T::IntOrNull),
        ])),
    }
}

/// Foxglove's `SceneUpdate`: the fields of its entities and primitives
/// that pada writes (lines), the others as arrays.
fn scene_update() -> String {
    let num = json!({"type": "number"});
    let vec3 = json!({"type": "object", "properties": {"x": num, "y": num, "z": num}, "required": ["x", "y", "z"]});
    let quat = json!({"type": "object", "properties": {"x": num, "y": num, "z": num, "w": num}, "required": ["x", "y", "z", "w"]});
    let color = json!({"type": "object", "properties": {"r": num, "g": num, "b": num, "a": num}, "required": ["r", "g", "b", "a"]});
    let time = json!({"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}, "required": ["sec", "nsec"]});
    let pose = json!({"type": "object", "properties": {"position": vec3, "orientation": quat}, "required": ["position", "orientation"]});
    let line = json!({
        "type": "object",
        "title": "foxglove.LinePrimitive",
        "properties": {
            "type": {"type": "integer", "enum": [0, 1, 2], "description": "0 line strip, 1 line loop, 2 line list"},
            "pose": pose,
            "thickness": num,
            "scale_invariant": {"type": "boolean"},
            "points": {"type": "array", "items": vec3},
            "color": color,
            "colors": {"type": "array", "items": color},
            "indices": {"type": "array", "items": {"type": "integer", "minimum": 0}},
        },
        "required": ["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"],
    });
    let any_array = json!({"type": "array"});
    let entity = json!({
        "type": "object",
        "title": "foxglove.SceneEntity",
        "properties": {
            "timestamp": time,
            "frame_id": {"type": "string"},
            "id": {"type": "string"},
            "lifetime": time,
            "frame_locked": {"type": "boolean"},
            "metadata": {"type": "array", "items": {"type": "object", "properties": {"key": {"type": "string"}, "value": {"type": "string"}}, "required": ["key", "value"]}},
            "arrows": any_array, "cubes": any_array, "spheres": any_array, "cylinders": any_array,
            "lines": {"type": "array", "items": line},
            "triangles": any_array, "texts": any_array, "models": any_array,
        },
        "required": ["timestamp", "frame_id", "id", "lifetime", "frame_locked", "metadata", "arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"],
    });
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "foxglove.SceneUpdate",
        "description": "An update to the entities of a 3D scene",
        "type": "object",
        "properties": {
            "deletions": {"type": "array", "items": {"type": "object", "properties": {"timestamp": time, "type": {"type": "integer", "enum": [0, 1]}, "id": {"type": "string"}}, "required": ["timestamp", "type", "id"]}},
            "entities": {"type": "array", "items": entity},
        },
        "required": ["deletions", "entities"],
    })
    .to_string()
}

/// The schema's name and JSON Schema text of `topic`'s channel.
pub fn of(topic: Topic) -> (&'static str, &'static str) {
    static ALL: OnceLock<Vec<(Topic, &'static str, String)>> = OnceLock::new();
    let all = ALL.get_or_init(|| {
        Topic::all()
            .into_iter()
            .map(|t| {
                let (name, text) = build(t);
                (t, name, text)
            })
            .collect()
    });
    let fallback = all.iter().find(|e| matches!(e.0, Topic::Fatigue(0)));
    match all.iter().find(|e| e.0 == topic).or(fallback) {
        Some((_, name, text)) => (name, text.as_str()),
        None => ("", ""),
    }
}
