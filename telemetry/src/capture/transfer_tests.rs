//! A checkpoint transfer's rows.

use super::transfer::{full_save_link_s, link_s, Direction};
use super::*;
use pada_core::checkpoint::stream::Chunk;
use pada_core::wire::{CheckpointReport, FrameEncoder, Hello, RestoreOutcome, RestoreRequest, MAX_FRAME_LEN, PROTOCOL_VERSION};

/// An image of a header and `windows` body windows.
const WINDOWS: u32 = 40;
const LEN: u32 = 32 + 128 * WINDOWS;

fn hello() -> ToHost {
    ToHost::Hello(Hello {
        protocol: PROTOCOL_VERSION,
        robot: "leo".try_into().unwrap(),
        robot_hash: 0,
        config_hash: 9,
        weight_count: 2,
        period_us: 3,
        state_dims: 2,
        joints: 1,
    })
}

/// A save of generation `g` as the board streams it: every body window
/// (one of them a run of zeros), the header last.
fn save(g: u32) -> Vec<ToHost> {
    let mut v: Vec<ToHost> = (0..WINDOWS - 2)
        .map(|k| ToHost::CheckpointChunk(Chunk::words(g, LEN, 32 + 128 * k, &[k as u8 + 1; 128])))
        .collect();
    v.push(ToHost::CheckpointChunk(Chunk::zeros(g, LEN, 32 + 128 * (WINDOWS - 2), 2)));
    v.push(ToHost::CheckpointChunk(Chunk::words(g, LEN, 0, &[7; 32])));
    v
}

fn request(offset: u32) -> ToHost {
    ToHost::RestoreWanted(RestoreRequest { config_hash: 9, image_len: LEN, offset })
}

/// Records `msgs` into a CSV; returns the recorder and the rows.
fn record(msgs: &[ToHost], then: impl FnOnce(&mut Recorder)) -> (Recorder, Vec<csv::StringRecord>) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    let file = std::fs::File::create(&path).unwrap();
    let mut rec = Recorder::new(Some(Box::new(file) as Box<dyn Write + Send>)).unwrap();
    let mut enc = FrameEncoder::new();
    let mut out = Vec::new();
    for (i, m) in msgs.iter().enumerate() {
        let mut buf = [0u8; MAX_FRAME_LEN];
        rec.feed(enc.encode(m, &mut buf).unwrap(), i as f64, &mut out).unwrap();
    }
    then(&mut rec);
    rec.end().unwrap();
    rec.flush().unwrap();
    let rows = csv::Reader::from_path(&path).unwrap().records().map(|r| r.unwrap()).collect();
    (rec, rows)
}

fn kinds(rows: &[csv::StringRecord]) -> Vec<&str> {
    rows.iter().map(|r| &r[2]).collect()
}

#[test]
fn a_save_is_one_row_and_a_restore_one_row_not_one_per_frame() {
    // Regression: every chunk and every request was a row of its own
    // (475 865 + 105 723 rows in a 1800 s LEO run).
    let mut msgs = vec![hello()];
    msgs.extend(save(3));
    msgs.push(ToHost::Checkpoint(CheckpointReport::Streamed { generation: 3, chunks: WINDOWS, image_len: LEN }));
    msgs.push(hello());
    msgs.extend((0..WINDOWS / 3 + 1).map(|k| request(if k == 0 { 0 } else { 32 + 128 * (3 * k - 1) })));
    msgs.push(ToHost::Restored(RestoreOutcome::Loaded { generation: 3, chunks: WINDOWS }));
    let (rec, rows) = record(&msgs, |_| {});
    assert_eq!(kinds(&rows), ["hello", "checkpoint-save", "hello", "checkpoint-restore"]);
    let col = |r: &csv::StringRecord, name: &str| r[col(name)].to_string();
    let (s, r) = (&rows[1], &rows[3]);
    assert_eq!([col(s, "generation"), col(s, "bytes"), col(s, "chunks"), col(s, "outcome")], ["3", &LEN.to_string(), &WINDOWS.to_string(), "streamed"]);
    assert_eq!([col(r, "generation"), col(r, "bytes"), col(r, "chunks"), col(r, "outcome")], ["3", &LEN.to_string(), &WINDOWS.to_string(), "loaded"]);
    assert_eq!(col(r, "seq"), "", "a row of many frames has no one sequence number");
    // Every frame is still counted, and its bytes are the link time.
    let c = rec.counts();
    assert_eq!((c.checkpoint_chunk, c.restore_wanted, c.hello, c.other), (WINDOWS as u64, (WINDOWS / 3 + 1) as u64, 2, 2));
    let t = rec.transfers();
    assert_eq!(t.len(), 2);
    assert_eq!((t[0].direction, t[1].direction), (Direction::Save, Direction::Restore));
    assert_eq!(t[1].requests, WINDOWS / 3 + 1);
    let hello_bytes = 2 * {
        let mut buf = [0u8; MAX_FRAME_LEN];
        FrameEncoder::new().encode(&hello(), &mut buf).unwrap().len() as u64
    };
    assert_eq!(t[0].board_bytes + t[1].board_bytes + hello_bytes, rec.stats().bytes);
    assert_eq!(col(s, "link_s"), format!("{:.3}", link_s(t[0].board_bytes)));
    assert!(t[0].link_s > 0.0 && t[0].link_s < full_save_link_s(LEN));
}

