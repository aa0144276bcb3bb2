//! The two hashes of the project: CRC-32 of telemetry frames and checkpoints,
//! and the FNV-1a configuration hash stored in checkpoints and `Hello`.
//!
//! One module for both so that the wire framing and the checkpoint slots
//! import their integrity check from here rather than from each other.
//!
//! CRC-32 is the `crc` crate's table-driven CRC-32/ISO-HDLC (the
//! zlib/Ethernet CRC), one 1 KB table in flash. FNV-1a is written out: it
//! is four lines, and the value is a stored format (a crate's changed
//! default would silently orphan every saved checkpoint).

/// CRC-32/ISO-HDLC (polynomial 0x04C11DB7 reflected, init and xor-out
/// 0xFFFFFFFF), used by checkpoints and telemetry frames.
pub static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// CRC-32 of `bytes` (see [`CRC32`]).
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// FNV-1a (32 bit) of a configuration's byte description: the value stored
/// in a checkpoint's header and compared at load.
pub fn config_hash(bytes: &[u8]) -> u32 {
    let mut h = ConfigHasher::new();
    h.write(bytes);
    h.finish()
}

/// Incremental FNV-1a (32 bit), to describe a configuration field by field
/// without building a byte buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigHasher(u32);

impl Default for ConfigHasher {
    fn default() -> Self {
        Self::new()
    }
}

impl ConfigHasher {
    const OFFSET: u32 = 0x811C_9DC5;
    const PRIME: u32 = 0x0100_0193;

    /// A hasher at FNV-1a's offset basis.
    pub const fn new() -> Self {
        ConfigHasher(Self::OFFSET)
    }
    /// Adds bytes.
    pub fn write(&mut self, bytes: &[u8]) -> &mut Self {
        for &b in bytes {
            self.0 = (self.0 ^ b as u32).wrapping_mul(Self::PRIME);
        }
        self
    }
    /// Adds a `u32`, little endian.
    pub fn write_u32(&mut self, v: u32) -> &mut Self {
        self.write(&v.to_le_bytes())
    }
    /// Adds an `f32` by its bit pattern, little endian.
    pub fn write_f32(&mut self, v: f32) -> &mut Self {
        self.write_u32(v.to_bits())
    }
    /// Adds a string's bytes and its length (so `"ab","c"` ≠ `"a","bc"`).
    pub fn write_str(&mut self, s: &str) -> &mut Self {
        self.write_u32(s.len() as u32).write(s.as_bytes())
    }
    /// The hash.
    pub fn finish(&self) -> u32 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_reference_values() {
        assert_eq!(config_hash(b""), 0x811C_9DC5);
        assert_eq!(config_hash(b"a"), 0xE40C_292C);
        assert_eq!(config_hash(b"foobar"), 0xBF9C_F968);
        let mut h = ConfigHasher::new();
        h.write(b"foo").write(b"bar");
        assert_eq!(h.finish(), config_hash(b"foobar"));
        let (mut a, mut b) = (ConfigHasher::new(), ConfigHasher::new());
        a.write_str("ab").write_str("c");
        b.write_str("a").write_str("bc");
        assert_ne!(a.finish(), b.finish());
    }

    #[test]
    fn crc32_check_value() {
        // The catalogue's check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }
}
