//! The numbers the paper publishes for the pendulums (Section VII), to be
//! printed next to pada's.

/// A published mean with its 95% confidence half-width, if given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Published {
    /// Mean.
    pub mean: f64,
    /// 95% confidence half-width, if the paper gives one.
    pub ci95: Option<f64>,
}

/// SARSA(λ) on the simulated pendulum: end performance −851 (±39).
pub const SIM_SARSA_END: Published = Published {
    mean: -851.0,
    ci95: Some(39.0),
};
/// SARSA(λ) on the simulated pendulum: rise time 681 s (±67).
pub const SIM_SARSA_RISE_S: Published = Published {
    mean: 681.0,
    ci95: Some(67.0),
};
/// SARSA(λ) on the simulated pendulum: MTBF 1596 s (±34).
pub const SIM_SARSA_MTBF_S: Published = Published {
    mean: 1596.0,
    ci95: Some(34.0),
};
/// The paper's end-performance threshold derived from SARSA(λ): −1093.
pub const SIM_END_THRESHOLD: f64 = -1093.0;
/// The paper's rise-time threshold derived from SARSA(λ): 839 s.
pub const SIM_RISE_THRESHOLD_S: f64 = 839.0;
/// Trials on the simulated pendulum.
pub const SIM_TRIALS: u32 = 29;
/// The smallest low-pass α meeting the objective on the simulated pendulum.
pub const SIM_LOWPASS_ALPHA: f32 = 0.834;
/// PADA's Δ meeting the objective on the simulated pendulum.
pub const SIM_PADA_DELTA: f32 = 0.5;
/// Both increase the MTBF "by a factor of two".
pub const SIM_MTBF_FACTOR: f64 = 2.0;

/// Physical pendulum: MTBF of SARSA(λ), 6.92·10⁷ s.
pub const PHYS_SARSA_MTBF_S: f64 = 6.92e7;
/// Physical pendulum: MTBF of the low-pass filter α = 0.834, 1.31·10⁸ s.
pub const PHYS_LOWPASS_MTBF_S: f64 = 1.31e8;
/// Physical pendulum: MTBF of PADA Δ = 0.5, 1.39·10⁸ s.
pub const PHYS_PADA_MTBF_S: f64 = 1.39e8;
/// Trials on the physical pendulum.
pub const PHYS_TRIALS: u32 = 28;
