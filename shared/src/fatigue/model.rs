//! The damage model, Eqs. 3–7 and Table I: the gearbox and material
//! parameters, the damage of one backlash re-engagement at a motor torque
//! (also precomputed, [`FatigueModel`]), the fixed-point format the damage
//! is summed in, and why a parameter or update is refused.

use core::fmt;

/// Fractional bits of the damage accumulator: damage `J` is stored as a
/// `u64` counting units of 2⁻⁴⁸ (≈ 3.55·10⁻¹⁵), i.e. unsigned Q16.48.
///
/// - Resolution 2⁻⁴⁸; each event's increment is rounded to the nearest unit,
///   so its error is at most 2⁻⁴⁹ ≈ 1.8·10⁻¹⁵ (1.3·10⁻¹¹ relative for a
///   typical 1.3·10⁻⁴ increment). Increments below 2⁻⁴⁹ (re-engagements at
///   torques of a few mN·m) round to zero.
/// - Maximum `(2⁶⁴ − 1)·2⁻⁴⁸ ≈ 65 536` (J = 1 is one predicted gear life);
///   beyond that the accumulator saturates, it never wraps.
///
/// 2⁻⁴⁰ (Q24.40) would not do: its rounding error, up to 2⁻⁴¹ ≈ 4.5·10⁻¹³
/// per event, is 3.4·10⁻⁹ of a 1.3·10⁻⁴ increment and systematic when the
/// torque repeats, which misses a 10⁻⁹ relative accuracy over millions of
/// equal events.
pub const DAMAGE_FRAC_BITS: u32 = 48;

/// 2^DAMAGE_FRAC_BITS as f64 (exact).
const DAMAGE_SCALE: f64 = (1u64 << DAMAGE_FRAC_BITS) as f64;

/// A damage increment (f64, ≥ 0) in accumulator units, rounded to nearest;
/// `as` saturates (+∞ and anything ≥ 2⁶⁴ become `u64::MAX`).
pub(super) fn damage_to_raw(damage: f64) -> u64 {
    libm::round(damage * DAMAGE_SCALE) as u64
}

/// Accumulator units to damage.
pub(super) fn raw_to_damage(raw: u64) -> f64 {
    raw as f64 / DAMAGE_SCALE
}

/// Damage J of `raw` accumulator units (Q16.48, [`DAMAGE_FRAC_BITS`]).
pub fn damage_of_raw(raw: u64) -> f64 {
    raw_to_damage(raw)
}

/// Accumulator units (Q16.48, rounded to nearest, saturating) of a damage
/// `damage ≥ 0`.
pub fn raw_of_damage(damage: f64) -> u64 {
    damage_to_raw(damage)
}

/// Why a fatigue parameter or update was refused. A refused update changes
/// nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FatigueError {
    /// A parameter is outside its valid range.
    InvalidParameter {
        /// The parameter's name, as the field is spelled (`"k_nm_per_rad"`).
        param: &'static str,
        /// The offending value (integers converted to f64).
        value: f64,
        /// The valid range, in words (`"0 < k_nm_per_rad < ∞"`).
        valid: &'static str,
    },
    /// A torque given to [`super::JointFatigue::update`] is NaN or infinite.
    NonFiniteTorque,
    /// The torque of joint `joint` given to [`super::FatigueCounter::update`] is NaN
    /// or infinite (no joint was updated).
    NonFiniteJointTorque {
        /// Index of the offending joint.
        joint: usize,
    },
}

impl fmt::Display for FatigueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FatigueError::InvalidParameter { param, value, valid } => {
                write!(f, "invalid {param} = {value}: valid is {valid}")
            }
            FatigueError::NonFiniteTorque => write!(f, "torque is NaN or infinite"),
            FatigueError::NonFiniteJointTorque { joint } => {
                write!(f, "torque of joint {joint} is NaN or infinite")
            }
        }
    }
}

/// The error for `param` = `value`, valid range `valid`.
pub(super) const fn invalid(param: &'static str, value: f64, valid: &'static str) -> FatigueError {
    FatigueError::InvalidParameter { param, value, valid }
}

