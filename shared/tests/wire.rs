//! The wire protocol: every message round trips, the largest fit a frame,
//! and the decoder resynchronises and counts every loss on corrupted
//! streams without ever panicking.

use heapless::{String, Vec as HVec};
use pada_core::checkpoint::stream::Chunk;
use pada_core::checkpoint::{LoadOutcome, Saved};
use pada_core::dynamixel::ErrorFlags;
use pada_core::policy::{PolicyKind, PolicyName};
use pada_core::governor::{GovernorStatus, Restricts};
use pada_core::safety::{FaultCause, Rejection, State};
use pada_core::wire::*;

/// The postcard bytes of a value.
fn body<T: serde::Serialize>(v: &T) -> Vec<u8> {
    let mut buf = [0u8; 1024];
    postcard::to_slice(v, &mut buf).unwrap().to_vec()
}

fn text(s: &str) -> String<MAX_TEXT> {
    String::try_from(s).unwrap()
}

fn full_step() -> Step {
    Step {
        step: u32::MAX,
        time_ms: u32::MAX,
        episode: u32::MAX,
        mode: RunMode::Testing,
        kind: StepKind::Timeout,
        state: HVec::from_slice(&[-1.5e30; MAX_STATE_DIMS]).unwrap(),
        action: u32::MAX,
        output: HVec::from_slice(&[f32::MAX; MAX_ACTION_DIMS]).unwrap(),
        reward: f32::MIN,
        td_error: i32::MIN,
        explored: true,
        footstep: true,
        joints: HVec::from_slice(&[JointFatigue { damage: 1e-300, reengagements: u32::MAX }; MAX_GEARBOXES]).unwrap(),
        loop_us: u32::MAX,
        agent_cycles: u32::MAX,
    }
}

fn full_health() -> Health {
    Health {
        uptime_ms: u32::MAX,
        servo_temps_c: HVec::from_slice(&[255; MAX_SERVOS]).unwrap(),
        min_voltage_dv: 255,
        bus_errors: u32::MAX,
        checksum_errors: u32::MAX,
        timeouts: u32::MAX,
        trace_drops: u32::MAX,
        weight_saturations: u32::MAX,
        overruns: u32::MAX,
        max_loop_us: u32::MAX,
        telemetry_drops: u32::MAX,
        checkpoint_erases: u32::MAX,
        saves_refused: u32::MAX,
        table_claimed: u32::MAX,
        table_slots: u32::MAX,
        claims_refused: u32::MAX,
    }
}

