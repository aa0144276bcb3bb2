//! The framing: a transport of its own, shared by telemetry, commands and
//! the emulated board's lock-step clock link.
//!
//! ```text
//! frame   = COBS( body ‖ crc32_le(body) ) ‖ 0x00
//! body    = postcard( (seq: u32, message) )
//! ```
//!
//! COBS is the `cobs` crate (the one postcard's own COBS flavour is built
//! on): [`encode_frame`] serialises the body, appends the CRC and encodes
//! into the caller's buffer; the decoder collects the bytes of one frame up
//! to its 0x00 and decodes them in place.
//!
//! A frame is accepted only in its canonical form: its COBS encoding is the
//! one the encoder writes (the same length for the decoded bytes) and its
//! body is the one postcard writes for the decoded value (no overlong
//! varint, no alternative encoding that happens to decode). So every
//! accepted frame re-encodes to exactly the bytes received; anything else
//! is counted as [`FrameError::NonCanonical`].

use crate::crc::CRC32;
use core::marker::PhantomData;
use postcard::ser_flavors::Flavor;
use super::messages::PROTOCOL_VERSION;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::messages::{ToChip, ToHost};

/// Largest postcard body of a frame, sequence number included.
pub const MAX_BODY: usize = 256;
/// Bytes of the CRC after the body.
pub const CRC_LEN: usize = 4;
/// Largest frame on the wire: COBS of body and CRC, plus the 0x00.
pub const MAX_FRAME_LEN: usize = cobs_max_len(MAX_BODY + CRC_LEN) + 1;
/// A forward jump of the sequence number by more than this many frames is
/// counted as a resynchronisation ([`LinkStats::seq_resyncs`]), not as
/// frames missed: at the fastest telemetry rate (one `Step` per 30 ms
/// period plus a `Health` a second, about 35 frames/s) it is more than half
/// an hour of silence, longer than any outage the link recovers from
/// without the sender restarting, and it keeps one damaged number from
/// reporting billions of frames lost.
pub const MAX_SEQ_GAP: u32 = 1 << 16;

/// Longest COBS encoding of `n` bytes.
pub const fn cobs_max_len(n: usize) -> usize {
    n + n / 254 + 1
}

/// Length of the COBS encoding the encoder writes for `data` (without the
/// 0x00): the `cobs` crate's own encoder state machine, counted, so the
/// decoder's canonical check and the encoder cannot disagree.
fn cobs_len(data: &[u8]) -> usize {
    if data.is_empty() {
        return 0;
    }
    let mut state = cobs::EncoderState::default();
    let mut len = 1;
    for (i, &b) in data.iter().enumerate() {
        len += match state.push(b) {
            cobs::PushResult::AddSingle(_) | cobs::PushResult::ModifyFromStartAndSkip(_) => 1,
            // A full 254-byte block: the next block's code byte is written
            // only if more data follows (`cobs::CobsEncoder` leaves no
            // empty block at the end).
            cobs::PushResult::ModifyFromStartAndPushAndSkip(_) if i + 1 == data.len() => 1,
            cobs::PushResult::ModifyFromStartAndPushAndSkip(_) => 2,
        };
    }
    len
}

/// Why a frame could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireError {
    /// The output buffer cannot hold the frame (use [`MAX_FRAME_LEN`]).
    BufferTooSmall,
    /// postcard refused the message (a value it cannot encode).
    Serialize,
}

/// Encodes `msg` with sequence number `seq` into `out` and returns the
/// frame, delimiter included. A buffer of [`MAX_FRAME_LEN`] bytes holds any
/// [`ToHost`] or [`ToChip`] message.
///
/// The body is serialised into a [`MAX_BODY`]-byte buffer on the stack and
/// COBS-encoded from there into `out` by the `cobs` crate. (postcard's own
/// COBS and CRC flavours would encode straight into `out`, but their
/// per-byte `try_push` is inlined into every field of every message: with
/// them the F405 pendulum image was 12 kB larger, 184 716 B of flash
/// against 172 544 B.)
pub fn encode_frame<'b, M: Serialize>(msg: &M, seq: u32, out: &'b mut [u8]) -> Result<&'b [u8], WireError> {
    let mut raw = [0u8; MAX_BODY + CRC_LEN];
    let body_len = match postcard::to_slice(&(seq, msg), &mut raw[..MAX_BODY]) {
        Ok(body) => body.len(),
        Err(postcard::Error::SerializeBufferFull) => return Err(WireError::BufferTooSmall),
        Err(_) => return Err(WireError::Serialize),
    };
    let crc = CRC32.checksum(&raw[..body_len]);
    raw[body_len..body_len + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
    let raw = &raw[..body_len + CRC_LEN];
    let n = cobs::try_encode(raw, out).map_err(|_| WireError::BufferTooSmall)?;
    *out.get_mut(n).ok_or(WireError::BufferTooSmall)? = 0;
    Ok(&out[..=n])
}

