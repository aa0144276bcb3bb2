//! The policies by name ([`PolicyName`]) and with their parameters
//! ([`PolicyKind`]), and the parameter checks: the one list that the
//! checkpoint's policy code, the wire's `SetPolicy` and the host's `--algo`
//! names all derive from.
//!
//! The first six are Section V's; the four after them are the gentler
//! explorations, each scored by the same fatigue counter:
//!
//! | name | parameters | what it restricts |
//! |---|---|---|
//! | `epsilon-pada` | Δ | only the exploratory draws, to within Δ of the previous action (GRL's `sampler/epsilon_pada`, `docs/reference/grl.md` §6.3); the greedy choice is free |
//! | `ou` | θ, σ | no ε-greedy: the greedy level plus Ornstein–Uhlenbeck noise `n ← n − θ·n + σ·N(0, 1)`, re-discretised (GRL's OU sampler, §6.6) |
//! | `pink` | σ | the same with pink (1/f) noise of unit variance scaled by σ (after Eberhard et al., ICLR 2023) |
//! | `action-penalty` | w | nothing: ε-greedy SARSA(λ) learns from `r − w·Σᵢ((aᵢ − a⁻ᵢ)/rangeᵢ)²`, the reward-shaping baseline (legged_gym's `action_rate`) |

use crate::error::{check_range, ConfigError};

