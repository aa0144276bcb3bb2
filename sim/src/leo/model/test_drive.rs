//! What the model's checks drive LEO with.

use rand_core::RngCore;

use super::NUM_JOINTS;

/// Every servo at a voltage drawn uniformly from ±10 V.
pub(super) fn random_voltages(rng: &mut rand_pcg::Pcg32) -> [f32; NUM_JOINTS] {
    std::array::from_fn(|_| (rng.next_u32() as f32 / u32::MAX as f32) * 20.0 - 10.0)
}
