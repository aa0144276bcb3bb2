//! The link to the host: clock frames both ways over two semihosting
//! FIFOs, the bytes of both streams (servo bus and telemetry) buffered
//! until they are reported, the host's forecasts and when the board may
//! use them without an exchange ([`pada_firmware::sil`], "Forecasts").

use super::panic::exit_failure;
use super::semi;
use crate::board::machine;
use core::cell::RefCell;
use core::task::{Poll, Waker};
use critical_section::Mutex;
use heapless::{Deque, Vec};
use pada_core::wire::{encode_frame, FrameDecoder};
use pada_firmware::sil::{self, Channel, FromBoard, ToBoard, CHUNK_LEN, CLOCK_FRAME_LEN};

/// Bytes of the servo bus's receive buffer.
const SERVO_RX_BUF: usize = 256;
/// Bytes of the command receive buffer: a restore's batch arrives at one
/// instant, so it holds a whole one (the wire's).
const TELEMETRY_RX_BUF: usize = pada_core::wire::CHIP_RX_BUFFER;
/// Bus writes buffered until the next report (a LEO period writes 8 reads,
/// a SYNC_WRITE and a torque broadcast).
const BUS_CHUNKS: usize = 16;
/// Telemetry bytes buffered until the next report (a period's frames; the
/// weights of a `ReadWeights` go four chunks per period).
const TELEMETRY_OUT: usize = 2048;
/// Clock frames buffered for one semihosting write.
const WRITE_BUF: usize = 4096;
/// Forecasts held at once (LEO's period reads eight).
const FORECASTS: usize = 16;

/// FIFO the board writes [`FromBoard`] frames to.
pub(super) const CLOCK_OUT: &[u8] = b"clock-from-board\0";
const _: () = assert!(CLOCK_OUT.len() == sil::CLOCK_FROM_BOARD.len() + 1);
/// FIFO the board reads [`ToBoard`] frames from.
pub(super) const CLOCK_IN: &[u8] = b"clock-to-board\0";
const _: () = assert!(CLOCK_IN.len() == sil::CLOCK_TO_BOARD.len() + 1);

/// A servo-bus write not yet reported.
struct BusChunk {
    at_us: u64,
    bytes: Vec<u8, CHUNK_LEN>,
    /// Its answer came from a forecast.
    answered: bool,
}

/// A forecast of the host ([`ToBoard::Forecast`]).
struct Forecast {
    request_at_us: u64,
    request: Vec<u8, { sil::MAX_REQUEST }>,
    reply_at_us: u64,
    reply: Vec<u8, { sil::MAX_REPLY }>,
}

/// A receive buffer and the task waiting on it.
pub(super) struct Rx<const N: usize> {
    pub(super) bytes: Deque<u8, N>,
    /// Bytes lost because the buffer was full.
    overflows: u32,
    waker: Option<Waker>,
}

impl<const N: usize> Rx<N> {
    const fn new() -> Self {
        Rx { bytes: Deque::new(), overflows: 0, waker: None }
    }

    fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if self.bytes.push_back(b).is_err() {
                self.overflows = self.overflows.wrapping_add(1);
            }
        }
    }

    pub(super) fn take(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        while n < buf.len() {
            match self.bytes.pop_front() {
                Some(b) => {
                    buf[n] = b;
                    n += 1;
                }
                None => break,
            }
        }
        n
    }

    fn wake(&mut self) {
        if !self.bytes.is_empty() {
            if let Some(w) = self.waker.take() {
                w.wake();
            }
        }
    }

    /// Ready when bytes are there, else registers `waker`.
    pub(super) fn poll(&mut self, waker: &Waker) -> Poll<()> {
        if self.bytes.is_empty() {
            self.waker = Some(waker.clone());
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }
}

/// Everything the emulated board shares between its tasks and its idle
/// loop.
pub(super) struct Link {
    /// The semihosting handles of the two FIFOs.
    pub(super) to_host: usize,
    pub(super) from_host: usize,
    /// Current time \[µs\], set only by the host's `Advance` or a forecast.
    pub(super) now_us: u64,
    /// The host's next event ([`ToBoard::Advance::horizon_us`]).
    pub(super) horizon_us: u64,
    /// Instructions executed outside the transport, up to `mark`.
    pub(super) busy: u64,
    /// The instruction counter when `busy` was last brought up to date.
    mark: u32,
    /// Sequence number of the next frame to the host.
    seq: u32,
    bus_out: Vec<BusChunk, BUS_CHUNKS>,
    telemetry_out: Vec<u8, TELEMETRY_OUT>,
    pub(super) bus_rx: Rx<SERVO_RX_BUF>,
    pub(super) telemetry_rx: Rx<TELEMETRY_RX_BUF>,
    forecasts: Deque<Forecast, FORECASTS>,
    /// The front forecast's request has been sent; its answer is due.
    matched: bool,
    /// Frames not yet written to the host.
    write: Vec<u8, WRITE_BUF>,
}