/// The one table of the policies: per row, the variant (of [`PolicyName`]
/// and [`PolicyKind`] alike), its code, the name the command line spells,
/// the title of figures and reports, and the parameters (the
/// [`PolicyKind`] variant's fields, in the order of
/// [`PolicyName::parameter_names`]). It defines [`PolicyName`] and what
/// of both types follows from the table alone.
macro_rules! policy_table {
    ($($(#[$doc:meta])* $variant:ident = $code:literal, $name:literal, $title:literal, [$($param:ident),*];)+) => {
        /// The policies by name, without their parameters.
        ///
        /// The discriminant is the checkpoint code and the variant index on the
        /// wire, so the order is a stored format: append, never reorder.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[derive(serde::Serialize, serde::Deserialize)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[repr(u8)]
        pub enum PolicyName {
            $($(#[$doc])* #[serde(rename = $name)] $variant = $code,)+
        }

        impl PolicyName {
            /// Every policy, in code order: Section V's six, then the four gentle
            /// explorations.
            pub const ALL: [PolicyName; POLICY_COUNT] = [$(PolicyName::$variant),+];

            /// The name of `kind`.
            pub const fn of(kind: &PolicyKind) -> PolicyName {
                match kind {
                    $(PolicyKind::$variant { .. } => PolicyName::$variant,)+
                }
            }

            /// The kind of this name with `parameters` (in the order of
            /// [`parameter_names`](Self::parameter_names); extra entries ignored).
            /// The parameters are not checked here ([`PolicyKind::validate`]).
            pub const fn with_parameters(self, parameters: [f32; 2]) -> PolicyKind {
                match self {
                    $(PolicyName::$variant => policy_table!(@kind $variant [$($param),*] parameters),)+
                }
            }

            /// The names of the kind's parameters, as the command line spells its
            /// flags (`--alpha`, `--delta`, `--theta`, `--sigma`, `--weight`).
            pub const fn parameter_names(self) -> &'static [&'static str] {
                match self {
                    $(PolicyName::$variant => &[$(stringify!($param)),*],)+
                }
            }

            /// The name as the command line spells it.
            pub const fn name(self) -> &'static str {
                match self {
                    $(PolicyName::$variant => $name,)+
                }
            }

            /// The name used in figures and reports.
            pub const fn title(self) -> &'static str {
                match self {
                    $(PolicyName::$variant => $title,)+
                }
            }
        }

        impl PolicyKind {
            /// Its parameters in the order of [`PolicyName::parameter_names`], 0
            /// where it has none.
            pub fn parameters(&self) -> [f32; 2] {
                match *self {
                    $(PolicyKind::$variant { $($param),* } => policy_table!(@pair [$($param),*]),)+
                }
            }
        }
    };
    (@kind $variant:ident [] $p:ident) => { PolicyKind::$variant {} };
    (@kind $variant:ident [$a:ident] $p:ident) => { PolicyKind::$variant { $a: $p[0] } };
    (@kind $variant:ident [$a:ident, $b:ident] $p:ident) => { PolicyKind::$variant { $a: $p[0], $b: $p[1] } };
    (@pair []) => { [0.0, 0.0] };
    (@pair [$a:ident]) => { [$a, 0.0] };
    (@pair [$a:ident, $b:ident]) => { [$a, $b] };
}

policy_table! {
    /// SARSA(λ): the chosen level is applied.
    Sarsa = 0, "sarsa", "SARSA(λ)", [];
    /// Low-pass filtered actions (Eq. 8).
    LowPass = 1, "lowpass", "low-pass filter", [alpha];
    /// Low-pass filter with the previous output in the state.
    MarkovLowPass = 2, "markov-lowpass", "Markov low-pass filter", [alpha];
    /// Integrating controller: the learner chooses −Δ, 0 or +Δ.
    Integrator = 3, "integrator", "integrating controller", [delta];
    /// Integrating controller with the integrated command in the state.
    MarkovIntegrator = 4, "markov-integrator", "Markov integrating controller", [delta];
    /// Previous-action-dependent actions (Eq. 9).
    Pada = 5, "pada", "PADA", [delta];
    /// ε-PADA: only the exploratory draws stay within Δ of the previous
    /// action.
    EpsilonPada = 6, "epsilon-pada", "ε-PADA", [delta];
    /// Ornstein–Uhlenbeck noise on the greedy action's level.
    OrnsteinUhlenbeck = 7, "ou", "Ornstein–Uhlenbeck noise", [theta, sigma];
    /// Pink (1/f) noise on the greedy action's level.
    PinkNoise = 8, "pink", "pink noise", [sigma];
    /// ε-greedy SARSA(λ) with an action-change penalty in its reward.
    ActionPenalty = 9, "action-penalty", "action-change penalty", [weight];
}

/// How many policies there are.
pub const POLICY_COUNT: usize = 10;

impl PolicyName {
    /// The six policies of Section V.
    pub const PAPER: [PolicyName; 6] = [
        PolicyName::Sarsa,
        PolicyName::LowPass,
        PolicyName::MarkovLowPass,
        PolicyName::Integrator,
        PolicyName::MarkovIntegrator,
        PolicyName::Pada,
    ];

    /// The kind of this name with `parameter` as its only (or first)
    /// parameter ([`with_parameters`](Self::with_parameters)).
    pub const fn with_parameter(self, parameter: f32) -> PolicyKind {
        self.with_parameters([parameter, 0.0])
    }

    /// The number that stands for the policy in a checkpoint (its
    /// discriminant: 0 sarsa … 5 pada, 6 epsilon-pada, 7 ou, 8 pink,
    /// 9 action-penalty).
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The policy of a [`code`](Self::code); `None` for an unknown code.
    pub fn from_code(code: u8) -> Option<PolicyName> {
        PolicyName::ALL.get(code as usize).copied()
    }

    /// The policy of a command-line name.
    pub fn from_name(name: &str) -> Option<PolicyName> {
        PolicyName::ALL.into_iter().find(|n| n.name() == name)
    }

    /// Whether the policy takes α (the low-pass filters, Eq. 8).
    pub const fn takes_alpha(self) -> bool {
        matches!(self, PolicyName::LowPass | PolicyName::MarkovLowPass)
    }

    /// Whether the policy takes Δ (the integrators, PADA, ε-PADA).
    pub const fn takes_delta(self) -> bool {
        matches!(
            self,
            PolicyName::Integrator | PolicyName::MarkovIntegrator | PolicyName::Pada | PolicyName::EpsilonPada
        )
    }

    /// Whether a learner of this policy can run as (or switch back to)
    /// plain SARSA(λ) without changing its actions or state (Section VIII):
    /// every policy that chooses motor levels on the plain state — SARSA
    /// itself, PADA, the low-pass filter and the four gentle explorations.
    pub const fn can_switch(self) -> bool {
        !matches!(self, PolicyName::MarkovLowPass | PolicyName::Integrator | PolicyName::MarkovIntegrator)
    }

    /// How this policy explores ([`Exploration`]).
    pub const fn exploration(self) -> Exploration {
        match self {
            PolicyName::EpsilonPada => Exploration::EpsilonLocal,
            PolicyName::OrnsteinUhlenbeck | PolicyName::PinkNoise => Exploration::Noise,
            _ => Exploration::EpsilonGreedy,
        }
    }
}

impl core::fmt::Display for PolicyName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// How a policy's learner explores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exploration {
    /// With probability ε a uniformly random candidate, else the best
    /// candidate (the candidates are the policy's: all, or PADA's
    /// neighbourhood).
    EpsilonGreedy,
    /// ε-PADA: the greedy choice among all actions; with probability ε a
    /// uniformly random action within Δ of the previous one.
    EpsilonLocal,
    /// No ε-greedy: the greedy action's level moved by the policy's noise
    /// process and re-discretised ([`crate::exploration`]).
    Noise,
}

