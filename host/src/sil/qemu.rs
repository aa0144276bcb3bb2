//! Starting `qemu-system-arm` with the emulated board's image and wiring
//! its one channel to the host.
//!
//! - The channel is two FIFOs in a private temporary directory, which is
//!   QEMU's working directory: the board opens them through semihosting,
//!   together with its checkpoint file. Everything goes through them: the
//!   clock, the servo bus's bytes and the telemetry's
//!   ([`pada_firmware::sil`]).
//! - QEMU's standard output is the firmware's defmt log (semihosting
//!   console), its standard error QEMU's own messages; both go to files.
//! - `-icount shift=0`: one instruction per nanosecond of QEMU's virtual
//!   clock, so the board's timer counts instructions (the board measures
//!   this at boot, [`pada_firmware::sil::FromBoard::Boot`]).
//!
//! The host reads the board's FIFO itself, without a reader thread: the
//! lock-step loop waits for the board anyway, and a hand-over between
//! threads would add its latency to every exchange.

use anyhow::{anyhow, bail, Context};
use pada_firmware::sil::{CLOCK_FROM_BOARD, CLOCK_TO_BOARD};
use rustix::event::{poll, PollFd, PollFlags, Timespec};
use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Where QEMU and the run's files are.
#[derive(Debug, Clone)]
pub struct QemuSetup {
    /// The `qemu-system-arm` to run.
    pub qemu: PathBuf,
    /// QEMU's `-machine`.
    pub machine: &'static str,
    /// The firmware ELF (built for the emulated board of `machine`).
    pub elf: PathBuf,
    /// QEMU's standard output: the firmware's defmt log.
    pub defmt_log: PathBuf,
    /// QEMU's standard error.
    pub qemu_log: PathBuf,
}

/// The running emulator and its channel.
pub struct Emulator {
    setup: QemuSetup,
    child: Child,
    /// The temporary directory of the FIFOs and the checkpoint file.
    dir: tempfile::TempDir,
    /// Frames to the board.
    to_board: File,
    /// Frames from the board.
    from_board: File,
}

/// The command line of a run on `machine` (without the image).
pub fn qemu_args(machine: &str) -> Vec<String> {
    [
        "-machine",
        machine,
        "-display",
        "none",
        "-monitor",
        "none",
        "-parallel",
        "none",
        // Nothing on the serial ports: the board's bytes go through the
        // FIFOs.
        "-serial",
        "null",
        "-icount",
        "shift=0",
        "-semihosting-config",
        "enable=on,target=native",
    ]
    .map(String::from)
    .to_vec()
}

fn mkfifo(path: &Path) -> anyhow::Result<()> {
    rustix::fs::mknodat(
        rustix::fs::CWD,
        path,
        rustix::fs::FileType::Fifo,
        rustix::fs::Mode::from_raw_mode(0o600),
        0,
    )
    .with_context(|| format!("cannot create the FIFO {}", path.display()))
}

impl Emulator {
    /// Starts QEMU.
    pub fn start(setup: &QemuSetup) -> anyhow::Result<Emulator> {
        if !setup.elf.is_file() {
            bail!("firmware image {} does not exist", setup.elf.display());
        }
        let dir = tempfile::Builder::new()
            .prefix("pada-sil-")
            .tempdir()
            .context("cannot create a temporary directory")?;
        let from_path = dir.path().join(CLOCK_FROM_BOARD);
        let to_path = dir.path().join(CLOCK_TO_BOARD);
        mkfifo(&from_path)?;
        mkfifo(&to_path)?;
        // Read-write opens of a FIFO do not wait for the other end.
        let rw = |p: &Path| std::fs::OpenOptions::new().read(true).write(true).open(p);
        let from_board = rw(&from_path).context("cannot open the clock FIFO")?;
        let to_board = rw(&to_path).context("cannot open the clock FIFO")?;

        let child = spawn(setup, dir.path(), false)?;
        Ok(Emulator { setup: setup.clone(), child, dir, to_board, from_board })
    }

