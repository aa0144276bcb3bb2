//! `pada capture` end to end: the real binary reading a pseudo-terminal
//! (as it reads a USB serial adapter) fed with a telemetry stream the
//! firmware recorded in QEMU, with corruption, garbage and a lost frame
//! mixed in; and the same stream from a file.
//!
//! `tests/data/sil-pendulum-3s.bin` (repository root) is the raw USART2 stream of
//! `pada sil --task pendulum --seconds 3` (telemetry.bin; wire protocol 10).
//! Regenerate it with that command when the wire format changes.
//! `tests/data/sil-pendulum-3s-protocol8.bin` is the same run recorded by
//! an older pada (protocol 8), which a capture refuses in one line.

mod common;
use common::{capture_json, damaged, frames, plug_at, raw_pty};

use pada_core::wire::{HostDecoder, ToHost};
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn recording() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/sil-pendulum-3s.bin"
    ))
    .expect("the recorded stream")
}

/// What was done to the stream, and what a capture must count.
struct Damaged {
    bytes: Vec<u8>,
    good_frames: u32,
    bad_frames: u32,
    seq_gaps: u32,
    frames_missed: u64,
}

/// The recording with: 3 frames with a byte changed (CRC error or broken
/// COBS), 1 frame cut out (lost on the line), 2 bursts of garbage between
/// frames ending in a 0x00 (line noise that looks like a frame), all
/// isolated from each other.
fn damage(clean: &[u8]) -> Damaged {
    let f = frames(clean);
    let n = f.len();
    assert!(n > 300, "{n} frames");
    // Every frame of the clean recording decodes, in sequence.
    let mut d = HostDecoder::new();
    let kinds: Vec<bool> = d
        .feed(clean)
        .map(|r| matches!(r.unwrap().msg, ToHost::Step(_)))
        .collect();
    assert_eq!(kinds.len(), n);
    assert!(d.stats().is_clean());
    // Damage Step frames only (the episodes stay countable), far apart.
    let step_near = |x: f64| (((n as f64) * x) as usize..n).find(|&k| kinds[k]).unwrap();
    let corrupt = [step_near(0.1), step_near(0.4), step_near(0.8)];
    let dropped = step_near(0.6);
    let garbage_before = [step_near(0.3), step_near(0.9)];
    let out = damaged(clean, &garbage_before, &[dropped], &corrupt);
    Damaged {
        bytes: out,
        good_frames: (n - corrupt.len() - 1) as u32,
        bad_frames: (corrupt.len() + garbage_before.len()) as u32,
        seq_gaps: (corrupt.len() + 1) as u32,
        frames_missed: (corrupt.len() + 1) as u64,
    }
}

fn check_summary(json: &serde_json::Value, want: &Damaged) {
    let link = &json["link"];
    assert_eq!(link["frames"], want.good_frames, "{json:#}");
    assert_eq!(json["bad_frames"], want.bad_frames, "{json:#}");
    assert_eq!(link["seq_gaps"], want.seq_gaps, "{json:#}");
    assert_eq!(link["frames_missed"], want.frames_missed, "{json:#}");
    assert_eq!(link["bytes"], want.bytes.len() as u64, "{json:#}");
    // What the status line shows survived the damage: the three episodes.
    assert_eq!(json["latest"]["learning_episodes"], 1, "{json:#}");
    assert_eq!(json["latest"]["test_episodes"], 2, "{json:#}");
}

