//! The command's errors: bad input (exit code 2) or a failure while
//! running (exit code 1). Both print as one line.

/// An error of the `pada` command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad input: an unknown name, a parameter out of range, an unreadable
    /// or malformed file, an output directory that cannot be written.
    #[error("{0}")]
    Usage(String),
    /// A failure while running.
    #[error("{0:#}")]
    Runtime(#[from] anyhow::Error),
}

impl CliError {
    /// The process exit code: 2 for bad input, 1 otherwise.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Usage(_) => 2,
            CliError::Runtime(_) => 1,
        }
    }

    /// The message on one line (newlines of nested causes joined).
    pub fn one_line(&self) -> String {
        self.to_string()
            .split('\n')
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Shorthand for a usage error.
pub fn usage(msg: impl Into<String>) -> CliError {
    CliError::Usage(msg.into())
}
