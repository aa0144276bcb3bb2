//! The six algorithms of Section V by their command-line names, with their
//! parameter (α of Eq. 8 or Δ of Eq. 9), checked before anything runs.

use pada_core::policy::PolicyKind;
use serde::Serialize;
use std::fmt;

/// An algorithm of Section V.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Algo {
    /// SARSA(λ): the chosen torque is applied.
    Sarsa,
    /// Low-pass filtered actions (Eq. 8).
    Lowpass,
    /// Low-pass filter with the previous output in the state.
    MarkovLowpass,
    /// Integrating controller: the learner chooses −Δ, 0 or +Δ.
    Integrator,
    /// Integrating controller with the integrated command in the state.
    MarkovIntegrator,
    /// Previous-action-dependent actions (Eq. 9).
    Pada,
}

impl Algo {
    /// Every algorithm, in the paper's order.
    pub const ALL: [Algo; 6] = [
        Algo::Sarsa,
        Algo::Lowpass,
        Algo::MarkovLowpass,
        Algo::Integrator,
        Algo::MarkovIntegrator,
        Algo::Pada,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Algo::Sarsa => "sarsa",
            Algo::Lowpass => "lowpass",
            Algo::MarkovLowpass => "markov-lowpass",
            Algo::Integrator => "integrator",
            Algo::MarkovIntegrator => "markov-integrator",
            Algo::Pada => "pada",
        }
    }

    /// The name used in the paper's figures.
    pub fn title(self) -> &'static str {
        match self {
            Algo::Sarsa => "SARSA(λ)",
            Algo::Lowpass => "low-pass filter",
            Algo::MarkovLowpass => "Markov low-pass filter",
            Algo::Integrator => "integrating controller",
            Algo::MarkovIntegrator => "Markov integrating controller",
            Algo::Pada => "PADA",
        }
    }

    /// Whether the algorithm takes α (the low-pass filters).
    pub fn takes_alpha(self) -> bool {
        matches!(self, Algo::Lowpass | Algo::MarkovLowpass)
    }

    /// Whether the algorithm takes Δ (the integrators and PADA).
    pub fn takes_delta(self) -> bool {
        matches!(self, Algo::Integrator | Algo::MarkovIntegrator | Algo::Pada)
    }

    /// Whether it can switch back to SARSA(λ) after an exploration phase
    /// (Section VIII): PADA and the low-pass filter.
    pub fn can_switch(self) -> bool {
        matches!(self, Algo::Sarsa | Algo::Lowpass | Algo::Pada)
    }
}

impl fmt::Display for Algo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A bad algorithm parameter: the message names it and its valid range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct AlgoError(pub String);

/// Default α when none is given: the smallest α the paper found to meet
/// its objective (Section VII).
pub const DEFAULT_ALPHA: f32 = 0.834;
/// Default Δ when none is given: the paper's PADA Δ (Section VII).
pub const DEFAULT_DELTA: f32 = 0.5;

/// The policy of `algo` with `alpha` / `delta` (defaults
/// [`DEFAULT_ALPHA`], [`DEFAULT_DELTA`]). A parameter the algorithm does not
/// take, or one outside its range, is an error.
pub fn policy_kind(
    algo: Algo,
    alpha: Option<f32>,
    delta: Option<f32>,
) -> Result<PolicyKind, AlgoError> {
    if alpha.is_some() && !algo.takes_alpha() {
        return Err(AlgoError(format!(
            "--alpha applies only to lowpass and markov-lowpass, not to {algo}"
        )));
    }
    if delta.is_some() && !algo.takes_delta() {
        return Err(AlgoError(format!(
            "--delta applies only to integrator, markov-integrator and pada, not to {algo}"
        )));
    }
    let a = alpha.unwrap_or(DEFAULT_ALPHA);
    let d = delta.unwrap_or(DEFAULT_DELTA);
    if algo.takes_alpha() && !(a.is_finite() && a > 0.0 && a <= 1.0) {
        return Err(AlgoError(format!(
            "--alpha {a} is out of range: valid is 0 < alpha <= 1"
        )));
    }
    if algo.takes_delta() && !(d.is_finite() && d > 0.0 && d <= 1.0) {
        return Err(AlgoError(format!(
            "--delta {d} is out of range: valid is 0 < delta <= 1 (relative to the action range)"
        )));
    }
    Ok(match algo {
        Algo::Sarsa => PolicyKind::Sarsa,
        Algo::Lowpass => PolicyKind::LowPass { alpha: a },
        Algo::MarkovLowpass => PolicyKind::MarkovLowPass { alpha: a },
        Algo::Integrator => PolicyKind::Integrator { delta: d },
        Algo::MarkovIntegrator => PolicyKind::MarkovIntegrator { delta: d },
        Algo::Pada => PolicyKind::Pada { delta: d },
    })
}

