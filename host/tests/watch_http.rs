//! `pada watch` over HTTP with a real client (ureq), against the real
//! binary: a stream recorded by `pada run --telemetry`, the same stream
//! corrupted, a live run over loopback TCP, a stalled sender, a serial
//! port (a pseudo-terminal), bad requests, and slow and closed viewers.
//! `/api/state` is checked against `pada capture --json` of the same bytes
//! and against the run's own summary.

mod common;
use common::{capture_json, damaged, frames, plug_at, raw_pty};

mod watch_common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;
use watch_common::{pada_run, Watch};

/// The fields `/api/state` shares with `pada capture --json`.
const CAPTURE_FIELDS: [&str; 6] = [
    "source",
    "ended",
    "link",
    "bad_frames",
    "messages",
    "latest",
];

fn assert_same_as_capture(state: &serde_json::Value, capture: &serde_json::Value) {
    for f in CAPTURE_FIELDS {
        assert_eq!(state[f], capture[f], "field {f}: watch vs capture");
    }
}

/// A 600 s PADA run on the pendulum, recorded; its stream and summary.
fn recorded_run(dir: &Path) -> (std::path::PathBuf, serde_json::Value) {
    let bin = dir.join("run.bin");
    let o = pada_run("pendulum", "600", bin.to_str().unwrap(), &dir.join("run"));
    (bin, serde_json::from_slice(&o.stdout).unwrap())
}

/// The CSV without its first column (the wall-clock time of each row).
fn without_time(csv: &str) -> Vec<String> {
    csv.lines()
        .map(|l| l.split_once(',').map_or(l, |x| x.1).to_string())
        .collect()
}

