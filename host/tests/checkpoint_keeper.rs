//! The checkpoint keeper with real files: only complete checkpoints reach
//! the path, by rename; a torn stream leaves the previous file whole; each
//! refusal of a restore names its cause; a checkpoint streamed to the
//! keeper and back reassembles into the same image.

/// In a module so that `cargo test -p pada checkpoint_keeper` selects these.
mod checkpoint_keeper {
    use std::os::unix::fs::MetadataExt;
    use std::path::Path;

    use pada::checkpoint_keeper::{CheckpointKeeper, KeepError, Kept, RestoreRefusal};
    use pada_core::checkpoint::stream::{
        AssembleError, Assembler, Chunk, Chunker, Expect, ImageSource, Order, Progress, TableImage,
    };
    use pada_core::checkpoint::{load, slot_len, CheckpointStore, LearnerState, LoadOutcome, RamStore, STATE_LEN};
    use pada_core::claim_table::{ClaimTable, InitialWeights, Tags16};
    use pada_core::fixed::Q16;
    use pada_core::weights::Half;

    const HASH: u32 = 0x5EED_1234;
    const N: usize = 500;
    const LEN: usize = slot_len(N, 4);

    /// A table that differs with `seed`, a third of it zero.
    fn weights(seed: i32) -> Vec<Q16> {
        (0..N as i32).map(|i| if i % 3 == 0 { Q16::ZERO } else { Q16(i.wrapping_mul(0x0101_0101) ^ seed) }).collect()
    }

    fn record(seed: u32) -> [u8; STATE_LEN] {
        let mut s = LearnerState::default();
        s.agent.stats.episodes = seed;
        s.user = [seed, 1, 2, 3];
        s.to_bytes()
    }

    /// Checkpoint `generation`: its image's bytes and its chunks in a save.
    fn checkpoint(generation: u32, seed: i32) -> (Vec<u8>, Vec<Chunk>) {
        let (w, r) = (weights(seed), record(seed as u32));
        let image = TableImage::new(HASH, generation, &r, &w[..]).unwrap();
        let mut bytes = vec![0u8; image.image_len()];
        image.read(0, &mut bytes);
        let chunks = Chunker::new(&image, Order::HeaderLast).unwrap().collect();
        (bytes, chunks)
    }

    fn feed_all(keeper: &mut CheckpointKeeper, chunks: &[Chunk]) -> Option<Kept> {
        let mut kept = None;
        for c in chunks {
            kept = keeper.feed(c).unwrap();
        }
        kept
    }

    fn read(path: &Path) -> Vec<u8> {
        std::fs::read(path).unwrap()
    }

    #[test]
    fn only_a_complete_checkpoint_reaches_the_path_by_an_atomic_rename() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        let (image, chunks) = checkpoint(1, 1);
        let (last, body) = chunks.split_last().unwrap();
        for c in body {
            assert_eq!(keeper.feed(c).unwrap(), None);
            assert!(!path.exists(), "nothing at the path before the header arrives");
        }
        let partial_inode = std::fs::metadata(keeper.partial_path()).unwrap().ino();
        let kept = keeper.feed(last).unwrap().unwrap();
        let encoded: usize = chunks.iter().map(Chunk::encoded_len).sum();
        assert_eq!(
            kept,
            Kept { generation: 1, bytes: LEN as u64, chunks: chunks.len() as u32, encoded_bytes: encoded as u64 }
        );
        assert_eq!(kept.csv_row(), format!("1,{LEN},{},{encoded}", chunks.len()));
        assert_eq!(Kept::CSV_HEADER.split(',').count(), kept.csv_row().split(',').count());
        assert_eq!(read(&path), image);
        assert_eq!(std::fs::metadata(&path).unwrap().ino(), partial_inode, "the partial file was renamed, not copied");
        assert!(!keeper.partial_path().exists());
        assert_eq!(keeper.kept(), &[kept]);
        assert_eq!(keeper.kept_generation(), Some(1));

