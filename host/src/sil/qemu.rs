//! Starting `qemu-system-arm` with the emulated board's image and wiring
//! its channels to the host.
//!
//! - USART1 (servo bus) and USART2 (telemetry) are Unix sockets in a
//!   private temporary directory; QEMU connects to them as a client.
//! - The lock-step clock runs over two FIFOs in the same directory, which is
//!   QEMU's working directory (the board opens them through semihosting,
//!   together with its checkpoint file).
//! - QEMU's standard output is the firmware's defmt log (semihosting
//!   console), its standard error QEMU's own messages; both go to files.
//! - `-icount shift=0`: one instruction per nanosecond of QEMU's virtual
//!   clock, so the board's TIM2 counts instructions (the board checks this
//!   at boot, [`pada_firmware::sil::FromBoard::Boot`]).
//!
//! Each channel has a reader thread that forwards what arrives, so QEMU is
//! never blocked writing (its USART model writes synchronously).

use anyhow::{anyhow, bail, Context};
use pada_firmware::sil::{CLOCK_FROM_BOARD, CLOCK_TO_BOARD};
use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

/// How long QEMU may take to connect its serial ports.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(30);

/// Where QEMU and the run's files are.
#[derive(Debug, Clone)]
pub struct QemuSetup {
    /// The `qemu-system-arm` to run.
    pub qemu: PathBuf,
    /// The firmware ELF (built with the `qemu` feature).
    pub elf: PathBuf,
    /// QEMU's standard output: the firmware's defmt log.
    pub defmt_log: PathBuf,
    /// QEMU's standard error.
    pub qemu_log: PathBuf,
}

/// The running emulator and its channels.
pub struct Emulator {
    child: Child,
    /// The temporary directory of sockets, FIFOs and the checkpoint file.
    dir: tempfile::TempDir,
    /// Writes to USART1.
    pub bus: UnixStream,
    /// What USART1 sent.
    pub bus_rx: Receiver<Vec<u8>>,
    /// Writes to USART2.
    pub telemetry: UnixStream,
    /// What USART2 sent.
    pub telemetry_rx: Receiver<Vec<u8>>,
    /// Writes clock frames to the board.
    pub clock: File,
    /// Clock frames from the board.
    pub clock_rx: Receiver<Vec<u8>>,
}

/// The command line of a run (without the image).
pub fn qemu_args(dir: &Path) -> Vec<String> {
    let sock = |name: &str| dir.join(name).display().to_string();
    vec![
        "-machine".into(),
        "netduinoplus2".into(),
        "-display".into(),
        "none".into(),
        "-monitor".into(),
        "none".into(),
        "-parallel".into(),
        "none".into(),
        "-icount".into(),
        "shift=0".into(),
        "-semihosting-config".into(),
        "enable=on,target=native".into(),
        "-chardev".into(),
        format!("socket,id=bus,path={}", sock("bus.sock")),
        "-chardev".into(),
        format!("socket,id=telemetry,path={}", sock("telemetry.sock")),
        "-serial".into(),
        "chardev:bus".into(),
        "-serial".into(),
        "chardev:telemetry".into(),
    ]
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

fn reader<R: Read + Send + 'static>(mut r: R) -> Receiver<Vec<u8>> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut buf = vec![0u8; 65536];
        loop {
            match r.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    if tx.send(buf[..n].to_vec()).is_err() {
                        break;
                    }
                }
            }
        }
    });
    rx
}