#[test]
fn capture_from_a_pseudo_terminal_resynchronises_counts_every_loss_and_keeps_going() {
    let want = damage(&recording());
    let (master, slave) = raw_pty();
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("capture.csv");
    let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args([
            "capture", "--port", &slave, "--baud", "921600", "--json", "--out",
        ])
        .arg(&csv)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The status lines, as they come.
    let stderr = child.stderr.take().unwrap();
    let lines = std::thread::spawn(move || {
        BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
            .collect::<Vec<_>>()
    });
    // Give it time to open the port, then feed the stream as a board would:
    // in pieces, over about two and a half seconds.
    std::thread::sleep(Duration::from_millis(500));
    let mut m = std::fs::File::from(master);
    let started = Instant::now();
    for chunk in want.bytes.chunks(256) {
        m.write_all(chunk).unwrap();
        std::thread::sleep(Duration::from_millis(40));
    }
    let fed_in = started.elapsed();
    // Let it drain, then hang up: the port goes away, and the capture
    // waits for it to come back (counting the disconnect) until Ctrl-C.
    std::thread::sleep(Duration::from_millis(500));
    drop(m);
    std::thread::sleep(Duration::from_millis(500));
    let pid = rustix::process::Pid::from_child(&child);
    rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
    let out = child.wait_with_output().unwrap();
    let lines = lines.join().unwrap();
    assert!(
        out.status.success(),
        "exit {:?}; stderr:\n{}",
        out.status,
        lines.join("\n")
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    check_summary(&json, &want);
    assert_eq!(json["ended"], "interrupted", "{json:#}");
    assert_eq!(json["disconnects"], 1, "{json:#}");
    assert!(lines.iter().any(|l| l.contains("waiting for it to come back")), "{lines:?}");
    // A live status line every second while bytes came in, and a last one.
    let status: Vec<&String> = lines.iter().filter(|l| l.starts_with("frames ")).collect();
    assert!(
        status.len() >= 2 && fed_in > Duration::from_secs(2),
        "{lines:?}"
    );
    let last = status.last().unwrap();
    assert!(
        last.contains(&format!(
            "gaps {} ({} frames)",
            want.seq_gaps, want.frames_missed
        )),
        "{last}"
    );
    // Every frame, lost frame and gap is a CSV row.
    let text = std::fs::read_to_string(&csv).unwrap();
    let kind = |k: &str| {
        text.lines()
            .filter(|l| l.split(',').nth(2) == Some(k))
            .count()
    };
    assert_eq!(kind("lost") as u32, want.bad_frames);
    assert_eq!(kind("gap") as u32, want.seq_gaps);
    let rows = text.lines().count() - 1;
    assert_eq!(rows - kind("lost") - kind("gap"), want.good_frames as usize);
}

#[test]
fn capture_from_a_file_counts_the_same() {
    let want = damage(&recording());
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("damaged.bin");
    std::fs::write(&file, &want.bytes).unwrap();
    let json = capture_json(&file, None);
    check_summary(&json, &want);
    assert_eq!(json["ended"], "end of file");
}

#[test]
fn a_recording_of_an_older_protocol_is_refused_in_one_line() {
    let old = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sil-pendulum-3s-protocol8.bin");
    common::assert_bad_input(
        &["capture", "--file", old],
        &["telemetry protocol 8", "this pada reads protocol 10", "an older pada wrote it"],
    );
}

#[test]
fn capture_rejects_bad_input_with_exit_code_2() {
    let bin = env!("CARGO_BIN_EXE_pada");
    for args in [
        vec!["capture"],
        vec!["capture", "--file", "/nonexistent/stream.bin"],
        vec!["capture", "--port", "/dev/nonexistent-tty"],
        vec!["capture", "--file", "-", "--port", "/dev/null"],
        vec!["capture", "--file", "-", "--baud", "0"],
        vec!["capture", "--file", "-", "--seconds", "-1"],
    ] {
        let out = Command::new(&bin)
            .args(&args)
            .stdin(Stdio::null())
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.starts_with("error: ") && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

/// A pseudo-terminal behind a fixed path (a symlink, as udev's
/// `/dev/serial/by-id/…` names a USB adapter): closing its master is
/// pulling the adapter; a new pty behind the same link is plugging it in.
struct Adapter {
    link: std::path::PathBuf,
    master: Option<std::fs::File>,
}

impl Adapter {
    fn plug(&mut self) {
        self.master = Some(plug_at(&self.link));
    }

    fn pull(&mut self) {
        self.master = None;
        let _ = std::fs::remove_file(&self.link);
    }
}

#[test]
fn capture_survives_ten_disconnects_of_its_port_and_records_every_frame_sent_while_connected() {
    let stream = recording();
    let bounds = frames(&stream);
    let dir = tempfile::tempdir().unwrap();
    let mut adapter = Adapter { link: dir.path().join("ttyUSB-pada"), master: None };
    adapter.plug();
    let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["capture", "--baud", "921600", "--json", "--port"])
        .arg(&adapter.link)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    let lines = std::thread::spawn(move || {
        let mut all = Vec::new();
        for l in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(l.clone());
            all.push(l);
        }
        all
    });
    // Waits for a stderr line containing `what`.
    let wait_for = |what: &str| {
        let deadline = Instant::now() + Duration::from_secs(20);
        while Instant::now() < deadline {
            if let Ok(l) = rx.recv_timeout(Duration::from_millis(100)) {
                if l.contains(what) {
                    return;
                }
            }
        }
        panic!("no line with {what:?} within 20 s");
    };
    std::thread::sleep(Duration::from_millis(500));
    // Eleven connected stretches, each a slice of whole frames; ten
    // disconnects between them.
    let per = bounds.len() / 11;
    let mut sent = 0u64;
    for k in 0..11 {
        let (a, b) = (bounds[k * per].0, bounds[if k == 10 { bounds.len() - 1 } else { (k + 1) * per - 1 }].1);
        let m = adapter.master.as_mut().unwrap();
        for chunk in stream[a..b].chunks(512) {
            m.write_all(chunk).unwrap();
            std::thread::sleep(Duration::from_millis(5));
        }
        sent += HostDecoder::new().feed(&stream[a..b]).filter(|f| f.is_ok()).count() as u64;
        // Let the capture read it all before the cable goes.
        std::thread::sleep(Duration::from_millis(400));
        if k < 10 {
            adapter.pull();
            wait_for("waiting for it to come back");
            std::thread::sleep(Duration::from_millis(300));
            adapter.plug();
            wait_for("is back");
        }
    }
    std::thread::sleep(Duration::from_millis(300));
    let pid = rustix::process::Pid::from_child(&child);
    rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
    let out = child.wait_with_output().unwrap();
    let lines = lines.join().unwrap();
    assert!(out.status.success(), "exit {:?}; stderr:\n{}", out.status, lines.join("\n"));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Ctrl-C still gives the summary; every frame sent while connected was
    // recorded, each disconnect counted, and nothing else lost.
    assert_eq!(json["ended"], "interrupted", "{json:#}");
    assert_eq!(json["disconnects"], 10, "{json:#}");
    assert_eq!(json["link"]["frames"], sent, "{json:#}");
    assert_eq!(json["bad_frames"], 0, "{json:#}");
    // Each stretch starts where the last ended: no frame was sent while
    // unplugged, so there is no gap either.
    assert_eq!(json["link"]["seq_gaps"], 0, "{json:#}");
}
