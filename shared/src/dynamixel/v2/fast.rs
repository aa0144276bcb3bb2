//! The one combined reply to Fast Sync Read (0x8A) and Fast Bulk Read
//! (0x9A) (e-Manual, "DYNAMIXEL Protocol 2.0", §§ "Fast Sync Read" and
//! "Fast Bulk Read", read through the e-Manual's source: see
//! docs/reference/dynamixel.md §3).
//!
//! Every servo asked sends its part of one status packet, in the order of
//! the IDs in the instruction; the packet's ID is the broadcast ID and it is
//! not byte-stuffed:
//!
//! ```text
//! FF FF FD 00  FE  LEN_L LEN_H  55
//!   ERR_1 ID_1 DATA_1 (X_1 bytes) CRC_1 (2)
//!   ERR_2 ID_2 DATA_2 (X_2 bytes) CRC_2 (2)
//!   …
//!   ERR_n ID_n DATA_n (X_n bytes) CRC_n (2)     ← CRC_n is the packet's CRC
//! LENGTH = 1 + Σ (X_i + 4)
//! ```
//!
//! Each block carries its own servo's ID and ERROR, and each CRC_i is the
//! running CRC of the packet from its first header byte to the end of
//! DATA_i (the earlier blocks' CRC bytes included), so the last one is the
//! packet's ordinary CRC: the e-Manual's example
//! `… 55 00 03 A6 00 00 00 84 08 00 07 1F 08 00 00 16 CA 00 04 FF 03 00 00
//! D1 9E` has CRC-16 0x0884 up to ID 3's data, 0xCA16 up to ID 7's and
//! 0x9ED1 over all (checked in this module's tests). The e-Manual says a
//! master may check the last CRC only; [`FastBlocks`] checks each block's
//! too, so a block is known good on its own.
//!
//! As a [`StatusPacket`], the reply has `id` = [`BROADCAST_ID`], `error` =
//! ERR_1 and `params` = everything from ID_1 to DATA_n.

use super::crc::{crc16, update_crc};
use super::packet::{EncodeError, StatusPacket, BROADCAST_ID, HEADER, MAX_ID, STATUS};
use super::status::StatusError;
use heapless::Vec;

/// Bytes a block adds besides its data: ERROR, ID and the two CRC bytes.
pub const BLOCK_OVERHEAD: usize = 4;

// The default buffer holds the fast reply of the present block from every
// servo a robot may have (a robot that asks for more is refused at build
// time, not at run time). (Here, not beside the buffer's size in
// `packet`, so that `packet` need not know this module.)
const _: () = {
    let block = crate::dynamixel::control_table::x_series::PRESENT_BLOCK_LEN as usize + BLOCK_OVERHEAD;
    assert!(super::packet::PREFIX_LEN + 1 + crate::limits::MAX_SERVOS * block <= super::packet::DEFAULT_PACKET_LEN);
};

/// One servo's block of a fast reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FastBlock<'a> {
    /// The servo's ID (its own, in its block).
    pub id: u8,
    /// The servo's ERROR byte.
    pub error: StatusError,
    /// The data read from it.
    pub data: &'a [u8],
}

/// Why a fast reply does not have the expected layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FastReplyError {
    /// The status packet is not from the broadcast ID.
    NotFast,
    /// Block `block` ends past the packet.
    Truncated {
        /// Index of the block (0: the first servo).
        block: usize,
    },
    /// Block `block`'s CRC does not match the running CRC.
    BlockCrc {
        /// Index of the block.
        block: usize,
        /// The ID in the block.
        id: u8,
    },
    /// Bytes left after the blocks asked for (or a data length of zero in
    /// a uniform layout, which would never end).
    Trailing {
        /// Bytes left over.
        bytes: usize,
    },
}

/// The data lengths of a fast reply's blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlockLens<'a> {
    /// Fast Sync Read: every block has the same length, and the reply's
    /// length says how many blocks there are.
    Uniform(u16),
    /// Fast Bulk Read: one length per servo, in the instruction's order.
    Each(&'a [u16]),
}

/// The blocks of a fast reply, checked one by one (layout and running
/// CRC). Yields an error at most once, then ends.
#[derive(Debug, Clone)]
pub struct FastBlocks<'a> {
    params: &'a [u8],
    lens: BlockLens<'a>,
    first_error: StatusError,
    pos: usize,
    index: usize,
    crc: u16,
    done: bool,
}

