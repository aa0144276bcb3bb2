//! Fatigue counter: backlash re-engagements → damage J → predicted MTBF
//! (Section IV, Eqs. 1–7 and Table I).
//!
//! The chain, per backlash re-engagement at motor torque `T_m`:
//!
//! - Eq. 3: `T_e,max = T_m + sqrt(T_m² + 2·T_m·θ_bl·k)` — peak torque in the
//!   elastic element (from Eqs. 1–2: the motor accelerates the reflected
//!   inertia across the backlash `θ_bl`, then all energy goes into the spring
//!   of stiffness `k`);
//! - Eq. 4: `σ_max = 2·T_e,max / (d_w·b·m_n) · Y_Fa·Y_Sa·Y_ε·Y_β` — tooth-root
//!   stress of the last gear. **This module works in MPa**: torques in N·m are
//!   multiplied by 1000 to N·mm and the gear dimensions are in mm, so the
//!   stress comes out in N/mm² = MPa, the unit of Table I's `σ'_f`;
//! - Eq. 5: `σ_ar = σ_max / √2` — equivalent completely reversed amplitude
//!   (Smith–Watson–Topper with `σ_a = σ_max / 2`);
//! - Eq. 6: `N_f = ½·(σ_ar / σ'_f)^(1/d)` — cycles to failure;
//! - Eq. 7: `J = Σ 1 / (teeth·N_f)` — damage; the gear is predicted to fail
//!   when `J` reaches 1, so the predicted MTBF is `elapsed time / J`.
//!
//! A re-engagement is a change of sign of the applied torque relative to the
//! last **non-zero** torque (Section IV, "Stress cycles"); zero torque is no
//! sign, and the first non-zero torque of a run is not a re-engagement.
//!
//! Damage is accumulated in an integer fixed-point format (see
//! [`DAMAGE_FRAC_BITS`]) so that the sum is exact up to one rounding per
//! event, never loses small increments to a large total, and is bit-identical
//! on x86-64 and on the Cortex-M4 (the per-event increment is computed in f64
//! with `libm`, which is software and therefore identical on both).
//!
//! Memory is constant whatever the run length: a joint keeps a few counters,
//! never a history.
//!
//! | file | its one job |
//! |---|---|
//! | `model.rs` | Eqs. 3–7: the gearbox parameters, the damage of one re-engagement, its fixed-point format, the errors |
//! | `counter.rs` | the counters: re-engagements and damage per joint, the MTBF window, the robot's MTBF, their state |

mod counter;
mod model;
#[cfg(test)]
mod tests;

pub use counter::*;
pub use model::*;
