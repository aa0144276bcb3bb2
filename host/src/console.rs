//! Standard output and standard error that never panic.
//!
//! A closed pipe (`pada … | head`, `| true`) or a full disk
//! (`> /dev/full`) on standard output is an error of the command — one line
//! on stderr and exit code 1 — rather than `println!`'s panic (exit 101).
//! Every command writes its results with [`outln!`], which flushes each
//! line so that the error is seen where it happens, not at exit when Rust
//! would drop it silently. Messages for the user go through [`errln!`],
//! which drops a failed write to standard error: there is nowhere left to
//! report it, and the exit code still tells.

use crate::error::CliError;
use std::io::Write;

/// `println!` that returns a [`CliError`] instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::console::write_line(format_args!($($arg)*))
    };
}
pub(crate) use outln;

/// `eprintln!` that ignores a standard error that cannot be written.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::console::write_error_line(format_args!($($arg)*))
    };
}
pub(crate) use errln;

/// Writes one line to standard error, ignoring failure.
pub fn write_error_line(args: std::fmt::Arguments<'_>) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(args).and_then(|()| err.write_all(b"\n"));
}

/// Writes one line to standard output and flushes it.
pub fn write_line(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .map_err(error)
}

/// Flushes standard output (the last check before exit).
pub fn flush() -> Result<(), CliError> {
    std::io::stdout().lock().flush().map_err(error)
}

fn error(e: std::io::Error) -> CliError {
    CliError::Runtime(anyhow::anyhow!("cannot write to standard output: {e}"))
}

/// Shows a live one-line status on stderr: redrawn in place on a
/// terminal (a newline after the `last` one), one line each otherwise (a
/// log keeps every one).
pub fn status_line(line: &str, tty: bool, last: bool) {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    if tty {
        let _ = write!(err, "\r\x1b[K{line}");
        if last {
            let _ = writeln!(err);
        }
    } else {
        let _ = writeln!(err, "{line}");
    }
    let _ = err.flush();
}
