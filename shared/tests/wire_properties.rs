//! The wire protocol under arbitrary inputs (proptest): arbitrary steps
//! and weight chunks round trip, and a single corrupted bit is never
//! delivered as a message.

use heapless::Vec as HVec;
use pada_core::wire::*;
use proptest::prelude::*;

fn arb_step() -> impl Strategy<Value = Step> {
    (
        (any::<u32>(), any::<u32>(), any::<u32>(), any::<bool>(), 0u8..4),
        proptest::collection::vec(-1e9f32..1e9, 0..=MAX_STATE_DIMS),
        (any::<u32>(), proptest::collection::vec(-1.0f32..1.0, 0..=MAX_ACTION_DIMS)),
        (-1e6f32..1e6, any::<i32>(), any::<bool>(), any::<u32>()),
        proptest::collection::vec((0.0f64..1e3, any::<u32>()), 0..=MAX_GEARBOXES),
    )
        .prop_map(|((step, time_ms, episode, testing, kind), state, (action, output), (reward, td, ex, lus), j)| {
            Step {
                step,
                time_ms,
                episode,
                mode: if testing { RunMode::Testing } else { RunMode::Learning },
                kind: [StepKind::Start, StepKind::Step, StepKind::Absorbing, StepKind::Timeout][kind as usize],
                state: HVec::from_slice(&state).unwrap(),
                action,
                output: HVec::from_slice(&output).unwrap(),
                reward,
                td_error: td,
                explored: ex,
                footstep: !ex,
                joints: j.into_iter().map(|(damage, reengagements)| JointFatigue { damage, reengagements }).collect(),
                loop_us: lus,
                agent_cycles: lus.rotate_left(7),
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000), chunk in 1usize..100) {
        let mut host = HostDecoder::new();
        let mut chip = ChipDecoder::new();
        let mut small = FrameDecoder::<ToHost, 8>::new();
        for c in bytes.chunks(chunk) {
            for r in host.feed(c) { let _ = r; }
            for r in chip.feed(c) { let _ = r; }
            for r in small.feed(c) { let _ = r; }
        }
        let s = host.stats();
        prop_assert_eq!(s.bytes, bytes.len() as u64);
    }

    #[test]
    fn arbitrary_zero_free_bodies_never_panic(frames in proptest::collection::vec(proptest::collection::vec(1u8..=255, 0..300), 0..20)) {
        // Frames that are valid COBS-wise more often: random non-zero bytes
        // with delimiters, so decoding reaches the CRC and postcard stages.
        let mut dec = HostDecoder::new();
        for f in &frames {
            let mut bytes = f.clone();
            bytes.push(0);
            for r in dec.feed(&bytes) { let _ = r; }
        }
    }

    #[test]
    fn arbitrary_steps_round_trip(step in arb_step(), seq in any::<u32>()) {
        let msg = ToHost::Step(step);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let frame = encode_frame(&msg, seq, &mut buf).unwrap().to_vec();
        let mut dec = HostDecoder::new();
        let got: Vec<_> = dec.feed(&frame).collect();
        prop_assert_eq!(got.len(), 1);
        let d = got[0].as_ref().unwrap();
        prop_assert_eq!(d.seq, seq);
        prop_assert_eq!(&d.msg, &msg);
    }

    #[test]
    fn arbitrary_weight_chunks_round_trip(offset in any::<u32>(), total in any::<u32>(),
            w in proptest::collection::vec(any::<i32>(), 0..=WEIGHTS_PER_CHUNK)) {
        let msg = ToHost::Weights(WeightsChunk { offset, total, weights: HVec::from_slice(&w).unwrap() });
        let mut buf = [0u8; MAX_FRAME_LEN];
        let frame = encode_frame(&msg, 1, &mut buf).unwrap().to_vec();
        let mut dec = HostDecoder::new();
        let d = dec.feed(&frame).next().unwrap().unwrap();
        prop_assert_eq!(d.msg, msg);
    }

    #[test]
    fn single_corruptions_are_never_delivered(pos in any::<prop::sample::Index>(), bit in 0u8..8, step in arb_step()) {
        let msg = ToHost::Step(step);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let mut frame = encode_frame(&msg, 0, &mut buf).unwrap().to_vec();
        let i = pos.index(frame.len() - 1);
        frame[i] ^= 1 << bit;
        let mut dec = HostDecoder::new();
        for r in dec.feed(&frame) {
            prop_assert!(r.is_err(), "a corrupted frame was delivered");
        }
        // A flip that makes a 0x00 inside splits the frame: two errors.
        prop_assert!(dec.stats().bad_frames() >= 1);
    }
}