#[test]
fn a_recorded_run_shows_what_capture_and_the_run_itself_report() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, run) = recorded_run(dir.path());
    let capture_csv = dir.path().join("capture.csv");
    let capture = capture_json(&bin, Some(&capture_csv));
    let watch_csv = dir.path().join("watch.csv");
    let w = Watch::start(&[
        "--file",
        bin.to_str().unwrap(),
        "--out",
        watch_csv.to_str().unwrap(),
        "--json",
    ]);
    let s = w.wait_for(60, "end of file", |s| !s["ended"].is_null());
    assert_same_as_capture(&s, &capture);
    assert!(
        s["link"]["frames"].as_u64().unwrap() > 10_000,
        "{}",
        watch_common::short(&s)
    );
    assert_eq!(s["bad_frames"], 0);

    // The page's numbers are the run's own: end performance, rise time and
    // the paper's windowed MTBF of trial 0 (the streamed trial).
    let trial = &run["per_trial"][0];
    let close = |a: &serde_json::Value, b: &serde_json::Value, tol: f64| {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        assert!((a - b).abs() <= tol * b.abs().max(1.0), "{a} vs {b}");
    };
    // Returns travel as f32.
    close(
        &s["learning"]["end_performance"],
        &trial["end_performance"],
        1e-5,
    );
    close(&s["learning"]["rise_time_s"], &trial["rise_time_s"], 1e-9);
    close(&s["fatigue"]["robot_window_mtbf_s"], &trial["mtbf_s"], 1e-9);
    assert_eq!(s["fatigue"]["window_actions_seen"], 1200);
    assert_eq!(s["learning"]["learning_time_s"], 600.0);
    assert_eq!(s["policy"]["built"], "pada");
    assert_eq!(s["policy"]["parameter"], 0.5);
    assert_eq!(s["policy"]["parameter_name"], "delta");
    let curve = s["learning"]["curve"].as_array().unwrap();
    // One test run before learning and one after every 10 of the 200
    // learning episodes.
    assert_eq!(curve.len(), 21);
    assert_eq!(s["learning"]["end_window_runs"], curve.len().div_ceil(10));
    // The last episode's trace: the pendulum's 60 actions of 3 s, and the
    // time-limit step after the last one (no action).
    let steps = s["last_episode"]["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 61, "{}", s["last_episode"]);
    assert_eq!(steps[60]["output"].as_array().unwrap().len(), 0);
    assert_eq!(steps[59]["t_s"], 2.95);
    assert!(!s["stalled"].as_bool().unwrap());

    // The page and its parts.
    let (status, page) = w.get("");
    assert_eq!(status, 200);
    for id in [
        "plot-returns",
        "plot-damage",
        "plot-reengagements",
        "plot-episode",
    ] {
        let at = page
            .find(&format!("id=\"{id}\""))
            .unwrap_or_else(|| panic!("{id} missing"));
        assert!(
            page[at..].starts_with(&format!("id=\"{id}\"><svg")),
            "{id} holds no SVG"
        );
    }
    assert!(page.contains("end-performance window"), "no window marked");
    assert!(page.contains("pada Δ=0.5"), "no policy shown");
    assert!(page.contains("the stream ended (end of file)"));
    // Nothing is loaded from elsewhere (the SVGs' xmlns is a name, not a load).
    assert!(!page.contains(" src=") && !page.contains("<link") && !page.contains("@import"));
    let (status, live) = w.get("live");
    assert_eq!(status, 200);
    assert!(live.contains("plot-episode") && !live.contains("<html"));
    for p in ["returns", "damage", "reengagements", "episode"] {
        let (status, svg) = w.get(&format!("plot/{p}.svg"));
        assert_eq!(status, 200, "{p}");
        assert!(
            svg.starts_with("<svg") && (svg.contains("<polyline") || svg.contains("<path")),
            "{p}"
        );
    }

    // Ctrl-C: the summary as capture prints it, and the same CSV.
    let out = w.interrupt();
    assert!(out.status.success(), "{out:?}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_same_as_capture(&summary, &capture);
    assert!(summary["requests"].as_u64().unwrap() >= 8);
    let a = std::fs::read_to_string(&capture_csv).unwrap();
    let b = std::fs::read_to_string(&watch_csv).unwrap();
    assert_eq!(
        without_time(&a),
        without_time(&b),
        "watch --out differs from capture --out"
    );
}

#[test]
fn a_corrupted_recording_counts_the_same_losses_as_capture() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, _) = recorded_run(dir.path());
    let clean = std::fs::read(&bin).unwrap();
    let f = frames(&clean);
    let n = f.len();
    // Bytes changed in 5 frames, 2 frames cut out, 2 bursts of garbage,
    // and a cut-off frame at the very end.
    let corrupt: Vec<usize> = [0.1, 0.3, 0.5, 0.7, 0.9]
        .iter()
        .map(|x| (n as f64 * x) as usize)
        .collect();
    let dropped = [n / 4, 3 * n / 4];
    let garbage = [n / 3, 2 * n / 3];
    let mut out = damaged(&clean, &garbage, &dropped, &corrupt);
    let (a, b) = f[n / 2];
    out.extend_from_slice(&clean[a..a + (b - a) / 2]);
    let damaged_file = dir.path().join("damaged.bin");
    std::fs::write(&damaged_file, &out).unwrap();

    let capture = capture_json(&damaged_file, None);
    assert!(capture["bad_frames"].as_u64().unwrap() >= 7, "{capture:#}");
    let w = Watch::start(&["--file", damaged_file.to_str().unwrap()]);
    let s = w.wait_for(60, "end of file", |s| !s["ended"].is_null());
    assert_same_as_capture(&s, &capture);
    assert!(s["link"]["seq_gaps"].as_u64().unwrap() >= 7);
    // The page shows the losses and still draws every plot.
    let (_, page) = w.get("");
    assert!(
        page.contains(&format!("lost {}", s["bad_frames"])),
        "losses not shown"
    );
    assert_eq!(page.matches("<svg").count(), 4);
}

