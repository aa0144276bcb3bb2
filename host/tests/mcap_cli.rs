//! `pada capture --mcap` and `--foxglove` end to end: the real binary
//! records the firmware's stream (QEMU, `tests/data/sil-pendulum-3s.bin`),
//! a damaged copy of it and a host LEO run as MCAP, reads each recording
//! back with `--file X.mcap` into the same summary, refuses bad paths and
//! damaged recordings with exit code 2, and serves a live client in
//! Foxglove's WebSocket protocol every message of every channel.

mod common;
use common::{assert_bad_input, capture_json, damaged, frames, ok, pada};

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Command, Stdio};

fn recording() -> Vec<u8> {
    std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sil-pendulum-3s.bin")).expect("the recorded stream")
}

/// `pada capture --file STREAM --mcap OUT --json`, parsed.
fn capture_to_mcap(stream: &Path, mcap: &Path) -> serde_json::Value {
    let out = pada(&["capture", "--json", "--file", stream.to_str().unwrap(), "--mcap", mcap.to_str().unwrap()]);
    serde_json::from_str(&ok(&out)).unwrap()
}

/// A summary without what differs between two reads of one stream.
fn comparable(v: &serde_json::Value) -> serde_json::Value {
    let mut v = v.clone();
    let o = v.as_object_mut().unwrap();
    for k in ["wall_s", "source"] {
        assert!(o.remove(k).is_some(), "{k}");
    }
    v
}

/// The stream's summary, recorded, and read back from the recording.
fn round_trip(stream: &[u8], name: &str) -> (serde_json::Value, serde_json::Value, std::path::PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join(format!("{name}.bin"));
    std::fs::write(&bin, stream).unwrap();
    let mcap = dir.path().join(format!("{name}.mcap"));
    let live = capture_to_mcap(&bin, &mcap);
    let back = capture_json(&mcap, None);
    (live, back, mcap, dir)
}

#[test]
fn a_recording_reads_back_into_the_summary_of_its_stream() {
    let (live, back, mcap, _dir) = round_trip(&recording(), "sil");
    assert_eq!(comparable(&live), comparable(&back));
    assert!(live["messages"]["step"].as_u64().unwrap() > 300, "{live}");
    // And the same as a capture without --mcap.
    let plain = capture_json(&_dir.path().join("sil.bin"), None);
    assert_eq!(comparable(&plain), comparable(&back));
    let bytes = std::fs::read(&mcap).unwrap();
    assert!(bytes.starts_with(b"\x89MCAP0\r\n") && bytes.ends_with(b"\x89MCAP0\r\n"));
    // The metadata names pada's version and the board's configuration.
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains(env!("CARGO_PKG_VERSION")) && text.contains("config_hash"), "metadata");
}

#[test]
fn a_damaged_stream_gives_a_valid_recording_with_its_losses_counted() {
    let clean = recording();
    let n = frames(&clean).len();
    let stream = damaged(&clean, &[n / 3, 2 * n / 3], &[n / 2], &[n / 10, n / 4, 3 * n / 4]);
    let (live, back, _mcap, _dir) = round_trip(&stream, "damaged");
    assert!(live["bad_frames"].as_u64().unwrap() >= 3, "{live}");
    assert!(live["link"]["seq_gaps"].as_u64().unwrap() >= 1, "{live}");
    assert_eq!(comparable(&live), comparable(&back));
}

#[test]
fn a_stream_cut_off_in_a_frame_counts_it_in_the_recording() {
    let clean = recording();
    let (live, back, _mcap, _dir) = round_trip(&clean[..clean.len() - 5], "cut");
    assert_eq!(live["link"]["truncated"], 1, "{live}");
    assert_eq!(comparable(&live), comparable(&back));
}

#[test]
fn a_leo_run_records_every_channel_with_its_scene() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("leo.bin");
    ok(&pada(&[
        "run", "--task", "leo", "--algo", "pada", "--delta", "0.1667", "--trials", "1", "--seconds", "20",
        "--telemetry", bin.to_str().unwrap(), "--out", dir.path().join("run").to_str().unwrap(), "--json",
    ]));
    let mcap = dir.path().join("leo.mcap");
    let live = capture_to_mcap(&bin, &mcap);
    let back = capture_json(&mcap, None);
    assert_eq!(comparable(&live), comparable(&back));
    // Per topic, as the text summary lists them.
    let out = pada(&["capture", "--file", mcap.to_str().unwrap()]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let counts: BTreeMap<String, u64> = stderr
        .lines()
        .filter_map(|l| {
            let (topic, rest) = l.trim().split_once(": ")?;
            Some((topic.to_string(), rest.split_whitespace().next()?.parse().ok()?))
        })
        .collect();
    let steps = live["messages"]["step"].as_u64().unwrap();
    assert!(steps > 100);
    for topic in ["/step", "/scene", "/fatigue/0", "/fatigue/1", "/fatigue/2", "/fatigue/3"] {
        assert_eq!(counts.get(topic), Some(&steps), "{topic}: {stderr}");
    }
    assert_eq!(counts.get("/episode").copied(), live["messages"]["episode"].as_u64(), "{stderr}");
    assert_eq!(counts.get("/hello"), Some(&1));
    assert!(stderr.contains("robot") || stderr.contains("configuration 00000000"), "{stderr}");
}

