//! The packet decoder ([`pada_core::dynamixel::Decoder`]) in both
//! directions: status packets as the firmware reads them (with and without
//! an expected reply) and instruction packets as the bus emulator reads
//! them, in either instruction table that rides on Protocol 1.0's framing
//! ([`Dialect`]: Dynamixel 1.0's, Feetech's).

use super::tally::{accept, Tally};
use super::{ensure, Outcome, Target};
use crate::gen::{below, bytes, mutate};
use pada_core::dynamixel::{
    DecodeError, DecoderStats, ErrorFlags, Instruction, InstructionDecoder, Reply, StatusDecoder,
    StatusPacket,
};
use pada_core::feetech;
use rand_core::RngCore;

/// Which instruction table the instruction side parses with.
#[derive(Clone, Copy)]
pub enum Dialect {
    /// Dynamixel Protocol 1.0 ([`Instruction`]).
    Dynamixel,
    /// Feetech's ([`feetech::Instruction`]): SYNC READ, no BULK READ.
    Feetech,
}

impl Dialect {
    /// Parses `code` and `params` and encodes the instruction back for
    /// `id`: `None` if it does not parse, else whether it encoded to
    /// `bytes`.
    fn round_trip(self, id: u8, code: u8, params: &[u8], bytes: &[u8], out: &mut [u8]) -> Option<bool> {
        match self {
            Dialect::Dynamixel => {
                let ins = Instruction::parse(code, params).ok()?;
                Some(ins.encode(id, out).is_ok_and(|e| e == bytes))
            }
            Dialect::Feetech => {
                let ins = feetech::Instruction::parse(code, params).ok()?;
                Some(ins.encode(id, out).is_ok_and(|e| e == bytes))
            }
        }
    }
}

/// The status side: the first three input bytes say what the decoder
/// expects (byte 0 odd: a reply from ID byte 1 with byte 2 parameters).
pub struct Status<const N: usize> {
    name: &'static str,
}

impl<const N: usize> Status<N> {
    pub fn new(name: &'static str) -> Self {
        Status { name }
    }
}

/// Valid packets, some from `id` with `params` parameter bytes, with bytes
/// of noise between some of them.
fn packets(
    rng: &mut rand_pcg::Pcg64,
    id: u8,
    params: usize,
    max_params: usize,
    status: bool,
) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = [0u8; 300];
    for _ in 0..1 + below(rng, 5) {
        if below(rng, 3) == 0 {
            let n = below(rng, 6);
            out.extend(bytes(rng, n));
        }
        let (pid, n) = if below(rng, 2) == 0 {
            (id, params)
        } else {
            (below(rng, 254) as u8, below(rng, max_params + 1))
        };
        let data = bytes(rng, n);
        if status {
            if let Ok(p) = StatusPacket::<300>::new(pid, ErrorFlags(rng.next_u32() as u8), &data) {
                if let Ok(b) = p.encode(&mut buf) {
                    out.extend_from_slice(b);
                }
            }
        } else {
            if below(rng, 5) == 0 && !data.is_empty() {
                let ids = &data[..data.len().min(8)];
                if let Ok(b) = feetech::sync_read(36, n as u8 % 9, ids, &mut buf) {
                    out.extend_from_slice(b);
                }
                continue;
            }
            let ins = match below(rng, 4) {
                0 => Instruction::Read {
                    addr: data.first().copied().unwrap_or(0),
                    len: n as u8,
                },
                1 if !data.is_empty() => Instruction::Write {
                    addr: 30,
                    data: &data,
                },
                2 => Instruction::SyncWrite {
                    addr: 32,
                    data_len: 2,
                    entries: &data[..data.len() / 3 * 3],
                },
                _ => Instruction::Ping,
            };
            if let Ok(b) = ins.encode(pid, &mut buf) {
                out.extend_from_slice(b);
            }
        }
    }
    out
}