#[test]
fn bad_requests_get_a_4xx_and_the_page_keeps_being_served() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, _) = recorded_run(dir.path());
    let w = Watch::start(&["--file", bin.to_str().unwrap()]);
    assert_eq!(w.get("nope").0, 404);
    assert_eq!(w.get("api/state/../../etc/passwd").0, 404);
    assert_eq!(w.get(&format!("api/state?{}", "x".repeat(4000))).0, 414);
    let agent = watch_common::agent();
    let post = agent.post(format!("{}api/state", w.url)).send("x").unwrap();
    assert_eq!(post.status().as_u16(), 405);
    assert_eq!(post.headers()["allow"], "GET, HEAD");
    let head = agent.head(&w.url).call().unwrap();
    assert_eq!(head.status().as_u16(), 200);
    // Not HTTP at all, and a request line cut short by a hang-up.
    let addr = w
        .url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let mut raw = TcpStream::connect(&addr).unwrap();
    raw.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    raw.write_all(b"\x16\x03\x01 hello, this is not HTTP\r\n\r\n")
        .unwrap();
    let mut answer = String::new();
    let _ = raw.read_to_string(&mut answer);
    assert!(answer.starts_with("HTTP/1.1 400"), "{answer:?}");
    let mut cut = TcpStream::connect(&addr).unwrap();
    cut.write_all(b"GET /api/sta").unwrap();
    drop(cut);
    // Still serving.
    assert_eq!(w.get("").0, 200);
    assert_eq!(w.state()["bad_frames"], 0);
}

#[test]
fn slow_and_closed_viewers_do_not_slow_the_decoder() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("run.bin");
    // A longer run: about 1.2 MB of frames.
    pada_run(
        "pendulum",
        "1000",
        bin.to_str().unwrap(),
        &dir.path().join("run"),
    );
    let bytes = std::fs::read(&bin).unwrap();
    let capture = capture_json(&bin, None);
    // From standard input, so the viewers are in place before a byte is
    // decoded.
    let mut w = Watch::start_with(&["--file", "-"], Stdio::piped());
    let addr = w
        .url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    // Viewers that ask for the page many times and never read: each
    // answer is over 100 kB, so 200 of them overfill the sockets and the
    // workers answering them wait.
    let slow: Vec<TcpStream> = (0..3)
        .map(|_| {
            let mut s = TcpStream::connect(&addr).unwrap();
            let req = "GET / HTTP/1.1\r\nHost: x\r\n\r\n".repeat(200);
            s.write_all(req.as_bytes()).unwrap();
            s
        })
        .collect();
    // Viewers that ask and hang up at once.
    for _ in 0..20 {
        let mut s = TcpStream::connect(&addr).unwrap();
        s.write_all(b"GET /api/state HTTP/1.1\r\nHost: x\r\n\r\n")
            .unwrap();
        drop(s);
    }
    std::thread::sleep(Duration::from_millis(300));
    // The whole stream goes in while they are stuck.
    let mut stdin = w.child.as_mut().unwrap().stdin.take().unwrap();
    stdin.write_all(&bytes).unwrap();
    drop(stdin);
    let s = w.wait_for(60, "end of file", |s| !s["ended"].is_null());
    let mut capture = capture;
    capture["source"] = "standard input".into();
    assert_same_as_capture(&s, &capture);
    // The slow viewers are still connected (and unread) now.
    for v in &slow {
        assert!(v.peer_addr().is_ok());
    }
    drop(slow);
    // Many viewers at once, each polling as the page does.
    let viewers: Vec<_> = (0..12)
        .map(|_| {
            let url = w.url.clone();
            std::thread::spawn(move || {
                for path in ["", "live", "api/state", "live", "plot/damage.svg"] {
                    assert_eq!(watch_common::get(&format!("{url}{path}")).0, 200, "{path}");
                }
            })
        })
        .collect();
    for v in viewers {
        v.join().unwrap();
    }
    assert_eq!(w.state()["link"], capture["link"]);
}