/// One of every chip → host message (and variant of the nested enums).
fn all_to_host() -> Vec<ToHost> {
    let small_step = Step {
        step: 3,
        time_ms: 150,
        episode: 0,
        mode: RunMode::Learning,
        kind: StepKind::Step,
        state: HVec::from_slice(&[0.1, -0.2]).unwrap(),
        action: 2,
        output: HVec::from_slice(&[0.5]).unwrap(),
        reward: -1.0,
        td_error: -65536,
        explored: false,
        footstep: false,
        joints: HVec::from_slice(&[JointFatigue { damage: 3.2e-9, reengagements: 4 }]).unwrap(),
        loop_us: 812,
        agent_cycles: 41_000,
    };
    let mut v = vec![
        ToHost::Hello(Hello {
            protocol: PROTOCOL_VERSION,
            robot: heapless::String::try_from("a-robot-name-of-32-bytes-exactly").unwrap(),
            robot_hash: u32::MAX,
            config_hash: 0xDEAD_BEEF,
            weight_count: 1 << 16,
            period_us: 33_333,
            state_dims: 10,
            joints: 3,
        }),
        ToHost::Step(small_step),
        ToHost::Step(full_step()),
        ToHost::Episode(Episode {
            index: 7,
            mode: RunMode::Testing,
            total_reward: -812.5,
            length: 300,
            weights_checksum: 0x1234_5678,
        }),
        ToHost::Health(full_health()),
        ToHost::Health(Health { servo_temps_c: HVec::new(), ..full_health() }),
        ToHost::Log(Log { level: LogLevel::Info, text: text("booted") }),
        ToHost::Log(Log { level: LogLevel::Error, text: text(&"é".repeat(MAX_TEXT / 2)) }),
        ToHost::Log(Log { level: LogLevel::Warn, text: String::new() }),
        ToHost::Warning(Warning::CheckpointIgnored(LoadOutcome::ConfigMismatch { expected: 1, found: 2 })),
        ToHost::Warning(Warning::TelemetryDropped { frames: 12 }),
        ToHost::Warning(Warning::Text(text(&"x".repeat(MAX_TEXT)))),
        ToHost::Weights(WeightsChunk {
            offset: 96,
            total: 1 << 20,
            weights: (0..WEIGHTS_PER_CHUNK as i32).map(|i| i32::MIN + i).collect(),
        }),
        ToHost::Ack(Ack { seq: 41 }),
        ToHost::Checkpoint(CheckpointReport::Saved(Saved { generation: 3, slot: 0, erases: u32::MAX })),
        ToHost::Checkpoint(CheckpointReport::SaveFailed),
        ToHost::Policy(PolicyReport { step: 7, built: PolicyKind::Pada { delta: 0.5 }, switched_to_sarsa: true, governor: None }),
        ToHost::Policy(PolicyReport {
            step: u32::MAX,
            built: PolicyKind::LowPass { alpha: 0.834 },
            switched_to_sarsa: false,
            governor: None,
        }),
        ToHost::Policy(PolicyReport {
            step: 1234,
            built: PolicyKind::Pada { delta: 1.0 / 3.0 },
            switched_to_sarsa: false,
            governor: Some(GovernorStatus {
                budget_s: 2600.0,
                restricts: Restricts::Delta,
                parameter: 1.0 / 3.0,
                rung: 1,
                rungs: 6,
                window_steps: 1134,
                damage_rate: 3.1e-4,
                window_mtbf_s: 3225.8,
                moves: 17,
                over_budget_steps: 0,
            }),
        }),
        ToHost::Policy(PolicyReport {
            step: 9,
            built: PolicyKind::LowPass { alpha: 0.1 },
            switched_to_sarsa: false,
            governor: Some(GovernorStatus {
                budget_s: 1.0e10,
                restricts: Restricts::Alpha,
                parameter: 0.1,
                rung: 0,
                rungs: 7,
                window_steps: 0,
                damage_rate: 0.0,
                window_mtbf_s: f32::INFINITY,
                moves: 0,
                over_budget_steps: u32::MAX,
            }),
        }),
        ToHost::Checkpoint(CheckpointReport::TooLarge { needed: 8_389_136, capacity: 131_072 }),
        ToHost::Checkpoint(CheckpointReport::Streamed { generation: 3, chunks: 65_541, image_len: 8_389_664 }),
        ToHost::CheckpointChunk(full_chunk()),
        ToHost::CheckpointChunk(Chunk::zeros(u32::MAX, u32::MAX - 3, u32::MAX - 127, u32::MAX)),
        ToHost::RestoreWanted(RestoreRequest { config_hash: u32::MAX, image_len: u32::MAX, offset: u32::MAX }),
        ToHost::Restored(RestoreOutcome::Loaded { generation: u32::MAX, chunks: u32::MAX }),
        ToHost::Restored(RestoreOutcome::NoAnswer { waited_ms: 2000 }),
        ToHost::Restored(RestoreOutcome::ChunkRefused { offset: 1056 }),
        ToHost::Restored(RestoreOutcome::InvalidState),
    ];
    for d in all_denials() {
        v.push(ToHost::Restored(RestoreOutcome::Denied(d)));
    }
    for o in [
        LoadOutcome::Loaded { generation: 9, slot: 1 },
        LoadOutcome::NoCheckpoint,
        LoadOutcome::ConfigMismatch { expected: 5, found: 6 },
        LoadOutcome::SizeMismatch { expected: 5, found: 6 },
        LoadOutcome::UnsupportedVersion { found: 1 },
        LoadOutcome::Corrupt,
        LoadOutcome::InvalidState,
    ] {
        v.push(ToHost::Checkpoint(CheckpointReport::Load(o)));
    }
    for reason in [
        NackReason::State(Rejection::InFault),
        NackReason::State(Rejection::NotRunning),
        NackReason::InvalidParameter,
        NackReason::OutOfRange,
        NackReason::Busy,
        NackReason::CheckpointFailed,
        NackReason::Unsupported,
    ] {
        v.push(ToHost::Nack(Nack { seq: 99, reason }));
    }
    let causes = [
        FaultCause::ServoTimeout { servo: 3, attempts: 3 },
        FaultCause::ChecksumErrors { count: 5, window_ms: 1000 },
        FaultCause::ServoError { servo: 2, error: ErrorFlags::OVERHEATING | ErrorFlags::OVERLOAD },
        FaultCause::SoftLimit { joint: 1, position: -2.5 },
        FaultCause::OverrunStreak { count: 3 },
        FaultCause::WatchdogReset,
        FaultCause::HardwareAlert { servo: 4, error: pada_core::dynamixel::control_table::x_series::HardwareError::OVERLOAD },
    ];
    for cause in causes {
        v.push(ToHost::Fault(Fault { step: 1000, time_ms: 33_000, cause }));
    }
    let states = [State::Idle, State::Learning, State::Testing, State::Paused, State::Fault(causes[3])];
    for w in states.windows(2) {
        v.push(ToHost::State(StateChange { step: 5, from: w[0], to: w[1] }));
    }
    v
}

