//! `pada capture --checkpoint` and `pada watch --checkpoint` end to end:
//! the test plays a board whose table fits no flash on a pseudo-terminal.
//! It streams saves (body first, header last), is unplugged ten times
//! (some of them in the middle of a save, some in the middle of a frame),
//! and at every boot asks for its checkpoint back and reassembles what the
//! host sends. The file at PATH is at every moment absent or the last
//! checkpoint the board completed.

mod common;
use common::plug_at;

use pada::checkpoint_keeper::read_kept;
use pada_core::checkpoint::stream::{Assembler, Chunk, Chunker, Expect, ImageSource, Order, TableImage};
use pada_core::checkpoint::{slot_len, LearnerState, STATE_LEN};
use pada_core::fixed::Q16;
use pada_core::wire::{
    ChipDecoder, FrameEncoder, Hello, RestoreDenied, RestoreOutcome, RestoreRequest, ToChip, ToHost, MAX_FRAME_LEN,
    PROTOCOL_VERSION, RESTORE_BATCH,
};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

const HASH: u32 = 0x5EED_1234;
const N: usize = 500;
const LEN: usize = slot_len(N, 4);

/// One save of the board: generation, image, chunks (header last).
#[derive(Clone)]
struct Save {
    generation: u32,
    image: Vec<u8>,
    chunks: Vec<Chunk>,
}

/// Checkpoint `generation` of a table that differs with `seed` (a third
/// of it zero).
fn save(generation: u32, seed: i32) -> Save {
    let w: Vec<Q16> =
        (0..N as i32).map(|i| if i % 3 == 0 { Q16::ZERO } else { Q16(i.wrapping_mul(0x0101_0101) ^ seed) }).collect();
    let mut s = LearnerState::default();
    s.agent.stats.episodes = seed as u32;
    let r: [u8; STATE_LEN] = s.to_bytes();
    let image = TableImage::new(HASH, generation, &r, &w[..]).unwrap();
    let mut bytes = vec![0u8; image.image_len()];
    image.read(0, &mut bytes);
    let chunks: Vec<Chunk> = Chunker::new(&image, Order::HeaderLast).unwrap().collect();
    assert!(chunks.len() >= 8, "a save of several batches: {}", chunks.len());
    Save { generation, image: bytes, chunks }
}

/// The board at the far end of a pty behind a fixed path (a symlink, as
/// udev names a USB adapter): unplugging closes the master, plugging in
/// makes a new pty behind the same link. Every plug-in is a boot: its
/// frames are numbered from 0 again.
struct Board {
    link: PathBuf,
    master: Option<std::fs::File>,
    encoder: FrameEncoder,
    decoder: ChipDecoder,
    /// The host's last sequence number seen (the host numbers its frames
    /// 0, 1, 2, … over the whole capture).
    host_seq: Option<u32>,
}

impl Board {
    /// A board at `link`, plugged in.
    fn plugged_at(link: PathBuf) -> Board {
        let mut board =
            Board { link, master: None, encoder: FrameEncoder::new(), decoder: ChipDecoder::new(), host_seq: None };
        board.plug();
        board
    }

    fn plug(&mut self) {
        let m = plug_at(&self.link);
        // Non-blocking: the test waits for the host's answers with a deadline.
        let flags = rustix::fs::fcntl_getfl(&m).unwrap();
        rustix::fs::fcntl_setfl(&m, flags | rustix::fs::OFlags::NONBLOCK).unwrap();
        self.master = Some(m);
        self.encoder = FrameEncoder::new();
        self.decoder = ChipDecoder::new();
    }

    fn pull(&mut self) {
        self.master = None;
        let _ = std::fs::remove_file(&self.link);
    }