#[test]
fn a_live_run_over_tcp_and_a_sender_that_stalls() {
    let dir = tempfile::tempdir().unwrap();
    let w = Watch::start(&["--listen", "tcp:127.0.0.1:0"]);
    let target = w.listen.clone().unwrap();
    // Nothing yet: the page says so.
    let s = w.wait_for(10, "stalled before any data", |s| s["stalled"] == true);
    assert!(s["no_data_for_s"].is_null());
    let out = pada_run("pendulum", "300", &target, &dir.path().join("run"));
    let run: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = w.wait_for(30, "the sender's end", |s| !s["ended"].is_null());
    assert_eq!(s["ended"], "the sender closed the connection");
    assert_eq!(s["link"]["seq_gaps"], 0);
    assert_eq!(s["bad_frames"], 0);
    assert_eq!(s["messages"]["hello"], 1);
    let trial = &run["per_trial"][0];
    let (a, b) = (
        s["fatigue"]["robot_window_mtbf_s"].as_f64().unwrap(),
        trial["mtbf_s"].as_f64().unwrap(),
    );
    assert!((a - b).abs() <= 1e-9 * b, "{a} vs {b}");
    assert_eq!(s["policy"]["label"], "pada Δ=0.5");
    // One sender only: the listener is closed now.
    let port = target.rsplit(':').next().unwrap();
    assert!(TcpStream::connect(format!("127.0.0.1:{port}")).is_err());
    drop(w);

    // A sender that says hello and then falls silent.
    let w = Watch::start(&["--listen", "tcp:127.0.0.1:0"]);
    let target = w.listen.clone().unwrap();
    let mut sender = TcpStream::connect(target.trim_start_matches("tcp:")).unwrap();
    let mut enc = pada_core::wire::FrameEncoder::new();
    let mut buf = [0u8; pada_core::wire::MAX_FRAME_LEN];
    let hello = pada_core::wire::ToHost::Hello(pada_core::wire::Hello {
        protocol: pada_core::wire::PROTOCOL_VERSION,
        robot: "physical-pendulum-20hz".try_into().unwrap(),
        robot_hash: 0,
        config_hash: 0,
        weight_count: 1,
        period_us: 50_000,
        state_dims: 2,
        joints: 1,
    });
    sender
        .write_all(enc.encode(&hello, &mut buf).unwrap())
        .unwrap();
    let s = w.wait_for(10, "the hello", |s| s["messages"]["hello"] == 1);
    assert_eq!(s["stalled"], false);
    let s = w.wait_for(10, "the stall", |s| s["stalled"] == true);
    assert!(s["no_data_for_s"].as_f64().unwrap() >= 2.0);
    let (_, live) = w.get("live");
    assert!(live.contains("no data for "), "no stall banner");
    drop(sender);
    let s = w.wait_for(10, "the hang-up", |s| !s["ended"].is_null());
    assert_eq!(s["stalled"], false);
}

#[test]
fn a_serial_port_is_a_source_too() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, _) = recorded_run(dir.path());
    let bytes = std::fs::read(&bin).unwrap();
    let capture = capture_json(&bin, None);
    let (master, slave) = raw_pty();
    let w = Watch::start(&["--port", &slave]);
    std::thread::sleep(Duration::from_millis(300));
    let mut m = std::fs::File::from(master);
    for chunk in bytes.chunks(4096) {
        m.write_all(chunk).unwrap();
    }
    let want = capture["link"]["frames"].as_u64().unwrap();
    let s = w.wait_for(60, "every frame", |s| {
        s["link"]["frames"].as_u64() == Some(want)
    });
    assert_eq!(s["link"], capture["link"]);
    assert_eq!(s["latest"], capture["latest"]);
    assert_eq!(s["source"], slave.as_str());
    drop(m);
}