#[test]
fn bad_paths_addresses_and_damaged_recordings_are_refused_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("s.bin");
    std::fs::write(&bin, recording()).unwrap();
    let b = bin.to_str().unwrap();
    assert_bad_input(&["capture", "--file", b, "--mcap", "/nonexistent/dir/x.mcap"], &["--mcap", "cannot create"]);
    assert_bad_input(&["capture", "--file", b, "--mcap", dir.path().to_str().unwrap()], &["--mcap", "directory"]);
    assert_bad_input(&["capture", "--file", b, "--foxglove", "127.0.0.1:1"], &["--foxglove", "tcp:HOST:PORT"]);
    assert_bad_input(&["capture", "--file", b, "--foxglove", "tcp:nowhere.invalid:1"], &["--foxglove"]);
    // A good recording, then damaged copies of it.
    let mcap = dir.path().join("good.mcap");
    capture_to_mcap(&bin, &mcap);
    let good = std::fs::read(&mcap).unwrap();
    let half = dir.path().join("half.mcap");
    std::fs::write(&half, &good[..good.len() / 2]).unwrap();
    assert_bad_input(&["capture", "--file", half.to_str().unwrap()], &["half.mcap", "not a valid MCAP file"]);
    let mut flipped = good.clone();
    let mid = flipped.len() / 2;
    for b in &mut flipped[mid..mid + 64] {
        *b ^= 0x5A;
    }
    let bad = dir.path().join("flipped.mcap");
    std::fs::write(&bad, &flipped).unwrap();
    assert_bad_input(&["capture", "--file", bad.to_str().unwrap()], &["flipped.mcap"]);
    let garbage = dir.path().join("garbage.mcap");
    let mut g = b"\x89MCAP0\r\n".to_vec();
    g.extend((0..500u32).map(|i| (i * 37) as u8));
    std::fs::write(&garbage, &g).unwrap();
    assert_bad_input(&["capture", "--file", garbage.to_str().unwrap()], &["garbage.mcap", "MCAP"]);
    // A recording is read back, not recorded again.
    assert_bad_input(
        &["capture", "--file", mcap.to_str().unwrap(), "--mcap", dir.path().join("again.mcap").to_str().unwrap()],
        &["summary only"],
    );
}