/// A postcard flavour that compares what is serialised with `expected`
/// instead of storing it: the canonical check of a decoded body, without a
/// second body-sized buffer.
struct SameAs<'a> {
    expected: &'a [u8],
    at: usize,
}

impl Flavor for SameAs<'_> {
    /// Whether the serialisation was exactly `expected`.
    type Output = bool;

    fn try_push(&mut self, byte: u8) -> postcard::Result<()> {
        match self.expected.get(self.at) {
            Some(&b) if b == byte => {
                self.at += 1;
                Ok(())
            }
            // Stop serialising at the first difference.
            _ => Err(postcard::Error::SerializeBufferFull),
        }
    }

    fn finalize(self) -> postcard::Result<bool> {
        Ok(self.at == self.expected.len())
    }
}

/// Whether postcard writes exactly `body` for `value`.
fn is_canonical<T: Serialize>(value: &T, body: &[u8]) -> bool {
    postcard::serialize_with_flavor(value, SameAs { expected: body, at: 0 }).unwrap_or(false)
}

/// Numbers outgoing frames: 0, 1, 2, … (wrapping).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrameEncoder {
    next_seq: u32,
}

impl FrameEncoder {
    /// Starts at sequence number 0.
    pub const fn new() -> Self {
        FrameEncoder { next_seq: 0 }
    }

    /// The sequence number the next frame gets.
    pub fn next_seq(&self) -> u32 {
        self.next_seq
    }

    /// Encodes `msg` with the next sequence number; the number is used up
    /// only if encoding succeeds.
    pub fn encode<'b, M: Serialize>(&mut self, msg: &M, out: &'b mut [u8]) -> Result<&'b [u8], WireError> {
        let frame = encode_frame(msg, self.next_seq, out)?;
        self.next_seq = self.next_seq.wrapping_add(1);
        Ok(frame)
    }

    /// Counts a frame as sent without sending it (e.g. dropped for a full
    /// queue), so that the receiver sees the gap.
    pub fn skip(&mut self) {
        self.next_seq = self.next_seq.wrapping_add(1);
    }
}

/// The protocol version of a frame body that begins as a
/// [`ToHost::Hello`](super::ToHost::Hello) of any version begins: the
/// sequence number, the message's variant 0 and the `protocol` field, all
/// varints. `None` for any other body. [`Hello::protocol`](super::Hello)
/// is its first field so that this holds for every version.
pub fn hello_protocol(body: &[u8]) -> Option<u16> {
    match postcard::take_from_bytes::<(u32, u32, u16)>(body) {
        Ok(((_seq, 0, protocol), _)) => Some(protocol),
        _ => None,
    }
}

/// Why a frame was lost. Each is also counted in [`LinkStats`], once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// More bytes than the decoder holds before a 0x00.
    Oversize,
    /// Not valid COBS.
    Cobs,
    /// Shorter than a body byte plus the CRC.
    TooShort,
    /// The CRC does not match.
    Crc {
        /// CRC computed over the body.
        computed: u32,
        /// CRC received.
        received: u32,
    },
    /// The CRC matched but postcard could not decode the body (or bytes
    /// were left over): a sender of another protocol version.
    Decode,
    /// The CRC matched and the body decoded, but not from the bytes the
    /// encoder writes for that value (an overlong varint, a COBS block
    /// split differently): refused, so that an accepted frame always
    /// re-encodes to the bytes received.
    NonCanonical,
    /// The input ended inside a frame (bytes after the last 0x00, or a
    /// frame still too long for the buffer): reported by
    /// [`FrameDecoder::finish`].
    Truncated,
}

/// A sequence number other than the one expected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SeqGap {
    /// The number expected.
    pub expected: u32,
    /// The number received.
    pub got: u32,
}

impl SeqGap {
    /// Frames missing in between: the forward distance, if it is at most
    /// [`MAX_SEQ_GAP`]; 0 for a resynchronisation ([`is_resync`](Self::is_resync)).
    pub fn missed(&self) -> u32 {
        if self.is_resync() {
            0
        } else {
            self.got.wrapping_sub(self.expected)
        }
    }

    /// Whether the number jumped too far to count frames: backwards (the
    /// sender restarted) or forwards by more than [`MAX_SEQ_GAP`].
    pub fn is_resync(&self) -> bool {
        self.got.wrapping_sub(self.expected) > MAX_SEQ_GAP
    }
}

/// A decoded frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded<M> {
    /// Its sequence number.
    pub seq: u32,
    /// The message.
    pub msg: M,
    /// Set when `seq` was not the one expected.
    pub gap: Option<SeqGap>,
}