#[test]
fn bad_command_lines_are_one_line_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let pada = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_pada"))
            .arg("watch")
            .args(args)
            .output()
            .unwrap()
    };
    let busy = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let busy_addr = busy.local_addr().unwrap().to_string();
    let d = dir.path().to_str().unwrap();
    for (args, says) in [
        (
            vec!["--listen", "tcp:10.0.0.1:9000"],
            "only the loopback interface",
        ),
        (vec!["--listen", "127.0.0.1:9000"], "expected tcp:HOST:PORT"),
        (vec!["--file", d], "is a directory"),
        (vec!["--file", "/no/such/file"], "cannot open"),
        (
            vec!["--file", "-", "--seconds", "-1"],
            "--seconds -1 is out of range",
        ),
        (
            vec!["--file", "-", "--serve", "nonsense"],
            "--serve nonsense: not a HOST:PORT",
        ),
        (vec!["--file", "-", "--serve", &busy_addr], "cannot listen"),
        (
            vec!["--port", "/dev/null", "--baud", "0"],
            "--baud 0 is out of range",
        ),
        (vec![], "required"),
    ] {
        let o = pada(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

#[test]
fn the_firmware_s_own_recording_shows_its_safety_state() {
    // Recorded from the firmware in QEMU (`pada sil --seconds 3`): the
    // state comes from its State frames, the policy from its Policy frames.
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/sil-pendulum-3s.bin"
    );
    let capture = capture_json(Path::new(file), None);
    let w = Watch::start(&["--file", file]);
    let s = w.wait_for(60, "end of file", |s| !s["ended"].is_null());
    assert_same_as_capture(&s, &capture);
    assert_eq!(s["hello"]["protocol"], pada_core::wire::PROTOCOL_VERSION);
    assert!(s["messages"]["state"].as_u64().unwrap() >= 1);
    assert!(
        s["safety"]["state"].is_string(),
        "{}",
        watch_common::short(&s)
    );
    assert!(!s["policy"].is_null(), "{}", watch_common::short(&s));
}

#[test]
fn a_csv_that_cannot_be_written_ends_the_watch_with_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let (bin, _) = recorded_run(dir.path());
    let o = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args([
            "watch",
            "--serve",
            "127.0.0.1:0",
            "--seconds",
            "60",
            "--out",
            "/dev/full",
            "--file",
        ])
        .arg(&bin)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let last = err.trim().lines().last().unwrap();
    assert!(
        last.starts_with("error: ") && last.contains("cannot write the CSV"),
        "{err}"
    );
}

#[test]
fn watch_waits_for_its_port_to_come_back_and_counts_each_disconnect() {
    // A pty behind a symlink (as udev names a USB adapter): closing the
    // master pulls the adapter, a new pty behind the link plugs it in.
    use pada_core::wire::HostDecoder;
    let dir = tempfile::tempdir().unwrap();
    let (bin, _) = recorded_run(dir.path());
    let bytes = std::fs::read(&bin).unwrap();
    let capture = capture_json(&bin, None);
    let link = dir.path().join("ttyUSB-pada");
    let plug = || plug_at(&link);
    // Split the stream at frame boundaries into three stretches.
    let ends: Vec<usize> = bytes.iter().enumerate().filter(|(_, b)| **b == 0).map(|(i, _)| i + 1).collect();
    let cuts = [0, ends[ends.len() / 3], ends[2 * ends.len() / 3], bytes.len()];
    let mut m = plug();
    let w = Watch::start(&["--port", link.to_str().unwrap()]);
    std::thread::sleep(Duration::from_millis(300));
    for k in 0..3 {
        m.write_all(&bytes[cuts[k]..cuts[k + 1]]).unwrap();
        if k < 2 {
            let upto = HostDecoder::new().feed(&bytes[..cuts[k + 1]]).filter(|f| f.is_ok()).count() as u64;
            w.wait_for(60, "the stretch", |s| s["link"]["frames"].as_u64() == Some(upto));
            drop(m);
            let _ = std::fs::remove_file(&link);
            w.wait_for(20, "the disconnect", |s| s["disconnects"].as_u64() == Some(k as u64 + 1));
            m = plug();
        }
    }
    let want = capture["link"]["frames"].as_u64().unwrap();
    let s = w.wait_for(60, "every frame", |s| s["link"]["frames"].as_u64() == Some(want));
    assert_eq!(s["disconnects"], 2);
    assert_eq!(s["link"], capture["link"]);
    drop(m);
}