// All zero, so in .bss (the handles are set by `Board::init` before use).
static LINK: Mutex<RefCell<Link>> = Mutex::new(RefCell::new(Link {
    to_host: 0,
    from_host: 0,
    now_us: 0,
    horizon_us: 0,
    busy: 0,
    mark: 0,
    seq: 0,
    bus_out: Vec::new(),
    telemetry_out: Vec::new(),
    bus_rx: Rx::new(),
    telemetry_rx: Rx::new(),
    forecasts: Deque::new(),
    matched: false,
    write: Vec::new(),
}));

pub(super) fn link<R>(f: impl FnOnce(&mut Link) -> R) -> R {
    critical_section::with(|cs| f(&mut LINK.borrow_ref_mut(cs)))
}

impl Link {
    /// Brings `busy` up to date: what ran since `mark` was the firmware's.
    pub(super) fn pause(&mut self) {
        let t = machine::counter();
        self.busy += t.wrapping_sub(self.mark) as u64 * machine::INSTRUCTIONS_PER_COUNT as u64;
        self.mark = t;
    }

    /// From here on the firmware's instructions count again.
    pub(super) fn resume(&mut self) {
        self.mark = machine::counter();
    }

    pub(super) fn instructions_now(&self) -> u64 {
        self.busy + machine::counter().wrapping_sub(self.mark) as u64 * machine::INSTRUCTIONS_PER_COUNT as u64
    }

    /// Encodes `msg` into the write buffer (writing the buffer out first if
    /// it is full).
    pub(super) fn queue(&mut self, msg: &FromBoard) {
        let mut frame = [0u8; CLOCK_FRAME_LEN];
        // The clock messages are bounded (their sizes are tested); they fit.
        let Ok(bytes) = encode_frame(msg, self.seq, &mut frame) else {
            defmt::error!("lock-step clock: a message did not fit its frame");
            exit_failure()
        };
        self.seq = self.seq.wrapping_add(1);
        if self.write.extend_from_slice(bytes).is_err() {
            self.flush_writes();
            // Empty now, and a frame is smaller than the buffer.
            let _ = self.write.extend_from_slice(bytes);
        }
    }

    /// Writes the buffered frames to the host.
    pub(super) fn flush_writes(&mut self) {
        if !self.write.is_empty() && !semi::write(self.to_host, &self.write) {
            defmt::error!("lock-step clock: the host is gone");
            exit_failure()
        }
        self.write.clear();
    }

    /// Queues every unreported byte as [`FromBoard::Output`] frames; the
    /// forecasts left are void.
    pub(super) fn report_output(&mut self) {
        self.forecasts.clear();
        self.matched = false;
        let chunks = core::mem::take(&mut self.bus_out);
        for c in &chunks {
            self.queue(&FromBoard::Output { channel: Channel::Bus, at_us: c.at_us, answered: c.answered, bytes: c.bytes.clone() });
        }
        let telemetry = core::mem::take(&mut self.telemetry_out);
        for piece in telemetry.chunks(CHUNK_LEN) {
            // A piece of at most CHUNK_LEN bytes fits.
            let bytes = Vec::from_slice(piece).unwrap_or_default();
            self.queue(&FromBoard::Output { channel: Channel::Telemetry, at_us: self.now_us, answered: false, bytes });
        }
    }

    /// A servo-bus write at the current instant.
    pub(super) fn bus_write(&mut self, bytes: &[u8]) {
        let forecast = self.forecasts.front().is_some_and(|f| {
            f.request_at_us == self.now_us && f.request.as_slice() == bytes
        });
        let alone = self.telemetry_out.is_empty() && self.bus_out.iter().all(|c| c.answered);
        if forecast && alone && !self.matched {
            self.matched = true;
        } else {
            self.forecasts.clear();
            self.matched = false;
        }
        for piece in bytes.chunks(CHUNK_LEN) {
            let chunk = BusChunk { at_us: self.now_us, bytes: Vec::from_slice(piece).unwrap_or_default(), answered: false };
            if let Err(chunk) = self.bus_out.push(chunk) {
                // Full: report what is there (without an exchange).
                self.report_output();
                self.flush_writes();
                let _ = self.bus_out.push(chunk);
            }
        }
    }

    /// Telemetry bytes at the current instant: no forecast is used until
    /// they are reported (the host reacts to them at this instant).
    pub(super) fn telemetry_write(&mut self, mut bytes: &[u8]) {
        self.forecasts.clear();
        self.matched = false;
        while !bytes.is_empty() {
            let room = TELEMETRY_OUT - self.telemetry_out.len();
            if room == 0 {
                self.report_output();
                self.flush_writes();
                continue;
            }
            let (now, rest) = bytes.split_at(room.min(bytes.len()));
            let _ = self.telemetry_out.extend_from_slice(now);
            bytes = rest;
        }
    }