/// What a [`FrameDecoder`] received and lost.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkStats {
    /// Frames decoded.
    pub frames: u32,
    /// Bytes received (delimiters included).
    pub bytes: u64,
    /// Frames with a wrong CRC.
    pub crc_errors: u32,
    /// Frames that were not valid COBS.
    pub cobs_errors: u32,
    /// Frames longer than the decoder's buffer.
    pub oversize: u32,
    /// Frames too short to hold a body and CRC.
    pub too_short: u32,
    /// Frames with a good CRC that postcard could not decode.
    pub decode_errors: u32,
    /// Frames with a good CRC that decoded from a non-canonical encoding.
    pub noncanonical: u32,
    /// A frame cut off by the end of the input ([`FrameDecoder::finish`]).
    pub truncated: u32,
    /// Times the sequence number was not the one expected.
    pub seq_gaps: u32,
    /// Frames missing according to the sequence numbers (gaps of at most
    /// [`MAX_SEQ_GAP`]).
    pub frames_missed: u64,
    /// Gaps too large to count frames in: the number went backwards or
    /// jumped forwards by more than [`MAX_SEQ_GAP`] (also in `seq_gaps`).
    pub seq_resyncs: u32,
}

impl LinkStats {
    /// Frames received but unusable (every error kind).
    pub fn bad_frames(&self) -> u32 {
        self.crc_errors
            .saturating_add(self.cobs_errors)
            .saturating_add(self.oversize)
            .saturating_add(self.too_short)
            .saturating_add(self.decode_errors)
            .saturating_add(self.noncanonical)
            .saturating_add(self.truncated)
    }

    /// Whether nothing was lost at all.
    pub fn is_clean(&self) -> bool {
        self.bad_frames() == 0 && self.seq_gaps == 0
    }

    fn count(&mut self, e: &FrameError) {
        let c = match e {
            FrameError::Oversize => &mut self.oversize,
            FrameError::Cobs => &mut self.cobs_errors,
            FrameError::TooShort => &mut self.too_short,
            FrameError::Crc { .. } => &mut self.crc_errors,
            FrameError::Decode => &mut self.decode_errors,
            FrameError::NonCanonical => &mut self.noncanonical,
            FrameError::Truncated => &mut self.truncated,
        };
        *c = c.saturating_add(1);
    }
}

/// Incremental frame decoder for messages `M` ([`ToHost`] on the host,
/// [`ToChip`] on the chip), holding up to `N` encoded bytes of one frame.
pub struct FrameDecoder<M, const N: usize = MAX_FRAME_LEN> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
    expected: Option<u32>,
    stats: LinkStats,
    foreign_protocol: Option<u16>,
    _msg: PhantomData<fn() -> M>,
}