#[test]
fn a_transfer_cut_short_is_a_row_too_and_a_new_stream_starts_another() {
    let mut msgs = save(4);
    msgs.truncate(10);
    // The board was restored and saves generation 4 again from the start.
    msgs.extend(save(4));
    msgs.push(ToHost::Checkpoint(CheckpointReport::Streamed { generation: 4, chunks: WINDOWS + 1, image_len: LEN }));
    msgs.push(save(5)[0].clone());
    msgs.push(request(0));
    let (rec, rows) = record(&msgs, |rec| {
        // A power cut: the save of generation 5 and the restore end.
        assert!(!rec.restarted().unwrap());
    });
    let outcomes: Vec<(&str, &str, &str)> = rows.iter().map(|r| (&r[2], &r[col("outcome")], &r[col("chunks")])).collect();
    assert_eq!(
        outcomes,
        [
            ("checkpoint-save", "cut-off", "10"),
            ("checkpoint-save", "incomplete", "40"),
            ("checkpoint-save", "cut-off", "1"),
            ("checkpoint-restore", "cut-off", "0"),
        ],
        "{rows:?}"
    );
    assert!(rows[1][DETAIL].contains("the board sent 41 chunks, 40 arrived"), "{:?}", &rows[1][DETAIL]);
    assert_eq!(rec.counts().checkpoint_chunk, 51);
    // The end of the input inside a save: unfinished.
    let (_, rows) = record(&save(6)[..5], |_| {});
    assert_eq!((&rows[0][2], &rows[0][col("outcome")]), ("checkpoint-save", "unfinished"));
}

#[test]
fn a_restores_answers_count_on_its_link_time() {
    let msgs = [request(0)];
    let (rec, rows) = record(&msgs, |rec| {
        rec.answered(3, 500);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let restored = ToHost::Restored(RestoreOutcome::Denied(pada_core::wire::RestoreDenied::Older));
        let mut out = Vec::new();
        let mut enc = FrameEncoder::new();
        enc.encode(&hello(), &mut buf).unwrap();
        rec.feed(enc.encode(&restored, &mut buf).unwrap(), 2.0, &mut out).unwrap();
    });
    let t = &rec.transfers()[0];
    assert_eq!((t.chunks, t.host_bytes, t.outcome.as_str(), t.generation), (3, 500, "denied-older", None));
    assert_eq!(t.link_s, link_s(t.board_bytes + 500));
    assert_eq!(&rows[0][col("generation")], "", "no generation loaded");
}

#[test]
fn a_full_leo_table_takes_about_two_minutes_to_save() {
    // LEO's F429 image: the 32-byte header, the learner record and
    // 2^21 four-byte entries.
    let profile = pada_core::profile::Board::F429Sdram.profile(&pada_core::robot::leo::SPEC).unwrap();
    let image = pada_core::checkpoint::slot_len(profile.weights().unwrap(), profile.entry_bytes());
    let s = full_save_link_s(image as u32);
    assert!((100.0..140.0).contains(&s), "{s} s");
}