/// Checks the decoder's counters against `tally` and the `fed` bytes.
fn check_counts(s: &DecoderStats, fed: usize, buffered: usize, tally: &Tally<3>) -> Outcome {
    let refusals = [s.bad_checksums, s.bad_lengths, s.unexpected_ids];
    tally.check(s.packets, refusals, s.skipped_bytes, fed, buffered)
}

fn kind(e: &DecodeError) -> usize {
    match e {
        DecodeError::BadChecksum { .. } => 0,
        DecodeError::BadLength { .. } => 1,
        DecodeError::UnexpectedId { .. } | DecodeError::BroadcastStatus => 2,
    }
}

impl<const N: usize> Target for Status<N> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let (id, params) = (below(rng, 254) as u8, below(rng, N - 5));
        let mut input = vec![rng.next_u32() as u8, id, params as u8];
        match below(rng, 6) {
            0 => {
                let n = below(rng, 300);
                input.extend(bytes(rng, n));
            }
            1 => input.extend(packets(rng, id, params, N - 6, true)),
            _ => {
                let mut s = packets(rng, id, params, N - 6, true);
                let other = packets(rng, id, params, N - 6, true);
                mutate(rng, &mut s, &other);
                input.extend(s);
            }
        }
        input
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let Some((&[mode, id, params], stream)) = input.split_first_chunk::<3>() else {
            return Outcome::Ok;
        };
        let reply = (mode & 1 == 1).then_some(Reply { id, params });
        let mut dec = StatusDecoder::<N>::new();
        dec.expect(reply);
        let mut tally = Tally::<3>::new();
        let mut buf = [0u8; 300];
        for (i, &b) in stream.iter().enumerate() {
            let mut next = dec.push(b);
            while let Some(r) = next {
                match r {
                    Ok(p) => {
                        // Invariant 2: it re-encodes to bytes that were fed.
                        accept!(
                            tally,
                            p.encode(&mut buf),
                            &stream[..=i],
                            format_args!("at byte {i}")
                        );
                        if let Some(r) = reply {
                            ensure!(
                                p.id == r.id && p.params.len() == r.params as usize,
                                "accepted {p:?}, expected {r:?}"
                            );
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

/// The instruction side (the bus emulator's decoder), parsing with one
/// instruction table.
pub struct Instructions<const N: usize> {
    name: &'static str,
    dialect: Dialect,
}

impl<const N: usize> Instructions<N> {
    pub fn new(name: &'static str, dialect: Dialect) -> Self {
        Instructions { name, dialect }
    }
}

impl<const N: usize> Target for Instructions<N> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        match below(rng, 6) {
            0 => {
                let n = below(rng, 300);
                bytes(rng, n)
            }
            1 => packets(rng, 1, 4, N - 8, false),
            _ => {
                let mut s = packets(rng, 1, 4, N - 8, false);
                let other = packets(rng, 2, 2, N - 8, false);
                mutate(rng, &mut s, &other);
                s
            }
        }
    }

    fn check(&self, stream: &[u8]) -> Outcome {
        let mut dec = InstructionDecoder::<N>::new();
        let mut tally = Tally::<3>::new();
        let (mut buf, mut again) = ([0u8; 300], [0u8; 300]);
        for (i, p) in dec.feed(stream).enumerate() {
            match p {
                Ok(p) => {
                    let bytes = accept!(tally, p.encode(&mut buf), stream, i);
                    // The encoder and the parser agree: what parses encodes
                    // back to the same packet.
                    let same = self.dialect.round_trip(p.id, p.code, &p.params, bytes, &mut again);
                    ensure!(
                        same != Some(false),
                        "code {:#04x} {:?} parses but does not encode back",
                        p.code,
                        p.params
                    );
                }
                Err(e) => tally.refuse(kind(&e)),
            }
        }
        check_counts(&dec.stats(), stream.len(), dec.buffered(), &tally)
    }
}