/// One of every host → chip command.
fn all_to_chip() -> Vec<ToChip> {
    vec![
        ToChip::Ping,
        ToChip::Start(RunMode::Learning),
        ToChip::Start(RunMode::Testing),
        ToChip::Stop,
        ToChip::Pause,
        ToChip::SetPolicy(PolicyKind::Sarsa),
        ToChip::SetPolicy(PolicyKind::LowPass { alpha: 0.3 }),
        ToChip::SetPolicy(PolicyKind::MarkovLowPass { alpha: 0.3 }),
        ToChip::SetPolicy(PolicyKind::Integrator { delta: 0.1 }),
        ToChip::SetPolicy(PolicyKind::MarkovIntegrator { delta: 0.1 }),
        ToChip::SetPolicy(PolicyKind::Pada { delta: 0.25 }),
        ToChip::SetPolicy(PolicyKind::EpsilonPada { delta: 0.25 }),
        ToChip::SetPolicy(PolicyKind::OrnsteinUhlenbeck { theta: 0.15, sigma: 0.3 }),
        ToChip::SetPolicy(PolicyKind::PinkNoise { sigma: 0.5 }),
        ToChip::SetPolicy(PolicyKind::ActionPenalty { weight: 2.0 }),
        ToChip::SetMtbfBudget(Some(2600.0)),
        ToChip::SetMtbfBudget(None),
        ToChip::SwitchToSarsa,
        ToChip::SetEpsilon(0.05),
        ToChip::SaveCheckpoint,
        ToChip::LoadCheckpoint,
        ToChip::ReadWeights { offset: u32::MAX, count: u32::MAX },
        ToChip::ClearFault,
        ToChip::RestoreChunk(full_chunk()),
        ToChip::RestoreChunk(Chunk::zeros(1, 8_389_664, 1056, 65_000)),
    ]
    .into_iter()
    .chain(all_denials().into_iter().map(ToChip::RestoreNone))
    .collect()
}

/// Every reason the host gives for sending no checkpoint.
fn all_denials() -> [RestoreDenied; 8] {
    [
        RestoreDenied::NoCheckpoint,
        RestoreDenied::Unreadable,
        RestoreDenied::Truncated,
        RestoreDenied::Corrupted,
        RestoreDenied::OtherConfiguration,
        RestoreDenied::WrongSize,
        RestoreDenied::Older,
        RestoreDenied::NotAChunk,
    ]
}

/// The largest checkpoint chunk: a whole window of nonzero words, every
/// field at its largest encoding.
fn full_chunk() -> Chunk {
    Chunk::words(u32::MAX, u32::MAX - 3, u32::MAX - 127 - 3, &[0xA5; 128])
}


fn round_trip<M: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug, const N: usize>(
    msgs: &[M],
) {
    let mut enc = FrameEncoder::new();
    let mut stream = Vec::new();
    for m in msgs {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let frame = enc.encode(m, &mut buf).unwrap_or_else(|e| panic!("{e:?} for {m:?}"));
        assert!(frame.len() <= N, "{} bytes for {m:?}", frame.len());
        assert_eq!(frame.last(), Some(&0));
        assert!(!frame[..frame.len() - 1].contains(&0));
        stream.extend_from_slice(frame);
    }
    for chunk in [1, 3, 64, stream.len().max(1)] {
        let mut dec = FrameDecoder::<M, N>::new();
        let got: Vec<_> = stream.chunks(chunk).flat_map(|c| dec.feed(c).collect::<Vec<_>>()).collect();
        assert_eq!(got.len(), msgs.len());
        for (i, (g, m)) in got.into_iter().zip(msgs).enumerate() {
            let d = g.unwrap();
            assert_eq!((d.seq, &d.msg, d.gap), (i as u32, m, None));
        }
        assert!(dec.stats().is_clean());
        assert_eq!(dec.stats().frames, msgs.len() as u32);
        assert_eq!(dec.stats().bytes, stream.len() as u64);
    }
}

/// CRC-32 of the postcard bytes of one of every message, both directions.
fn layout_fingerprint() -> u32 {
    let mut bytes = Vec::new();
    for m in all_to_host() {
        bytes.extend(body(&m));
    }
    for m in all_to_chip() {
        bytes.extend(body(&m));
    }
    pada_core::crc::crc32(&bytes)
}

