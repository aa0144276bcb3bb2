//! The checkpoint the host keeps, for a board whose table fits no flash
//! (LEO's 8 MiB claim table on the F429): the save streamed to the host on
//! `SaveCheckpoint`, and the restore asked of the host at boot. The
//! controller's side (the image, the sink, the checks) is
//! `pada_firmware::control::host_kept`; the stream's format is
//! `pada_core::checkpoint::stream`.
//!
//! A save: the host paused the robot (torque off); the control loop
//! queues every chunk, body first and header last, taking no command and
//! running no period until the last is queued, so the learner stands
//! still while its image streams (the consistency rule). Telemetry is not
//! lost: the chunks wait for room in the telemetry queue like every
//! reliable message, and no `Step` is made meanwhile.
//!
//! A restore: at boot, before the control loop starts, the board asks
//! for the kept checkpoint from offset 0 and then after every batch of
//! [`RESTORE_BATCH`] chunks; it waits [`RESTORE_WAIT`] for each answer.
//! No answer, a refusal, or a chunk that fails its checks: the board
//! starts fresh (a learner half restored is rebuilt from the seed) and
//! says why in a `Restored` report.

use crate::channels::{send_reliable, set_long_watchdog, WatchdogRequest, FROM_HOST, WATCHDOG};
use crate::table::Ctl;
use defmt::{info, warn};
use embassy_time::{with_timeout, Duration};
use pada_core::checkpoint::stream::{Assembler, Chunker, Expect, Order, Progress, TableImage};
use pada_core::wire::{
    self, CheckpointReport, NackReason, RestoreOutcome, RestoreRequest, ToChip, ToHost, RESTORE_BATCH,
};

/// How long the board waits for each answer of the host in a restore at
/// boot. A host that runs answers within a link round trip (a few ms); two
/// seconds cover a host busy writing a file, and cost a board without a
/// host two seconds at boot.
pub const RESTORE_WAIT: Duration = Duration::from_millis(2_000);

/// Chunks queued between two watchdog feeds while a save streams: 16
/// frames of at most 170 bytes take 30 ms at 921,600 baud.
const CHUNKS_PER_FEED: u32 = 16;

/// Streams the learner's checkpoint to the host (torque off only): the
/// report for the host, or why not. The watchdog runs its long period
/// meanwhile (the image's CRC is one pass over the whole table, and a run
/// of zero windows one scan of it) and is fed as chunks go out.
pub async fn save_to_host(ctl: &mut Ctl) -> Result<CheckpointReport, NackReason> {
    let save = ctl.host_save().map_err(|_| NackReason::Busy)?;
    set_long_watchdog(true).await;
    let result = stream_save(ctl, &save).await;
    set_long_watchdog(false).await;
    result
}

async fn stream_save(ctl: &Ctl, save: &pada_firmware::control::HostSave) -> Result<CheckpointReport, NackReason> {
    let image = match TableImage::new(ctl.config_hash(), save.generation, &save.record, ctl.weights()) {
        Ok(image) => image,
        Err(e) => {
            warn!("checkpoint not streamed: {}", e);
            return Err(NackReason::CheckpointFailed);
        }
    };
    let chunker = match Chunker::new(&image, Order::HeaderLast) {
        Ok(chunker) => chunker,
        Err(e) => {
            warn!("checkpoint not streamed: {}", e);
            return Err(NackReason::CheckpointFailed);
        }
    };
    let mut chunks = 0u32;
    for chunk in chunker {
        send_reliable(ToHost::CheckpointChunk(chunk)).await;
        chunks += 1;
        if chunks % CHUNKS_PER_FEED == 0 {
            WATCHDOG.send(WatchdogRequest::Alive).await;
        }
    }
    let image_len = ctl.checkpoint_bytes() as u32;
    info!(
        "checkpoint generation {=u32} streamed to the host: {=u32} chunks, {=u32} bytes",
        save.generation, chunks, image_len
    );
    Ok(CheckpointReport::Streamed { generation: save.generation, chunks, image_len })
}

/// Asks the host for the checkpoint it keeps and restores it, or leaves a
/// fresh learner; tells the host which (`Restored`).
pub async fn restore_from_host(ctl: &mut Ctl) -> RestoreOutcome {
    let request =
        RestoreRequest { config_hash: ctl.config_hash(), image_len: ctl.checkpoint_bytes() as u32, offset: 0 };
    let expect =
        Expect { config_hash: Some(request.config_hash), image_len: Some(request.image_len), newer_than: None };
    let mut assembler = Assembler::new(ctl.restore_sink(), Order::HeaderFirst, expect);
    let received = receive(&mut assembler, request).await;
    let touched = assembler.sink().touched();
    let record = *assembler.sink().record();
    drop(assembler);
    let outcome = match received {
        Ok((generation, chunks)) => ctl.finish_host_restore(&record, generation, chunks),
        Err(outcome) => {
            ctl.abandon_host_restore(touched);
            outcome
        }
    };
    match outcome {
        RestoreOutcome::Loaded { generation, chunks } => {
            let stats = ctl.agent_stats();
            info!(
                "checkpoint generation {=u32} restored from the host ({=u32} chunks): {=u32} episodes, {=u64} agent steps, policy {}",
                generation,
                chunks,
                stats.episodes,
                stats.steps,
                ctl.policy()
            );
        }
        RestoreOutcome::Denied(wire::RestoreDenied::NoCheckpoint) => {
            info!("the host keeps no checkpoint; fresh learner")
        }
        other => warn!("no checkpoint restored from the host, fresh learner: {}", other),
    }
    send_reliable(ToHost::Restored(outcome)).await;
    outcome
}

/// Receives the stream batch by batch: the generation and the chunks of a
/// whole, checked image, or the outcome of a restore that failed.
async fn receive<S>(assembler: &mut Assembler<S>, mut request: RestoreRequest) -> Result<(u32, u32), RestoreOutcome>
where
    S: pada_core::checkpoint::stream::ImageSink,
    S::Error: core::fmt::Debug,
{
    let mut chunks = 0u32;
    loop {
        send_reliable(ToHost::RestoreWanted(request)).await;
        let mut batch = 0;
        while batch < RESTORE_BATCH {
            let (seq, msg) = match with_timeout(RESTORE_WAIT, FROM_HOST.receive()).await {
                Ok(received) => received,
                Err(_) => return Err(RestoreOutcome::NoAnswer { waited_ms: RESTORE_WAIT.as_millis() as u32 }),
            };
            match msg {
                ToChip::RestoreChunk(chunk) => {
                    batch += 1;
                    chunks += 1;
                    match assembler.accept(&chunk) {
                        Ok(Progress::Complete(header)) => return Ok((header.generation, chunks)),
                        Ok(_) => {}
                        Err(e) => {
                            warn!("restore: chunk at offset {=u32} refused: {}", chunk.offset, defmt::Debug2Format(&e));
                            return Err(RestoreOutcome::ChunkRefused { offset: assembler.expected_offset() });
                        }
                    }
                }
                ToChip::RestoreNone(denied) => return Err(RestoreOutcome::Denied(denied)),
                // Nothing else runs before the restore is over.
                _ => send_reliable(ToHost::Nack(wire::Nack { seq, reason: NackReason::Busy })).await,
            }
        }
        request.offset = assembler.expected_offset();
    }
}