    /// A power cut: kills QEMU at once (SIGKILL), leaving the checkpoint
    /// file in the run directory as it is, drops whatever either side had
    /// not read from the FIFOs, and boots the same image again in the same
    /// directory (its logs appended).
    pub fn power_cycle(&mut self) -> anyhow::Result<()> {
        // `Child::kill` is SIGKILL on Unix.
        let _ = self.child.kill();
        let _ = self.child.wait();
        drain(&mut self.from_board)?;
        drain(&mut self.to_board)?;
        self.child = spawn(&self.setup, self.dir.path(), true)?;
        Ok(())
    }
}

/// Reads and drops everything a FIFO holds now.
fn drain(f: &mut File) -> anyhow::Result<()> {
    let mut buf = [0u8; 4096];
    loop {
        let mut fds = [PollFd::new(&*f, PollFlags::IN)];
        match poll(&mut fds, Some(&Timespec { tv_sec: 0, tv_nsec: 0 })) {
            Ok(0) => return Ok(()),
            Ok(_) => {
                if f.read(&mut buf).context("draining a FIFO")? == 0 {
                    return Ok(());
                }
            }
            Err(rustix::io::Errno::INTR) => {}
            Err(e) => return Err(e).context("draining a FIFO"),
        }
    }
}

/// Starts QEMU on `setup`'s image in `dir`; `append`: add to the logs.
fn spawn(setup: &QemuSetup, dir: &Path, append: bool) -> anyhow::Result<Child> {
    let open = |p: &Path| {
        std::fs::OpenOptions::new()
            .create(true)
            .write(true)
            .append(append)
            .truncate(!append)
            .open(p)
            .with_context(|| format!("cannot create {}", p.display()))
    };
    let stdout = open(&setup.defmt_log)?;
    let stderr = open(&setup.qemu_log)?;
    let elf = std::fs::canonicalize(&setup.elf).with_context(|| format!("{}", setup.elf.display()))?;
    Command::new(&setup.qemu)
        .args(qemu_args(setup.machine))
        .arg("-kernel")
        .arg(&elf)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .spawn()
        .map_err(|e| {
            anyhow!(
                "cannot start {} ({e}); install QEMU 10 (`bash .ci/install qemu`: qemu-system-arm from bookworm-backports) or pass --qemu",
                setup.qemu.display()
            )
        })
}

impl Emulator {
    /// The run's temporary directory (the board's working directory).
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    /// Whether QEMU has exited, and how.
    pub fn exited(&mut self) -> Option<ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// Ends QEMU (if still running) and waits for it.
    pub fn stop(&mut self) -> Option<ExitStatus> {
        if let Some(s) = self.exited() {
            return Some(s);
        }
        let _ = self.child.kill();
        self.child.wait().ok()
    }

    /// Writes frames to the board.
    pub fn send(&mut self, bytes: &[u8]) -> anyhow::Result<()> {
        self.to_board.write_all(bytes).context("writing to the board's FIFO")
    }

    /// Reads what the board wrote into `buf`, waiting at most `timeout` of
    /// wall-clock time; the error says whether QEMU is gone or hung.
    pub fn receive(&mut self, buf: &mut [u8], timeout: Duration) -> anyhow::Result<usize> {
        let started = Instant::now();
        loop {
            // Wake at least once a second to notice QEMU exiting (the
            // FIFO is open for writing here too, so it never ends).
            let slice = (timeout.saturating_sub(started.elapsed())).min(Duration::from_secs(1));
            let wait = Timespec { tv_sec: slice.as_secs() as i64, tv_nsec: slice.subsec_nanos() as i64 };
            let mut fds = [PollFd::new(&self.from_board, PollFlags::IN)];
            match poll(&mut fds, Some(&wait)) {
                Ok(0) | Err(rustix::io::Errno::INTR) => {}
                Ok(_) => match self.from_board.read(buf) {
                    Ok(n) => return Ok(n),
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(e) => return Err(e).context("reading the board's FIFO"),
                },
                Err(e) => return Err(e).context("waiting for the board's FIFO"),
            }
            if let Some(st) = self.exited() {
                bail!("QEMU exited ({st}): the firmware stopped (a panic or fault is in firmware.log)");
            }
            if started.elapsed() >= timeout {
                bail!("the board sent nothing for {} s of wall-clock time: hung", timeout.as_secs());
            }
        }
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop();
    }
}