/// The algorithm of a policy.
pub fn algo_of(kind: &PolicyKind) -> Algo {
    match kind {
        PolicyKind::Sarsa => Algo::Sarsa,
        PolicyKind::LowPass { .. } => Algo::Lowpass,
        PolicyKind::MarkovLowPass { .. } => Algo::MarkovLowpass,
        PolicyKind::Integrator { .. } => Algo::Integrator,
        PolicyKind::MarkovIntegrator { .. } => Algo::MarkovIntegrator,
        PolicyKind::Pada { .. } => Algo::Pada,
    }
}

/// The policy's parameter (α or Δ), if it has one.
pub fn parameter_of(kind: &PolicyKind) -> Option<f32> {
    match *kind {
        PolicyKind::Sarsa => None,
        PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => Some(alpha),
        PolicyKind::Integrator { delta }
        | PolicyKind::MarkovIntegrator { delta }
        | PolicyKind::Pada { delta } => Some(delta),
    }
}

/// A short label: `sarsa`, `lowpass α=0.834`, `pada Δ=0.5`.
pub fn label(kind: &PolicyKind) -> String {
    let algo = algo_of(kind);
    match parameter_of(kind) {
        None => algo.name().to_string(),
        Some(p) if algo.takes_alpha() => format!("{} α={}", algo.name(), p),
        Some(p) => format!("{} Δ={}", algo.name(), p),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_map_and_are_checked() {
        assert_eq!(
            policy_kind(Algo::Pada, None, Some(0.5)),
            Ok(PolicyKind::Pada { delta: 0.5 })
        );
        assert_eq!(
            policy_kind(Algo::Lowpass, None, None),
            Ok(PolicyKind::LowPass { alpha: 0.834 })
        );
        assert_eq!(policy_kind(Algo::Sarsa, None, None), Ok(PolicyKind::Sarsa));
        let e = policy_kind(Algo::Lowpass, Some(1.5), None).unwrap_err().0;
        assert!(e.contains("0 < alpha <= 1"), "{e}");
        let e = policy_kind(Algo::Integrator, None, Some(0.0))
            .unwrap_err()
            .0;
        assert!(e.contains("0 < delta <= 1"), "{e}");
        assert!(policy_kind(Algo::Pada, None, Some(f32::NAN)).is_err());
        let e = policy_kind(Algo::Sarsa, Some(0.5), None).unwrap_err().0;
        assert!(e.contains("--alpha applies only"), "{e}");
        assert!(policy_kind(Algo::Lowpass, None, Some(0.5)).is_err());
    }

    #[test]
    fn labels() {
        assert_eq!(label(&PolicyKind::Pada { delta: 0.5 }), "pada Δ=0.5");
        assert_eq!(
            label(&PolicyKind::LowPass { alpha: 0.834 }),
            "lowpass α=0.834"
        );
        assert_eq!(label(&PolicyKind::Sarsa), "sarsa");
        for a in Algo::ALL {
            assert_eq!(algo_of(&policy_kind(a, None, None).unwrap()), a);
        }
    }
}
