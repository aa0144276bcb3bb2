//! The master's encoders: one function per instruction, taking typed
//! values and building the parameters on the fly (no scratch buffer), so a
//! firmware bus task writes `sync_write_values(GOAL_PWM, &[(1, pwm.to_le_bytes()), …], &mut tx)`.
//! Each refuses what [`Instruction::parse`] would refuse, and what it
//! encodes parses back to the instruction it describes (tested).

use super::instruction::{distinct_servo_ids, BulkReadEntry, BulkWriteEntry, Instruction, InstructionCode, ResetMode};
use super::packet::{write_frame, EncodeError, BROADCAST_ID};
use core::iter::once;

/// PING of servo `id` (or of every servo, to [`BROADCAST_ID`]).
pub fn ping(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Ping.encode(id, out)
}

/// READ of `len` bytes at `addr` of servo `id`.
pub fn read(id: u8, addr: u16, len: u16, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Read { addr, len }.encode(id, out)
}

/// WRITE of `data` at `addr` of servo `id`.
pub fn write<'b>(id: u8, addr: u16, data: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::Write { addr, data }.encode(id, out)
}

/// REG WRITE of `data` at `addr` of servo `id` (executed on [`action`]).
pub fn reg_write<'b>(id: u8, addr: u16, data: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::RegWrite { addr, data }.encode(id, out)
}

/// ACTION (usually to [`BROADCAST_ID`]).
pub fn action(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Action.encode(id, out)
}

/// REBOOT of servo `id`.
pub fn reboot(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Reboot.encode(id, out)
}

/// FACTORY RESET of servo `id`.
pub fn factory_reset(id: u8, mode: ResetMode, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::FactoryReset(mode).encode(id, out)
}

/// CLEAR of servo `id`'s multi-turn count.
pub fn clear_multi_turn(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::ClearMultiTurn.encode(id, out)
}

/// SYNC READ of `len` bytes at `addr` from `ids` (each answers in turn).
pub fn sync_read<'b>(addr: u16, len: u16, ids: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::SyncRead { addr, len, ids }.encode(BROADCAST_ID, out)
}

/// FAST SYNC READ of `len` bytes at `addr` from `ids` (one combined reply).
pub fn fast_sync_read<'b>(addr: u16, len: u16, ids: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::FastSyncRead { addr, len, ids }.encode(BROADCAST_ID, out)
}

fn sync_write_frame<I: Iterator<Item = u8> + Clone>(
    addr: u16,
    len: u16,
    ids: impl Iterator<Item = u8>,
    entries: I,
    out: &mut [u8],
) -> Result<&[u8], EncodeError> {
    let code = InstructionCode::SyncWrite as u8;
    if len == 0 || !distinct_servo_ids(ids) {
        return Err(EncodeError::BadParams { code });
    }
    let body = addr.to_le_bytes().into_iter().chain(len.to_le_bytes()).chain(entries);
    write_frame(BROADCAST_ID, code, body, out)
}

/// SYNC WRITE of `len` bytes at `addr`, one `(id, data)` per servo; every
/// `data` must be `len` long.
pub fn sync_write<'b>(addr: u16, len: u16, entries: &[(u8, &[u8])], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    if entries.iter().any(|(_, d)| d.len() != len as usize) {
        return Err(EncodeError::BadParams { code: InstructionCode::SyncWrite as u8 });
    }
    let body = entries.iter().flat_map(|(id, d)| once(*id).chain(d.iter().copied()));
    sync_write_frame(addr, len, entries.iter().map(|e| e.0), body, out)
}

/// SYNC WRITE of one `W`-byte value per servo at `addr` (the usual case:
/// every joint's Goal PWM, `(-300i16).to_le_bytes()`, in one packet).
pub fn sync_write_values<'b, const W: usize>(
    addr: u16,
    entries: &[(u8, [u8; W])],
    out: &'b mut [u8],
) -> Result<&'b [u8], EncodeError> {
    let len = u16::try_from(W).map_err(|_| EncodeError::TooLong { bytes: W })?;
    let body = entries.iter().flat_map(|(id, d)| once(*id).chain(d.iter().copied()));
    sync_write_frame(addr, len, entries.iter().map(|e| e.0), body, out)
}

fn bulk_read_frame<'b>(code: InstructionCode, entries: &[BulkReadEntry], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    if entries.iter().any(|e| e.len == 0) || !distinct_servo_ids(entries.iter().map(|e| e.id)) {
        return Err(EncodeError::BadParams { code: code as u8 });
    }
    write_frame(BROADCAST_ID, code as u8, entries.iter().flat_map(|e| e.to_bytes()), out)
}

/// BULK READ: each servo its own address and length (each answers in turn).
pub fn bulk_read<'b>(entries: &[BulkReadEntry], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    bulk_read_frame(InstructionCode::BulkRead, entries, out)
}

/// FAST BULK READ: as [`bulk_read`], one combined reply.
pub fn fast_bulk_read<'b>(entries: &[BulkReadEntry], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    bulk_read_frame(InstructionCode::FastBulkRead, entries, out)
}

/// BULK WRITE: each servo its own address and data.
pub fn bulk_write<'b>(entries: &[BulkWriteEntry<'_>], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    let code = InstructionCode::BulkWrite as u8;
    for e in entries {
        if e.data.is_empty() || u16::try_from(e.data.len()).is_err() {
            return Err(EncodeError::BadParams { code });
        }
    }
    if !distinct_servo_ids(entries.iter().map(|e| e.id)) {
        return Err(EncodeError::BadParams { code });
    }
    let body = entries.iter().flat_map(|e| {
        let [a0, a1] = e.addr.to_le_bytes();
        let [l0, l1] = (e.data.len() as u16).to_le_bytes();
        [e.id, a0, a1, l0, l1].into_iter().chain(e.data.iter().copied())
    });
    write_frame(BROADCAST_ID, code, body, out)
}
