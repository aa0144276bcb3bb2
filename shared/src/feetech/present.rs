//! One servo's present block (Present Position … Present Temperature,
//! addresses 56–63 of the STS memory table), as a SYNC READ or READ
//! returns it, decoded in the servo's byte order and with Feetech's sign
//! bits (docs/reference/feetech.md § "Values"): what the firmware's
//! Feetech bus gives the controller every period.
//!
//! | bytes | item | decoded as |
//! |---|---|---|
//! | 0–1 | Present Position (56) | steps, sign bit 15 |
//! | 2–3 | Present Velocity (58) | steps/s, sign bit 15 |
//! | 4–5 | Present Load (60) | 0.1 % of the drive, sign bit 10 |
//! | 6 | Present Voltage (62) | 0.1 V |
//! | 7 | Present Temperature (63) | °C |

use super::control_table::sts3215::PRESENT_BLOCK_LEN;
use super::value::{from_sign_magnitude, LOAD_SIGN_BIT, POSITION_SIGN_BIT, VELOCITY_SIGN_BIT};
use super::ByteOrder;
use crate::servo::Present;

/// The present block of `bytes` (at least [`PRESENT_BLOCK_LEN`] of them)
/// in `order`; `None` if it is shorter.
pub fn present(bytes: &[u8], order: ByteOrder) -> Option<Present> {
    let block = bytes.get(..PRESENT_BLOCK_LEN as usize)?;
    let signed = |i: usize, bit: u8| order.u16_at(block, i).map(|raw| from_sign_magnitude(raw, bit));
    Some(Present {
        position: signed(0, POSITION_SIGN_BIT)?,
        speed: signed(2, VELOCITY_SIGN_BIT)?,
        load: signed(4, LOAD_SIGN_BIT)?,
        voltage_dv: *block.get(6)? as u16,
        temperature: *block.get(7)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_and_byte_orders() {
        // 3000 steps, -100 steps/s, load -50 (0.1 %), 7.4 V, 35 °C.
        let le = [0xB8, 0x0B, 0x64, 0x80, 0x32, 0x04, 74, 35];
        let p = present(&le, ByteOrder::Little).unwrap();
        assert_eq!(p, Present { position: 3000, speed: -100, load: -50, voltage_dv: 74, temperature: 35 });
        let be = [0x0B, 0xB8, 0x80, 0x64, 0x04, 0x32, 74, 35];
        assert_eq!(present(&be, ByteOrder::Big), Some(p));
        assert_eq!(present(&le[..7], ByteOrder::Little), None);
        // A position past bit 15 reads negative (a multi-turn mode).
        assert_eq!(present(&[0x01, 0x80, 0, 0, 0, 0, 0, 0], ByteOrder::Little).unwrap().position, -1);
    }
}