/// Which policy, with its parameters. Its variants are [`PolicyName`]'s in
/// the same order, so its postcard encoding (the variant index, then the
/// `f32` parameters if any) is what the wire's `SetPolicy` carries.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PolicyKind {
    /// Plain SARSA(λ): the chosen level is applied.
    Sarsa,
    /// First-order low-pass filter on the applied output (Eq. 8), `0 < alpha ≤ 1`.
    LowPass {
        /// Filter coefficient α of Eq. 8 (1 = no filtering).
        alpha: f32,
    },
    /// Low-pass filter with the previous filtered output in the state.
    MarkovLowPass {
        /// Filter coefficient α of Eq. 8.
        alpha: f32,
    },
    /// The learner chooses −Δ, 0 or +Δ on an integrated command.
    Integrator {
        /// Increment relative to the action range, `0 < delta ≤ 1`.
        delta: f32,
    },
    /// Integrating controller with the integrated command in the state.
    MarkovIntegrator {
        /// Increment relative to the action range, `0 < delta ≤ 1`.
        delta: f32,
    },
    /// Previous-action-dependent actions (Eq. 9): the next level is within Δ
    /// of the previous one, for greedy choice and exploration alike.
    Pada {
        /// Reach relative to the action range, `delta ≥ 0` (≥ 1 allows all).
        delta: f32,
    },
    /// ε-PADA: the greedy choice is free, an exploratory draw stays within
    /// Δ of the previous action.
    EpsilonPada {
        /// Reach of the exploratory draws relative to the action range,
        /// `delta ≥ 0`.
        delta: f32,
    },
    /// The greedy level plus Ornstein–Uhlenbeck noise, in units of the
    /// largest distance from 0 to a bound of the range, re-discretised.
    OrnsteinUhlenbeck {
        /// Mean reversion per step, `0 < theta ≤ 1`.
        theta: f32,
        /// Noise per step, `0 < sigma ≤ 4`.
        sigma: f32,
    },
    /// The greedy level plus pink noise of unit variance times σ, in the
    /// same units, re-discretised.
    PinkNoise {
        /// Noise scale, `0 < sigma ≤ 4`.
        sigma: f32,
    },
    /// ε-greedy SARSA(λ) learning from `r − weight·Σᵢ((aᵢ − a⁻ᵢ)/rangeᵢ)²`.
    ActionPenalty {
        /// Penalty per squared full-range change, `0 < weight ≤ 10000`.
        weight: f32,
    },
}

// The variant order of the two enums is one format (checkpoint code, wire
// variant index): keep them in step.
const _: () = {
    let mut i = 0;
    while i < POLICY_COUNT {
        let name = PolicyName::ALL[i];
        assert!(name as usize == i);
        assert!(PolicyName::of(&name.with_parameters([0.5, 0.5])) as usize == i);
        i += 1;
    }
};

/// The valid range of OU's and pink noise's σ, in words.
const SIGMA_VALID: &str = "0 < sigma <= 4 (in units of the largest distance from 0 to a bound of the action range)";