#[test]
fn the_protocol_version_changes_with_the_layout() {
    // A change of any message's layout changes this fingerprint: then bump
    // PROTOCOL_VERSION and put the new pair here (with the docs that name
    // the version: docs/sil.md, docs/core.md, firmware/README.md).
    assert_eq!((PROTOCOL_VERSION, layout_fingerprint()), (10, EXPECTED_FINGERPRINT), "{:#010x}", layout_fingerprint());
}

/// [`layout_fingerprint`] of protocol 10 (`FaultCause::HardwareAlert`, a
/// Protocol 2.0 servo's Alert with its Hardware Error Status); 9 (`Hello`
/// names the robot and its definition's hash, and a restore's batch grew
/// from 3 to 24 chunks, which only the board's receive buffer sees; 8 was
/// 0xaca4_4e73) and 8 (the checkpoint the host keeps:
/// `CheckpointChunk`, `RestoreWanted`, `Restored`, `Streamed`,
/// `RestoreChunk`, `RestoreNone`; 7 the claim table's occupancy in
/// `Health`; 6 added the gentle explorations in `PolicyKind`, the governor
/// in `PolicyReport`, `SetMtbfBudget`; 5 `Step::footstep`).
const EXPECTED_FINGERPRINT: u32 = 0x5283_00f9;

#[test]
fn every_chip_message_round_trips() {
    round_trip::<ToHost, MAX_FRAME_LEN>(&all_to_host());
}

#[test]
fn every_host_command_round_trips() {
    // The chip's decoder holds a whole frame: a restore's chunk needs it.
    round_trip::<ToChip, MAX_FRAME_LEN>(&all_to_chip());
}

#[test]
fn the_largest_messages_fit_the_documented_limits() {
    for m in all_to_host() {
        let b = body(&(u32::MAX, &m));
        assert!(b.len() <= MAX_BODY, "{} body bytes: {m:?}", b.len());
    }
    for m in all_to_chip() {
        let b = body(&(u32::MAX, &m));
        assert!(b.len() <= MAX_BODY, "{} body bytes: {m:?}", b.len());
    }
    // A batch of the largest restore chunks fits the board's command
    // buffer (firmware/src/board/hw.rs and lockstep/link.rs), and a batch
    // is large enough that a restore of LEO's table (65 543 chunks) takes
    // at most 2 731 requests, each a round trip (21 848 with protocol 8's
    // batches of 3 in a 512-byte buffer).
    let mut frame = [0u8; MAX_FRAME_LEN];
    let largest = encode_frame(&ToChip::RestoreChunk(full_chunk()), u32::MAX, &mut frame).unwrap().len();
    assert!(largest * RESTORE_BATCH <= CHIP_RX_BUFFER, "{RESTORE_BATCH} x {largest} B in {CHIP_RX_BUFFER} B");
    assert!(65_543usize.div_ceil(RESTORE_BATCH) <= 2_731, "{RESTORE_BATCH} chunks a request");
    let step = body(&(u32::MAX, ToHost::Step(full_step())));
    let weights = body(&(
        u32::MAX,
        ToHost::Weights(WeightsChunk {
            offset: u32::MAX,
            total: u32::MAX,
            weights: HVec::from_slice(&[i32::MIN; WEIGHTS_PER_CHUNK]).unwrap(),
        }),
    ));
    eprintln!("largest bodies: step {} B, weights {} B, frame limit {MAX_FRAME_LEN} B", step.len(), weights.len());
    assert!(step.len() <= MAX_BODY && weights.len() <= MAX_BODY);
}

#[test]
fn a_small_buffer_is_an_error_not_a_panic() {
    let m = ToHost::Step(full_step());
    for len in 0..MAX_FRAME_LEN / 2 {
        let mut buf = vec![0u8; len];
        assert_eq!(encode_frame(&m, 0, &mut buf), Err(WireError::BufferTooSmall), "len {len}");
    }
}

#[test]
fn frame_bytes_are_cobs_of_body_and_crc() {
    // The layout of the module documentation, checked byte by byte on Ack.
    let mut buf = [0u8; 32];
    let frame = encode_frame(&ToHost::Ack(Ack { seq: 5 }), 300, &mut buf).unwrap().to_vec();
    // body: seq 300 = varint AC 02, variant Ack = index 10, seq 5.
    let body = [0xAC, 0x02, 10, 5];
    let crc = pada_core::checkpoint::crc32(&body).to_le_bytes();
    let mut raw = body.to_vec();
    raw.extend_from_slice(&crc);
    assert!(!raw.contains(&0), "this example has no zero byte, so COBS adds one code byte");
    let mut expected = vec![raw.len() as u8 + 1];
    expected.extend_from_slice(&raw);
    expected.push(0);
    assert_eq!(frame, expected);
}

