//! Dynamixel Protocol 1.0 codec: round trips in both directions (firmware ↔
//! bus emulator), resynchronisation after corruption, and no panic on any
//! input.

use pada_core::dynamixel::table::*;
use pada_core::dynamixel::*;
use proptest::prelude::*;

type Status = StatusPacket<64>;

fn encode_status(st: &Status) -> Vec<u8> {
    let mut buf = [0u8; 300];
    st.encode(&mut buf).unwrap().to_vec()
}

fn decode_all_status(dec: &mut StatusDecoder<64>, bytes: &[u8]) -> Vec<Result<Status, DecodeError>> {
    dec.feed(bytes).collect()
}

#[test]
fn every_instruction_round_trips_through_the_emulator_decoder() {
    let sync_entries = [1u8, 0x10, 0x02, 2, 0x20, 0x06];
    let cases: [(u8, Instruction<'_>); 7] = [
        (1, Instruction::Ping),
        (2, Instruction::Read { addr: PRESENT_BLOCK, len: PRESENT_BLOCK_LEN }),
        (3, Instruction::Write { addr: TORQUE_ENABLE, data: &[1] }),
        (4, Instruction::RegWrite { addr: MOVING_SPEED, data: &[0xFF, 0x07] }),
        (BROADCAST_ID, Instruction::Action),
        (5, Instruction::Reset),
        (BROADCAST_ID, Instruction::SyncWrite { addr: MOVING_SPEED, data_len: 2, entries: &sync_entries }),
    ];
    let mut stream = Vec::new();
    for (id, ins) in &cases {
        let mut buf = [0u8; 64];
        let bytes = ins.encode(*id, &mut buf).unwrap();
        let v: heapless::Vec<u8, 64> = ins.encode_vec(*id).unwrap();
        assert_eq!(&v[..], bytes);
        stream.extend_from_slice(bytes);
    }
    // Fed as one stream, in chunks of every size.
    for chunk in 1..=stream.len() {
        let mut dec = InstructionDecoder::<64>::new();
        let mut got = Vec::new();
        for c in stream.chunks(chunk) {
            got.extend(dec.feed(c));
        }
        assert_eq!(got.len(), cases.len(), "chunk {chunk}");
        for (p, (id, ins)) in got.iter().zip(&cases) {
            let p = p.as_ref().unwrap();
            assert_eq!(p.id, *id);
            assert_eq!(p.instruction().unwrap(), *ins);
        }
        assert_eq!(dec.stats().packets, cases.len() as u32);
        assert_eq!(dec.stats().skipped_bytes, 0);
    }
    let Instruction::SyncWrite { .. } = cases[6].1 else { unreachable!() };
    let entries: Vec<(u8, &[u8])> = cases[6].1.sync_entries().collect();
    assert_eq!(entries, vec![(1, &[0x10, 0x02][..]), (2, &[0x20, 0x06][..])]);
}

#[test]
fn convenience_encoders_decode_to_their_instruction() {
    let mut buf = [0u8; 64];
    let mut dec = InstructionDecoder::<64>::new();
    let p = sync_write_u16(MOVING_SPEED, &[(1, moving_speed_from_ratio(-0.25)), (7, 1023)], &mut buf).unwrap();
    let got: Vec<_> = dec.feed(p).collect();
    let pkt = got[0].as_ref().unwrap();
    let ins = pkt.instruction().unwrap();
    let e: Vec<(u8, u16)> = ins.sync_entries().map(|(id, d)| (id, u16::from_le_bytes([d[0], d[1]]))).collect();
    assert_eq!(e, vec![(1, 1024 + 256), (7, 1023)]);
    assert!((ratio_from_moving_speed(e[0].1) + 0.25).abs() < 1e-3);
}

#[test]
fn unknown_instructions_and_bad_params_are_typed() {
    assert_eq!(Instruction::parse(0x42, &[]), Err(InstructionError::UnknownCode { code: 0x42 }));
    assert_eq!(Instruction::parse(0x02, &[1]), Err(InstructionError::BadParams { code: 2, len: 1 }));
    assert_eq!(Instruction::parse(0x01, &[1]), Err(InstructionError::BadParams { code: 1, len: 1 }));
    assert_eq!(Instruction::parse(0x83, &[32, 2, 1, 0]), Err(InstructionError::BadParams { code: 0x83, len: 4 }));
    assert_eq!(Instruction::parse(0x83, &[32, 0]), Err(InstructionError::BadParams { code: 0x83, len: 2 }));
    // BULK_READ: 0x00, then length, ID, address per servo (the Protocol
    // 1.0 page's example: two bytes at 30 of ID 1, two at 36 of ID 2).
    let bulk = Instruction::parse(0x92, &[0x00, 2, 1, 0x1E, 2, 2, 0x24]).unwrap();
    assert_eq!(bulk.bulk_read_entries().collect::<Vec<_>>(), vec![(1, 0x1E, 2), (2, 0x24, 2)]);
    let mut buf = [0u8; 32];
    assert_eq!(bulk.encode(BROADCAST_ID, &mut buf).unwrap(), &[0xFF, 0xFF, 0xFE, 0x09, 0x92, 0x00, 0x02, 0x01, 0x1E, 0x02, 0x02, 0x24, 0x1D]);
    assert_eq!(Instruction::parse(0x92, &[0x01, 2, 1, 30]), Err(InstructionError::BadParams { code: 0x92, len: 4 }));
    assert_eq!(Instruction::parse(0x92, &[0x00, 2, 1]), Err(InstructionError::BadParams { code: 0x92, len: 3 }));
    // An ID named twice: the first counts.
    let twice = Instruction::parse(0x92, &[0x00, 2, 1, 30, 4, 1, 36]).unwrap();
    assert_eq!(twice.bulk_read_entries().collect::<Vec<_>>(), vec![(1, 30, 2)]);
}

#[test]
fn status_packets_round_trip_with_every_error_bit() {
    let mut dec = StatusDecoder::<64>::new();
    for bits in 0..=255u8 {
        let st = Status::new((bits % 253) + 1, ErrorFlags(bits), &[bits, 0x55, 0xFF, 0xFF]).unwrap();
        let got = decode_all_status(&mut dec, &encode_status(&st));
        assert_eq!(got, vec![Ok(st)]);
    }
    // The largest status packet the decoder holds.
    let st = Status::new(1, ErrorFlags::NONE, &[0xAB; 58]).unwrap();
    assert_eq!(decode_all_status(&mut dec, &encode_status(&st)), vec![Ok(st)]);
}

#[test]
fn garbage_before_a_packet_is_skipped() {
    let st = Status::new(1, ErrorFlags::NONE, &[0x00, 0x02]).unwrap();
    let mut bytes = vec![0x00, 0x13, 0xFF, 0x42, 0xFF, 0xFF, 0xFF];
    // The extra 0xFF run in front of the packet's own header is skipped too.
    let garbage = bytes.len() as u32;
    bytes.extend(encode_status(&st));
    let mut dec = StatusDecoder::<64>::new();
    assert_eq!(decode_all_status(&mut dec, &bytes), vec![Ok(st)]);
    assert_eq!(dec.stats().skipped_bytes, garbage);
}

#[test]
fn bad_checksum_is_reported_and_the_next_packet_still_decodes() {
    let a = Status::new(1, ErrorFlags::NONE, &[1, 2, 3]).unwrap();
    let b = Status::new(2, ErrorFlags::OVERLOAD, &[4]).unwrap();
    let mut bad = encode_status(&a);
    let last = bad.len() - 1;
    bad[last] ^= 0x01;
    let mut stream = bad.clone();
    stream.extend(encode_status(&b));
    let mut dec = StatusDecoder::<64>::new();
    let got = decode_all_status(&mut dec, &stream);
    assert_eq!(got.len(), 2);
    assert!(matches!(got[0], Err(DecodeError::BadChecksum { id: 1, .. })));
    assert_eq!(got[1], Ok(b));
    assert_eq!(dec.stats().bad_checksums, 1);
}

#[test]
fn a_corrupted_length_that_swallows_the_next_packet_is_recovered() {
    // The first packet's LENGTH claims more bytes than it has, so it spans
    // the second packet; after the checksum fails, the decoder scans the
    // buffered bytes again and finds the second packet inside.
    let a = Status::new(1, ErrorFlags::NONE, &[1, 2]).unwrap();
    let b = Status::new(2, ErrorFlags::NONE, &[9, 8, 7]).unwrap();
    let mut stream = encode_status(&a);
    stream[3] = 12; // LENGTH: 10 params instead of 2
    stream.extend(encode_status(&b));
    stream.extend([0u8; 8]); // padding so the long packet completes
    let mut dec = StatusDecoder::<64>::new();
    let got = decode_all_status(&mut dec, &stream);
    assert!(matches!(got[0], Err(DecodeError::BadChecksum { id: 1, .. })), "{got:?}");
    assert_eq!(got[1], Ok(b));
}

#[test]
fn impossible_lengths_are_reported() {
    let mut dec = StatusDecoder::<16>::new();
    let got: Vec<_> = dec.feed(&[0xFF, 0xFF, 1, 1]).collect();
    assert_eq!(got, vec![Err(DecodeError::BadLength { id: 1, length: 1 })]);
    let got: Vec<_> = dec.feed(&[0xFF, 0xFF, 1, 13]).collect();
    assert_eq!(got, vec![Err(DecodeError::BadLength { id: 1, length: 13 })]);
    assert_eq!(dec.stats().bad_lengths, 2);
    // After them, a good packet.
    let st = StatusPacket::<16>::new(1, ErrorFlags::NONE, &[5]).unwrap();
    let mut buf = [0u8; 16];
    let got: Vec<_> = dec.feed(st.encode(&mut buf).unwrap()).collect();
    assert_eq!(got, vec![Ok(st)]);
}

#[test]
fn reset_drops_a_partial_packet() {
    let st = Status::new(1, ErrorFlags::NONE, &[5]).unwrap();
    let bytes = encode_status(&st);
    let mut dec = StatusDecoder::<64>::new();
    assert_eq!(decode_all_status(&mut dec, &bytes[..4]), vec![]);
    dec.reset();
    assert_eq!(dec.stats().skipped_bytes, 4);
    assert_eq!(decode_all_status(&mut dec, &bytes), vec![Ok(st)]);
}

/// A deterministic xorshift for the corruption test.
fn xorshift(s: &mut u32) -> u32 {
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    *s
}

#[test]
fn corrupted_streams_lose_only_the_corrupted_packets() {
    // 2000 packets; a third get one byte flipped, dropped or inserted. Every
    // intact packet that is not right behind a corrupted one must decode,
    // and no packet decodes that was not sent (the checksum catches the
    // single-byte corruptions).
    let mut seed = 0x1234_5678u32;
    let mut stream = Vec::new();
    let mut sent = Vec::new();
    let mut intact = Vec::new();
    let mut prev_corrupt = false;
    for i in 0..2000u32 {
        let id = (i % 20 + 1) as u8;
        let n = (xorshift(&mut seed) % 9) as usize;
        let params: Vec<u8> = (0..n).map(|_| xorshift(&mut seed) as u8).collect();
        let st = Status::new(id, ErrorFlags((xorshift(&mut seed) & 0x7F) as u8), &params).unwrap();
        let mut bytes = encode_status(&st);
        let corrupt = xorshift(&mut seed) % 3 == 0;
        if corrupt {
            let pos = (xorshift(&mut seed) as usize) % bytes.len();
            match xorshift(&mut seed) % 3 {
                0 => bytes[pos] ^= 1 << (xorshift(&mut seed) % 8),
                1 => {
                    bytes.remove(pos);
                }
                _ => bytes.insert(pos, xorshift(&mut seed) as u8),
            }
        } else if !prev_corrupt {
            intact.push(st.clone());
        }
        prev_corrupt = corrupt;
        sent.push(st);
        stream.extend(bytes);
    }
    let mut dec = StatusDecoder::<64>::new();
    let mut decoded = Vec::new();
    for chunk in stream.chunks(7) {
        decoded.extend(dec.feed(chunk).flatten());
    }
    for st in &decoded {
        assert!(sent.contains(st), "decoded a packet that was never sent: {st:?}");
    }
    let missing = intact.iter().filter(|st| !decoded.contains(st)).count();
    assert_eq!(missing, 0, "{missing} intact packets lost");
    assert!(decoded.len() >= intact.len());
    let s = dec.stats();
    assert!(s.bad_checksums + s.bad_lengths > 0);
}

#[test]
fn a_status_packet_from_the_broadcast_id_is_refused() {
    // Found by `cargo xtask fuzz`: the decoder accepted a status packet from
    // ID 0xFE, which no servo sends and the encoder refuses.
    let mut raw = vec![0xFF, 0xFF, BROADCAST_ID, 2, 0];
    raw.push(checksum(&raw[2..]));
    let good = encode_status(&Status::new(1, ErrorFlags::NONE, &[]).unwrap());
    raw.extend(&good);
    let mut dec = StatusDecoder::<64>::new();
    let got = decode_all_status(&mut dec, &raw);
    assert_eq!(got[0], Err(DecodeError::BroadcastStatus));
    assert!(matches!(got.last(), Some(Ok(p)) if p.id == 1));
    assert_eq!(dec.stats().unexpected_ids, 1);
    assert_eq!(dec.stats().skipped_bytes as usize, raw.len() - good.len());
    // Instructions to the broadcast ID are packets like any other.
    let mut ins = InstructionDecoder::<64>::new();
    let mut buf = [0u8; 16];
    let sent = action(BROADCAST_ID, &mut buf).unwrap();
    assert!(matches!(ins.feed(sent).next(), Some(Ok(p)) if p.id == BROADCAST_ID));
}

#[test]
fn writes_without_data_are_refused_by_encoder_and_parser_alike() {
    // Regression: WRITE and REG_WRITE with no data
    // encoded, and the emulator's parser then refused them as BadParams.
    let mut buf = [0u8; 16];
    for code in [0x03u8, 0x04] {
        let ins = if code == 3 { Instruction::Write { addr: 24, data: &[] } } else { Instruction::RegWrite { addr: 24, data: &[] } };
        assert_eq!(ins.encode(1, &mut buf), Err(EncodeError::NoData { code }));
        assert_eq!(Instruction::parse(code, &[24]), Err(InstructionError::BadParams { code, len: 1 }));
    }
    assert_eq!(write_data(1, 24, &[], &mut buf), Err(EncodeError::NoData { code: 3 }));
    // Every instruction that encodes parses back to itself (one byte of
    // data is the least a write carries).
    let one = [7u8];
    for ins in [Instruction::Write { addr: 3, data: &one }, Instruction::RegWrite { addr: 3, data: &one }] {
        let p = ins.encode(2, &mut buf).unwrap();
        assert_eq!(Instruction::parse(p[4], &p[5..p.len() - 1]), Ok(ins));
    }
}

#[test]
fn only_the_expected_reply_is_accepted_and_a_spurious_header_holds_nothing_back() {
    // Regression: garbage that formed a header with a
    // valid checksum was accepted, and a spurious header with a large
    // LENGTH held back the real reply behind it.
    let reply = Status::new(3, ErrorFlags::NONE, &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
    let real = encode_status(&reply);
    // A well-formed status packet from another servo, one of the right ID
    // with the wrong length (valid checksums both), and a spurious header
    // announcing 200 bytes: all before the real reply.
    let other_id = encode_status(&Status::new(4, ErrorFlags::NONE, &[9; 8]).unwrap());
    let other_len = encode_status(&Status::new(3, ErrorFlags::NONE, &[9; 2]).unwrap());
    let mut stream = other_id.clone();
    stream.extend(&other_len);
    stream.extend([0xFF, 0xFF, 3, 50]);
    stream.extend(&real);
    let mut dec = StatusDecoder::<64>::new();
    dec.expect(Some(Reply { id: 3, params: 8 }));
    let got = decode_all_status(&mut dec, &stream);
    assert_eq!(got.last(), Some(&Ok(reply.clone())), "{got:?}");
    assert_eq!(got.iter().filter(|r| r.is_ok()).count(), 1, "only the expected reply: {got:?}");
    assert!(got.contains(&Err(DecodeError::UnexpectedId { expected: 3, got: 4 })));
    assert!(got.contains(&Err(DecodeError::BadLength { id: 3, length: 4 })));
    assert!(got.contains(&Err(DecodeError::BadLength { id: 3, length: 50 })));
    // Everything before the reply was discarded and counted, byte for byte.
    let s = dec.stats();
    assert_eq!(s.skipped_bytes as usize, stream.len() - real.len());
    assert_eq!((s.packets, s.unexpected_ids, s.bad_lengths), (1, 1, 2));
    assert_eq!(dec.buffered(), 0);
    // Without the expectation the spurious header waits for its 54 bytes
    // and holds the reply back; with it, the reply is found at once.
    let mut early = vec![0xFF, 0xFF, 3, 50];
    early.extend(&real);
    let mut any = StatusDecoder::<64>::new();
    assert!(decode_all_status(&mut any, &early).is_empty());
    let mut dec = StatusDecoder::<64>::new();
    dec.expect(Some(Reply { id: 3, params: 8 }));
    assert_eq!(decode_all_status(&mut dec, &early).last(), Some(&Ok(reply)));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600), chunk in 1usize..40) {
        let mut s = StatusDecoder::<16>::new();
        s.expect(Some(Reply { id: 1, params: 8 }));
        let mut i = InstructionDecoder::<64>::new();
        for c in bytes.chunks(chunk) {
            for r in s.feed(c) { let _ = r; }
            for p in i.feed(c).flatten() {
                let _ = p.instruction();
            }
        }
        for &b in &bytes {
            let _ = s.push(b);
            while s.poll().is_some() {}
        }
    }

    #[test]
    fn arbitrary_status_packets_round_trip(id in 0u8..=0xFD, err in any::<u8>(),
            params in proptest::collection::vec(any::<u8>(), 0..58),
            junk in proptest::collection::vec(any::<u8>(), 0..20)) {
        let st = Status::new(id, ErrorFlags(err), &params).unwrap();
        let mut stream = junk.clone();
        stream.extend(encode_status(&st));
        // As the firmware listens: for the asked servo's reply of the length
        // its request implies. Junk before it that looks like a header (even
        // one announcing more bytes than follow, which a decoder expecting
        // anything would wait for) cannot hold it back.
        let mut dec = StatusDecoder::<64>::new();
        dec.expect(Some(Reply { id, params: params.len() as u8 }));
        let got: Vec<_> = dec.feed(&stream).filter_map(|r| r.ok()).collect();
        prop_assert_eq!(got.last(), Some(&st));
    }

    #[test]
    fn arbitrary_writes_round_trip(id in 0u8..=0xFD, addr in any::<u8>(),
            data in proptest::collection::vec(any::<u8>(), 1..50)) {
        let mut buf = [0u8; 64];
        let bytes = write_data(id, addr, &data, &mut buf).unwrap();
        let mut dec = InstructionDecoder::<64>::new();
        let got: Vec<_> = dec.feed(bytes).collect();
        prop_assert_eq!(got.len(), 1);
        let p = got[0].as_ref().unwrap();
        prop_assert_eq!(p.id, id);
        prop_assert_eq!(p.instruction().unwrap(), Instruction::Write { addr, data: &data });
    }

    #[test]
    fn signed_encoding_is_monotone_and_bounded(r in -2.0f32..2.0) {
        let v = moving_speed_from_ratio(r);
        prop_assert!(v <= 2047);
        let back = ratio_from_moving_speed(v);
        prop_assert!((back - r.clamp(-1.0, 1.0)).abs() <= 0.5 / 1023.0 + 1e-6);
    }
}
