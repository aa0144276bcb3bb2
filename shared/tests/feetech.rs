//! Feetech's protocol against its reference page: the STS3215 memory map
//! in docs/reference/feetech.md is the table the code holds, and a SYNC
//! READ's replies decode one after another with the shared decoder.

use pada_core::feetech::{self, control_table::sts3215::STS3215, ErrorFlags, Reply, StatusDecoder, StatusPacket};

#[test]
fn the_reference_page_holds_the_sts3215_table() {
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/reference/feetech.md")).unwrap();
    let table = STS3215.markdown().to_string();
    assert!(page.contains(&table), "docs/reference/feetech.md must hold, verbatim:\n{table}");
}

#[test]
fn a_sync_reads_replies_decode_in_turn_and_every_byte_is_counted() {
    let mut wire = Vec::new();
    let mut buf = [0u8; 32];
    wire.extend_from_slice(&[0x00, 0xFF]); // noise before the first reply
    for id in 1..=6u8 {
        let p = StatusPacket::<32>::new(id, ErrorFlags::NONE, &[id, 8, 0, 0, 0, 0, 74, 40]).unwrap();
        wire.extend_from_slice(p.encode(&mut buf).unwrap());
    }
    let mut dec = StatusDecoder::<32>::new();
    let mut next = 1u8;
    dec.expect(Some(Reply { id: next, params: 8 }));
    for &b in &wire {
        let mut r = dec.push(b);
        while let Some(got) = r {
            let p = got.unwrap();
            assert_eq!((p.id, feetech::ByteOrder::Little.u16_at(&p.params, 0)), (next, Some(0x0800 | next as u16)));
            next += 1;
            dec.expect(Some(Reply { id: next, params: 8 }));
            r = dec.poll();
        }
    }
    assert_eq!(next, 7);
    let s = dec.stats();
    assert_eq!((s.packets, s.skipped_bytes, dec.buffered()), (6, 2, 0));
}
