//! The Protocol 2.0 decoders ([`pada_core::dynamixel::v2::Decoder`]) in
//! both directions: status packets as the firmware reads them (with and
//! without an expected reply, fast replies included) and instruction
//! packets as a servo or the bus emulator reads them (every instruction,
//! other servos' replies among them), plus the parsers behind them (the
//! fast reply's blocks, the instructions, the control table's write
//! checks).

use super::tally::{accept, Tally};
use super::{ensure, Outcome, Target};
use crate::gen::{below, bytes, mutate};
use pada_core::dynamixel::control_table::x_series::XM430_W350;
use pada_core::dynamixel::v2::crc::crc16;
use pada_core::dynamixel::v2::encoders as enc;
use pada_core::dynamixel::v2::fast::{BlockLens, FastBlock};
use pada_core::dynamixel::v2::{
    BulkReadEntry, BulkWriteEntry, DecodeError, DecoderStats, InstructionDecoder, Reply, ResetMode, StatusDecoder,
    StatusError, StatusPacket, BROADCAST_ID, STATUS,
};
use rand_core::RngCore;

/// Bytes that make stuffing happen more often than uniform bytes would.
fn payload(rng: &mut rand_pcg::Pcg64, n: usize) -> Vec<u8> {
    (0..n)
        .map(|_| match below(rng, 4) {
            0 => 0xFF,
            1 => 0xFD,
            _ => rng.next_u32() as u8,
        })
        .collect()
}

/// A packet with a correct CRC whose sender forgot to stuff: a bare
/// `FF FF FD` in its payload (the decoders refuse it as bad stuffing).
fn unstuffed(rng: &mut rand_pcg::Pcg64, instruction: u8) -> Vec<u8> {
    let n = below(rng, 6);
    let mut body = payload(rng, n);
    let at = below(rng, body.len() + 1);
    let x = if below(rng, 2) == 0 { 0x00 } else { rng.next_u32() as u8 | 1 };
    body.splice(at..at, [0xFF, 0xFF, 0xFD, if x == 0xFD { 0 } else { x }]);
    let [l0, l1] = (body.len() as u16 + 3).to_le_bytes();
    let mut frame = vec![0xFF, 0xFF, 0xFD, 0x00, below(rng, 253) as u8, l0, l1, instruction];
    frame.extend(body);
    let crc = crc16(&frame).to_le_bytes();
    frame.extend(crc);
    frame
}

/// A valid status packet: a servo's (ID 0–252) or a fast reply; now and
/// then one that was not stuffed.
fn status(rng: &mut rand_pcg::Pcg64, max_params: usize, fast_len: usize) -> Vec<u8> {
    let mut buf = [0u8; 600];
    if below(rng, 10) == 0 {
        return unstuffed(rng, STATUS);
    }
    let p: Option<StatusPacket<300>> = if below(rng, 4) == 0 {
        let n = 1 + below(rng, 4);
        let datas: Vec<Vec<u8>> = (0..n).map(|_| payload(rng, fast_len)).collect();
        let ids: Vec<u8> = (0..n).map(|_| below(rng, 253) as u8).collect();
        let blocks: Vec<FastBlock> =
            ids.iter().zip(&datas).map(|(&id, d)| FastBlock { id, error: StatusError(rng.next_u32() as u8), data: d }).collect();
        StatusPacket::fast_reply(&blocks).ok()
    } else {
        let n = below(rng, max_params + 1);
        StatusPacket::new(below(rng, 253) as u8, StatusError(rng.next_u32() as u8), &payload(rng, n)).ok()
    };
    p.and_then(|p| p.encode(&mut buf).ok().map(<[u8]>::to_vec)).unwrap_or_default()
}