        // The kept file is a flash slot: the checkpoint code loads it.
        let mut store = RamStore::<LEN>::new();
        store.write(0, 0, &read(&path)).unwrap();
        let (mut st, mut out) = (LearnerState::default(), vec![Q16(7); N]);
        assert_eq!(load(&store, HASH, &mut st, &mut out), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
        assert_eq!(out, weights(1));
        assert_eq!(st.to_bytes(), record(1));
    }

    #[test]
    fn a_torn_stream_leaves_the_previous_file_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        let (one, chunks1) = checkpoint(1, 1);
        feed_all(&mut keeper, &chunks1).unwrap();
        // Generation 2 stops half-way: the path still holds generation 1.
        let (_, chunks2) = checkpoint(2, 2);
        for c in &chunks2[..chunks2.len() / 2] {
            assert_eq!(keeper.feed(c).unwrap(), None);
        }
        assert_eq!(read(&path), one);
        assert!(keeper.partial_path().exists());
        // Generation 3 starts: generation 2 is abandoned, never kept.
        let (three, chunks3) = checkpoint(3, 3);
        for c in &chunks3[..chunks3.len() - 1] {
            keeper.feed(c).unwrap();
            assert_eq!(read(&path), one);
        }
        // A late chunk of generation 2 is refused and changes nothing.
        let late = keeper.feed(&chunks2[chunks2.len() / 2]).unwrap_err();
        assert!(
            matches!(late, KeepError::Refused(AssembleError::GenerationChanged { expected: 3, found: 2 })),
            "{late}"
        );
        assert_eq!(keeper.feed(chunks3.last().unwrap()).unwrap().map(|k| k.generation), Some(3));
        assert_eq!(read(&path), three);
        assert_eq!(keeper.kept().iter().map(|k| k.generation).collect::<Vec<_>>(), [1, 3]);

