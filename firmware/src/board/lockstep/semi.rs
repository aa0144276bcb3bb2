//! Semihosting operations (ARM's semihosting specification): the files
//! and FIFOs the emulated board reads and writes on the host, and defmt
//! over semihosting (QEMU writes it to its standard output).

use cortex_m_semihosting::{nr, syscall};
// defmt over semihosting (QEMU writes it to its standard output).
use defmt_semihosting as _;

/// Opens `path` (NUL-terminated) with an fopen mode of `nr::open`.
pub fn open(path: &[u8], mode: usize) -> Option<usize> {
    // SAFETY: the path is NUL-terminated and outlives the call; the
    // length excludes the NUL, as SYS_OPEN wants.
    let h = unsafe { syscall!(OPEN, path.as_ptr(), mode, path.len() - 1) };
    (h as isize >= 0).then_some(h)
}

pub fn seek(h: usize, pos: usize) -> bool {
    // SAFETY: plain integers.
    unsafe { syscall!(SEEK, h, pos) == 0 }
}

/// Reads all of `buf`; false if the file ended or the host failed.
pub fn read(h: usize, buf: &mut [u8]) -> bool {
    // SAFETY: the buffer is valid for writes of its length.
    unsafe { syscall!(READ, h, buf.as_mut_ptr(), buf.len()) == 0 }
}

pub fn write(h: usize, data: &[u8]) -> bool {
    // SAFETY: the data is valid for reads of its length.
    unsafe { syscall!(WRITE, h, data.as_ptr(), data.len()) == 0 }
}

pub fn len(h: usize) -> Option<usize> {
    // SAFETY: a plain integer.
    let n = unsafe { syscall!(FLEN, h) };
    (n as isize >= 0).then_some(n)
}

/// Reads what is there (blocking until something is), up to
/// `buf.len()` bytes; 0 at the end of the file or on an error.
pub fn read_some(h: usize, buf: &mut [u8]) -> usize {
    // SAFETY: the buffer is valid for writes of its length.
    let left = unsafe { syscall!(READ, h, buf.as_mut_ptr(), buf.len()) };
    buf.len().saturating_sub(left)
}

pub const READ: usize = nr::open::R_BINARY;
pub const WRITE: usize = nr::open::W_TRUNC_BINARY;
pub const READ_WRITE: usize = nr::open::RW_BINARY;
pub const CREATE: usize = nr::open::RW_TRUNC_BINARY;
