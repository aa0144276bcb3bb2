//! The stream against the flash slot: a streamed save reassembles into the
//! bytes `save` writes and loads back; every kind of damage is refused with
//! its own variant; random images and random damage never complete.

extern crate std;

use super::*;
use crate::checkpoint::record::{LearnerState, STATE_LEN};
use crate::checkpoint::slots::{load, save, slot_len, Header, HeaderError, LoadOutcome, FORMAT_VERSION, HEADER_LEN};
use crate::checkpoint::store::{CheckpointStore, RamStore};
use crate::checkpoint::wear::FlashWear;
use crate::claim_table::{ClaimTable, InitialWeights, Tags16};
use crate::fixed::Q16;
use crate::weights::{Half, WeightStore};
use proptest::prelude::*;
use rand_core::RngCore;
use std::format;
use std::string::ToString;
use std::vec;
use std::vec::Vec;

const HASH: u32 = 0xC0FF_EE00;

/// A learner state that differs with `seed`.
fn state(seed: u32) -> LearnerState {
    let mut s = LearnerState::default();
    s.agent.stats.steps = 1000 * seed as u64;
    s.agent.stats.episodes = seed;
    s.rng.state = 0x1234_5678_9abc_def0 ^ seed as u64;
    s.rng.increment = 0x0f0f_0f0f_0f0f_0f0f | 1;
    s.user = [seed, 2 * seed, 0, 7];
    s
}

/// The record `save` writes for `state(seed)` as the first save into an
/// empty store: its wear counts that save's erase of slot 0.
fn saved_record(seed: u32) -> [u8; STATE_LEN] {
    let mut s = state(seed);
    s.wear = FlashWear { erases: [1, 0], operating_s: 0 };
    s.to_bytes()
}

/// A plain table of `n` weights, a third of them zero.
fn plain(n: usize) -> Vec<Q16> {
    (0..n as i32).map(|i| if i % 3 == 0 { Q16::ZERO } else { Q16(i.wrapping_mul(0x0101_0101) ^ 0x55) }).collect()
}

type LeoTable = ClaimTable<Half<Vec<i16>, 12>, Tags16<Vec<u16>>>;

/// A claim table as LEO's on the F429 (16-bit weights, 16-bit tags) of
/// `slots` slots with `claims` features claimed.
fn claim_table(slots: usize, claims: u32, seed: u64) -> LeoTable {
    let mut t = ClaimTable::new(Half::new(vec![0i16; slots]), Tags16(vec![0u16; slots])).unwrap();
    t.reset(InitialWeights { seed, lo: -(1 << 16), span: 1 << 17 });
    let mut rng = rand_pcg::Pcg32::new(seed, 0x0a02_bdbf_7bb3_c0a7);
    while t.occupancy().claimed < claims {
        t.claim(rng.next_u32());
    }
    t
}

/// All chunks of `image` in `order`.
fn chunks_of<S: ImageSource + ?Sized>(image: &S, order: Order) -> Vec<Chunk> {
    Chunker::new(image, order).unwrap().collect()
}

/// The bytes of an image source.
fn bytes_of<S: ImageSource + ?Sized>(image: &S) -> Vec<u8> {
    let mut v = vec![0u8; image.image_len()];
    image.read(0, &mut v);
    v
}

/// Feeds `chunks` to a fresh assembler over a buffer of `len` bytes of
/// 0xFF; every outcome, the buffer.
type Outcomes = Vec<Result<Progress, AssembleError<assembler::OutsideSlice>>>;
fn feed(chunks: &[Chunk], order: Order, expect: Expect, len: usize) -> (Outcomes, Vec<u8>) {
    let mut buf = vec![0xFFu8; len];
    let mut a = Assembler::new(&mut buf[..], order, expect);
    let outcomes = chunks.iter().map(|c| a.accept(c)).collect();
    (outcomes, buf)
}

fn completed(outcomes: &Outcomes) -> bool {
    outcomes.iter().any(|o| matches!(o, Ok(Progress::Complete(_))))
}