    fn write(&mut self, mut bytes: &[u8]) {
        let m = self.master.as_mut().unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        while !bytes.is_empty() {
            match m.write(bytes) {
                Ok(n) => bytes = &bytes[n..],
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock && Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(1))
                }
                Err(e) => panic!("writing to the pty: {e}"),
            }
        }
    }

    fn frame(&mut self, msg: &ToHost) -> Vec<u8> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        self.encoder.encode(msg, &mut buf).unwrap().to_vec()
    }

    fn send(&mut self, msg: &ToHost) {
        let f = self.frame(msg);
        self.write(&f);
    }

    /// The host's frames until `done` says the answer is whole.
    fn receive(&mut self, done: impl Fn(&[ToChip]) -> bool) -> Vec<ToChip> {
        let mut got = Vec::new();
        let mut buf = [0u8; 1024];
        let deadline = Instant::now() + Duration::from_secs(10);
        while !done(&got) {
            assert!(Instant::now() < deadline, "no whole answer from the host within 10 s; got {got:?}");
            let n = match self.master.as_mut().unwrap().read(&mut buf) {
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    std::thread::sleep(Duration::from_millis(1));
                    continue;
                }
                Err(e) => panic!("reading the pty: {e}"),
            };
            for &b in &buf[..n] {
                if let Some(frame) = self.decoder.push(b) {
                    let frame = frame.expect("the host's frames arrive whole");
                    let expected = self.host_seq.map_or(0, |s| s + 1);
                    assert_eq!(frame.seq, expected, "the host numbers its frames 0, 1, 2, …");
                    self.host_seq = Some(frame.seq);
                    got.push(frame.msg);
                }
            }
        }
        got
    }

    /// A boot: asks for its checkpoint, batch by batch, and reassembles
    /// it; returns its generation and image, or `None` with the refusal.
    fn restore(&mut self) -> Result<(u32, Vec<u8>), RestoreDenied> {
        self.send(&ToHost::Hello(Hello {
            protocol: PROTOCOL_VERSION,
            robot: "leo".try_into().unwrap(),
            robot_hash: pada_core::robot::leo::SPEC.definition_hash(),
            config_hash: HASH,
            weight_count: N as u32,
            period_us: 33_333,
            state_dims: 4,
            joints: 1,
        }));
        let mut image = vec![0xA5u8; LEN];
        let expect = Expect { config_hash: Some(HASH), image_len: Some(LEN as u32), newer_than: None };
        let mut a = Assembler::new(&mut image[..], Order::HeaderFirst, expect);
        let mut batches = 0;
        while !a.is_complete() {
            let offset = a.expected_offset();
            self.send(&ToHost::RestoreWanted(RestoreRequest { config_hash: HASH, image_len: LEN as u32, offset }));
            let answer = self.receive(|got| {
                matches!(got.last(), Some(ToChip::RestoreNone(_))) || got.len() == RESTORE_BATCH
                // The last batch may be short: it ends with the header's
                // stream complete, which the caller checks below.
                    || got.iter().any(|m| matches!(m, ToChip::RestoreChunk(c) if c.offset + c.covered_len() as u32 >= LEN as u32))
            });
            batches += 1;
            for msg in answer {
                match msg {
                    ToChip::RestoreChunk(c) => {
                        a.accept(&c).unwrap_or_else(|e| panic!("chunk at {} refused: {e}", c.offset));
                    }
                    ToChip::RestoreNone(why) => {
                        assert_eq!(batches, 1, "a refusal comes at the start");
                        self.send(&ToHost::Restored(RestoreOutcome::Denied(why)));
                        return Err(why);
                    }
                    other => panic!("not a restore's answer: {other:?}"),
                }
            }
        }
        let chunks = a.accepted();
        let generation = a.generation().unwrap();
        self.send(&ToHost::Restored(RestoreOutcome::Loaded { generation, chunks }));
        Ok((generation, image))
    }
}

/// The capture's stderr, line by line, as it comes.
struct Stderr {
    rx: Receiver<String>,
    all: Vec<String>,
}

impl Stderr {
    fn follow(child: &mut Child) -> Stderr {
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel::<String>();
        std::thread::spawn(move || {
            for l in BufReader::new(stderr).lines().map_while(Result::ok) {
                let _ = tx.send(l);
            }
        });
        Stderr { rx, all: Vec::new() }
    }

    /// Waits for a line containing `what`; returns it.
    fn wait_for(&mut self, what: &str) -> String {
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Ok(l) = self.rx.recv_timeout(Duration::from_millis(50)) {
                self.all.push(l.clone());
                if l.contains(what) {
                    return l;
                }
            }
        }
        panic!("no line with {what:?} within 10 s; stderr so far:\n{}", self.all.join("\n"));
    }

    /// The rest, once the process ended.
    fn rest(mut self) -> Vec<String> {
        while let Ok(l) = self.rx.recv_timeout(Duration::from_secs(5)) {
            self.all.push(l);
        }
        self.all
    }
}

