//! Errors of the learning core: configuration errors name the parameter and
//! its valid range; step errors leave the agent unchanged.

use core::fmt;

/// A parameter given to a constructor is outside its valid range.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigError {
    /// The parameter's name, as a user would write it (`"alpha"`, `"state[2].min"`).
    pub param: &'static str,
    /// Index of the element when the parameter is one of several (a state or
    /// action dimension), otherwise `None`.
    pub index: Option<u16>,
    /// The offending value, as far as it is a number.
    pub value: f32,
    /// The valid range, in words (`"0 < alpha <= 1"`).
    pub valid: &'static str,
}

impl ConfigError {
    /// An error for `param` whose `value` is outside `valid`.
    pub const fn new(param: &'static str, value: f32, valid: &'static str) -> Self {
        ConfigError { param, index: None, value, valid }
    }

    /// The same error, for element `index` of a list parameter.
    pub const fn at(mut self, index: usize) -> Self {
        self.index = Some(index as u16);
        self
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index {
            Some(i) => write!(f, "invalid {}[{}] = {}: valid is {}", self.param, i, self.value, self.valid),
            None => write!(f, "invalid {} = {}: valid is {}", self.param, self.value, self.valid),
        }
    }
}

/// Why an agent step was refused. A refused step changes no weight, no trace
/// and no policy state.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepError {
    /// The observation has the wrong number of dimensions.
    WrongStateLength {
        /// Dimensions the agent was built for.
        expected: u8,
        /// Dimensions given.
        got: u8,
    },
    /// State dimension `dim` is NaN or infinite.
    NonFiniteState {
        /// The offending dimension.
        dim: u8,
    },
    /// The reward is NaN or infinite.
    NonFiniteReward,
    /// `step` or `end_episode` was called without a running episode.
    NoEpisode,
    /// The policy cannot be switched to plain SARSA: its agent actions or its
    /// state are not those of SARSA (the integrators and Markov variants).
    CannotSwitch,
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            StepError::WrongStateLength { expected, got } => {
                write!(f, "observation has {got} dimensions, the agent expects {expected}")
            }
            StepError::NonFiniteState { dim } => write!(f, "state dimension {dim} is NaN or infinite"),
            StepError::NonFiniteReward => write!(f, "reward is NaN or infinite"),
            StepError::NoEpisode => write!(f, "no episode is running: call start_episode first"),
            StepError::CannotSwitch => write!(
                f,
                "only PADA and the low-pass filter can switch back to SARSA (the others change the action set or the state)"
            ),
        }
    }
}

/// Checks that `value` is finite and inside `[lo, hi]`.
pub(crate) fn check_range(
    param: &'static str,
    value: f32,
    lo: f32,
    hi: f32,
    valid: &'static str,
) -> Result<(), ConfigError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(ConfigError::new(param, value, valid))
    }
}

impl core::error::Error for ConfigError {}

impl core::error::Error for StepError {}