/// Writes an image into slot 0 of a store.
fn store_with<const N: usize>(image: &[u8]) -> RamStore<N> {
    let mut store = RamStore::<N>::new();
    store.write(0, 0, image).unwrap();
    store
}

#[test]
fn a_streamed_save_of_a_plain_table_is_the_flash_slot_byte_for_byte_and_loads() {
    const N: usize = 300;
    const LEN: usize = slot_len(N, 4);
    let weights = plain(N);
    let mut flash = RamStore::<LEN>::new();
    save(&mut flash, HASH, &state(3), &weights).unwrap();

    let record = saved_record(3);
    let image = TableImage::new(HASH, 1, &record, &weights[..]).unwrap();
    assert_eq!(image.image_len(), LEN);
    let chunks = chunks_of(&image, Order::HeaderLast);
    assert_eq!(chunks.last().map(|c| c.offset), Some(0), "the header goes last in a save");
    assert!(chunks[..chunks.len() - 1].windows(2).all(|w| w[0].offset < w[1].offset));
    let (outcomes, buf) = feed(&chunks, Order::HeaderLast, Expect::default(), LEN);
    assert!(outcomes[..chunks.len() - 1].iter().all(|o| *o == Ok(Progress::More)));
    assert_eq!(outcomes.last(), Some(&Ok(Progress::Complete(image.header()))));
    assert_eq!(&buf[..], &flash.slot(0).unwrap()[..], "the reassembled image is the slot save wrote");

    let store: RamStore<LEN> = store_with(&buf);
    let mut st = LearnerState::default();
    let mut out = vec![Q16(9); N];
    assert_eq!(load(&store, HASH, &mut st, &mut out), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
    assert_eq!(out, weights);
    st.wear = FlashWear::default();
    assert_eq!(st, state(3));
}

#[test]
fn a_streamed_save_of_a_claim_table_is_the_flash_slot_byte_for_byte_and_loads() {
    const SLOTS: usize = 1024;
    const LEN: usize = slot_len(SLOTS, 4);
    let table = claim_table(SLOTS, 300, 5);
    let mut flash = RamStore::<LEN>::new();
    save(&mut flash, HASH, &state(4), &table).unwrap();

    let record = saved_record(4);
    let image = TableImage::new(HASH, 1, &record, &table).unwrap();
    for order in [Order::HeaderLast, Order::HeaderFirst] {
        let chunks = chunks_of(&image, order);
        let (outcomes, buf) = feed(&chunks, order, Expect { config_hash: Some(HASH), ..Expect::default() }, LEN);
        assert_eq!(outcomes.last(), Some(&Ok(Progress::Complete(image.header()))), "{order:?}");
        assert_eq!(&buf[..], &flash.slot(0).unwrap()[..], "{order:?}");
    }

    let store: RamStore<LEN> = store_with(&bytes_of(&image));
    let mut st = LearnerState::default();
    let mut back = claim_table(SLOTS, 0, 5);
    assert_eq!(load(&store, HASH, &mut st, &mut back), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
    for i in 0..SLOTS {
        assert_eq!(back.tag(i), table.tag(i), "tag {i}");
        assert_eq!(back.get(i), table.get(i), "weight {i}");
    }
    st.wear = FlashWear::default();
    assert_eq!(st, state(4));
}

#[test]
fn a_restore_sends_the_header_first_and_a_kept_slot_streams_back_unchanged() {
    const N: usize = 64;
    const LEN: usize = slot_len(N, 4);
    let weights = plain(N);
    let mut flash = RamStore::<LEN>::new();
    save(&mut flash, HASH, &state(1), &weights).unwrap();
    let slot: &[u8] = &flash.slot(0).unwrap()[..];
    let chunks = chunks_of(slot, Order::HeaderFirst);
    assert_eq!(chunks[0].offset, 0);
    let (outcomes, buf) = feed(&chunks, Order::HeaderFirst, Expect::default(), LEN);
    assert!(completed(&outcomes));
    assert_eq!(&buf[..], slot);
}

#[test]
fn bytes_past_the_end_of_an_image_read_as_zero_from_a_slice_as_from_a_table() {
    // The trait's promise, for an image in memory: a read that runs past
    // the end fills the rest with zeros, whatever `out` held before.
    let image = [0u8; 64];
    let mut out = [0xEE; 8];
    ImageSource::read(&image[..], 60, &mut out);
    assert_eq!(out, [0; 8]);
    let mut out = [0xEE; 4];
    ImageSource::read(&image[..], 1000, &mut out);
    assert_eq!(out, [0; 4], "a read wholly past the end");
    // A slice and a table image of the same bytes read alike at every
    // offset around the end, into a buffer that held other bytes.
    let weights = plain(7);
    let record = saved_record(3);
    let table = TableImage::new(HASH, 1, &record, &weights[..]).unwrap();
    let bytes = bytes_of(&table);
    let len = bytes.len();
    for offset in len - 12..len + 4 {
        let (mut a, mut b) = ([0xA5u8; 16], [0x5Au8; 16]);
        ImageSource::read(&bytes[..], offset, &mut a);
        table.read(offset, &mut b);
        assert_eq!(a, b, "offset {offset} of {len}");
    }
}

#[test]
fn zero_words_and_zero_windows_are_not_sent() {
    let weights = vec![Q16::ZERO; 4096];
    let record = [0u8; STATE_LEN];
    let image = TableImage::new(HASH, 1, &record, &weights[..]).unwrap();
    let chunks = chunks_of(&image, Order::HeaderLast);
    // A zero record and zero table: one run, then the header.
    assert_eq!(chunks.len(), 2);
    assert_eq!(chunks[0].body, Body::Zeros { windows: ((STATE_LEN + 4 * 4096) / WINDOW) as u32 });
    assert_eq!(chunks[0].covered_len() as usize, STATE_LEN + 4 * 4096);
    // One nonzero word in a window costs that word.
    let mut weights = weights;
    weights[100] = Q16(7);
    let image = TableImage::new(HASH, 1, &record, &weights[..]).unwrap();
    let chunks = chunks_of(&image, Order::HeaderLast);
    assert_eq!(chunks.len(), 4, "{chunks:?}");
    let Body::Words { mask, words } = &chunks[1].body else { panic!("{:?}", chunks[1]) };
    assert_eq!(mask.count_ones(), 1);
    assert_eq!(words.len(), 4);
    assert_eq!(chunks[1].encoded_len(), 21 + 4);
    let (outcomes, buf) = feed(&chunks, Order::HeaderLast, Expect::default(), image.image_len());
    assert!(completed(&outcomes));
    assert_eq!(buf, bytes_of(&image));
}

#[test]
fn every_chunk_encodes_and_decodes_to_itself_within_the_bound() {
    let table = claim_table(512, 100, 9);
    let record = saved_record(2);
    let image = TableImage::new(HASH, 77, &record, &table).unwrap();
    let mut buf = [0u8; MAX_ENCODED_LEN];
    for c in chunks_of(&image, Order::HeaderFirst) {
        let n = c.encode(&mut buf).unwrap();
        assert!(n <= MAX_ENCODED_LEN);
        assert_eq!(n, c.encoded_len());
        assert_eq!(Chunk::decode(&buf[..n]), Ok(c.clone()));
        assert!(c.is_intact());
        assert_eq!(c.encode(&mut buf[..n - 1]), Err(ChunkError::BufferTooSmall { needed: n, got: n - 1 }));
        assert!(matches!(
            Chunk::decode(&buf[..n - 1]),
            Err(ChunkError::PayloadLength { .. } | ChunkError::Truncated { .. })
        ));
    }
}

#[test]
fn malformed_bytes_are_refused_by_decode_with_their_cause() {
    let c = Chunk::words(1, 2000, 32, &[1u8; WINDOW]);
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let n = c.encode(&mut buf).unwrap();
    assert_eq!(Chunk::decode(&buf[..5]), Err(ChunkError::Truncated { needed: 21, got: 5 }));
    let mut b = buf;
    b[0] = 7;
    assert_eq!(Chunk::decode(&b[..n]), Err(ChunkError::UnknownKind { found: 7 }));
    let mut long = [0u8; MAX_ENCODED_LEN + 4];
    long[..n].copy_from_slice(&buf[..n]);
    assert_eq!(Chunk::decode(&long[..n + 4]), Err(ChunkError::PayloadLength { expected: 128, found: 132 }));
    let odd = Chunk::words(1, 2000, 33, &[1u8; WINDOW]);
    let n = odd.encode(&mut buf).unwrap();
    assert_eq!(Chunk::decode(&buf[..n]), Err(ChunkError::NotAWindow { offset: 33, image_len: 2000 }));
    let bad_len = Chunk::zeros(1, 2002, 32, 1);
    let n = bad_len.encode(&mut buf).unwrap();
    assert_eq!(Chunk::decode(&buf[..n]), Err(ChunkError::BadImageLength { image_len: 2002 }));
    // 1968 body bytes are 16 windows, the last short: a 17th is past the end.
    assert_eq!(Chunk::zeros(1, 2000, 32, 16).check(), Ok(()));
    let past_end = Chunk::zeros(1, 2000, 32, 17);
    let n = past_end.encode(&mut buf).unwrap();
    assert_eq!(Chunk::decode(&buf[..n]), Err(ChunkError::BadRun { offset: 32, windows: 17 }));
    // The header window has 8 words: a ninth mask bit is refused.
    let mut header = Chunk::words(1, 2000, 0, &[1u8; 32]);
    if let Body::Words { mask, words } = &mut header.body {
        *mask |= 1 << 8;
        words.extend_from_slice(&[1, 1, 1, 1]).unwrap();
    }
    assert_eq!(header.check(), Err(ChunkError::MaskBeyondWindow { mask: 0x1FF, words: 8 }));
    assert!(ChunkError::MaskBeyondWindow { mask: 0x1FF, words: 8 }.to_string().contains("valid are bits 0..8"));
}

#[test]
fn the_chunker_refuses_an_image_without_a_valid_header_or_of_another_length() {
    let weights = plain(16);
    let record = saved_record(1);
    let mut image = bytes_of(&TableImage::new(HASH, 1, &record, &weights[..]).unwrap());
    assert!(matches!(Chunker::new(&image[..image.len() - 4], Order::HeaderLast), Err(ChunkerError::Length { .. })));
    image[0] ^= 1;
    assert_eq!(Chunker::new(&image[..], Order::HeaderLast).err(), Some(ChunkerError::BadHeader(HeaderError::Corrupt)));
}

/// A small image, its chunks in a save, and its bytes.
fn small(generation: u32, seed: u32) -> (Vec<u8>, Vec<Chunk>) {
    let weights = plain(200 + seed as usize);
    let record = saved_record(seed);
    let image = TableImage::new(HASH, generation, &record, &weights[..]).unwrap();
    (bytes_of(&image), chunks_of(&image, Order::HeaderLast))
}

/// The refusal of `bad` fed after `good` (all accepted), and whether the
/// assembler then still completes with the rest of `good`'s stream.
fn refusal_after(
    chunks: &[Chunk],
    at: usize,
    bad: &Chunk,
    order: Order,
    expect: Expect,
) -> AssembleError<assembler::OutsideSlice> {
    let len = chunks[0].image_len as usize;
    let mut buf = vec![0xFFu8; len];
    let mut a = Assembler::new(&mut buf[..], order, expect);
    for c in &chunks[..at] {
        a.accept(c).unwrap();
    }
    let refusal = a.accept(bad).unwrap_err();
    // A refused chunk changes nothing: the rest of the stream completes.
    let mut last = None;
    for c in &chunks[at..] {
        last = Some(a.accept(c));
    }
    assert!(matches!(last, Some(Ok(Progress::Complete(_)))), "{refusal:?} then {last:?}");
    refusal
}

#[test]
fn each_kind_of_damage_is_refused_with_its_own_variant() {
    let (_, chunks) = small(5, 1);
    let (_, other) = small(6, 1);
    let (_, longer) = small(5, 9);
    let save = Order::HeaderLast;
    let none = Expect::default();

    // Out of order: the third chunk in place of the second.
    let e = refusal_after(&chunks, 1, &chunks[2], save, none);
    assert_eq!(e, AssembleError::OutOfOrder { expected: chunks[1].offset, found: chunks[2].offset });
    assert!(e.to_string().contains(&format!("expected offset {}", chunks[1].offset)), "{e}");
    // Another generation mid-stream.
    let e = refusal_after(&chunks, 3, &other[3], save, none);
    assert_eq!(e, AssembleError::GenerationChanged { expected: 5, found: 6 });
    assert!(e.to_string().contains("expected generation 5"), "{e}");
    // Another image length mid-stream.
    let e = refusal_after(&chunks, 3, &longer[3], save, none);
    assert_eq!(e, AssembleError::WrongLength { expected: chunks[0].image_len, found: longer[0].image_len });
    // A corrupt chunk: a flipped payload bit.
    let w = (1..chunks.len()).find(|&k| matches!(chunks[k].body, Body::Words { .. })).unwrap();
    let mut bad = chunks[w].clone();
    if let Body::Words { words, .. } = &mut bad.body {
        words[0] ^= 0x10;
    }
    let e = refusal_after(&chunks, w, &bad, save, none);
    assert!(
        matches!(e, AssembleError::Corrupt { offset, carried, .. } if offset == bad.offset && carried == bad.crc),
        "{e:?}"
    );
    // A malformed one.
    let mut bad = chunks[2].clone();
    bad.offset += 4;
    assert!(matches!(
        refusal_after(&chunks, 2, &bad, save, none),
        AssembleError::Malformed(ChunkError::NotAWindow { .. })
    ));
    // Another configuration, when told the expected one.
    let expect = Expect { config_hash: Some(HASH ^ 1), ..none };
    let (outcomes, buf) = feed(&chunks, save, expect, chunks[0].image_len as usize);
    assert_eq!(outcomes.last(), Some(&Err(AssembleError::ConfigMismatch { expected: HASH ^ 1, found: HASH })));
    assert!(buf[..HEADER_LEN].iter().all(|&b| b == 0xFF), "a refused header is not written");
    // Stale: not newer than the generation the receiver has.
    for have in [5, 6, 5 + (1 << 31)] {
        let (outcomes, _) =
            feed(&chunks, save, Expect { newer_than: Some(have), ..none }, chunks[0].image_len as usize);
        assert_eq!(outcomes[0], Err(AssembleError::Stale { have, found: 5 }));
        assert!(!completed(&outcomes));
    }
    let (outcomes, _) = feed(&chunks, save, Expect { newer_than: Some(4), ..none }, chunks[0].image_len as usize);
    assert!(completed(&outcomes));
    // A wrong total length, when told the expected one.
    let expect = Expect { image_len: Some(chunks[0].image_len + 4), ..none };
    let (outcomes, _) = feed(&chunks, save, expect, chunks[0].image_len as usize);
    assert_eq!(
        outcomes[0],
        Err(AssembleError::WrongLength { expected: chunks[0].image_len + 4, found: chunks[0].image_len })
    );
    // Nothing after completion.
    let (outcomes, _) =
        feed(&[chunks.clone(), vec![chunks[0].clone()]].concat(), save, none, chunks[0].image_len as usize);
    assert_eq!(outcomes.last(), Some(&Err(AssembleError::AlreadyComplete { generation: 5 })));
}

/// The header window of `header` as a chunk of a stream of `len` bytes.
fn header_chunk(header: &Header, generation: u32, len: u32) -> Chunk {
    Chunk::words(generation, len, 0, &header.to_bytes())
}

#[test]
fn a_bad_header_is_refused_before_any_entry_is_written() {
    let (image, chunks) = small(5, 1);
    let len = image.len() as u32;
    let mut hb = [0u8; HEADER_LEN];
    hb.copy_from_slice(&image[..HEADER_LEN]);
    let header = Header::parse(&hb).unwrap();
    let restore = Order::HeaderFirst;
    let feed_header = |c: &Chunk| {
        let mut buf = vec![0xFFu8; len as usize];
        let e = Assembler::new(&mut buf[..], restore, Expect::default()).accept(c);
        assert!(buf.iter().all(|&b| b == 0xFF), "nothing written");
        e
    };
    // Magic, header CRC.
    let mut bad = hb;
    bad[0] ^= 1;
    let e = feed_header(&Chunk::words(5, len, 0, &bad)).unwrap_err();
    assert_eq!(e, AssembleError::BadHeader(HeaderError::Corrupt));
    assert!(e.to_string().contains("wrong magic, header length or header CRC"), "{e}");
    let mut bad = hb;
    bad[29] ^= 1;
    assert_eq!(feed_header(&Chunk::words(5, len, 0, &bad)), Err(AssembleError::BadHeader(HeaderError::Corrupt)));
    // Version.
    let e = feed_header(&header_chunk(&Header { version: 3, ..header }, 5, len)).unwrap_err();
    assert_eq!(e, AssembleError::BadHeader(HeaderError::UnsupportedVersion { found: 3 }));
    assert!(e.to_string().contains(&format!("valid is {FORMAT_VERSION}")), "{e}");
    // A header of another generation or length than the stream's.
    let e = feed_header(&header_chunk(&Header { generation: 6, ..header }, 5, len));
    assert_eq!(e, Err(AssembleError::HeaderGeneration { header: 6, stream: 5 }));
    let e = feed_header(&header_chunk(&Header { weight_count: header.weight_count + 1, ..header }, 5, len));
    assert_eq!(e, Err(AssembleError::HeaderLength { header: len + 4, stream: len }));
    // A body chunk first in a restore.
    assert_eq!(feed_header(&chunks[0]), Err(AssembleError::OutOfOrder { expected: 0, found: HEADER_LEN as u32 }));
}

#[test]
fn a_payload_that_fails_the_header_crc_is_refused_with_the_last_chunk() {
    let weights = plain(200);
    let record = saved_record(1);
    let image = TableImage::new(HASH, 5, &record, &weights[..]).unwrap();
    let mut bytes = bytes_of(&image);
    // The table changed after its header was made: every chunk is intact,
    // the payload is not the header's.
    bytes[HEADER_LEN + STATE_LEN + 9] ^= 0x40;
    for order in [Order::HeaderLast, Order::HeaderFirst] {
        let chunks = chunks_of(&bytes[..], order);
        let (outcomes, buf) = feed(&chunks, order, Expect::default(), bytes.len());
        let Some(Err(e)) = outcomes.last() else { panic!("{order:?}: {outcomes:?}") };
        assert!(
            matches!(e, AssembleError::PayloadCrc { header, .. } if *header == image.header().payload_crc),
            "{e:?}"
        );
        assert!(e.to_string().contains("the header states"), "{e}");
        assert!(!completed(&outcomes));
        if order == Order::HeaderLast {
            assert!(buf[..HEADER_LEN].iter().all(|&b| b == 0xFF), "no header is written over a wrong payload");
        }
    }
}

#[test]
fn an_8_mib_leo_table_streams_cheaply_when_empty_and_reassembles_when_full() {
    const SLOTS: usize = 1 << 21;
    let record = saved_record(1);
    let mut report = Vec::new();
    for claims in [0u32, 1_200_000] {
        let table = claim_table(SLOTS, claims, 3);
        let image = TableImage::new(HASH, 1, &record, &table).unwrap();
        assert_eq!(image.image_len(), HEADER_LEN + STATE_LEN + (8 << 20));
        let chunks = chunks_of(&image, Order::HeaderLast);
        let bytes: usize = chunks.iter().map(Chunk::encoded_len).sum();
        report.push(format!("{claims} of {SLOTS} slots claimed: {} chunks, {bytes} bytes encoded", chunks.len()));
        let (outcomes, buf) = feed(&chunks, Order::HeaderLast, Expect::default(), image.image_len());
        assert!(completed(&outcomes));
        assert!(buf == bytes_of(&image), "reassembled image differs");
        if claims == 0 {
            assert!(chunks.len() <= 10 && bytes <= 2048, "{}", report[0]);
        } else {
            // A claimed slot's word is sent, an empty one is not.
            assert!(bytes < 21 * chunks.len() + 4 * claims as usize + 1100, "{report:?}");
        }
    }
    std::println!("{}", report.join("\n"));
}

/// A random image: a table of up to 400 weights, each zero with
/// probability ½, and a record with some zero stretches.
fn arb_image() -> impl Strategy<Value = Vec<u8>> {
    (prop::collection::vec(prop_oneof![Just(0i32), any::<i32>()], 0..400), any::<u32>(), any::<u32>()).prop_map(
        |(w, seed, generation)| {
            let weights: Vec<Q16> = w.into_iter().map(Q16).collect();
            let record = if seed % 2 == 0 { [0u8; STATE_LEN] } else { saved_record(seed % 1000) };
            bytes_of(&TableImage::new(HASH, generation, &record, &weights[..]).unwrap())
        },
    )
}

fn arb_order() -> impl Strategy<Value = Order> {
    prop_oneof![Just(Order::HeaderLast), Just(Order::HeaderFirst)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_images_reassemble_exactly(image in arb_image(), order in arb_order()) {
        let chunks = chunks_of(&image[..], order);
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let decoded: Vec<Chunk> = chunks.iter().map(|c| {
            let n = c.encode(&mut buf).unwrap();
            Chunk::decode(&buf[..n]).unwrap()
        }).collect();
        let (outcomes, out) = feed(&decoded, order, Expect::default(), image.len());
        prop_assert!(matches!(outcomes.last(), Some(Ok(Progress::Complete(_)))));
        prop_assert_eq!(out, image);
    }

    #[test]
    fn a_single_corrupt_byte_never_completes(image in arb_image(), order in arb_order(), pick in any::<(usize, usize)>(), flip in 1u8..=255) {
        let chunks = chunks_of(&image[..], order);
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let i = pick.0 % chunks.len();
        let mut stream = Vec::new();
        for (k, c) in chunks.iter().enumerate() {
            let n = c.encode(&mut buf).unwrap();
            if k == i {
                buf[pick.1 % n] ^= flip;
            }
            // A chunk that no longer decodes is lost on the way.
            if let Ok(d) = Chunk::decode(&buf[..n]) {
                stream.push(d);
            }
        }
        let (outcomes, _) = feed(&stream, order, Expect::default(), image.len());
        prop_assert!(!completed(&outcomes));
    }

    #[test]
    fn a_dropped_or_swapped_chunk_never_completes(image in arb_image(), order in arb_order(), pick in any::<(usize, usize)>(), drop_it in any::<bool>()) {
        let mut chunks = chunks_of(&image[..], order);
        let i = pick.0 % chunks.len();
        if drop_it {
            chunks.remove(i);
        } else {
            let j = pick.1 % chunks.len();
            prop_assume!(i != j);
            chunks.swap(i, j);
        }
        let (outcomes, _) = feed(&chunks, order, Expect::default(), image.len());
        prop_assert!(!completed(&outcomes));
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200)) {
        if let Ok(c) = Chunk::decode(&bytes) {
            let mut out = [0u8; MAX_ENCODED_LEN];
            let n = c.encode(&mut out).unwrap();
            prop_assert_eq!(&out[..n], &bytes[..]);
            let mut sink = [0u8; 64];
            let mut a = Assembler::new(&mut sink[..], Order::HeaderFirst, Expect::default());
            let _ = a.accept(&c);
        }
    }
}
