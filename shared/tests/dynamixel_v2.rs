//! Dynamixel Protocol 2.0: the e-Manual's worked example packets byte for
//! byte (docs/reference/dynamixel.md §3), round trips of every instruction
//! and reply through the decoders, and property tests of the round trips
//! and of the decoder's byte accounting.

use pada_core::dynamixel::control_table::x_series::{GOAL_POSITION, GOAL_PWM, GOAL_VELOCITY, PRESENT_POSITION};
use pada_core::dynamixel::v2::encoders::*;
use pada_core::dynamixel::v2::fast::{fast_bulk_reply_params, fast_sync_reply_params, BlockLens, FastBlock};
use pada_core::dynamixel::v2::*;
use proptest::prelude::*;

type Status = StatusPacket<256>;

/// Bytes from the e-Manual's hex tables.
fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace().map(|b| u8::from_str_radix(b, 16).unwrap()).collect()
}

fn statuses(bytes: &[u8]) -> Vec<Result<Status, DecodeError>> {
    StatusDecoder::<256>::new().feed(bytes).collect()
}

fn instruction_packet(bytes: &[u8]) -> InstructionPacket<256> {
    let got: Vec<_> = InstructionDecoder::<256>::new().feed(bytes).collect();
    assert_eq!(got.len(), 1, "{got:?}");
    got.into_iter().next().unwrap().unwrap()
}

/// Every instruction packet of the e-Manual's § "Instruction Details", as
/// printed, and the instruction it carries: pada encodes the same bytes
/// and parses them back to the same instruction.
#[test]
fn the_manuals_instruction_packets_encode_and_parse_byte_for_byte() {
    let mut buf = [0u8; 64];
    let cases: Vec<(&str, u8, Instruction<'static>)> = vec![
        ("FF FF FD 00 01 03 00 01 19 4E", 1, Instruction::Ping),
        ("FF FF FD 00 FE 03 00 01 31 42", BROADCAST_ID, Instruction::Ping),
        ("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15", 1, Instruction::Read { addr: 132, len: 4 }),
        ("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89", 1, Instruction::Write { addr: 116, data: &[0x00, 0x02, 0x00, 0x00] }),
        ("FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E", 1, Instruction::RegWrite { addr: 104, data: &[200, 0, 0, 0] }),
        ("FF FF FD 00 01 03 00 05 02 CE", 1, Instruction::Action),
        ("FF FF FD 00 01 04 00 06 01 A1 E6", 1, Instruction::FactoryReset(ResetMode::ExceptId)),
        ("FF FF FD 00 01 03 00 08 2F 4E", 1, Instruction::Reboot),
        ("FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC", 1, Instruction::ClearMultiTurn),
        ("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA", BROADCAST_ID, Instruction::SyncRead { addr: 132, len: 4, ids: &[1, 2] }),
        (
            "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87",
            BROADCAST_ID,
            Instruction::SyncWrite { addr: 116, len: 4, entries: &[1, 150, 0, 0, 0, 2, 170, 0, 0, 0] },
        ),
        (
            "FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05",
            BROADCAST_ID,
            Instruction::BulkRead { entries: &[1, 0x90, 0, 2, 0, 2, 0x92, 0, 1, 0] },
        ),
        (
            "FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00 02 1F 00 01 00 50 B7 68",
            BROADCAST_ID,
            Instruction::BulkWrite { entries: &[1, 0x20, 0, 2, 0, 0xA0, 0, 2, 0x1F, 0, 1, 0, 0x50] },
        ),
        (
            "FF FF FD 00 FE 0A 00 8A 84 00 04 00 03 07 04 20 F2",
            BROADCAST_ID,
            Instruction::FastSyncRead { addr: 132, len: 4, ids: &[3, 7, 4] },
        ),
    ];
    for (printed, id, ins) in &cases {
        let bytes = hex(printed);
        assert_eq!(ins.encode(*id, &mut buf).unwrap(), &bytes[..], "{ins:?}");
        let p = instruction_packet(&bytes);
        assert_eq!((p.id, p.instruction().unwrap()), (*id, *ins));
    }
}