impl<'a> FastBlocks<'a> {
    fn new<const N: usize>(packet: &'a StatusPacket<N>, lens: BlockLens<'a>) -> Self {
        // The running CRC starts with everything before ID_1: header, ID,
        // LENGTH (1 + params + ERR_1 + CRC, unstuffed), 0x55, ERR_1.
        let length = packet.params.len() + 4;
        let [l0, l1] = (length.min(u16::MAX as usize) as u16).to_le_bytes();
        let start = [HEADER[0], HEADER[1], HEADER[2], HEADER[3], BROADCAST_ID, l0, l1, STATUS, packet.error.0];
        let uniform_empty = matches!(lens, BlockLens::Uniform(0));
        FastBlocks {
            params: &packet.params,
            lens,
            first_error: packet.error,
            pos: 0,
            index: 0,
            crc: crc16(&start),
            done: packet.id != BROADCAST_ID || uniform_empty,
        }
    }

    fn fail(&mut self, e: FastReplyError) -> Option<Result<FastBlock<'a>, FastReplyError>> {
        self.done = true;
        Some(Err(e))
    }
}

impl<'a> Iterator for FastBlocks<'a> {
    type Item = Result<FastBlock<'a>, FastReplyError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let block = self.index;
        let (len, last_by_count) = match self.lens {
            BlockLens::Uniform(n) => (n as usize, false),
            BlockLens::Each(lens) => match lens.get(block) {
                Some(&n) => (n as usize, block + 1 == lens.len()),
                None => {
                    self.done = true;
                    return None;
                }
            },
        };
        let start = self.pos;
        let error = if block == 0 {
            self.first_error
        } else {
            match self.params.get(self.pos) {
                Some(&e) => {
                    self.pos += 1;
                    StatusError(e)
                }
                None => return self.fail(FastReplyError::Truncated { block }),
            }
        };
        let Some(&id) = self.params.get(self.pos) else {
            return self.fail(FastReplyError::Truncated { block });
        };
        let data_at = self.pos + 1;
        let Some(data) = self.params.get(data_at..data_at + len) else {
            return self.fail(FastReplyError::Truncated { block });
        };
        self.pos = data_at + len;
        self.crc = update_crc(self.crc, self.params.get(start..self.pos).unwrap_or_default());
        let at_end = self.pos == self.params.len();
        let item = FastBlock { id, error, data };
        if at_end || last_by_count {
            // The last block: its CRC is the packet's, which the decoder
            // has checked.
            self.done = true;
            if !at_end {
                return Some(Err(FastReplyError::Trailing { bytes: self.params.len() - self.pos }));
            }
            if matches!(self.lens, BlockLens::Each(lens) if block + 1 != lens.len()) {
                return Some(Err(FastReplyError::Truncated { block: block + 1 }));
            }
            return Some(Ok(item));
        }
        let Some(crc) = self.params.get(self.pos..self.pos + 2) else {
            return self.fail(FastReplyError::Truncated { block });
        };
        if crc != self.crc.to_le_bytes() {
            return self.fail(FastReplyError::BlockCrc { block, id });
        }
        self.crc = update_crc(self.crc, crc);
        self.pos += 2;
        self.index += 1;
        Some(Ok(item))
    }
}