#[test]
fn sequence_gaps_are_counted() {
    let mut enc = FrameEncoder::new();
    let mut dec = HostDecoder::new();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut send = |enc: &mut FrameEncoder, dec: &mut HostDecoder| {
        let f = enc.encode(&ToHost::Ack(Ack { seq: 0 }), &mut buf).unwrap().to_vec();
        dec.feed(&f).next().unwrap().unwrap()
    };
    assert_eq!(send(&mut enc, &mut dec).gap, None);
    enc.skip();
    enc.skip();
    enc.skip();
    let d = send(&mut enc, &mut dec);
    assert_eq!(d.gap, Some(SeqGap { expected: 1, got: 4 }));
    assert_eq!(d.gap.unwrap().missed(), 3);
    assert_eq!(send(&mut enc, &mut dec).gap, None);
    // The sender restarts: a backwards jump is a gap with nothing missed.
    let mut enc2 = FrameEncoder::new();
    let d = send(&mut enc2, &mut dec);
    assert_eq!(d.gap, Some(SeqGap { expected: 6, got: 0 }));
    let s = dec.stats();
    assert_eq!((s.seq_gaps, s.frames_missed, s.frames), (2, 3, 4));
    // Wrapping is not a gap.
    let mut dec = HostDecoder::new();
    for seq in [u32::MAX - 1, u32::MAX, 0, 1] {
        let f = encode_frame(&ToHost::Ack(Ack { seq }), seq, &mut buf).unwrap().to_vec();
        assert_eq!(dec.feed(&f).next().unwrap().unwrap().gap, None);
    }
}

#[test]
fn garbage_between_frames_costs_nothing_but_itself() {
    let msgs = all_to_host();
    let mut enc = FrameEncoder::new();
    let mut stream = vec![0x13, 0x37, 0xFF]; // joined mid-frame
    for (i, m) in msgs.iter().enumerate() {
        let mut buf = [0u8; MAX_FRAME_LEN];
        stream.extend_from_slice(enc.encode(m, &mut buf).unwrap());
        if i % 3 == 0 {
            stream.extend_from_slice(&[0x00, 0x00]); // flushes: ignored
        }
        if i % 5 == 0 {
            stream.extend_from_slice(&[0x42, 0x42, 0x42, 0x00]); // garbage frame
        }
    }
    let mut dec = HostDecoder::new();
    let got: Vec<_> = dec.feed(&stream).collect();
    let ok: Vec<ToHost> = got.iter().filter_map(|r| r.as_ref().ok().map(|d| d.msg.clone())).collect();
    // The leading garbage has no delimiter, so it and the first frame form
    // one bad frame; everything after arrives.
    assert_eq!(ok, msgs[1..]);
    let s = dec.stats();
    let garbage_frames = 1 + msgs.len().div_ceil(5) as u32;
    assert_eq!(s.bad_frames(), garbage_frames);
    assert_eq!(s.seq_gaps, 0, "the first frame seen sets the expected number");
}

#[test]
fn oversize_frames_are_dropped_and_counted() {
    let mut dec = FrameDecoder::<ToChip, 16>::new();
    let mut stream = vec![0x55; 40];
    stream.push(0);
    let mut buf = [0u8; 64];
    stream.extend_from_slice(encode_frame(&ToChip::Stop, 0, &mut buf).unwrap());
    let got: Vec<_> = dec.feed(&stream).collect();
    assert_eq!(got.len(), 2);
    assert_eq!(got[0], Err(FrameError::Oversize));
    assert_eq!(got[1].as_ref().unwrap().msg, ToChip::Stop);
    assert_eq!(dec.stats().oversize, 1);
}

