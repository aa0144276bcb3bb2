//! pada-core: the learning core of pada, identical on the host and on the chip.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