impl<const N: usize> StatusPacket<N> {
    /// The blocks of a fast reply whose data lengths are `lens`, each
    /// checked against its running CRC. A packet that is not a fast reply
    /// yields [`FastReplyError::NotFast`] once.
    pub fn fast_blocks<'a>(&'a self, lens: BlockLens<'a>) -> impl Iterator<Item = Result<FastBlock<'a>, FastReplyError>> + 'a {
        let not_fast = (self.id != BROADCAST_ID).then_some(Err(FastReplyError::NotFast));
        let zero = (self.id == BROADCAST_ID && matches!(lens, BlockLens::Uniform(0)))
            .then_some(Err(FastReplyError::Trailing { bytes: self.params.len() }));
        not_fast.into_iter().chain(zero).chain(FastBlocks::new(self, lens))
    }

    /// Builds the fast reply that carries `blocks` (the bus emulator's
    /// side), with every block's running CRC. Each block's ID must be a
    /// servo's (0–252), and the reply must fit `N` and the 16-bit LENGTH.
    pub fn fast_reply(blocks: &[FastBlock<'_>]) -> Result<Self, EncodeError> {
        let Some(first) = blocks.first() else {
            return Err(EncodeError::BadParams { code: STATUS });
        };
        let body: usize = blocks.iter().map(|b| b.data.len() + BLOCK_OVERHEAD).sum();
        // LENGTH = 0x55 + the blocks (ERR_1 and CRC_n included).
        let length = 1 + body;
        if length > u16::MAX as usize || length - 4 > N {
            return Err(EncodeError::TooLong { bytes: length });
        }
        let [l0, l1] = (length as u16).to_le_bytes();
        let mut crc = crc16(&[HEADER[0], HEADER[1], HEADER[2], HEADER[3], BROADCAST_ID, l0, l1, STATUS, first.error.0]);
        let mut params: Vec<u8, N> = Vec::new();
        let overflow = EncodeError::TooLong { bytes: length };
        for (i, b) in blocks.iter().enumerate() {
            if b.id > MAX_ID {
                return Err(EncodeError::InvalidId { id: b.id });
            }
            let start = params.len();
            if i > 0 {
                params.push(b.error.0).map_err(|_| overflow)?;
            }
            params.push(b.id).map_err(|_| overflow)?;
            params.extend_from_slice(b.data).map_err(|_| overflow)?;
            if i + 1 < blocks.len() {
                crc = update_crc(crc, params.get(start..).unwrap_or_default());
                params.extend_from_slice(&crc.to_le_bytes()).map_err(|_| overflow)?;
                crc = update_crc(crc, &crc.to_le_bytes());
            }
        }
        Ok(StatusPacket { id: BROADCAST_ID, error: first.error, params })
    }
}

/// The parameter count of the fast reply to a Fast Sync Read of `len`
/// bytes from `servos` servos (what the status decoder expects:
/// `LENGTH − 4`), or `None` if it overflows LENGTH.
pub const fn fast_sync_reply_params(servos: usize, len: u16) -> Option<u16> {
    let bytes = servos * (len as usize + BLOCK_OVERHEAD);
    if servos == 0 || bytes + 1 > u16::MAX as usize {
        None
    } else {
        Some((bytes - 3) as u16)
    }
}