impl Emulator {
    /// Starts QEMU and connects every channel.
    pub fn start(setup: &QemuSetup) -> anyhow::Result<Emulator> {
        if !setup.elf.is_file() {
            bail!("firmware image {} does not exist", setup.elf.display());
        }
        let dir = tempfile::Builder::new()
            .prefix("pada-sil-")
            .tempdir()
            .context("cannot create a temporary directory")?;
        let bus_listener = UnixListener::bind(dir.path().join("bus.sock"))
            .context("cannot create the bus socket")?;
        let tele_listener = UnixListener::bind(dir.path().join("telemetry.sock"))
            .context("cannot create the telemetry socket")?;
        let from_board = dir.path().join(CLOCK_FROM_BOARD);
        let to_board = dir.path().join(CLOCK_TO_BOARD);
        mkfifo(&from_board)?;
        mkfifo(&to_board)?;
        // Read-write opens of a FIFO do not wait for the other end.
        let rw = |p: &Path| std::fs::OpenOptions::new().read(true).write(true).open(p);
        let clock_in = rw(&from_board).context("cannot open the clock FIFO")?;
        let clock = rw(&to_board).context("cannot open the clock FIFO")?;

        let stdout = File::create(&setup.defmt_log)
            .with_context(|| format!("cannot create {}", setup.defmt_log.display()))?;
        let stderr = File::create(&setup.qemu_log)
            .with_context(|| format!("cannot create {}", setup.qemu_log.display()))?;
        let elf = std::fs::canonicalize(&setup.elf)
            .with_context(|| format!("{}", setup.elf.display()))?;
        let mut child = Command::new(&setup.qemu)
            .args(qemu_args(dir.path()))
            .arg("-kernel")
            .arg(&elf)
            .current_dir(dir.path())
            .stdin(Stdio::null())
            .stdout(stdout)
            .stderr(stderr)
            .spawn()
            .map_err(|e| {
                anyhow!(
                    "cannot start {} ({e}); install QEMU 10 (DESIGN.md: qemu-system-arm from bookworm-backports) or pass --qemu",
                    setup.qemu.display()
                )
            })?;

        let accept =
            |l: &UnixListener, child: &mut Child, what: &str| -> anyhow::Result<UnixStream> {
                l.set_nonblocking(true)?;
                let started = Instant::now();
                loop {
                    match l.accept() {
                        Ok((s, _)) => {
                            s.set_nonblocking(false)?;
                            return Ok(s);
                        }
                        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                            if let Some(status) = child.try_wait()? {
                                bail!(
                                "QEMU exited ({status}) before connecting its {what} port; see {}",
                                setup.qemu_log.display()
                            );
                            }
                            if started.elapsed() > CONNECT_TIMEOUT {
                                let _ = child.kill();
                                bail!(
                                    "QEMU did not connect its {what} port within {} s",
                                    CONNECT_TIMEOUT.as_secs()
                                );
                            }
                            std::thread::sleep(Duration::from_millis(5));
                        }
                        Err(e) => return Err(e.into()),
                    }
                }
            };
        let bus = accept(&bus_listener, &mut child, "servo-bus (USART1)")?;
        let telemetry = accept(&tele_listener, &mut child, "telemetry (USART2)")?;
        let bus_rx = reader(bus.try_clone()?);
        let telemetry_rx = reader(telemetry.try_clone()?);
        let clock_rx = reader(clock_in);
        Ok(Emulator {
            child,
            dir,
            bus,
            bus_rx,
            telemetry,
            telemetry_rx,
            clock,
            clock_rx,
        })
    }

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

    /// Writes to the board's servo bus.
    pub fn send_bus(&mut self, bytes: &[u8]) -> anyhow::Result<()> {
        self.bus
            .write_all(bytes)
            .context("writing to the servo bus (QEMU gone?)")
    }

    /// Writes to the board's telemetry port.
    pub fn send_telemetry(&mut self, bytes: &[u8]) -> anyhow::Result<()> {
        self.telemetry
            .write_all(bytes)
            .context("writing to the telemetry port (QEMU gone?)")
    }

    /// Writes a clock frame.
    pub fn send_clock(&mut self, bytes: &[u8]) -> anyhow::Result<()> {
        self.clock
            .write_all(bytes)
            .context("writing to the clock FIFO")
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop();
    }
}
