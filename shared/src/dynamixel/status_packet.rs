//! The status packet as both protocols hold it once decoded: the answering
//! servo, its error byte and the parameters, and the reading of parameters
//! as little-endian values. Each protocol names it with its own error byte
//! and encodes it its own way: [`super::packet::StatusPacket`] (Protocol
//! 1.0 and Feetech, [`super::packet::ErrorFlags`]) and
//! [`super::v2::StatusPacket`] ([`super::v2::StatusError`]).

use heapless::Vec;

/// A status packet (a servo's answer) whose error byte is an `E`, owning up
/// to `N` parameter bytes (unstuffed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StatusPacket<E, const N: usize> {
    /// The answering servo (Protocol 2.0: or the broadcast ID, for the
    /// combined reply of a fast read).
    pub id: u8,
    /// The error byte.
    pub error: E,
    /// The parameters: the data read (empty for answers to PING in
    /// Protocol 1.0 and to WRITE; model and firmware for a Protocol 2.0
    /// PING).
    pub params: Vec<u8, N>,
}

impl<E, const N: usize> StatusPacket<E, N> {
    /// Parameter byte `i`.
    pub fn u8_at(&self, i: usize) -> Option<u8> {
        self.params.get(i).copied()
    }

    /// Little-endian 16-bit value at parameter bytes `i, i+1`.
    pub fn u16_at(&self, i: usize) -> Option<u16> {
        Some(u16::from_le_bytes(*self.params.get(i..)?.first_chunk()?))
    }

    /// Little-endian 32-bit value at parameter bytes `i..i+4`.
    pub fn u32_at(&self, i: usize) -> Option<u32> {
        Some(u32::from_le_bytes(*self.params.get(i..)?.first_chunk()?))
    }
}
