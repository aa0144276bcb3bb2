//! The CRC-16 of Protocol 2.0 (e-Manual, "CRC Calculation",
//! <https://emanual.robotis.com/docs/en/dxl/crc/>, cited from the packet
//! pages' "CRC" sections): polynomial 0x8005 (x¹⁶ + x¹⁵ + x² + 1), initial
//! value 0, no reflection, no final XOR, over every byte of the packet from
//! the first header byte to the last parameter (after byte stuffing). The
//! e-Manual's `update_crc(crc_accum, data, size)` is a table-driven loop:
//! `i = ((crc >> 8) ^ byte) & 0xFF; crc = (crc << 8) ^ table[i]`, whose
//! table starts 0x0000, 0x8005, 0x800F, 0x000A.
//!
//! That algorithm is the catalogued CRC-16/UMTS (also called BUYPASS), which
//! the `crc` crate (already pada-core's CRC-32) provides with a 512-byte
//! table in flash; [`update_crc`] continues a running CRC the way the
//! e-Manual's function does (the Fast Sync Read reply's per-servo CRCs are
//! running CRCs of the one packet). The tests check the table against the
//! e-Manual's first entries, against a bit-by-bit division, and every
//! worked example packet of the Protocol 2.0 page byte for byte
//! (docs/reference/dynamixel.md §2).

/// The CRC-16 of Protocol 2.0 (CRC-16/UMTS: polynomial 0x8005, init 0, not
/// reflected, no final XOR).
pub static CRC16: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_UMTS);

/// The CRC of `bytes` from a fresh start (the e-Manual's
/// `update_crc(0, bytes, len)`).
pub fn crc16(bytes: &[u8]) -> u16 {
    CRC16.checksum(bytes)
}

/// Continues the running CRC `crc` over `bytes` (the e-Manual's
/// `update_crc(crc, bytes, len)`): `update_crc(update_crc(0, a), b)` is the
/// CRC of `a` followed by `b`.
pub fn update_crc(crc: u16, bytes: &[u8]) -> u16 {
    let mut digest = CRC16.digest_with_initial(crc);
    digest.update(bytes);
    digest.finalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The e-Manual's algorithm written out bit by bit (polynomial
    /// division, MSB first), independent of any table.
    fn bitwise(mut crc: u16, bytes: &[u8]) -> u16 {
        for &b in bytes {
            crc ^= (b as u16) << 8;
            for _ in 0..8 {
                crc = if crc & 0x8000 != 0 { (crc << 1) ^ 0x8005 } else { crc << 1 };
            }
        }
        crc
    }

    #[test]
    fn the_table_starts_as_the_e_manuals() {
        // e-Manual "CRC Calculation": crc_table[256] = {0x0000, 0x8005,
        // 0x800F, 0x000A, 0x801B, 0x001E, 0x0014, 0x8011, 0x8033, …,
        // 0x8207, 0x0202} (the last two entries of the table).
        let t = &CRC16.table()[0];
        assert_eq!(&t[..9], &[0x0000, 0x8005, 0x800F, 0x000A, 0x801B, 0x001E, 0x0014, 0x8011, 0x8033]);
        assert_eq!(&t[254..], &[0x8207, 0x0202]);
    }

    #[test]
    fn agrees_with_the_bitwise_division_and_runs_on() {
        let data: [u8; 12] = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x00, 0x80, 0x7F, 0xFE];
        for split in 0..=data.len() {
            let (a, b) = data.split_at(split);
            assert_eq!(update_crc(update_crc(0, a), b), crc16(&data));
        }
        assert_eq!(crc16(&data), bitwise(0, &data));
        // The catalogue's check value of CRC-16/UMTS.
        assert_eq!(crc16(b"123456789"), 0xFEE8);
        assert_eq!(bitwise(0, b"123456789"), 0xFEE8);
    }
}