impl<M: DeserializeOwned + Serialize, const N: usize> Default for FrameDecoder<M, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M: DeserializeOwned + Serialize, const N: usize> FrameDecoder<M, N> {
    /// A decoder that takes the first sequence number it sees as expected.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; N],
            len: 0,
            overflow: false,
            expected: None,
            stats: LinkStats {
                frames: 0,
                bytes: 0,
                crc_errors: 0,
                cobs_errors: 0,
                oversize: 0,
                too_short: 0,
                decode_errors: 0,
                noncanonical: 0,
                truncated: 0,
                seq_gaps: 0,
                frames_missed: 0,
                seq_resyncs: 0,
            },
            foreign_protocol: None,
            _msg: PhantomData,
        }
    }

    /// Counters since creation.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Forgets the expected sequence number (e.g. after the peer restarted
    /// on purpose).
    pub fn resync_seq(&mut self) {
        self.expected = None;
    }

    /// Bytes of the frame in progress (received since the last 0x00).
    pub fn pending(&self) -> usize {
        self.len
    }

    /// The protocol version of a `Hello` this decoder refused because it is
    /// of another version ([`hello_protocol`]), if it saw one: a recording
    /// or a board of another pada, which a reader refuses in one line
    /// rather than counting its frames as damaged.
    pub fn foreign_protocol(&self) -> Option<u16> {
        self.foreign_protocol
    }

    /// Takes one byte; a 0x00 ends a frame, which is then decoded. Returns
    /// `None` for bytes inside a frame and for empty frames (two 0x00 in a
    /// row, which a sender may use to flush the line).
    pub fn push(&mut self, byte: u8) -> Option<Result<Decoded<M>, FrameError>> {
        self.stats.bytes = self.stats.bytes.saturating_add(1);
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                Some(slot) if !self.overflow => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => self.overflow = true,
            }
            return None;
        }
        let (len, overflow) = (self.len, self.overflow);
        self.len = 0;
        self.overflow = false;
        if overflow {
            return Some(Err(self.lost(FrameError::Oversize)));
        }
        if len == 0 {
            return None;
        }
        Some(self.decode(len))
    }

    /// The input has ended: a frame in progress (bytes after the last 0x00)
    /// can never complete, so it is counted as [`FrameError::Truncated`] and
    /// returned. `None` if the input ended on a delimiter. The decoder is
    /// ready for a new stream afterwards (the expected sequence number is
    /// kept).
    pub fn finish(&mut self) -> Option<FrameError> {
        let cut = self.len > 0 || self.overflow;
        self.len = 0;
        self.overflow = false;
        cut.then(|| self.lost(FrameError::Truncated))
    }

    fn lost(&mut self, e: FrameError) -> FrameError {
        self.stats.count(&e);
        e
    }

    fn decode(&mut self, len: usize) -> Result<Decoded<M>, FrameError> {
        let frame = &mut self.buf[..len.min(N)];
        let Ok(n) = cobs::decode_in_place(frame) else {
            return Err(self.lost(FrameError::Cobs));
        };
        if n < 1 + CRC_LEN {
            return Err(self.lost(FrameError::TooShort));
        }
        let (body, crc) = frame[..n].split_at(n - CRC_LEN);
        let received = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
        let computed = CRC32.checksum(body);
        if computed != received {
            return Err(self.lost(FrameError::Crc { computed, received }));
        }
        let value = match postcard::take_from_bytes::<(u32, M)>(body) {
            Ok((v, [])) => v,
            _ => {
                if let Some(found) = hello_protocol(body).filter(|p| *p != PROTOCOL_VERSION) {
                    self.foreign_protocol = Some(found);
                }
                return Err(self.lost(FrameError::Decode));
            }
        };
        if cobs_len(&frame[..n]) != len || !is_canonical(&value, body) {
            return Err(self.lost(FrameError::NonCanonical));
        }
        let (seq, msg) = value;
        let s = &mut self.stats;
        let gap = match self.expected {
            Some(expected) if expected != seq => {
                let g = SeqGap { expected, got: seq };
                s.seq_gaps = s.seq_gaps.saturating_add(1);
                if g.is_resync() {
                    s.seq_resyncs = s.seq_resyncs.saturating_add(1);
                }
                s.frames_missed = s.frames_missed.saturating_add(g.missed() as u64);
                Some(g)
            }
            _ => None,
        };
        self.expected = Some(seq.wrapping_add(1));
        s.frames = s.frames.saturating_add(1);
        Ok(Decoded { seq, msg, gap })
    }

    /// Feeds a chunk and iterates over the frames and losses it completes;
    /// a partial frame at the end waits for the next chunk (or
    /// [`finish`](Self::finish)).
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> FrameFeed<'s, 'b, M, N> {
        FrameFeed { decoder: self, rest: bytes }
    }
}

/// Iterator returned by [`FrameDecoder::feed`].
pub struct FrameFeed<'s, 'b, M, const N: usize> {
    decoder: &'s mut FrameDecoder<M, N>,
    rest: &'b [u8],
}

impl<M: DeserializeOwned + Serialize, const N: usize> Iterator for FrameFeed<'_, '_, M, N> {
    type Item = Result<Decoded<M>, FrameError>;
    fn next(&mut self) -> Option<Self::Item> {
        while let Some((&b, rest)) = self.rest.split_first() {
            self.rest = rest;
            if let Some(r) = self.decoder.push(b) {
                return Some(r);
            }
        }
        None
    }
}

/// The host's decoder of chip telemetry.
pub type HostDecoder = FrameDecoder<ToHost, MAX_FRAME_LEN>;
/// The chip's decoder of host commands.
pub type ChipDecoder = FrameDecoder<ToChip, MAX_FRAME_LEN>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cobs_len_is_the_encoders_length() {
        let mut buf = [0u8; 700];
        for len in [0usize, 1, 2, 253, 254, 255, 508, 509, 600] {
            for fill in [0u8, 1, 0x55] {
                let data = [fill; 600];
                let data = &data[..len];
                let n = cobs::try_encode(data, &mut buf).unwrap();
                assert_eq!(cobs_len(data), n, "len {len} fill {fill}");
                assert!(n <= cobs_max_len(len));
            }
        }
    }

    #[test]
    fn same_as_flavour_finds_differences() {
        let body = postcard::to_slice(&(300u32, 7u8), &mut [0u8; 8]).unwrap().to_vec_like();
        assert!(is_canonical(&(300u32, 7u8), &body));
        assert!(!is_canonical(&(300u32, 8u8), &body));
        assert!(!is_canonical(&(300u32, 7u8), &body[..body.len() - 1]));
    }

    trait ToVecLike {
        fn to_vec_like(&self) -> heapless::Vec<u8, 16>;
    }
    impl ToVecLike for [u8] {
        fn to_vec_like(&self) -> heapless::Vec<u8, 16> {
            heapless::Vec::from_slice(self).unwrap()
        }
    }
}