#[test]
fn the_manuals_fast_bulk_read_packet_has_a_misprinted_crc() {
    // e-Manual § "Fast Bulk Read", Example: the instruction packet is
    // printed with CRC 0x20 0xF2, the Fast Sync Read example's CRC; the
    // CRC of its bytes is 0xDA 0x2D. Everything before the CRC matches.
    let printed = hex("FF FF FD 00 FE 12 00 9A 03 84 00 04 00 07 7C 00 02 00 04 92 00 01 00 20 F2");
    let entries = [
        BulkReadEntry { id: 3, addr: 132, len: 4 },
        BulkReadEntry { id: 7, addr: 124, len: 2 },
        BulkReadEntry { id: 4, addr: 146, len: 1 },
    ];
    let mut buf = [0u8; 64];
    let ours = fast_bulk_read(&entries, &mut buf).unwrap();
    assert_eq!(&ours[..ours.len() - 2], &printed[..printed.len() - 2]);
    assert_eq!(&ours[ours.len() - 2..], &[0xDA, 0x2D]);
    // As printed, the packet fails its CRC: the decoder refuses it.
    assert!(matches!(InstructionDecoder::<64>::new().feed(&printed).next(), Some(Err(DecodeError::BadCrc { .. }))));
    // § "Control Table Backup" (not implemented): the backup example's CRC
    // is right, the restore example's is printed 92 F5 for 9E F5.
    let crc = |s: &str| {
        let b = hex(s);
        (pada_core::dynamixel::v2::crc::crc16(&b[..b.len() - 2]).to_le_bytes(), [b[b.len() - 2], b[b.len() - 1]])
    };
    let (ours, printed) = crc("FF FF FD 00 01 08 00 20 01 43 54 52 4C 16 F5");
    assert_eq!(ours, printed);
    let (ours, printed) = crc("FF FF FD 00 01 08 00 20 02 43 54 52 4C 92 F5");
    assert_eq!((ours, printed), ([0x9E, 0xF5], [0x92, 0xF5]));
}