/// A valid instruction packet of any kind; now and then one that was not
/// stuffed.
fn instruction(rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
    let mut buf = [0u8; 600];
    if below(rng, 10) == 0 {
        return unstuffed(rng, 0x03);
    }
    let id = below(rng, 253) as u8;
    let addr = below(rng, 700) as u16;
    let n = 1 + below(rng, 8);
    let data = payload(rng, n);
    let ids: Vec<u8> = (0..1 + below(rng, 5)).map(|_| below(rng, 253) as u8).collect();
    let out = match below(rng, 14) {
        0 => enc::ping(if below(rng, 2) == 0 { id } else { BROADCAST_ID }, &mut buf),
        1 => enc::read(id, addr, n as u16, &mut buf),
        2 => enc::write(id, addr, &data, &mut buf),
        3 => enc::reg_write(id, addr, &data, &mut buf),
        4 => enc::action(BROADCAST_ID, &mut buf),
        5 => enc::reboot(id, &mut buf),
        6 => enc::factory_reset(id, ResetMode::ExceptId, &mut buf),
        7 => enc::clear_multi_turn(id, &mut buf),
        8 => enc::sync_read(addr, n as u16, &ids, &mut buf),
        9 => enc::fast_sync_read(addr, n as u16, &ids, &mut buf),
        10 => {
            let e: Vec<(u8, [u8; 2])> = ids.iter().map(|&i| (i, [rng.next_u32() as u8, 0xFF])).collect();
            enc::sync_write_values(addr, &e, &mut buf)
        }
        11 => {
            let e: Vec<BulkReadEntry> = ids.iter().map(|&i| BulkReadEntry { id: i, addr, len: n as u16 }).collect();
            enc::bulk_read(&e, &mut buf)
        }
        12 => {
            let e: Vec<BulkReadEntry> = ids.iter().map(|&i| BulkReadEntry { id: i, addr, len: n as u16 }).collect();
            enc::fast_bulk_read(&e, &mut buf)
        }
        _ => {
            let e: Vec<BulkWriteEntry> = ids.iter().map(|&i| BulkWriteEntry { id: i, addr, data: &data }).collect();
            enc::bulk_write(&e, &mut buf)
        }
    };
    // Duplicate IDs are refused by the encoders: then another packet.
    out.map(<[u8]>::to_vec).unwrap_or_else(|_| enc::ping(id, &mut [0u8; 16]).map(<[u8]>::to_vec).unwrap_or_default())
}

/// Valid packets with some noise between them.
fn stream(rng: &mut rand_pcg::Pcg64, statuses: bool, max_params: usize, fast_len: usize) -> Vec<u8> {
    let mut out = Vec::new();
    for _ in 0..1 + below(rng, 5) {
        if below(rng, 3) == 0 {
            let n = below(rng, 6);
            out.extend(bytes(rng, n));
        }
        if statuses || below(rng, 5) == 0 {
            out.extend(status(rng, max_params, fast_len));
        } else {
            out.extend(instruction(rng));
        }
    }
    out
}

fn kind(e: &DecodeError) -> usize {
    match e {
        DecodeError::BadCrc { .. } => 0,
        DecodeError::BadLength { .. } => 1,
        DecodeError::InvalidId { .. } | DecodeError::UnexpectedId { .. } => 2,
        DecodeError::NotStatus { .. } => 3,
        DecodeError::BadStuffing { .. } => 4,
    }
}

/// Checks the decoder's counters against `tally` and the `fed` bytes.
fn check_counts(s: &DecoderStats, fed: usize, buffered: usize, tally: &Tally<5>) -> Outcome {
    let refusals = [s.bad_crcs, s.bad_lengths, s.unexpected_ids, s.not_status, s.bad_stuffing];
    tally.check(s.packets, refusals, s.skipped_bytes, fed, buffered)
}

/// The status side: the first four input bytes say what the decoder
/// expects (byte 0 odd: a reply from ID byte 1 with bytes 2–3 parameters)
/// and how fast replies are cut (data length `byte 0 / 2 % 8 + 1`).
pub struct Status<const N: usize> {
    name: &'static str,
}

impl<const N: usize> Status<N> {
    pub fn new(name: &'static str) -> Self {
        Status { name }
    }
}