/// Gearbox and material parameters of Eqs. 3–7; [`Default`] is Table I with
/// the 45 teeth of Eq. 7.
///
/// Units are those of Table I: angles in rad, stiffness in N·m/rad, lengths
/// in mm, stress in MPa (N/mm²).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GearboxParams {
    /// θ_bl, backlash between the gears \[rad\] (Eqs. 2–3). Table I: 0.01.
    pub theta_bl_rad: f64,
    /// k, stiffness of the elastic element \[N·m/rad\] (Eqs. 1–3). Table I: 106.
    pub k_nm_per_rad: f64,
    /// d, fatigue exponent of Eq. 6 (negative). Table I: −0.262.
    pub d: f64,
    /// σ'_f, fatigue strength coefficient of Eq. 6 \[MPa\]. Table I: 4402.
    pub sigma_f_mpa: f64,
    /// b, face width of the last gear \[mm\] (Eq. 4). Table I: 4.
    pub b_mm: f64,
    /// m_n, module of the last gear \[mm\] (Eq. 4). Table I: 0.4.
    pub m_n_mm: f64,
    /// d_w, pitch circle diameter of the last gear \[mm\] (Eq. 4). Table I: 18.5.
    pub d_w_mm: f64,
    /// Y_Fa, form factor (Eq. 4). Table I: 2.15.
    pub y_fa: f64,
    /// Y_Sa, stress correction factor (Eq. 4). Table I: 2.
    pub y_sa: f64,
    /// Y_ε, contact ratio factor (Eq. 4). Table I: 1.22.
    pub y_epsilon: f64,
    /// Y_β, helix angle factor (Eq. 4). Table I: 1.
    pub y_beta: f64,
    /// Teeth of the last gear, over which each re-engagement's damage is
    /// spread (Eq. 7: "each of the 45 teeth … equally fatigued"). Default 45.
    pub teeth: u32,
}

impl Default for GearboxParams {
    fn default() -> Self {
        Self::TABLE_I
    }
}

impl GearboxParams {
    /// Table I of the paper, with 45 teeth (Eq. 7).
    pub const TABLE_I: GearboxParams = GearboxParams {
        theta_bl_rad: 0.01,
        k_nm_per_rad: 106.0,
        d: -0.262,
        sigma_f_mpa: 4402.0,
        b_mm: 4.0,
        m_n_mm: 0.4,
        d_w_mm: 18.5,
        y_fa: 2.15,
        y_sa: 2.0,
        y_epsilon: 1.22,
        y_beta: 1.0,
        teeth: 45,
    };

    /// Checks every parameter; the error names the first invalid one and its
    /// valid range. NaN and infinities are invalid everywhere.
    ///
    /// Valid: `0 ≤ θ_bl < ∞`; `k`, `σ'_f`, `b`, `m_n`, `d_w` and the four `Y`
    /// factors positive and finite; `d` negative, finite, with `1/d` finite;
    /// `teeth ≥ 1`; and the combined Eq. 4–5 coefficient
    /// `√2·1000·ΠY / (d_w·b·m_n·σ'_f)` finite and positive (no
    /// overflow/underflow from extreme but individually valid values).
    pub fn validate(&self) -> Result<(), FatigueError> {
        fn positive(param: &'static str, v: f64, valid: &'static str) -> Result<(), FatigueError> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(invalid(param, v, valid))
            }
        }
        let p = self;
        if !(p.theta_bl_rad.is_finite() && p.theta_bl_rad >= 0.0) {
            return Err(invalid("theta_bl_rad", p.theta_bl_rad, "0 <= theta_bl_rad < inf (rad)"));
        }
        positive("k_nm_per_rad", p.k_nm_per_rad, "0 < k_nm_per_rad < inf (Nm/rad)")?;
        if !(p.d.is_finite() && p.d < 0.0 && (1.0 / p.d).is_finite()) {
            return Err(invalid("d", p.d, "-inf < d < 0 with 1/d finite"));
        }
        positive("sigma_f_mpa", p.sigma_f_mpa, "0 < sigma_f_mpa < inf (MPa)")?;
        positive("b_mm", p.b_mm, "0 < b_mm < inf (mm)")?;
        positive("m_n_mm", p.m_n_mm, "0 < m_n_mm < inf (mm)")?;
        positive("d_w_mm", p.d_w_mm, "0 < d_w_mm < inf (mm)")?;
        positive("y_fa", p.y_fa, "0 < y_fa < inf")?;
        positive("y_sa", p.y_sa, "0 < y_sa < inf")?;
        positive("y_epsilon", p.y_epsilon, "0 < y_epsilon < inf")?;
        positive("y_beta", p.y_beta, "0 < y_beta < inf")?;
        if p.teeth == 0 {
            return Err(invalid("teeth", 0.0, "teeth >= 1"));
        }
        let c = p.sigma_ar_per_nm() / p.sigma_f_mpa;
        if !(c.is_finite() && c > 0.0) {
            return Err(invalid(
                "d_w_mm*b_mm*m_n_mm",
                p.d_w_mm * p.b_mm * p.m_n_mm,
                "a gear geometry giving a finite, non-zero stress per Nm",
            ));
        }
        Ok(())
    }

    /// Eq. 3: peak torque in the elastic element \[N·m\] after a backlash
    /// re-engagement at motor torque `t_m` \[N·m\]:
    /// `T_e,max = T_m + sqrt(T_m² + 2·T_m·θ_bl·k)`.
    ///
    /// The model assumes `T_m ≥ 0` (a magnitude); pass `|torque|`.
    pub fn t_e_max(&self, t_m: f64) -> f64 {
        t_m + libm::sqrt(t_m * t_m + 2.0 * t_m * self.theta_bl_rad * self.k_nm_per_rad)
    }

    /// Eq. 4: maximum tooth-root stress of the last gear **in MPa** for a
    /// torque `t_e_max` \[N·m\] on it:
    /// `σ_max = 2·(1000·T_e,max) / (d_w·b·m_n) · Y_Fa·Y_Sa·Y_ε·Y_β`
    /// (torque in N·mm over mm³ gives N/mm² = MPa).
    pub fn sigma_max(&self, t_e_max: f64) -> f64 {
        2.0 * (1000.0 * t_e_max) / (self.d_w_mm * self.b_mm * self.m_n_mm)
            * (self.y_fa * self.y_sa * self.y_epsilon * self.y_beta)
    }

    /// Eq. 6: cycles to failure of a completely reversed cycle of amplitude
    /// `sigma_ar` \[MPa\]: `N_f = ½·(σ_ar / σ'_f)^(1/d)`. `+∞` for
    /// `sigma_ar = 0`.
    pub fn cycles_to_failure(&self, sigma_ar: f64) -> f64 {
        0.5 * libm::pow(sigma_ar / self.sigma_f_mpa, 1.0 / self.d)
    }

    /// The term of Eq. 7 for one re-engagement at motor torque `t_m` \[N·m,
    /// magnitude\]: `1 / (teeth·N_f)`, through Eqs. 3 → 4 → 5 → 6 step by
    /// step (the reference; [`FatigueModel::damage`] is the fast form).
    pub fn damage_per_reengagement(&self, t_m: f64) -> f64 {
        let n_f = self.cycles_to_failure(sigma_ar(self.sigma_max(self.t_e_max(t_m))));
        1.0 / (self.teeth as f64 * n_f)
    }

    /// σ_ar per N·m of T_e,max \[MPa/(N·m)\]: Eqs. 4 and 5 folded,
    /// `2·1000·ΠY / (d_w·b·m_n) / √2`.
    fn sigma_ar_per_nm(&self) -> f64 {
        sigma_ar(self.sigma_max(1.0))
    }
}