/// The file at `path` is the checkpoint `kept` (or, with none kept yet,
/// absent), whole.
/// `pada ARGS LINK --checkpoint PATH`, once it says it keeps the checkpoint.
fn keep_checkpoint(args: &[&str], link: &Path, path: &Path) -> (Child, Stderr) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(args)
        .arg(link)
        .arg("--checkpoint")
        .arg(path)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = Stderr::follow(&mut child);
    err.wait_for("keeping the board's checkpoint at");
    (child, err)
}

fn assert_kept(path: &Path, kept: Option<&Save>, when: &str) {
    match kept {
        None => assert!(!path.exists(), "{when}: a file before the first complete save"),
        Some(s) => {
            let r = read_kept(path).unwrap_or_else(|e| panic!("{when}: the kept file is not a checkpoint: {e}"));
            assert_eq!(r.header().generation, s.generation, "{when}");
            assert!(std::fs::read(path).unwrap() == s.image, "{when}: the file is generation {}'s image", s.generation);
        }
    }
}

/// Stops `child` as Ctrl-C does; its exit must be a success.
fn interrupt(child: Child, err: Stderr) -> Vec<String> {
    let pid = rustix::process::Pid::from_child(&child);
    rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
    let out = child.wait_with_output().unwrap();
    let lines = err.rest();
    assert!(out.status.success(), "exit {:?}; stderr:\n{}", out.status, lines.join("\n"));
    assert!(!lines.iter().any(|l| l.contains("panicked")), "{}", lines.join("\n"));
    lines
}

#[test]
fn capture_keeps_the_checkpoint_through_ten_unplugs_mid_save_and_sends_it_back_at_every_boot() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("leo.ckpt");
    let mut board = Board::plugged_at(dir.path().join("ttyUSB-leo"));
    let (child, mut err) = keep_checkpoint(&["capture", "--port"], &board.link, &path);

    let mut kept: Option<Save> = None;
    // The generation the board saves next; a save cut off is made again
    // with its generation every other time (the board restored the one
    // before and learned on), else with the next.
    let mut generation = 1;
    let started = Instant::now();
    for k in 0..=10u32 {
        // A boot: the board asks for its checkpoint.
        match board.restore() {
            Ok((g, image)) => {
                let s = kept.as_ref().expect("a checkpoint sent back only once one was kept");
                assert_eq!(g, s.generation, "boot {k}");
                assert!(image == s.image, "boot {k}: the restored image is the kept one");
            }
            Err(why) => {
                assert_eq!(why, RestoreDenied::NoCheckpoint, "boot {k}");
                assert!(
                    kept.is_none(),
                    "boot {k}: refused although generation {:?} was kept",
                    kept.as_ref().map(|s| s.generation)
                );
                err.wait_for("no checkpoint sent to the board: no checkpoint kept at");
            }
        }
        if k == 4 {
            // A stale chunk (generation 1, older than the kept one) is
            // refused in one line and changes nothing.
            let stale = save(1, 99).chunks[0].clone();
            board.send(&ToHost::CheckpointChunk(stale));
            err.wait_for("refused: stale generation 1");
        }
        // A complete save.
        let s = save(generation, (k * 7 + 1) as i32);
        for c in &s.chunks {
            board.send(&ToHost::CheckpointChunk(c.clone()));
        }
        err.wait_for(&format!("checkpoint generation {} kept at", s.generation));
        kept = Some(s);
        generation += 1;
        assert_kept(&path, kept.as_ref(), &format!("after save {k}"));
        if k == 10 {
            break;
        }
        if k % 2 == 1 {
            // Unplugged in the middle of a save: after some chunks, and
            // every other time in the middle of a frame.
            let cut = save(generation, (k * 7 + 2) as i32);
            let whole = cut.chunks.len() * (k as usize % 5 + 1) / 7 + 1;
            for c in &cut.chunks[..whole] {
                board.send(&ToHost::CheckpointChunk(c.clone()));
            }
            if k % 4 == 1 {
                let f = board.frame(&ToHost::CheckpointChunk(cut.chunks[whole].clone()));
                board.write(&f[..f.len() / 2]);
            } else {
                generation += 1;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        board.pull();
        err.wait_for("waiting for it to come back");
        assert_kept(&path, kept.as_ref(), &format!("unplugged {k}"));
        board.plug();
        err.wait_for("is back");
        assert_kept(&path, kept.as_ref(), &format!("plugged in again {k}"));
    }
    let lines = interrupt(child, err);
    assert_kept(&path, kept.as_ref(), "at the end");
    assert_eq!(kept.as_ref().map(|s| s.generation), Some(generation - 1));
    let kept_lines =
        lines.iter().filter(|l| l.starts_with("capture: checkpoint generation") && l.contains(" kept at ")).count();
    assert_eq!(kept_lines, 11, "one line per checkpoint kept:\n{}", lines.join("\n"));
    let restores = lines.iter().filter(|l| l.contains("restoring checkpoint generation")).count();
    assert_eq!(restores, 10, "every boot after the first was restored:\n{}", lines.join("\n"));
    assert!(lines.iter().any(|l| l.contains("10 disconnects")), "{}", lines.join("\n"));
    assert!(!dir.path().join("leo.ckpt.partial").exists(), "the last save was renamed into place");
    assert!(started.elapsed() < Duration::from_secs(30), "{:?}", started.elapsed());
}

#[test]
fn a_recording_only_feeds_the_keeper() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("leo.ckpt");
    let mut enc = FrameEncoder::new();
    let mut stream = Vec::new();
    let mut put = |m: &ToHost| {
        let mut buf = [0u8; MAX_FRAME_LEN];
        stream.extend_from_slice(enc.encode(m, &mut buf).unwrap());
    };
    put(&ToHost::RestoreWanted(RestoreRequest { config_hash: HASH, image_len: LEN as u32, offset: 0 }));
    let (one, two) = (save(1, 1), save(2, 2));
    for c in &one.chunks {
        put(&ToHost::CheckpointChunk(c.clone()));
    }
    // Generation 2 with a chunk missing in its middle: refused from there
    // on; its header (the last chunk) starts a stream of its own, header
    // first, that never completes.
    for (i, c) in two.chunks.iter().enumerate() {
        if i != 3 {
            put(&ToHost::CheckpointChunk(c.clone()));
        }
    }
    let file = dir.path().join("board.bin");
    std::fs::write(&file, &stream).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(["capture", "--json", "--file"])
        .arg(&file)
        .arg("--checkpoint")
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_kept(&path, Some(&one), "after the recording");
    assert!(stderr.contains(&format!("checkpoint generation 1 kept at {}: {LEN} bytes", path.display())), "{stderr}");
    let refused: Vec<&str> = stderr.lines().filter(|l| l.contains("refused")).collect();
    assert_eq!(refused.len(), 2, "the first refusal, then a count of the rest:\n{stderr}");
    assert!(refused[0].contains("checkpoint chunk refused: "), "{stderr}");
    assert!(refused[1].contains(&format!("{} more checkpoint chunks refused", two.chunks.len() - 6)), "{stderr}");
    assert!(!stderr.contains("restoring"), "nobody to answer in a recording: {stderr}");
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["link"]["frames"], 1 + one.chunks.len() + two.chunks.len() - 1);
}