#[test]
fn the_manuals_status_packets_decode_and_encode_byte_for_byte() {
    let cases: [(&str, u8, &[u8]); 7] = [
        ("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D", 1, &[0x06, 0x04, 0x26]),
        ("FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D", 2, &[0x06, 0x04, 0x26]),
        ("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0", 1, &[0xA6, 0, 0, 0]),
        ("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE", 2, &[0x1F, 0x08, 0, 0]),
        ("FF FF FD 00 01 04 00 55 00 A1 0C", 1, &[]),
        ("FF FF FD 00 01 06 00 55 00 77 00 C3 69", 1, &[0x77, 0x00]),
        ("FF FF FD 00 02 05 00 55 00 24 8B A9", 2, &[0x24]),
    ];
    let mut buf = [0u8; 64];
    for (printed, id, params) in cases {
        let bytes = hex(printed);
        let st = Status::new(id, StatusError::NONE, params).unwrap();
        assert_eq!(st.encode(&mut buf).unwrap(), &bytes[..]);
        assert_eq!(statuses(&bytes), vec![Ok(st)]);
    }
    // The PING reply names an XM430-W210, model 1030, firmware 38.
    let ping = statuses(&hex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D")).remove(0).unwrap();
    assert_eq!(PingReply::from_params(&ping.params), Some(PingReply { model_number: 1030, firmware: 38 }));
    assert_eq!(ping.u32_at(0), None);
}

#[test]
fn the_manuals_fast_sync_read_reply_decodes_as_one_packet() {
    let bytes = hex(
        "FF FF FD 00 FE 19 00 55 00 03 A6 00 00 00 84 08 00 07 1F 08 00 00 16 CA 00 04 FF 03 00 00 D1 9E",
    );
    let mut dec = StatusDecoder::<256>::new();
    dec.expect(Some(Reply::status(BROADCAST_ID, fast_sync_reply_params(3, 4).unwrap())));
    let got: Vec<_> = dec.feed(&bytes).collect();
    let p = got[0].as_ref().unwrap();
    assert!(p.is_fast());
    let positions: Vec<(u8, i32)> =
        p.fast_blocks(BlockLens::Uniform(4)).map(|b| b.unwrap()).map(|b| (b.id, i32::from_le_bytes(b.data.try_into().unwrap()))).collect();
    assert_eq!(positions, vec![(3, 166), (7, 2079), (4, 1023)]);
    assert_eq!(dec.stats().packets, 1);
    assert_eq!(dec.stats().skipped_bytes, 0);
}

#[test]
fn a_fast_reply_is_never_stuffed() {
    // e-Manual § "Fast Sync Read": "Fast Sync Read Status Packet does not
    // perform Byte Stuffing(0xFD) process."
    let data = [0xFF, 0xFF, 0xFD, 0x00];
    let reply = Status::fast_reply(&[FastBlock { id: 1, error: StatusError::NONE, data: &data }]).unwrap();
    let mut buf = [0u8; 64];
    let bytes = reply.encode(&mut buf).unwrap().to_vec();
    assert_eq!(u16::from_le_bytes([bytes[5], bytes[6]]), 1 + 4 + 4);
    assert_eq!(&bytes[10..14], &data);
    let mut dec = StatusDecoder::<256>::new();
    dec.expect(Some(Reply::status(BROADCAST_ID, fast_sync_reply_params(1, 4).unwrap())));
    assert_eq!(dec.feed(&bytes).collect::<Vec<_>>(), vec![Ok(reply)]);
}

#[test]
fn stuffing_in_a_write_round_trips_and_counts_in_length() {
    // Goal Position 0xFDFFFF00: data 00 FF FF FD, stuffed to 00 FF FF FD FD.
    let mut buf = [0u8; 64];
    let data = [0x00, 0xFF, 0xFF, 0xFD];
    let p = write(1, GOAL_POSITION, &data, &mut buf).unwrap().to_vec();
    assert_eq!(u16::from_le_bytes([p[5], p[6]]), 3 + 2 + 4 + 1);
    assert_eq!(&p[10..15], &[0x00, 0xFF, 0xFF, 0xFD, 0xFD]);
    let back = instruction_packet(&p);
    assert_eq!(back.instruction().unwrap(), Instruction::Write { addr: GOAL_POSITION, data: &data });
    // Unstuffed, the same bytes with a fresh CRC are refused and dropped
    // whole (the CRC matched, so it is one packet).
    let mut bare = p.clone();
    bare.remove(14);
    bare[5] -= 1;
    let n = bare.len();
    let crc = pada_core::dynamixel::v2::crc::crc16(&bare[..n - 2]).to_le_bytes();
    bare[n - 2..].copy_from_slice(&crc);
    let mut dec = InstructionDecoder::<64>::new();
    assert_eq!(dec.feed(&bare).collect::<Vec<_>>(), vec![Err(DecodeError::BadStuffing { id: 1 })]);
    assert_eq!(dec.stats().bad_stuffing, 1);
    assert_eq!(dec.stats().skipped_bytes as usize, bare.len());
}

#[test]
fn every_instruction_round_trips_in_chunks_of_every_size() {
    let mut stream = Vec::new();
    let mut buf = [0u8; 128];
    let bw = [BulkWriteEntry { id: 1, addr: GOAL_PWM, data: &[0x2C, 0x01] }, BulkWriteEntry { id: 2, addr: 65, data: &[1] }];
    let br = [BulkReadEntry { id: 1, addr: PRESENT_POSITION, len: 4 }, BulkReadEntry { id: 3, addr: 70, len: 1 }];
    let packets: Vec<Vec<u8>> = vec![
        ping(BROADCAST_ID, &mut buf).unwrap().to_vec(),
        read(2, PRESENT_POSITION, 4, &mut buf).unwrap().to_vec(),
        reg_write(3, GOAL_VELOCITY, &(-20i32).to_le_bytes(), &mut buf).unwrap().to_vec(),
        action(BROADCAST_ID, &mut buf).unwrap().to_vec(),
        reboot(4, &mut buf).unwrap().to_vec(),
        factory_reset(5, ResetMode::ExceptIdAndBaudRate, &mut buf).unwrap().to_vec(),
        clear_multi_turn(6, &mut buf).unwrap().to_vec(),
        sync_read(PRESENT_POSITION, 4, &[1, 2, 3], &mut buf).unwrap().to_vec(),
        fast_sync_read(PRESENT_POSITION, 4, &[1, 2, 3], &mut buf).unwrap().to_vec(),
        sync_write(GOAL_PWM, 2, &[(1, &[0xFF, 0xFF][..]), (2, &[0xFD, 0x00][..])], &mut buf).unwrap().to_vec(),
        sync_write_values(GOAL_PWM, &[(1, (-885i16).to_le_bytes()), (7, 885i16.to_le_bytes())], &mut buf).unwrap().to_vec(),
        bulk_read(&br, &mut buf).unwrap().to_vec(),
        fast_bulk_read(&br, &mut buf).unwrap().to_vec(),
        bulk_write(&bw, &mut buf).unwrap().to_vec(),
    ];
    for p in &packets {
        stream.extend_from_slice(p);
    }
    for chunk in 1..=stream.len() {
        let mut dec = InstructionDecoder::<128>::new();
        let mut got = Vec::new();
        for c in stream.chunks(chunk) {
            got.extend(dec.feed(c));
        }
        assert_eq!(got.len(), packets.len(), "chunk {chunk}");
        for (p, bytes) in got.iter().zip(&packets) {
            let p = p.as_ref().unwrap();
            let ins = p.instruction().unwrap();
            assert_eq!(ins.encode(p.id, &mut buf).unwrap(), &bytes[..]);
        }
        assert_eq!(dec.stats().skipped_bytes, 0);
    }
    // The typed views of the multi-servo instructions.
    let sw = instruction_packet(&packets[9]);
    let e: Vec<(u8, Vec<u8>)> = sw.instruction().unwrap().sync_write_entries().map(|(id, d)| (id, d.to_vec())).collect();
    assert_eq!(e, vec![(1, vec![0xFF, 0xFF]), (2, vec![0xFD, 0x00])]);
    let b = instruction_packet(&packets[11]);
    assert_eq!(b.instruction().unwrap().bulk_read_entries().collect::<Vec<_>>(), br.to_vec());
    assert_eq!(b.instruction().unwrap().ids().collect::<Vec<_>>(), vec![1, 3]);
    let w = instruction_packet(&packets[13]);
    assert_eq!(w.instruction().unwrap().bulk_write_entries().collect::<Vec<_>>(), bw.to_vec());
    assert_eq!(Instruction::Read { addr: 0, len: 9 }.reply_params(), Some(9));
    assert_eq!(instruction_packet(&packets[12]).instruction().unwrap().reply_params(), None);
}

#[test]
fn what_the_parser_refuses_the_encoders_refuse() {
    let mut buf = [0u8; 64];
    let bad = |code: u8| EncodeError::BadParams { code };
    assert_eq!(read(1, 0, 0, &mut buf), Err(bad(0x02)));
    assert_eq!(write(1, 0, &[], &mut buf), Err(bad(0x03)));
    assert_eq!(sync_read(0, 4, &[], &mut buf), Err(bad(0x82)));
    assert_eq!(sync_read(0, 4, &[1, 1], &mut buf), Err(bad(0x82)));
    assert_eq!(fast_sync_read(0, 4, &[1, 0xFE], &mut buf), Err(bad(0x8A)));
    assert_eq!(sync_write(0, 2, &[(1, &[1][..])], &mut buf), Err(bad(0x83)));
    assert_eq!(sync_write_values::<0>(0, &[(1, [])], &mut buf), Err(bad(0x83)));
    assert_eq!(bulk_read(&[BulkReadEntry { id: 1, addr: 0, len: 0 }], &mut buf), Err(bad(0x92)));
    assert_eq!(bulk_write(&[BulkWriteEntry { id: 2, addr: 0, data: &[] }], &mut buf), Err(bad(0x93)));
    assert_eq!(
        Instruction::SyncRead { addr: 0, len: 1, ids: &[1] }.encode(1, &mut buf),
        Err(EncodeError::NotBroadcast { code: 0x82 })
    );
    assert_eq!(ping(0xFD, &mut buf), Err(EncodeError::InvalidId { id: 0xFD }));
    let p = |code: u8, params: &'static [u8]| Instruction::parse(code, params);
    assert_eq!(p(0x02, &[0, 0, 0, 0]), Err(InstructionError::BadParams { code: 2, len: 4 }));
    assert_eq!(p(0x06, &[0x03]), Err(InstructionError::BadParams { code: 6, len: 1 }));
    assert_eq!(p(0x10, &[0x01, 0x44, 0x58, 0x4C, 0x23]), Err(InstructionError::BadParams { code: 0x10, len: 5 }));
    assert_eq!(p(0x83, &[0, 0, 2, 0, 1, 5]), Err(InstructionError::BadParams { code: 0x83, len: 6 }));
    assert_eq!(p(0x93, &[1, 0, 0, 2, 0, 9]), Err(InstructionError::BadParams { code: 0x93, len: 6 }));
    assert_eq!(p(0x20, &[]), Err(InstructionError::UnknownCode { code: 0x20 }));
    assert_eq!(p(STATUS, &[0]), Err(InstructionError::Status));
    assert_eq!(InstructionError::Status.error_number(), None);
    assert_eq!(InstructionError::UnknownCode { code: 0x20 }.error_number(), Some(ErrorNumber::Instruction));
    // A multi-servo instruction to one servo parses as bytes but not as an
    // instruction a servo executes.
    let raw = InstructionPacket::<16> { id: 1, instruction: 0x82, params: heapless::Vec::from_slice(&[0, 0, 1, 0, 1]).unwrap() };
    assert_eq!(raw.instruction(), Err(InstructionError::NotBroadcast { code: 0x82 }));
}

#[test]
fn the_status_decoder_refuses_what_it_was_not_asked_for() {
    let mut buf = [0u8; 64];
    let reply = Status::new(3, StatusError::NONE, &[1, 2, 3, 4]).unwrap();
    let bytes = reply.encode(&mut buf).unwrap().to_vec();
    let mut dec = StatusDecoder::<256>::new();
    dec.expect(Some(Reply::status(4, 4)));
    assert_eq!(dec.feed(&bytes).next(), Some(Err(DecodeError::UnexpectedId { expected: 4, got: 3 })));
    dec.reset();
    dec.expect(Some(Reply::status(3, 2)));
    assert!(matches!(dec.feed(&bytes).next(), Some(Err(DecodeError::BadLength { id: 3, length: 8 }))));
    dec.reset();
    dec.expect(Some(Reply::status(3, 4)));
    assert_eq!(dec.feed(&bytes).collect::<Vec<_>>(), vec![Ok(reply)]);
    // The longest stuffing of the expected parameters is still in the window.
    let stuffed = Status::new(3, StatusError(0xFF), &[0xFF, 0xFD, 0xFF, 0xFF, 0xFD, 0xFF]).unwrap();
    let sb = stuffed.encode(&mut buf).unwrap().to_vec();
    dec.expect(Some(Reply::status(3, 6)));
    assert_eq!(dec.feed(&sb).collect::<Vec<_>>(), vec![Ok(stuffed)]);
    // An instruction (an echo of our own) where a status is expected.
    dec.expect(None);
    let echo = read(3, 0, 1, &mut buf).unwrap().to_vec();
    assert_eq!(dec.feed(&echo).next(), Some(Err(DecodeError::NotStatus { id: 3, instruction: 0x02 })));
    assert_eq!(dec.stats().not_status, 1);
    // IDs 253 and 255 are never IDs.
    let mut fake = bytes.clone();
    fake[4] = 0xFD;
    assert_eq!(dec.feed(&fake).next(), Some(Err(DecodeError::InvalidId { id: 0xFD })));
}

#[test]
fn a_damaged_packet_does_not_hide_the_next_one() {
    let mut buf = [0u8; 64];
    let a = Status::new(1, StatusError::NONE, &[9; 6]).unwrap();
    let b = Status::new(2, StatusError(0x80), &[7]).unwrap();
    let mut stream = a.encode(&mut buf).unwrap().to_vec();
    stream[5] = 40; // LENGTH now swallows the next packet
    stream.extend_from_slice(b.encode(&mut buf).unwrap());
    stream.extend_from_slice(&[0u8; 40]);
    let got = statuses(&stream);
    assert!(matches!(got[0], Err(DecodeError::BadCrc { id: 1, .. })), "{got:?}");
    assert_eq!(got[1], Ok(b));
    // Too long for the buffer: counted, never a panic.
    let mut small = StatusDecoder::<16>::new();
    let long = Status::new(1, StatusError::NONE, &[0; 8]).unwrap();
    let got: Vec<_> = small.feed(long.encode(&mut buf).unwrap()).collect();
    assert_eq!(got, vec![Err(DecodeError::BadLength { id: 1, length: 12 })]);
    assert_eq!(small.stats().bad_lengths, 1);
}

/// Every byte fed is in an accepted packet, skipped, or buffered, and
/// every refusal is counted once.
fn accounting_holds(stats: &DecoderStats, fed: usize, accepted: usize, buffered: usize, oks: usize, errs: usize) {
    assert_eq!(stats.skipped_bytes as usize + accepted + buffered, fed, "{stats:?}");
    assert_eq!(stats.packets as usize, oks);
    let counted = stats.bad_crcs + stats.bad_lengths + stats.unexpected_ids + stats.not_status + stats.bad_stuffing;
    assert_eq!(counted as usize, errs, "{stats:?}");
}

/// A decoder's results counted: `(packets, errors, bytes of the packets)`.
/// Each packet, encoded again by `reencode`, must stand in `bytes` as it
/// was, and pass `check`.
fn tally<P, E>(
    results: impl Iterator<Item = Result<P, E>>,
    bytes: &[u8],
    reencode: impl Fn(&P) -> Vec<u8>,
    mut check: impl FnMut(&P) -> Result<(), TestCaseError>,
) -> Result<(usize, usize, usize), TestCaseError> {
    let (mut oks, mut errs, mut accepted) = (0, 0, 0);
    for r in results {
        match r {
            Ok(p) => {
                oks += 1;
                let enc = reencode(&p);
                prop_assert!(bytes.windows(enc.len()).any(|w| w == enc));
                accepted += enc.len();
                check(&p)?;
            }
            Err(_) => errs += 1,
        }
    }
    Ok((oks, errs, accepted))
}

fn status_strategy() -> impl Strategy<Value = Status> {
    let byte = prop_oneof![Just(0xFFu8), Just(0xFD), Just(0x00), any::<u8>()];
    (0u8..=252, any::<u8>(), proptest::collection::vec(byte, 0..40))
        .prop_map(|(id, e, p)| Status::new(id, StatusError(e), &p).unwrap())
}

proptest! {
    #[test]
    fn status_packets_round_trip_through_encode_and_decode(packets in proptest::collection::vec(status_strategy(), 1..8), chunk in 1usize..20) {
        let mut stream = Vec::new();
        let mut buf = [0u8; 300];
        for p in &packets {
            stream.extend_from_slice(p.encode(&mut buf).unwrap());
        }
        let mut dec = StatusDecoder::<256>::new();
        let mut got = Vec::new();
        for c in stream.chunks(chunk) {
            got.extend(dec.feed(c));
        }
        prop_assert_eq!(got, packets.into_iter().map(Ok).collect::<Vec<_>>());
        prop_assert_eq!(dec.stats().skipped_bytes, 0);
        prop_assert_eq!(dec.buffered(), 0);
    }

    #[test]
    fn sync_writes_and_bulk_writes_parse_back(values in proptest::collection::btree_map(0u8..=252, any::<i32>(), 1..10)) {
        let entries: Vec<(u8, [u8; 4])> = values.iter().map(|(&id, v)| (id, v.to_le_bytes())).collect();
        let mut buf = [0u8; 256];
        let p = sync_write_values(GOAL_POSITION, &entries, &mut buf).unwrap().to_vec();
        let back = instruction_packet(&p);
        let parsed: Vec<(u8, i32)> = back.instruction().unwrap().sync_write_entries()
            .map(|(id, d)| (id, i32::from_le_bytes(d.try_into().unwrap()))).collect();
        prop_assert_eq!(parsed, values.iter().map(|(&k, &v)| (k, v)).collect::<Vec<_>>());
        let bw: Vec<BulkWriteEntry> = entries.iter().map(|(id, d)| BulkWriteEntry { id: *id, addr: 116, data: d }).collect();
        let q = bulk_write(&bw, &mut buf).unwrap().to_vec();
        let qp = instruction_packet(&q);
        prop_assert_eq!(qp.instruction().unwrap().bulk_write_entries().collect::<Vec<_>>(), bw);
    }

    #[test]
    fn fast_replies_round_trip(blocks in proptest::collection::btree_map(
        0u8..=252,
        (any::<u8>(), proptest::collection::vec(prop_oneof![Just(0xFFu8), Just(0xFD), any::<u8>()], 1..6)),
        1..6,
    )) {
        let lens: Vec<u16> = blocks.values().map(|(_, d)| d.len() as u16).collect();
        let fb: Vec<FastBlock> = blocks.iter().map(|(&id, (e, d))| FastBlock { id, error: StatusError(*e), data: d }).collect();
        let reply = Status::fast_reply(&fb).unwrap();
        let mut buf = [0u8; 300];
        let bytes = reply.encode(&mut buf).unwrap().to_vec();
        let mut dec = StatusDecoder::<256>::new();
        dec.expect(Some(Reply::status(BROADCAST_ID, fast_bulk_reply_params(&lens).unwrap())));
        let got: Vec<_> = dec.feed(&bytes).collect();
        prop_assert_eq!(got.len(), 1);
        let p = got[0].as_ref().unwrap();
        let back: Vec<FastBlock> = p.fast_blocks(BlockLens::Each(&lens)).map(|b| b.unwrap()).collect();
        prop_assert_eq!(back, fb);
    }

    #[test]
    fn any_bytes_never_panic_and_every_byte_is_accounted_for(
        pieces in proptest::collection::vec(prop_oneof![
            proptest::collection::vec(prop_oneof![Just(0xFFu8), Just(0xFD), Just(0x00), Just(0x55), any::<u8>()], 0..40).prop_map(Err),
            status_strategy().prop_map(Ok),
        ], 0..12),
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..3),
        expect in proptest::option::of((0u8..=255, 0u16..40)),
    ) {
        let mut buf = [0u8; 300];
        let mut bytes = Vec::new();
        for piece in &pieces {
            match piece {
                Ok(p) => bytes.extend_from_slice(p.encode(&mut buf).unwrap()),
                Err(noise) => bytes.extend_from_slice(noise),
            }
        }
        if !bytes.is_empty() {
            for (at, x) in &flips {
                let i = at.index(bytes.len());
                bytes[i] ^= x;
            }
        }
        let mut dec = StatusDecoder::<64>::new();
        dec.expect(expect.map(|(id, params)| Reply::status(id, params)));
        let reencode = |p: &StatusPacket<64>| p.encode(&mut [0u8; 300]).unwrap().to_vec();
        let (oks, errs, accepted) = tally(dec.feed(&bytes), &bytes, reencode, |p| {
            if let Some((id, params)) = expect {
                prop_assert_eq!((p.id, p.params.len()), (id, params as usize));
            }
            Ok(())
        })?;
        accounting_holds(&dec.stats(), bytes.len(), accepted, dec.buffered(), oks, errs);
        let mut ins = InstructionDecoder::<64>::new();
        let reencode = |p: &InstructionPacket<64>| p.encode(&mut [0u8; 300]).unwrap().to_vec();
        let (oks, errs, accepted) = tally(ins.feed(&bytes), &bytes, reencode, |_| Ok(()))?;
        accounting_holds(&ins.stats(), bytes.len(), accepted, ins.buffered(), oks, errs);
    }

    #[test]
    fn one_damaged_byte_loses_at_most_its_own_packet(packets in proptest::collection::vec(status_strategy(), 3..8), which in any::<prop::sample::Index>(), flip in 1u8..=255) {
        let mut buf = [0u8; 300];
        let encoded: Vec<Vec<u8>> = packets.iter().map(|p| p.encode(&mut buf).unwrap().to_vec()).collect();
        let target = which.index(encoded.len());
        let mut stream = Vec::new();
        for (i, e) in encoded.iter().enumerate() {
            let mut e = e.clone();
            if i == target {
                let at = e.len() / 2;
                e[at] ^= flip;
            }
            stream.extend(e);
        }
        // Padding as long as the decoder's buffer completes any candidate a
        // damaged LENGTH made wait.
        stream.extend([0u8; 256]);
        let got: Vec<Status> = statuses(&stream).into_iter().flatten().collect();
        let mut want = packets.clone();
        want.remove(target);
        prop_assert_eq!(got, want);
    }
}

#[test]
fn a_sync_reads_replies_are_expected_one_after_the_other() {
    // The e-Manual's Sync Read replies (IDs 1 and 2), arriving together.
    let mut bytes = hex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0");
    bytes.extend(hex("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE"));
    let ins = Instruction::SyncRead { addr: 132, len: 4, ids: &[1, 2] };
    let mut ids = ins.ids();
    let mut dec = StatusDecoder::<64>::new();
    dec.expect(Some(Reply::status(ids.next().unwrap(), ins.reply_params().unwrap())));
    let mut got = Vec::new();
    for &b in &bytes {
        let mut next = dec.push(b);
        while let Some(r) = next {
            got.push(r.unwrap().id);
            dec.expect(ids.next().map(|id| Reply::status(id, 4)));
            next = dec.poll();
        }
    }
    assert_eq!(got, vec![1, 2]);
    assert_eq!(dec.stats().skipped_bytes, 0);
}