/// Eq. 5: the equivalent completely reversed stress amplitude (Smith, Watson
/// and Topper with `σ_a = σ_max / 2`): `σ_ar = sqrt(σ_a·σ_max) = σ_max / √2`.
/// Same unit as `sigma_max` (MPa here).
pub fn sigma_ar(sigma_max: f64) -> f64 {
    sigma_max * core::f64::consts::FRAC_1_SQRT_2
}

/// Eqs. 3–7 with the constants precomputed, so that one re-engagement costs
/// one `sqrt` and one `pow`.
///
/// `damage(T_m) = (2/teeth) · (c·T_e,max)^(−1/d)`, with
/// `c = σ_ar/T_e,max / σ'_f` (Eqs. 4–5 over σ'_f), which is
/// `1 / (teeth·N_f)` of Eqs. 6–7 rearranged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FatigueModel {
    /// 2·θ_bl·k \[N·m\] (Eq. 3).
    two_theta_k: f64,
    /// σ_ar / (T_e,max·σ'_f) \[1/(N·m)\] (Eqs. 4–6).
    ratio_per_nm: f64,
    /// −1/d (Eq. 6), positive.
    neg_inv_d: f64,
    /// 2/teeth (Eqs. 6–7).
    two_over_teeth: f64,
}

impl FatigueModel {
    /// Validates `params` (see [`GearboxParams::validate`]) and precomputes.
    pub fn new(params: &GearboxParams) -> Result<Self, FatigueError> {
        params.validate()?;
        Ok(FatigueModel {
            two_theta_k: 2.0 * params.theta_bl_rad * params.k_nm_per_rad,
            ratio_per_nm: params.sigma_ar_per_nm() / params.sigma_f_mpa,
            neg_inv_d: -1.0 / params.d,
            two_over_teeth: 2.0 / params.teeth as f64,
        })
    }

    /// Eq. 7 term `1/(teeth·N_f)` for a re-engagement at motor torque `t_m`
    /// \[N·m\]; the sign of `t_m` is ignored. 0 for `t_m = 0`; equal to
    /// [`GearboxParams::damage_per_reengagement`] up to f64 rounding.
    pub fn damage(&self, t_m: f64) -> f64 {
        let t_m = libm::fabs(t_m);
        // Eq. 3.
        let t_e = t_m + libm::sqrt(t_m * (t_m + self.two_theta_k));
        // Eqs. 4–7.
        self.two_over_teeth * libm::pow(self.ratio_per_nm * t_e, self.neg_inv_d)
    }

    /// [`damage`](Self::damage) in accumulator units (Q16.48), as a
    /// re-engagement at `t_m` adds it to the counter.
    pub fn damage_raw(&self, t_m: f64) -> u64 {
        damage_to_raw(self.damage(t_m))
    }
}