    /// Delivers the matched forecast's answer if the board may take it
    /// without the host: nothing but answered requests unreported, the
    /// answer not after the next timer (`until`) and before the host's
    /// next event. Returns whether it did.
    pub(super) fn answer_locally(&mut self, until: u64) -> bool {
        let Some(f) = self.forecasts.front() else { return false };
        let ready = self.matched
            && f.reply_at_us <= until
            && f.reply_at_us < self.horizon_us
            && f.reply_at_us >= self.now_us
            && self.telemetry_out.is_empty()
            && self.bus_out.last().is_some_and(|c| !c.answered && c.at_us == f.request_at_us);
        if !ready {
            return false;
        }
        let Some(f) = self.forecasts.pop_front() else { return false };
        self.matched = false;
        if let Some(c) = self.bus_out.last_mut() {
            c.answered = true;
        }
        self.now_us = f.reply_at_us;
        self.bus_rx.push(&f.reply);
        self.bus_rx.wake();
        true
    }

    /// Advances the clock to the next timer (`until`) without the host, if
    /// the host would do exactly that: nothing is unreported but answered
    /// requests (and perhaps the matched forecast's, whose answer is not
    /// due before the timer), and the timer expires before the host's next
    /// event. (Without this, every timer the firmware left behind — a reply
    /// deadline whose answer came first stays in embassy's queue until it
    /// expires — would cost an exchange, and cut a chain of forecasts.)
    /// Returns whether it did.
    pub(super) fn skip_to_timer(&mut self, until: u64) -> bool {
        if until == sil::NEVER || until <= self.now_us || until >= self.horizon_us || !self.telemetry_out.is_empty() {
            return false;
        }
        let (last, earlier) = match self.bus_out.split_last() {
            Some((last, earlier)) => (Some(last), earlier),
            None => (None, &[][..]),
        };
        let last_ok = match last {
            None => true,
            Some(c) if c.answered => true,
            Some(c) => {
                self.matched && self.forecasts.front().is_some_and(|f| c.at_us == f.request_at_us && until <= f.reply_at_us)
            }
        };
        if !(last_ok && earlier.iter().all(|c| c.answered)) {
            return false;
        }
        self.now_us = until;
        true
    }

    /// Blocks until the host's next message.
    pub(super) fn receive(&mut self, decoder: &mut FrameDecoder<ToBoard, CLOCK_FRAME_LEN>, pending: &mut Deque<ToBoard, 8>) -> ToBoard {
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        loop {
            if let Some(m) = pending.pop_front() {
                return m;
            }
            let n = semi::read_some(self.from_host, &mut buf);
            if n == 0 {
                defmt::error!("lock-step clock: the host is gone");
                exit_failure()
            }
            for frame in decoder.feed(&buf[..n]) {
                match frame {
                    Ok(frame) => {
                        if pending.push_back(frame.msg).is_err() {
                            defmt::error!("lock-step clock: more than 8 host messages in one read");
                            exit_failure()
                        }
                    }
                    // A FIFO does not damage frames; if one came, the host
                    // would time out waiting for the next Idle.
                    Err(_) => defmt::warn!("lock-step clock: a damaged frame from the host"),
                }
            }
        }
    }
}

/// The host's messages: decoder and what was decoded but not yet taken.
pub(super) struct Inbox {
    pub(super) decoder: FrameDecoder<ToBoard, CLOCK_FRAME_LEN>,
    pub(super) pending: Deque<ToBoard, 8>,
}

/// Waits for the host's `Advance`, taking its `Input`s and `Forecast`s.
pub(super) fn wait_for_advance(inbox: &mut Inbox) {
    loop {
        let msg = link(|l| l.receive(&mut inbox.decoder, &mut inbox.pending));
        match msg {
            ToBoard::Input { channel: Channel::Bus, bytes } => link(|l| l.bus_rx.push(&bytes)),
            ToBoard::Input { channel: Channel::Telemetry, bytes } => link(|l| l.telemetry_rx.push(&bytes)),
            ToBoard::Forecast { request_at_us, request, reply_at_us, reply } => link(|l| {
                // More than the board holds: the rest is simply not used.
                let _ = l.forecasts.push_back(Forecast { request_at_us, request, reply_at_us, reply });
            }),
            ToBoard::Advance { now_us, horizon_us } => {
                link(|l| {
                    l.now_us = l.now_us.max(now_us);
                    l.horizon_us = horizon_us;
                    l.bus_rx.wake();
                    l.telemetry_rx.wake();
                });
                return;
            }
            ToBoard::Configure { .. } => defmt::warn!("lock-step clock: Configure after boot ignored"),
            ToBoard::CutInSave { after_bytes } => crate::board::injection::arm_cut(after_bytes),
            ToBoard::Hang => crate::board::injection::request_hang(),
        }
    }
}