impl<const N: usize> Target for Status<N> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let mode = rng.next_u32() as u8;
        let fast_len = (mode as usize >> 1) % 8 + 1;
        let max = N.saturating_sub(12);
        let (id, params) = match below(rng, 3) {
            0 => (BROADCAST_ID, (4 * (fast_len + 4) - 3) as u16),
            _ => (below(rng, 253) as u8, below(rng, max + 1) as u16),
        };
        let [p0, p1] = params.to_le_bytes();
        let mut input = vec![mode, id, p0, p1];
        match below(rng, 6) {
            0 => {
                let n = below(rng, 400);
                input.extend(payload(rng, n));
            }
            1 => input.extend(stream(rng, true, max, fast_len)),
            _ => {
                let mut s = stream(rng, true, max, fast_len);
                let statuses = below(rng, 2) == 0;
                let other = stream(rng, statuses, max, fast_len);
                mutate(rng, &mut s, &other);
                input.extend(s);
            }
        }
        input
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let Some((&[mode, id, p0, p1], stream)) = input.split_first_chunk::<4>() else {
            return Outcome::Ok;
        };
        let reply = (mode & 1 == 1).then_some(Reply::status(id, u16::from_le_bytes([p0, p1])));
        let fast_len = (mode as u16 >> 1) % 8 + 1;
        let mut dec = StatusDecoder::<N>::new();
        dec.expect(reply);
        let mut tally = Tally::<5>::new();
        let mut buf = vec![0u8; N + 16];
        for (i, &b) in stream.iter().enumerate() {
            let mut next = dec.push(b);
            while let Some(r) = next {
                match r {
                    Ok(p) => {
                        accept!(tally, p.encode(&mut buf), &stream[..=i], format_args!("at byte {i}"));
                        if let Some(r) = reply {
                            ensure!(p.id == r.id && p.params.len() == r.params as usize, "accepted {p:?}, expected {r:?}");
                        }
                        if p.is_fast() {
                            // A fast reply whose blocks all check rebuilds
                            // to the same packet.
                            let blocks: Result<Vec<FastBlock>, _> = p.fast_blocks(BlockLens::Uniform(fast_len)).collect();
                            if let Ok(blocks) = blocks {
                                let again = StatusPacket::<N>::fast_reply(&blocks);
                                ensure!(again.as_ref() == Ok(&p), "fast reply {p:?} rebuilds to {again:?}");
                            }
                        }
                    }
                    Err(e) => tally.refuse(kind(&e)),
                }
                next = dec.poll();
            }
        }
        check_counts(&dec.stats(), stream.len(), dec.buffered(), &tally)
    }
}

/// The instruction side (a servo's, or the bus emulator's, decoder).
pub struct Instructions<const N: usize> {
    name: &'static str,
}

impl<const N: usize> Instructions<N> {
    pub fn new(name: &'static str) -> Self {
        Instructions { name }
    }
}

impl<const N: usize> Target for Instructions<N> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let max = N.saturating_sub(12);
        match below(rng, 6) {
            0 => {
                let n = below(rng, 400);
                payload(rng, n)
            }
            1 => stream(rng, false, max, 4),
            _ => {
                let mut s = stream(rng, false, max, 4);
                let other = stream(rng, false, max, 4);
                mutate(rng, &mut s, &other);
                s
            }
        }
    }

    fn check(&self, stream: &[u8]) -> Outcome {
        let mut dec = InstructionDecoder::<N>::new();
        let mut tally = Tally::<5>::new();
        let (mut buf, mut again) = (vec![0u8; N + 16], vec![0u8; N + 16]);
        // A servo's table image for the write checks (XM430-W350 defaults
        // of the limits that matter).
        let mut memory = vec![0u8; XM430_W350.end as usize];
        memory[36..38].copy_from_slice(&885u16.to_le_bytes());
        memory[11] = 3;
        for (i, p) in dec.feed(stream).enumerate() {
            match p {
                Ok(p) => {
                    let bytes = accept!(tally, p.encode(&mut buf), stream, i);
                    // What parses encodes back to the same packet.
                    if let Ok(ins) = p.instruction() {
                        let enc = ins.encode(p.id, &mut again);
                        ensure!(enc.is_ok_and(|e| e == bytes), "{ins:?} parses but does not encode back: {enc:?}");
                        // The parsers behind a servo never panic.
                        let _ = (ins.ids().count(), ins.sync_write_entries().count(), ins.bulk_write_entries().count());
                        if let pada_core::dynamixel::v2::Instruction::Write { addr, data } = ins {
                            let _ = XM430_W350.check_write(addr, data, &memory);
                        }
                        if let pada_core::dynamixel::v2::Instruction::Read { addr, len } = ins {
                            let _ = XM430_W350.check_read(addr, len);
                        }
                    }
                }
                Err(e) => tally.refuse(kind(&e)),
            }
        }
        check_counts(&dec.stats(), stream.len(), dec.buffered(), &tally)
    }
}