impl PolicyKind {
    /// The policy's name as the command line spells it.
    pub fn name(&self) -> &'static str {
        PolicyName::of(self).name()
    }

    /// Its first parameter (α of the low-pass filters, Δ of the integrators,
    /// PADA and ε-PADA, θ of OU, σ of pink noise, the penalty's weight);
    /// `None` for SARSA.
    pub fn parameter(&self) -> Option<f32> {
        match *self {
            PolicyKind::Sarsa => None,
            _ => Some(self.parameters()[0]),
        }
    }

    /// Checks the parameters' ranges; the error names the parameter as its
    /// flag is spelled and says the valid range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        fn open_closed(param: &'static str, v: f32, hi: f32, valid: &'static str) -> Result<(), ConfigError> {
            if v.is_finite() && v > 0.0 && v <= hi {
                Ok(())
            } else {
                Err(ConfigError::new(param, v, valid))
            }
        }
        match *self {
            PolicyKind::Sarsa => Ok(()),
            PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => {
                open_closed("lowpass alpha", alpha, 1.0, "0 < alpha <= 1")
            }
            PolicyKind::Integrator { delta } | PolicyKind::MarkovIntegrator { delta } => {
                open_closed("delta", delta, 1.0, "0 < delta <= 1 (relative to the action range)")
            }
            PolicyKind::Pada { delta } | PolicyKind::EpsilonPada { delta } => {
                check_range("delta", delta, 0.0, f32::MAX, "delta >= 0 (relative to the action range)")
            }
            PolicyKind::OrnsteinUhlenbeck { theta, sigma } => {
                open_closed("theta", theta, 1.0, "0 < theta <= 1 (mean reversion per step)")?;
                open_closed("sigma", sigma, 4.0, SIGMA_VALID)
            }
            PolicyKind::PinkNoise { sigma } => open_closed("sigma", sigma, 4.0, SIGMA_VALID),
            PolicyKind::ActionPenalty { weight } => {
                open_closed("weight", weight, 10_000.0, "0 < weight <= 10000 (per squared full-range change)")
            }
        }
    }

    /// Whether the learner chooses increments of an integrated command.
    pub(super) fn is_integrator(&self) -> bool {
        matches!(self, PolicyKind::Integrator { .. } | PolicyKind::MarkovIntegrator { .. })
    }

    /// Whether the policy appends its memory to the state.
    pub(super) fn is_markov(&self) -> bool {
        matches!(self, PolicyKind::MarkovLowPass { .. } | PolicyKind::MarkovIntegrator { .. })
    }

    /// PADA's or ε-PADA's Δ: the reach of its neighbourhood.
    pub(super) fn reach_delta(&self) -> Option<f32> {
        match *self {
            PolicyKind::Pada { delta } | PolicyKind::EpsilonPada { delta } => Some(delta),
            _ => None,
        }
    }
}

/// The number that stands for a policy kind in a checkpoint
/// ([`PolicyName::code`]).
pub fn kind_code(kind: &PolicyKind) -> u8 {
    PolicyName::of(kind).code()
}

/// Kinds whose learners mean the same by an action and a state: every kind
/// that chooses motor levels on the plain state (SARSA, PADA, the low-pass
/// filter and the gentle explorations); each of the others is a family of
/// its own.
pub(super) fn family(kind: &PolicyKind) -> u8 {
    match kind {
        PolicyKind::MarkovLowPass { .. } => 1,
        PolicyKind::Integrator { .. } => 2,
        PolicyKind::MarkovIntegrator { .. } => 3,
        _ => 0,
    }
}

/// The first parameter of a kind (0 for SARSA), as a checkpoint stores it.
pub fn kind_parameter(kind: &PolicyKind) -> f32 {
    kind.parameters()[0]
}

/// The second parameter of a kind (OU's σ; 0 for the others), as a
/// checkpoint stores it.
pub fn kind_second_parameter(kind: &PolicyKind) -> f32 {
    kind.parameters()[1]
}

/// The kind of a [`kind_code`] with its parameters; `None` for an unknown
/// code. The parameters are not checked here ([`PolicyKind::validate`]).
pub fn kind_from_code(code: u8, parameters: [f32; 2]) -> Option<PolicyKind> {
    PolicyName::from_code(code).map(|n| n.with_parameters(parameters))
}