/// The parameter count of the fast reply to a Fast Bulk Read with these
/// data lengths, or `None` if it overflows LENGTH.
pub fn fast_bulk_reply_params(lens: &[u16]) -> Option<u16> {
    let bytes: usize = lens.iter().map(|&l| l as usize + BLOCK_OVERHEAD).sum();
    if lens.is_empty() || bytes + 1 > u16::MAX as usize {
        None
    } else {
        Some((bytes - 3) as u16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamixel::v2::crc::crc16;

    /// e-Manual § "Fast Sync Read", Example: IDs 3, 7, 4 (XC330-T288),
    /// Present Position (132, 4 bytes) = 166, 2079, 1023. The three
    /// servos' parts, concatenated, are one status packet.
    const FSR_REPLY: [u8; 32] = [
        0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x19, 0x00, 0x55, // header, ID FE, LENGTH 25, status
        0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x84, 0x08, // ID 3's block
        0x00, 0x07, 0x1F, 0x08, 0x00, 0x00, 0x16, 0xCA, // ID 7's
        0x00, 0x04, 0xFF, 0x03, 0x00, 0x00, 0xD1, 0x9E, // ID 4's (its CRC ends the packet)
    ];

    fn fsr_packet() -> StatusPacket<64> {
        StatusPacket::new(BROADCAST_ID, StatusError(FSR_REPLY[8]), &FSR_REPLY[9..30]).unwrap()
    }

    #[test]
    fn the_manuals_fast_sync_read_reply_is_one_packet_of_running_crcs() {
        assert_eq!(crc16(&FSR_REPLY[..14]), 0x0884);
        assert_eq!(crc16(&FSR_REPLY[..22]), 0xCA16);
        assert_eq!(crc16(&FSR_REPLY[..30]), 0x9ED1);
        let p = fsr_packet();
        let mut buf = [0u8; 64];
        assert_eq!(p.encode(&mut buf).unwrap(), &FSR_REPLY[..]);
        let mut blocks = p.fast_blocks(BlockLens::Uniform(4));
        let want = [(3u8, 166u32), (7, 2079), (4, 1023)];
        for (id, pos) in want {
            let b = blocks.next().unwrap().unwrap();
            assert_eq!((b.id, b.error, u32::from_le_bytes(b.data.try_into().unwrap())), (id, StatusError::NONE, pos));
        }
        assert!(blocks.next().is_none());
        assert_eq!(fast_sync_reply_params(3, 4), Some(p.params.len() as u16));
        // Built back from its blocks, it is the same packet.
        let data: [[u8; 4]; 3] = [[0xA6, 0, 0, 0], [0x1F, 0x08, 0, 0], [0xFF, 0x03, 0, 0]];
        let fb: [FastBlock; 3] = core::array::from_fn(|i| FastBlock { id: want[i].0, error: StatusError::NONE, data: &data[i] });
        assert_eq!(StatusPacket::<64>::fast_reply(&fb).unwrap(), p);
    }

    #[test]
    fn the_manuals_fast_bulk_read_reply_parses_with_its_lengths() {
        // e-Manual § "Fast Bulk Read", Example: ID 3 Present Position (4
        // bytes) = 166, ID 7 Present PWM (2) = 421, ID 4 Present
        // Temperature (1) = 31.
        let raw: [u8; 27] = [
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x14, 0x00, 0x55, 0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x67, 0xA4, 0x00, 0x07,
            0xA5, 0x01, 0x24, 0x74, 0x00, 0x04, 0x1F, 0xD9, 0xC1,
        ];
        assert_eq!(crc16(&raw[..25]), 0xC1D9);
        let p = StatusPacket::<64>::new(BROADCAST_ID, StatusError(0), &raw[9..25]).unwrap();
        let lens = [4u16, 2, 1];
        let got: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Each(&lens)).collect();
        assert_eq!(got.len(), 3);
        assert_eq!(got[1], Ok(FastBlock { id: 7, error: StatusError(0), data: &[0xA5, 0x01] }));
        assert_eq!(got[2], Ok(FastBlock { id: 4, error: StatusError(0), data: &[0x1F] }));
        assert_eq!(fast_bulk_reply_params(&lens), Some(p.params.len() as u16));
        // Wrong lengths do not parse silently.
        let bad: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Each(&[4, 1, 2])).collect();
        assert!(matches!(bad.last(), Some(Err(FastReplyError::BlockCrc { block: 1, .. }))), "{bad:?}");
        let short: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Each(&[4, 2])).collect();
        assert_eq!(short.last(), Some(&Err(FastReplyError::Trailing { bytes: 5 })));
    }

    #[test]
    fn damage_and_misuse_are_errors() {
        let mut p = fsr_packet();
        p.params[6] ^= 1; // ID 3's CRC, high byte
        // A block is yielded only once its CRC has been checked.
        let got: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Uniform(4)).collect();
        assert_eq!(&got[..], &[Err(FastReplyError::BlockCrc { block: 0, id: 3 })]);
        let p = fsr_packet();
        let trunc: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Uniform(5)).collect();
        assert!(matches!(trunc.last(), Some(Err(_))));
        let zero: heapless::Vec<_, 4> = p.fast_blocks(BlockLens::Uniform(0)).collect();
        assert_eq!(&zero[..], &[Err(FastReplyError::Trailing { bytes: 21 })]);
        let one = StatusPacket::<8>::new(1, StatusError(0), &[]).unwrap();
        let not: heapless::Vec<_, 4> = one.fast_blocks(BlockLens::Uniform(4)).collect();
        assert_eq!(&not[..], &[Err(FastReplyError::NotFast)]);
        assert_eq!(StatusPacket::<64>::fast_reply(&[]), Err(EncodeError::BadParams { code: STATUS }));
        let big = [0u8; 60];
        assert!(matches!(
            StatusPacket::<16>::fast_reply(&[FastBlock { id: 1, error: StatusError(0), data: &big }]),
            Err(EncodeError::TooLong { .. })
        ));
        assert_eq!(
            StatusPacket::<16>::fast_reply(&[FastBlock { id: 0xFE, error: StatusError(0), data: &[] }]),
            Err(EncodeError::InvalidId { id: 0xFE })
        );
        assert_eq!(fast_sync_reply_params(0, 4), None);
        assert_eq!(fast_sync_reply_params(10_000, 4), None);
    }
}
