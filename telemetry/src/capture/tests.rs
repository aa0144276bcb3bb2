//! The recorder's rows and counts.

use super::*;
use pada_core::wire::{Episode, FrameEncoder, Hello, MAX_FRAME_LEN, PROTOCOL_VERSION};

fn frames(msgs: &[ToHost]) -> Vec<u8> {
    let mut enc = FrameEncoder::new();
    let mut out = Vec::new();
    for m in msgs {
        let mut buf = [0u8; MAX_FRAME_LEN];
        out.extend_from_slice(enc.encode(m, &mut buf).unwrap());
    }
    out
}

fn hello() -> ToHost {
    ToHost::Hello(Hello {
        protocol: PROTOCOL_VERSION,
        robot: heapless::String::try_from("physical-pendulum").unwrap(),
        robot_hash: 0,
        config_hash: 1,
        weight_count: 2,
        period_us: 3,
        state_dims: 2,
        joints: 1,
    })
}

fn episode(index: u32, mode: RunMode, r: f32) -> ToHost {
    ToHost::Episode(Episode {
        index,
        mode,
        total_reward: r,
        length: 100,
        weights_checksum: 7,
    })
}

#[test]
fn the_end_of_the_input_counts_a_cut_off_frame() {
    // Regression: a frame cut off by the end of the input was not counted.
    let bytes = frames(&[hello(), episode(0, RunMode::Learning, -1.0)]);
    let mut rec = Recorder::new(None).unwrap();
    let mut out = Vec::new();
    rec.feed(&bytes[..bytes.len() - 4], 0.0, &mut out).unwrap();
    assert!(rec.stats().is_clean());
    assert!(rec.finish(1.0).unwrap());
    assert_eq!((rec.stats().frames, rec.stats().truncated), (1, 1));
    assert!(!rec.stats().is_clean());
    assert!(
        rec.status_line().contains("other 1"),
        "{}",
        rec.status_line()
    );
    assert!(!rec.finish(1.0).unwrap(), "counted once");
}

#[test]
fn garbage_costs_one_frame_and_is_counted_then_decoding_resumes() {
    let mut bytes = frames(&[
        hello(),
        episode(0, RunMode::Learning, -10.0),
        episode(1, RunMode::Testing, -5.0),
    ]);
    // Damage the middle frame: flip a byte inside it.
    let second_start = bytes.iter().position(|&b| b == 0).unwrap() + 1;
    // (COBS frames hold no 0x00, and the new byte is not one either.)
    let b = &mut bytes[second_start + 3];
    *b = if *b == 0xFF { 0xFE } else { *b + 1 };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    let mut out = Vec::new();
    {
        let file = std::fs::File::create(&path).unwrap();
        let mut rec = Recorder::new(Some(Box::new(file) as Box<dyn Write + Send>)).unwrap();
        // Fed in odd chunks, as a serial port delivers them.
        for chunk in bytes.chunks(7) {
            rec.feed(chunk, 1.5, &mut out).unwrap();
        }
        rec.flush().unwrap();
        let s = rec.stats();
        assert_eq!(s.frames, 2);
        assert_eq!(s.bad_frames(), 1);
        assert_eq!((s.seq_gaps, s.frames_missed), (1, 1));
        assert_eq!(rec.counts().episode, 1);
        assert_eq!(rec.latest().test_return, Some(-5.0));
        assert!(
            rec.status_line().contains("gaps 1 (1 frames)"),
            "{}",
            rec.status_line()
        );
    }
    assert_eq!(out.len(), 2);
    let text = std::fs::read_to_string(&path).unwrap();
    let kinds: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap())
        .collect();
    assert_eq!(kinds.len(), 4, "{text}");
    assert_eq!(kinds[0], "hello");
    assert!(kinds[1] == "lost");
    assert_eq!(&kinds[2..], ["gap", "episode"]);
}