#[test]
fn each_loss_kind_is_typed_and_counted() {
    let mut buf = [0u8; 64];
    let good = encode_frame(&ToChip::Pause, 0, &mut buf).unwrap().to_vec();
    let mut dec = ChipDecoder::new();
    // COBS error: a code byte that runs past the end.
    assert_eq!(dec.feed(&[9, 1, 2, 0]).collect::<Vec<_>>(), vec![Err(FrameError::Cobs)]);
    // Too short for body + CRC.
    assert_eq!(dec.feed(&[3, 1, 2, 0]).collect::<Vec<_>>(), vec![Err(FrameError::TooShort)]);
    // CRC error: a valid body with a wrong CRC.
    let mut raw = body(&(0u32, ToChip::Stop));
    let crc = pada_core::checkpoint::crc32(&raw);
    raw.extend_from_slice(&(crc ^ 0x0100).to_le_bytes());
    let mut bad = cobs_reference(&raw);
    bad.push(0);
    assert_eq!(
        dec.feed(&bad).collect::<Vec<_>>(),
        vec![Err(FrameError::Crc { computed: crc, received: crc ^ 0x0100 })]
    );
    // Good CRC, but not a ToChip: a ToHost Hello body.
    let mut hb = [0u8; MAX_FRAME_LEN];
    let hello = ToHost::Hello(Hello {
        protocol: 1,
        robot: heapless::String::try_from("leo").unwrap(),
        robot_hash: 7,
        config_hash: 0xFFFF_FFFF,
        weight_count: 0xFFFF_FFFF,
        period_us: 1,
        state_dims: 1,
        joints: 1,
    });
    let f = encode_frame(&hello, 0, &mut hb).unwrap().to_vec();
    assert_eq!(dec.feed(&f).collect::<Vec<_>>(), vec![Err(FrameError::Decode)]);
    // Trailing bytes after a valid body are a decode error too.
    let mut raw = body(&(0u32, ToChip::Stop));
    raw.push(7);
    let crc = pada_core::checkpoint::crc32(&raw);
    raw.extend_from_slice(&crc.to_le_bytes());
    let mut framed = cobs_reference(&raw);
    framed.push(0);
    assert_eq!(dec.feed(&framed).collect::<Vec<_>>(), vec![Err(FrameError::Decode)]);
    let s = dec.stats();
    assert_eq!((s.cobs_errors, s.too_short, s.crc_errors, s.decode_errors), (1, 1, 1, 2));
    assert_eq!(s.bad_frames(), 5);
    assert!(!s.is_clean());
    // And the decoder still works.
    assert_eq!(dec.feed(&good).next().unwrap().unwrap().msg, ToChip::Pause);
}

/// Plain COBS for building hand-made frames in tests.
fn cobs_reference(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8];
    let mut code_at = 0;
    for &b in data {
        if b == 0 {
            out[code_at] = (out.len() - code_at) as u8;
            code_at = out.len();
            out.push(0);
        } else {
            out.push(b);
            if out.len() - code_at == 255 {
                out[code_at] = 255;
                code_at = out.len();
                out.push(0);
            }
        }
    }
    out[code_at] = (out.len() - code_at) as u8;
    out
}

#[test]
fn floats_round_trip_bit_for_bit() {
    let mut step = full_step();
    step.reward = f32::from_bits(0x7FC0_1234); // a NaN with payload
    step.state = HVec::from_slice(&[-0.0, f32::INFINITY, f32::MIN_POSITIVE / 2.0]).unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let f = encode_frame(&ToHost::Step(step.clone()), 0, &mut buf).unwrap().to_vec();
    let mut dec = HostDecoder::new();
    let ToHost::Step(got) = dec.feed(&f).next().unwrap().unwrap().msg else { panic!() };
    assert_eq!(got.reward.to_bits(), 0x7FC0_1234);
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&got.state), bits(&step.state));
}

#[test]
fn set_policy_carries_the_policy_kind_as_its_code_and_parameter() {
    // The wire's PolicySpec is PolicyKind itself; its bytes are the
    // policy's code (the checkpoint's too) and then α or Δ.
    for name in PolicyName::ALL {
        let kind = name.with_parameters([0.25, 0.75]);
        let bytes = body(&ToChip::SetPolicy(kind));
        let mut expected = vec![4, name.code()];
        for (i, _) in name.parameter_names().iter().enumerate() {
            expected.extend_from_slice(&[0.25f32, 0.75][i].to_le_bytes());
        }
        assert_eq!(bytes, expected, "{name}");
        assert_eq!(pada_core::policy::kind_code(&kind), name.code());
    }
}

/// The bytes of one frame (delimiter included) for `msg` with `seq`.
fn frame_of<M: serde::Serialize>(msg: &M, seq: u32) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    encode_frame(msg, seq, &mut buf).unwrap().to_vec()
}

/// COBS of `raw` (no zero bytes in it, at most 253) and a delimiter.
fn cobs_small(raw: &[u8]) -> Vec<u8> {
    assert!(!raw.contains(&0) && raw.len() < 254);
    let mut f = vec![raw.len() as u8 + 1];
    f.extend_from_slice(raw);
    f.push(0);
    f
}