#[test]
fn the_live_server_delivers_every_message_of_every_channel_to_a_foxglove_client() {
    use tungstenite::client::IntoClientRequest;
    use tungstenite::Message;
    let stream = recording();
    let dir = tempfile::tempdir().unwrap();
    let mcap = dir.path().join("live.mcap");
    let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["capture", "--json", "--file", "-", "--foxglove", "tcp:127.0.0.1:0", "--mcap"])
        .arg(&mcap)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    let addr = loop {
        line.clear();
        assert!(stderr.read_line(&mut line).unwrap() > 0, "no address announced");
        if let Some(rest) = line.split("ws://").nth(1) {
            break rest.split_whitespace().next().unwrap().to_string();
        }
    };
    let mut req = format!("ws://{addr}").into_client_request().unwrap();
    req.headers_mut().insert("Sec-WebSocket-Protocol", "foxglove.websocket.v1, foxglove.sdk.v1".parse().unwrap());
    let (mut ws, resp) = tungstenite::connect(req).unwrap();
    assert_eq!(resp.headers()["Sec-WebSocket-Protocol"], "foxglove.websocket.v1");
    let mut channels: BTreeMap<u64, String> = BTreeMap::new();
    while channels.is_empty() {
        if let Message::Text(t) = ws.read().unwrap() {
            let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
            if v["op"] == "advertise" {
                for c in v["channels"].as_array().unwrap() {
                    assert_eq!(c["encoding"], "json");
                    assert_eq!(c["schemaEncoding"], "jsonschema");
                    channels.insert(c["id"].as_u64().unwrap(), c["topic"].as_str().unwrap().to_string());
                }
            }
        }
    }
    let subs: Vec<_> = channels.keys().map(|&id| serde_json::json!({"id": id + 100, "channelId": id})).collect();
    ws.send(Message::text(serde_json::json!({"op": "subscribe", "subscriptions": subs}).to_string())).unwrap();
    // Let the server take the subscription before the stream starts.
    std::thread::sleep(std::time::Duration::from_millis(300));
    {
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(&stream).unwrap();
    }
    let mut received: BTreeMap<String, u64> = BTreeMap::new();
    loop {
        match ws.read() {
            Ok(Message::Binary(b)) => {
                assert_eq!(b[0], 1, "messageData");
                let sub = u32::from_le_bytes(b[1..5].try_into().unwrap()) as u64;
                let topic = &channels[&(sub - 100)];
                let _: serde_json::Value = serde_json::from_slice(&b[13..]).expect("JSON payload");
                *received.entry(topic.clone()).or_insert(0) += 1;
            }
            Ok(Message::Close(_)) | Err(_) => break,
            Ok(_) => {}
        }
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &summary["messages"];
    assert_eq!(received.get("/step").copied(), m["step"].as_u64(), "{received:?}");
    assert_eq!(received.get("/scene").copied(), m["step"].as_u64(), "{received:?}");
    assert_eq!(received.get("/fatigue/0").copied(), m["step"].as_u64(), "{received:?}");
    assert_eq!(received.get("/episode").copied(), m["episode"].as_u64(), "{received:?}");
    assert_eq!(received.get("/hello").copied(), m["hello"].as_u64(), "{received:?}");
    // A `/link` message beside every health report, and one at the end.
    assert_eq!(received.get("/link").copied(), m["health"].as_u64().map(|h| h + 1), "{received:?}");
    assert_eq!(summary["foxglove"]["dropped"], 0, "{summary}");
    assert_eq!(summary["foxglove"]["clients"], 1, "{summary}");
    // The live view and the file carry the same messages.
    let back = capture_json(&mcap, None);
    assert_eq!(back["messages"], summary["messages"]);
    let total: u64 = received.values().sum();
    assert_eq!(summary["foxglove"]["sent"].as_u64(), Some(total));
}

#[test]
fn pada_run_records_the_same_file_as_a_capture_of_its_stream() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    ok(&pada(&[
        "run", "--task", "pendulum", "--algo", "sarsa", "--trials", "1", "--seconds", "30", "--json",
        "--telemetry", &p("run.bin"), "--mcap", &p("run.mcap"), "--out", &p("out"),
    ]));
    capture_to_mcap(Path::new(&p("run.bin")), Path::new(&p("cap.mcap")));
    // Board times and sequence numbers only: the same stream, the same bytes.
    assert!(std::fs::read(p("run.mcap")).unwrap() == std::fs::read(p("cap.mcap")).unwrap());
    assert_bad_input(
        &["run", "--task", "pendulum", "--algo", "sarsa", "--seconds", "1", "--trials", "1", "--out", &p("o2"), "--mcap", "/nonexistent/dir/x.mcap"],
        &["--mcap", "cannot create"],
    );
    assert_bad_input(
        &["run", "--board", "f405", "--task", "physical-pendulum", "--algo", "sarsa", "--mcap", &p("b.mcap")],
        &["--mcap", "not available with --board"],
    );
}

#[test]
fn a_claim_tables_occupancy_has_its_channel_and_reads_back() {
    use pada_core::wire::{FrameEncoder, Health, Hello, ToHost, MAX_FRAME_LEN, PROTOCOL_VERSION};
    let mut enc = FrameEncoder::new();
    let mut stream = Vec::new();
    let leo = &pada_core::robot::leo::SPEC;
    let robot = leo.name.try_into().unwrap();
    let hello = Hello { protocol: PROTOCOL_VERSION, robot, robot_hash: leo.definition_hash(), config_hash: 0xfeed, weight_count: 1 << 21, period_us: 33_333, state_dims: 10, joints: 3 };
    let mut msgs = vec![ToHost::Hello(hello)];
    for k in 1..=3u32 {
        msgs.push(ToHost::Health(Health { uptime_ms: 1000 * k, table_claimed: 100 * k, table_slots: 1000, claims_refused: k - 1, ..Health::default() }));
    }
    for m in &msgs {
        let mut buf = [0u8; MAX_FRAME_LEN];
        stream.extend_from_slice(enc.encode(m, &mut buf).unwrap());
    }
    let (live, back, mcap, _dir) = round_trip(&stream, "claims");
    assert_eq!(live["latest"]["table"]["claimed"], 300, "{live}");
    assert_eq!(comparable(&live), comparable(&back));
    let out = pada(&["capture", "--file", mcap.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&ok(&out).into_bytes()).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("/claims: 3 messages"), "{stderr}");
    assert!(String::from_utf8_lossy(&std::fs::read(&mcap).unwrap()).contains("0000feed"), "config hash in the metadata");
}
