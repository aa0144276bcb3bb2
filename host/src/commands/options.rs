//! The options and checks several commands share: the seed and thread
//! count of the commands that run trials, the learning time's range and
//! the size of the worker pool.

use crate::error::{usage, CliError};
use clap::Args;

/// Options shared by the commands that run trials.
#[derive(Debug, Clone, Args)]
pub struct TrialOptions {
    /// Master seed; each trial's seed derives from it.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

/// Largest learning time accepted per trial [s].
pub const MAX_SECONDS: f64 = 1.0e6;

/// Checks a learning time given with `flag`.
pub fn check_seconds(flag: &str, s: f64) -> Result<f64, CliError> {
    if s.is_finite() && s > 0.0 && s <= MAX_SECONDS {
        Ok(s)
    } else {
        Err(usage(format!(
            "{flag} {s} is out of range: valid is 0 < seconds <= {MAX_SECONDS}"
        )))
    }
}

/// Sets the size of rayon's pool, once.
pub fn set_threads(threads: Option<u32>) -> Result<(), CliError> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()
            .map_err(|e| CliError::Runtime(anyhow::anyhow!("cannot start {n} threads: {e}")))?;
    }
    Ok(())
}