        // A keeper that stops mid-stream (the host is killed) leaves a partial
        // file; the next one removes it and keeps the path as it was.
        let (_, chunks4) = checkpoint(4, 4);
        for c in &chunks4[..3] {
            keeper.feed(c).unwrap();
        }
        drop(keeper);
        let keeper = CheckpointKeeper::new(&path).unwrap();
        assert!(!keeper.partial_path().exists());
        assert_eq!(read(&path), three);
        assert_eq!(keeper.kept_generation(), Some(3));
    }

    #[test]
    fn a_save_cut_off_and_made_again_with_its_generation_is_kept() {
        // The board is cut off in the middle of generation 2, restores 1
        // from the keeper, learns on and saves generation 2 again, with
        // other contents: the new stream replaces the torn one.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        let (one, chunks1) = checkpoint(1, 1);
        feed_all(&mut keeper, &chunks1).unwrap();
        let (_, torn) = checkpoint(2, 2);
        for c in &torn[..torn.len() / 2] {
            assert_eq!(keeper.feed(c).unwrap(), None);
        }
        assert_eq!(read(&path), one);
        let (again, chunks2) = checkpoint(2, 5);
        assert_eq!(feed_all(&mut keeper, &chunks2).map(|k| k.generation), Some(2));
        assert_eq!(read(&path), again);
    }

    #[test]
    fn a_board_restores_batch_by_batch_from_the_server() {
        use pada::checkpoint_keeper::RestoreServer;
        use pada_core::wire::{RestoreDenied, RestoreRequest, ToChip, RESTORE_BATCH};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let mut server = RestoreServer::new(&path);
        let ask = |offset| RestoreRequest { config_hash: HASH, image_len: LEN as u32, offset };
        // Nothing kept yet.
        let none = server.answer(&ask(0));
        assert_eq!(none.messages, [ToChip::RestoreNone(RestoreDenied::NoCheckpoint)]);
        assert!(none.note.unwrap().contains("no checkpoint kept at"));

        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        let (image, chunks) = checkpoint(7, 7);
        feed_all(&mut keeper, &chunks).unwrap();
        // Another configuration or size: refused by name.
        let other = RestoreRequest { config_hash: HASH ^ 1, ..ask(0) };
        assert_eq!(server.answer(&other).messages, [ToChip::RestoreNone(RestoreDenied::OtherConfiguration)]);
        let larger = RestoreRequest { image_len: LEN as u32 + 4, ..ask(0) };
        assert_eq!(server.answer(&larger).messages, [ToChip::RestoreNone(RestoreDenied::WrongSize)]);

        // The board asks from 0, then from where each batch ended.
        let expect = Expect { config_hash: Some(HASH), image_len: Some(LEN as u32), newer_than: None };
        let mut restored = vec![0u8; LEN];
        let mut board = Assembler::new(&mut restored[..], Order::HeaderFirst, expect);
        let mut offset = 0;
        let (mut batches, mut done) = (0, false);
        while !done {
            let answer = server.answer(&ask(offset));
            assert!(answer.note.is_some() == (offset == 0));
            assert!((1..=RESTORE_BATCH).contains(&answer.messages.len()));
            batches += 1;
            for m in answer.messages {
                let ToChip::RestoreChunk(c) = m else { panic!("{m:?}") };
                done = matches!(board.accept(&c).unwrap(), Progress::Complete(_));
            }
            offset = board.expected_offset();
        }
        drop(board);
        assert_eq!(restored, image);
        assert_eq!(batches, chunks.len().div_ceil(RESTORE_BATCH));
        // An offset that starts no chunk.
        assert_eq!(server.answer(&ask(33)).messages, [ToChip::RestoreNone(RestoreDenied::NotAChunk)]);
    }

    #[test]
    fn an_older_or_equal_generation_is_refused_and_the_file_stays() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let (five, chunks5) = checkpoint(5, 5);
        feed_all(&mut CheckpointKeeper::new(&path).unwrap(), &chunks5).unwrap();
        // A new keeper reads the generation on disk.
        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        assert_eq!(keeper.kept_generation(), Some(5));
        for g in [4, 5] {
            let (_, chunks) = checkpoint(g, 9);
            let e = keeper.feed(&chunks[0]).unwrap_err();
            assert!(matches!(e, KeepError::Refused(AssembleError::Stale { have: 5, found }) if found == g), "{e}");
            assert_eq!(
                e.to_string(),
                format!("checkpoint chunk refused: stale generation {g}: valid is newer than 5, the one already kept")
            );
        }
        assert!(!keeper.partial_path().exists(), "a refused stream creates no file");
        assert_eq!(read(&path), five);
        // A stream's middle with no start is refused too.
        let (_, chunks6) = checkpoint(6, 6);
        assert!(matches!(
            keeper.feed(&chunks6[2]),
            Err(KeepError::Refused(AssembleError::OutOfOrder { expected: 32, .. }))
        ));
        assert_eq!(feed_all(&mut keeper, &chunks6).map(|k| k.generation), Some(6));
    }

    #[test]
    fn chunker_to_keeper_to_restore_to_assembler_gives_the_same_image() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let mut keeper = CheckpointKeeper::new(&path).unwrap();
        // LEO's table kind: a claim table of 16-bit weights and 16-bit tags.
        let slots = 4096;
        let mut table = ClaimTable::new(Half::<_, 12>::new(vec![0i16; slots]), Tags16(vec![0u16; slots])).unwrap();
        table.reset(InitialWeights { seed: 3, lo: -(1 << 15), span: 1 << 16 });
        for k in 0..1500u32 {
            table.claim(k.wrapping_mul(0x9E37_79B9));
        }
        let r = record(8);
        let image = TableImage::new(HASH, 8, &r, &table).unwrap();
        let mut bytes = vec![0u8; image.image_len()];
        image.read(0, &mut bytes);
        let kept =
            feed_all(&mut keeper, &Chunker::new(&image, Order::HeaderLast).unwrap().collect::<Vec<_>>()).unwrap();
        assert_eq!(kept.generation, 8);

        let restore = keeper.restore_for(HASH, bytes.len() as u64, Some(7)).unwrap();
        assert_eq!(restore.header(), image.header());
        let chunks: Vec<Chunk> = restore.chunks().collect();
        assert_eq!(chunks[0].offset, 0, "the header goes first in a restore");
        let mut board = vec![0xA5u8; bytes.len()];
        let expect = Expect { config_hash: Some(HASH), image_len: Some(bytes.len() as u32), newer_than: None };
        let mut a = Assembler::new(&mut board[..], Order::HeaderFirst, expect);
        let outcomes: Vec<_> = chunks.iter().map(|c| a.accept(c)).collect();
        assert_eq!(outcomes.last(), Some(&Ok(Progress::Complete(image.header()))));
        assert!(outcomes.iter().all(Result::is_ok));
        assert!(board == bytes, "the board's image is the one it sent");
        // The same generation as the board's own is sent (it may have lost its
        // table); a newer one too.
        assert!(keeper.restore_for(HASH, bytes.len() as u64, Some(8)).is_ok());
        assert!(keeper.restore_for(HASH, bytes.len() as u64, None).is_ok());
    }

    /// The refusal of a restore for the default board, as its message.
    fn refusal(path: &Path, hash: u32, len: u64, board: Option<u32>) -> (RestoreRefusal, String) {
        let keeper = CheckpointKeeper::new(path).unwrap();
        let e = keeper.restore_for(hash, len, board).unwrap_err();
        let msg = e.to_string();
        assert!(!msg.contains('\n'), "one line: {msg}");
        (e, msg)
    }

    #[test]
    fn every_restore_refusal_names_its_cause_in_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("leo.ckpt");
        let p = path.display().to_string();
        let len = LEN as u64;

        let (e, msg) = refusal(&path, HASH, len, None);
        assert!(matches!(e, RestoreRefusal::NoFile { .. }));
        assert_eq!(msg, format!("no checkpoint kept at {p}"));

        let (image, chunks) = checkpoint(5, 5);
        feed_all(&mut CheckpointKeeper::new(&path).unwrap(), &chunks).unwrap();
        let restore_whole = || std::fs::write(&path, &image).unwrap();

        std::fs::write(&path, &image[..LEN - 8]).unwrap();
        let (e, msg) = refusal(&path, HASH, len, None);
        assert!(matches!(e, RestoreRefusal::Truncated { .. }));
        assert_eq!(msg, format!("checkpoint {p} truncated: {} bytes, valid is {LEN} bytes", LEN - 8));
        std::fs::write(&path, &image[..10]).unwrap();
        let (_, msg) = refusal(&path, HASH, len, None);
        assert_eq!(msg, format!("checkpoint {p} truncated: 10 bytes, valid is 32 bytes"));

        let mut bad = image.clone();
        bad[LEN - 20] ^= 1;
        std::fs::write(&path, &bad).unwrap();
        let (e, msg) = refusal(&path, HASH, len, None);
        assert!(matches!(e, RestoreRefusal::Corrupted { .. }));
        assert!(
            msg.starts_with(&format!("checkpoint {p} corrupted: payload CRC 0x"))
                && msg.ends_with("as the header states"),
            "{msg}"
        );
        let mut bad = image.clone();
        bad[9] ^= 1;
        std::fs::write(&path, &bad).unwrap();
        let (_, msg) = refusal(&path, HASH, len, None);
        assert_eq!(msg, format!("checkpoint {p} corrupted: header corrupt: wrong magic, header length or header CRC"));

        restore_whole();
        let (e, msg) = refusal(&path, HASH ^ 0xFF, len, None);
        assert!(matches!(e, RestoreRefusal::OtherConfiguration { .. }));
        assert_eq!(
            msg,
            format!(
                "checkpoint {p} is of configuration {HASH:#010x}, the board runs configuration {:#010x}",
                HASH ^ 0xFF
            )
        );

        let (e, msg) = refusal(&path, HASH, len + 400, None);
        assert!(matches!(e, RestoreRefusal::WrongSize { .. }));
        assert_eq!(
            msg,
            format!("checkpoint {p} holds a {LEN}-byte image, the board's table needs {} bytes", LEN + 400)
        );

        let (e, msg) = refusal(&path, HASH, len, Some(6));
        assert!(matches!(e, RestoreRefusal::Older { board: 6, kept: 5, .. }));
        assert_eq!(msg, format!("checkpoint {p} is generation 5, older than the board's own generation 6"));

        // And the whole file is sent.
        assert_eq!(CheckpointKeeper::new(&path).unwrap().restore_for(HASH, len, Some(4)).unwrap().image(), &image[..]);
    }
}