#[test]
fn the_end_of_the_input_counts_a_cut_off_frame() {
    // Regression: a frame cut off by the end of the
    // stream, or bytes without a delimiter, were never counted as lost.
    let whole = frame_of(&ToHost::Ack(Ack { seq: 5 }), 0);
    let mut dec = HostDecoder::new();
    assert_eq!(dec.feed(&whole).count(), 1);
    assert_eq!(dec.finish(), None, "ended on a delimiter: nothing lost");
    dec.feed(&whole[..whole.len() - 3]).for_each(drop);
    assert_eq!(dec.pending(), whole.len() - 3);
    assert_eq!(dec.finish(), Some(FrameError::Truncated));
    assert_eq!((dec.stats().truncated, dec.stats().bad_frames()), (1, 1));
    assert!(!dec.stats().is_clean());
    assert_eq!(dec.finish(), None, "counted once");
    // 10 kB without a zero byte: one oversize frame in progress, lost.
    let mut dec = HostDecoder::new();
    assert_eq!(dec.feed(&[0x55; 10_000]).count(), 0);
    assert!(dec.stats().is_clean(), "nothing is known to be lost until the end");
    assert_eq!(dec.finish(), Some(FrameError::Truncated));
    assert!(!dec.stats().is_clean());
    // The decoder goes on with the next stream.
    assert_eq!(dec.feed(&whole).filter(|r| r.is_ok()).count(), 1);
}

#[test]
fn a_non_canonical_body_is_refused() {
    // Regression: an overlong varint with a valid CRC
    // decoded as if canonical. Ack { seq: 5 } with seq 300 written
    // canonically (AC 02), then with the 5 padded to two bytes (85 00),
    // then with the sequence number padded to three (AC 82 00).
    let good = [0xAC, 0x02, 10, 5];
    for body in [vec![0xAC, 0x02, 10, 0x85, 0x00], vec![0xAC, 0x82, 0x00, 10, 5], vec![0xAC, 0x02, 0x8A, 0x00, 5]] {
        let mut raw = body.clone();
        raw.extend_from_slice(&pada_core::crc::crc32(&body).to_le_bytes());
        // The zero padding byte is data: COBS encodes it as a block end.
        let mut f = vec![0u8; 32];
        let n = cobs::encode(&raw, &mut f);
        f.truncate(n);
        f.push(0);
        let mut dec = HostDecoder::new();
        assert_eq!(dec.feed(&f).next(), Some(Err(FrameError::NonCanonical)), "{body:02x?}");
        assert_eq!((dec.stats().noncanonical, dec.stats().frames), (1, 0));
    }
    let mut raw = good.to_vec();
    raw.extend_from_slice(&pada_core::crc::crc32(&good).to_le_bytes());
    let mut dec = HostDecoder::new();
    assert!(matches!(dec.feed(&cobs_small(&raw)).next(), Some(Ok(_))));
    // A non-canonical COBS encoding of canonical bytes: 254 non-zero bytes
    // fill a block (code FF) and end the frame; an empty block (01) after
    // it decodes to the same bytes, but is not what the encoder writes.
    type Blob = HVec<u8, 300>;
    let mut blob: Blob = HVec::from_slice(&[0x33; 247]).unwrap();
    let mut canonical = Vec::new();
    for fill in 1u8..=255 {
        blob[0] = fill;
        let f = frame_of(&blob, 1);
        if f.len() == 254 + 2 && f[0] == 0xFF {
            canonical = f;
            break;
        }
    }
    assert!(!canonical.is_empty(), "some fill gives a CRC without zero bytes");
    let mut padded = canonical.clone();
    padded.insert(255, 0x01);
    let mut dec = FrameDecoder::<Blob, 600>::new();
    assert_eq!(dec.feed(&padded).next(), Some(Err(FrameError::NonCanonical)));
    assert!(dec.feed(&canonical).next().unwrap().is_ok());
}

#[test]
fn a_large_sequence_jump_is_a_resync_not_billions_missed() {
    // Regression: a forward jump counted up to 2^31 - 1
    // missing frames.
    let mut dec = HostDecoder::new();
    let ack = ToHost::Ack(Ack { seq: 0 });
    for seq in [0u32, 1, 5, 7 + MAX_SEQ_GAP, 8 + MAX_SEQ_GAP, 3] {
        dec.feed(&frame_of(&ack, seq)).for_each(drop);
    }
    let s = dec.stats();
    assert_eq!(s.frames, 6);
    assert_eq!(s.seq_gaps, 3, "5 after 1, the jump, and the way back to 3");
    assert_eq!(s.seq_resyncs, 2);
    assert_eq!(s.frames_missed, 3, "only the three between 1 and 5");
    // The largest jump still counted as missed frames.
    let mut dec = HostDecoder::new();
    dec.feed(&frame_of(&ack, 10)).for_each(drop);
    dec.feed(&frame_of(&ack, 11 + MAX_SEQ_GAP)).for_each(drop);
    assert_eq!((dec.stats().frames_missed, dec.stats().seq_resyncs), (MAX_SEQ_GAP as u64, 0));
}

fn xorshift(s: &mut u64) -> u64 {
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    *s
}