#[test]
fn watch_keeps_the_checkpoint_and_sends_it_back_on_its_port() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("leo.ckpt");
    let mut board = Board::plugged_at(dir.path().join("ttyACM-leo"));
    let (child, mut err) = keep_checkpoint(&["watch", "--serve", "127.0.0.1:0", "--port"], &board.link, &path);
    assert_eq!(board.restore(), Err(RestoreDenied::NoCheckpoint));
    let s = save(3, 3);
    for c in &s.chunks {
        board.send(&ToHost::CheckpointChunk(c.clone()));
    }
    err.wait_for("watch: checkpoint generation 3 kept at");
    assert_kept(&path, Some(&s), "after the save");
    board.pull();
    err.wait_for("waiting for the port to come back");
    board.plug();
    err.wait_for("the port is back");
    let (g, image) = board.restore().unwrap();
    assert_eq!(g, 3);
    assert!(image == s.image, "the restored image is the kept one");
    interrupt(child, err);
}

#[test]
fn a_checkpoint_path_that_cannot_be_kept_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("board.bin");
    std::fs::write(&file, []).unwrap();
    let (f, d) = (file.to_str().unwrap(), dir.path().to_str().unwrap());
    let missing = dir.path().join("no/such/dir/leo.ckpt");
    common::assert_bad_input(&["capture", "--file", f, "--checkpoint", d], &["--checkpoint", "is a directory"]);
    common::assert_bad_input(
        &["capture", "--file", f, "--checkpoint", missing.to_str().unwrap()],
        &["--checkpoint", "no directory"],
    );
    common::assert_bad_input(
        &["watch", "--file", f, "--serve", "127.0.0.1:0", "--checkpoint", d],
        &["--checkpoint", "is a directory"],
    );
}