#[test]
fn corrupted_streams_lose_only_corrupted_frames_and_count_them() {
    // 3000 frames; every 4th gets one byte flipped, dropped or inserted, or
    // its delimiter lost. No wrong message is ever delivered, every intact
    // frame whose predecessor's delimiter survived is delivered, and the
    // sequence numbers account for every frame lost.
    let msgs = all_to_host();
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut enc = FrameEncoder::new();
    let mut stream = Vec::new();
    let mut sent = Vec::new();
    let mut must_arrive = Vec::new();
    let mut prev_delimiter_lost = false;
    for i in 0..3000u32 {
        let m = msgs[(xorshift(&mut seed) % msgs.len() as u64) as usize].clone();
        let mut buf = [0u8; MAX_FRAME_LEN];
        let mut f = enc.encode(&m, &mut buf).unwrap().to_vec();
        let corrupt = i % 4 == 3;
        let mut delimiter_lost = false;
        if corrupt {
            let pos = (xorshift(&mut seed) % (f.len() as u64 - 1)) as usize;
            match xorshift(&mut seed) % 4 {
                0 => f[pos] ^= 1 << (xorshift(&mut seed) % 8),
                1 => {
                    f.remove(pos);
                }
                2 => f.insert(pos, xorshift(&mut seed) as u8),
                _ => {
                    f.pop();
                    delimiter_lost = true;
                }
            }
        } else if !prev_delimiter_lost {
            must_arrive.push((i, m.clone()));
        }
        prev_delimiter_lost = delimiter_lost;
        sent.push(m);
        stream.extend(f);
    }
    let mut dec = HostDecoder::new();
    let mut got = Vec::new();
    for chunk in stream.chunks(13) {
        for d in dec.feed(chunk).flatten() {
            assert_eq!(d.msg, sent[d.seq as usize], "frame {} delivered wrong content", d.seq);
            got.push((d.seq, d.msg));
        }
    }
    for (seq, m) in &must_arrive {
        assert!(got.contains(&(*seq, m.clone())), "intact frame {seq} lost");
    }
    let s = dec.stats();
    let lost = 3000 - s.frames;
    assert!(lost >= 1);
    // Every lost frame that lies between two delivered frames is seen as a
    // gap (frames lost after the last delivered one cannot be).
    let last = got.last().unwrap().0;
    let first = got.first().unwrap().0;
    assert_eq!(s.frames_missed, (last - first + 1 - s.frames) as u64);
    assert!(s.bad_frames() >= 1);
}


/// A recording of an older pada: its `Hello` (protocol 8, before the robot
/// was named) does not decode, and the decoder says which protocol it was,
/// so a reader refuses the file in one line instead of counting damage.
#[test]
fn a_hello_of_another_protocol_is_told_apart_from_damage() {
    #[derive(serde::Serialize)]
    struct HelloV8 {
        protocol: u16,
        config_hash: u32,
        weight_count: u32,
        period_us: u32,
        state_dims: u8,
        joints: u8,
    }
    #[derive(serde::Serialize)]
    enum ToHostV8 {
        Hello(HelloV8),
    }
    let old = ToHostV8::Hello(HelloV8 { protocol: 8, config_hash: 1, weight_count: 2, period_us: 3, state_dims: 2, joints: 1 });
    let mut buf = [0u8; MAX_FRAME_LEN];
    let frame = encode_frame(&old, 0, &mut buf).unwrap().to_vec();
    let mut dec = HostDecoder::new();
    assert_eq!(dec.foreign_protocol(), None);
    assert_eq!(dec.feed(&frame).collect::<Vec<_>>(), vec![Err(FrameError::Decode)]);
    assert_eq!(dec.foreign_protocol(), Some(8));
    // Damage is damage: a body that is no Hello at all sets nothing.
    let mut dec = HostDecoder::new();
    let junk = encode_frame(&(5u32, 200u32, 7u8), 0, &mut buf).unwrap().to_vec();
    assert_eq!(dec.feed(&junk).count(), 1);
    assert_eq!(dec.foreign_protocol(), None);
    // And this version's own Hello decodes.
    let hello = ToHost::Hello(Hello {
        protocol: PROTOCOL_VERSION,
        robot: heapless::String::try_from("leo").unwrap(),
        robot_hash: 7,
        config_hash: 1,
        weight_count: 2,
        period_us: 3,
        state_dims: 2,
        joints: 1,
    });
    let frame = encode_frame(&hello, 0, &mut buf).unwrap().to_vec();
    let mut dec = HostDecoder::new();
    assert!(dec.feed(&frame).all(|r| r.is_ok()));
    assert_eq!(pada_core::wire::hello_protocol(&[0, 0, PROTOCOL_VERSION as u8]), Some(PROTOCOL_VERSION));
}
