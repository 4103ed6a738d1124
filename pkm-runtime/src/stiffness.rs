//! Static stiffness from the wrench Jacobian ([`crate::wrench`]): the limbs'
//! spring constants `K_p`, the platform's stiffness `K = Jᵀ K_p J`, its
//! deflection under a platform wrench and its directional stiffness
//! (seed 004 eqs. 13–17; docs/stiffness.md).
//!
//! # The model
//! Each row of `J` is one spring of the limb it belongs to, at the current
//! leg length `L` ([`crate::wrench::Limb::length`]: the distance from the
//! limb's distal joint centre to its proximal centre, the first R or S joint
//! centre down the limb that is not the distal one; for a 3-RPS leg the
//! distance from the R joint to the S centre, seed 004's `r_i` in eqs. 13–17,
//! which there is the leg length, not the radius vector of eq. 8):
//! - an actuation force: the leg's axial stiffness `k = E·A/L`, in series with
//!   the actuator's stiffness `k_act` if given, seen through the row's
//!   transmission `τ` (the actuator's force per unit wrench):
//!   `1/k = L/(E·A) + τ²/k_act` (τ = 1 for a slide along the leg);
//! - a constraint force: the leg as a cantilever clamped at its proximal
//!   joint (which holds it against bending in the force's direction) and
//!   loaded at its distal centre, `k = 3·E·I/L³`;
//! - a constraint couple (a U-P-U leg's): the leg turned by an end moment with
//!   its other end held, `k = E·I/L`. This takes the couple as bending; the
//!   part along the leg is torsion, `G·J/L`, which for a solid round section
//!   (`J = 2I`, `G = E/(2(1+ν))`) is `E·I/((1+ν)L)`, 23 % softer for steel:
//!   give [`Section::Springs`] where that matters.
//!
//! `K_p = diag(k)`, `K = Jᵀ K_p J`: a 6×6 map from the platform's small
//! displacement `δX = (δp, δθ)` (`δp` of the platform point at the base
//! origin, `δθ` the rotation) to the wrench `(f, m)` (moment about the base
//! origin) that holds it there. At a reference point `p`, with `δp_p = δp +
//! δθ × p` and `m_p = m − p × f`, `K_p = T⁻ᵀ K T⁻¹`, `T = [[I, −[p]×], [0, I]]`
//! ([`Stiffness::at`]).
//!
//! # Units
//! Whatever the model's length unit is (mm in the examples), forces in N:
//! E in N/mm², A in mm², I in mm⁴, axial and bending spring constants in
//! N/mm, couple ones in N·mm/rad; `K`'s translational block in N/mm, its
//! mixed blocks in N (per rad, per mm), its rotational block in N·mm/rad;
//! a wrench's force in N and moment in N·mm; a deflection's `δp` in mm and
//! `δθ` in rad. [`Section::from_si`] converts SI values (seed 004: E =
//! 2.11·10¹¹ N/m², I = 1.256·10⁻⁷ m⁴).
//!
//! # Directional stiffness
//! Along a unit direction `e` (x, y, z, then about x, y, z) at a point:
//! `k_e = 1/(eᵀ K⁻¹ e)`, the load along `e` per displacement along `e` when
//! that load alone is applied and the platform moves freely otherwise (what
//! a test or a finite-element run measures). The alternative `eᵀ K e` is the
//! load needed with every other displacement held to zero, always at least
//! as large.

use crate::bounded::Bounded;
use crate::wrench::{RowKind, WrenchAnalysis, MAX_ROWS};
use nalgebra::{Matrix3, Matrix6, SymmetricEigen, Vector3, Vector6};
use std::fmt;

/// Below this ratio of its smallest to its largest eigenvalue (translations
/// in units of the model's size) `K` counts as singular.
pub const K_SINGULAR: f64 = 1e-15;

/// A limb's cross-section, or its spring constants given outright.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// A beam of Young's modulus `e`, area `area` and second moment of area
    /// `inertia` (the same about both bending axes, as a round or square
    /// section): the spring constants follow from the leg length.
    Beam {
        /// Young's modulus (N/mm² for a model in mm).
        e: f64,
        /// Cross-section area (mm²).
        area: f64,
        /// Second moment of area (mm⁴).
        inertia: f64,
    },
    /// The spring constants, whatever the leg length.
    Springs {
        /// Along an actuation force (N/mm).
        axial: f64,
        /// Along a constraint force (N/mm).
        bending: f64,
        /// About a constraint couple (N·mm/rad); `None` where the limb has
        /// none (a couple row then is [`StiffnessError::NoCoupleStiffness`]).
        couple: Option<f64>,
    },
}

impl Section {
    /// A solid round bar of diameter `d`: `A = π d²/4`, `I = π d⁴/64`.
    pub fn solid_round(e: f64, d: f64) -> Section {
        let r = d / 2.0;
        Section::Beam {
            e,
            area: std::f64::consts::PI * r * r,
            inertia: std::f64::consts::PI * r.powi(4) / 4.0,
        }
    }

    /// A beam given in SI units (E in N/m², A in m², I in m⁴) for a model
    /// whose length unit is `unit` metres (1e-3 for mm): `E·unit²`,
    /// `A/unit²`, `I/unit⁴`. Seed 004's E = 2.11·10¹¹ N/m² is 2.11·10⁵
    /// N/mm², its I = 1.256·10⁻⁷ m⁴ is 1.256·10⁵ mm⁴.
    pub fn from_si(e: f64, area: f64, inertia: f64, unit: f64) -> Section {
        let u2 = unit * unit;
        Section::Beam {
            e: e * u2,
            area: area / u2,
            inertia: inertia / (u2 * u2),
        }
    }
}

/// A limb's stiffness properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbProperties {
    /// Its section or spring constants.
    pub section: Section,
    /// Its actuator's stiffness along the actuated joint's variable (N/mm
    /// for a slide, N·mm/rad for a revolute), in series with the leg's axial
    /// stiffness; `None`: rigid.
    pub actuator: Option<f64>,
}

/// Why a stiffness, deflection or directional stiffness has no answer.
#[derive(Debug, Clone, PartialEq)]
pub enum StiffnessError {
    /// A property is not a positive finite number.
    BadProperty {
        /// The limb.
        limb: usize,
        /// Which property.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// Properties given for the wrong number of limbs (one for all, or one per limb).
    PropertyCount {
        /// The limbs.
        limbs: usize,
        /// The properties given.
        got: usize,
    },
    /// A limb given by its section has no leg length (no R or S centre
    /// apart from its distal one), or a zero one.
    NoLegLength {
        /// The limb.
        limb: usize,
    },
    /// A limb given by its springs has a constraint couple but no couple
    /// stiffness.
    NoCoupleStiffness {
        /// The limb.
        limb: usize,
    },
    /// A wrench must have six components (f, m).
    WrongWrenchSize {
        /// The components given.
        got: usize,
    },
    /// A wrench component or a reference point coordinate is not finite.
    NonFinite {
        /// What.
        what: &'static str,
    },
    /// `K` is singular: its smallest eigenvalue over its largest
    /// (translations in units of the model's size) is at most [`K_SINGULAR`].
    Singular {
        /// λ_min/λ_max.
        ratio: f64,
    },
    /// The configuration has no position solution (the generated
    /// `stiffness` solves the position first).
    Position(crate::solution::SolveError),
    /// The wrench analysis has no answer there: a singular configuration
    /// (constraint or actuation singularity) or limbs it cannot read.
    Wrench(crate::wrench::WrenchError),
}

impl fmt::Display for StiffnessError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StiffnessError::BadProperty { limb, what, value } => {
                write!(f, "limb {limb}: {what} must be positive and finite, not {value}")
            }
            StiffnessError::PropertyCount { limbs, got } => {
                write!(
                    f,
                    "properties for {got} limbs, but there are {limbs} (give one or one each)"
                )
            }
            StiffnessError::NoLegLength { limb } => write!(
                f,
                "limb {limb} has no leg length (no R or S joint centre apart from its distal one): give its springs"
            ),
            StiffnessError::NoCoupleStiffness { limb } => write!(
                f,
                "limb {limb} bears a constraint couple, and its springs give no couple stiffness"
            ),
            StiffnessError::WrongWrenchSize { got } => write!(f, "a wrench has 6 components (f, m), not {got}"),
            StiffnessError::NonFinite { what } => write!(f, "{what} is not finite"),
            StiffnessError::Singular { ratio } => {
                write!(f, "the stiffness matrix is singular (λ_min/λ_max = {ratio:e})")
            }
            StiffnessError::Position(e) => write!(f, "no position solution: {e}"),
            StiffnessError::Wrench(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for StiffnessError {}

/// The platform's stiffness at one configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Stiffness {
    /// The spring constant of each row of `J` (`K_p`'s diagonal).
    pub springs: Bounded<f64, MAX_ROWS>,
    /// `K = Jᵀ K_p J` at the base origin: `(δp, δθ) ↦ (f, m)`.
    pub k: Matrix6<f64>,
    /// The model's size (scales translations for the singularity test).
    pub scale: f64,
}

fn positive(limb: usize, what: &'static str, value: f64) -> Result<f64, StiffnessError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(StiffnessError::BadProperty { limb, what, value })
    }
}

/// `[p]×`, the matrix of `x ↦ p × x`.
fn skew(p: &Vector3<f64>) -> Matrix3<f64> {
    p.cross_matrix()
}

/// The stiffness from the wrench analysis and the limbs' properties (one
/// for every limb, or one per limb in [`WrenchAnalysis::limbs`] order).
/// Allocates nothing but an error's text.
pub fn stiffness(analysis: &WrenchAnalysis, limbs: &[LimbProperties]) -> Result<Stiffness, StiffnessError> {
    let n = analysis.limbs.len();
    if limbs.len() != 1 && limbs.len() != n {
        return Err(StiffnessError::PropertyCount {
            limbs: n,
            got: limbs.len(),
        });
    }
    let props = |l: usize| &limbs[if limbs.len() == 1 { 0 } else { l }];
    for l in 0..n {
        let p = props(l);
        match p.section {
            Section::Beam { e, area, inertia } => {
                positive(l, "E", e)?;
                positive(l, "A", area)?;
                positive(l, "I", inertia)?;
                match analysis.limbs[l].length() {
                    Some(len) if len > 0.0 && len.is_finite() => {}
                    _ => return Err(StiffnessError::NoLegLength { limb: l }),
                }
            }
            Section::Springs { axial, bending, couple } => {
                positive(l, "the axial stiffness", axial)?;
                positive(l, "the bending stiffness", bending)?;
                if let Some(couple) = couple {
                    positive(l, "the couple stiffness", couple)?;
                }
            }
        }
        if let Some(k) = p.actuator {
            positive(l, "the actuator stiffness", k)?;
        }
    }
    let mut springs = Bounded::<f64, MAX_ROWS>::new();
    for row in analysis.rows.iter() {
        let p = props(row.limb);
        let len = analysis.limbs[row.limb].length().unwrap_or(f64::NAN);
        let (axial, bending, couple) = match p.section {
            Section::Beam { e, area, inertia } => {
                (e * area / len, 3.0 * e * inertia / len.powi(3), Some(e * inertia / len))
            }
            Section::Springs { axial, bending, couple } => (axial, bending, couple),
        };
        let spring = match row.kind {
            RowKind::Actuation { .. } => {
                let actuator = p.actuator.map_or(0.0, |k| row.transmission * row.transmission / k);
                1.0 / (1.0 / axial + actuator)
            }
            RowKind::ConstraintForce => bending,
            RowKind::ConstraintCouple => couple.ok_or(StiffnessError::NoCoupleStiffness { limb: row.limb })?,
        };
        // As many as the rows, which the analysis holds: never full.
        let _ = springs.push(spring);
    }
    let mut k = Matrix6::zeros();
    for (row, &kr) in analysis.rows.iter().zip(springs.iter()) {
        let w = Vector6::from_row_slice(&row.wrench.row());
        k += w * w.transpose() * kr;
    }
    let k = (k + k.transpose()) * 0.5;
    let out = Stiffness {
        springs,
        k,
        scale: analysis.scale,
    };
    out.check()?;
    Ok(out)
}

impl Stiffness {
    /// `D K D` with `D = diag(s, s, s, 1, 1, 1)`: every entry in force × length.
    fn scaled(k: &Matrix6<f64>, s: f64) -> Matrix6<f64> {
        let d = Vector6::new(s, s, s, 1.0, 1.0, 1.0);
        Matrix6::from_fn(|i, j| k[(i, j)] * d[i] * d[j])
    }

    fn check(&self) -> Result<(), StiffnessError> {
        let ks = Self::scaled(&self.k, self.scale);
        if !ks.iter().all(|x| x.is_finite()) {
            return Err(StiffnessError::NonFinite {
                what: "the stiffness matrix",
            });
        }
        if certified_definite(&ks) {
            return Ok(());
        }
        let ev = SymmetricEigen::new(ks).eigenvalues;
        let (lo, hi) = (ev.min(), ev.max());
        let ratio = if hi > 0.0 { lo / hi } else { 0.0 };
        if ratio <= K_SINGULAR {
            return Err(StiffnessError::Singular { ratio });
        }
        Ok(())
    }

    /// `K` at the reference point `point`: the map from the displacement of
    /// the platform point at `point` and the rotation to the force and its
    /// moment about `point`, `T⁻ᵀ K T⁻¹`.
    pub fn at(&self, point: [f64; 3]) -> Matrix6<f64> {
        let p = Vector3::from(point);
        let mut t_inv = Matrix6::identity();
        // T⁻¹ = [[I, [p]×], [0, I]]: δp = δp_p + p × δθ.
        t_inv.fixed_view_mut::<3, 3>(0, 3).copy_from(&skew(&p));
        let k = t_inv.transpose() * self.k * t_inv;
        (k + k.transpose()) * 0.5
    }

    /// The compliance `K⁻¹` at `point` (by Cholesky on the scaled matrix).
    pub fn compliance(&self, point: [f64; 3]) -> Result<Matrix6<f64>, StiffnessError> {
        finite_point(point)?;
        let s = self.scale;
        let ks = Self::scaled(&self.at(point), s);
        let chol = ks.cholesky().ok_or(StiffnessError::Singular { ratio: 0.0 })?;
        let inv = chol.inverse();
        let d = Vector6::new(s, s, s, 1.0, 1.0, 1.0);
        Ok(Matrix6::from_fn(|i, j| inv[(i, j)] * d[i] * d[j]))
    }

    /// The platform's deflection `δX = K⁻¹ W` under the wrench `wrench` =
    /// (f, m), its moment taken about `point`: `[δp, δθ]`, `δp` the
    /// displacement of the platform point at `point`.
    pub fn deflection(&self, wrench: &[f64], point: [f64; 3]) -> Result<[f64; 6], StiffnessError> {
        if wrench.len() != 6 {
            return Err(StiffnessError::WrongWrenchSize { got: wrench.len() });
        }
        if !wrench.iter().all(|x| x.is_finite()) {
            return Err(StiffnessError::NonFinite {
                what: "a wrench component",
            });
        }
        let c = self.compliance(point)?;
        let x = c * Vector6::from_column_slice(wrench);
        Ok(x.into())
    }

    /// The directional stiffness at `point` along x, y, z (N/mm) and about
    /// them (N·mm/rad): `1/(e_iᵀ K⁻¹ e_i)` (see the module's header).
    pub fn directional(&self, point: [f64; 3]) -> Result<[f64; 6], StiffnessError> {
        let c = self.compliance(point)?;
        Ok(std::array::from_fn(|i| 1.0 / c[(i, i)]))
    }
}

/// The platform's stiffness at one configuration with what it comes from:
/// the wrench analysis (`J`), the stiffness (`K`) and the reference point
/// (the platform point the declared outputs place) at which `K`, the
/// deflections and the directional stiffnesses are given. What the
/// generated `stiffness` returns.
#[derive(Debug, Clone, PartialEq)]
pub struct PlatformStiffness {
    /// The limbs, the rows of `J` (moments about the base origin) and the
    /// conditioning.
    pub wrenches: WrenchAnalysis,
    /// `K_p`'s diagonal and `K` about the base origin.
    pub stiffness: Stiffness,
    /// The reference point (world coordinates).
    pub point: [f64; 3],
}

impl PlatformStiffness {
    /// The stiffness of the analysed configuration for the limbs'
    /// properties (one for all, or one per limb in the analysis's order),
    /// referred to `point`.
    pub fn new(
        wrenches: WrenchAnalysis,
        limbs: &[LimbProperties],
        point: [f64; 3],
    ) -> Result<PlatformStiffness, StiffnessError> {
        finite_point(point)?;
        let stiffness = stiffness(&wrenches, limbs)?;
        Ok(PlatformStiffness {
            wrenches,
            stiffness,
            point,
        })
    }

    /// The wrench analysis from the limbs' twists
    /// ([`crate::wrench::analyse_twists`]), then [`PlatformStiffness::new`].
    pub fn from_twists(
        limbs: &[crate::wrench::LimbTwists],
        scale: f64,
        properties: &[LimbProperties],
        point: [f64; 3],
    ) -> Result<PlatformStiffness, StiffnessError> {
        let wrenches = crate::wrench::analyse_twists(limbs, scale).map_err(StiffnessError::Wrench)?;
        PlatformStiffness::new(wrenches, properties, point)
    }

    /// `J` with moments about the reference point: one row `[f, m_p]` per
    /// wrench, actuation rows first.
    pub fn jacobian(&self) -> nalgebra::DMatrix<f64> {
        self.wrenches.jacobian_at(self.point)
    }

    /// `K` at the reference point: `(δp, δθ) ↦ (f, m)`, `δp` the
    /// displacement of the platform point there, `m` the moment about it.
    pub fn k(&self) -> Matrix6<f64> {
        self.stiffness.at(self.point)
    }

    /// The compliance `K⁻¹` at the reference point.
    pub fn compliance(&self) -> Result<Matrix6<f64>, StiffnessError> {
        self.stiffness.compliance(self.point)
    }

    /// The deflection `[δp, δθ]` of the reference point under the wrench
    /// `[f, m]`, `m` about the reference point.
    pub fn deflection(&self, wrench: &[f64; 6]) -> Result<[f64; 6], StiffnessError> {
        self.stiffness.deflection(wrench, self.point)
    }

    /// The directional stiffnesses at the reference point along x, y, z
    /// and about them ([`Stiffness::directional`]).
    pub fn directional(&self) -> Result<[f64; 6], StiffnessError> {
        self.stiffness.directional(self.point)
    }
}

/// Whether the symmetric `ks`'s λ_min/λ_max is certainly above
/// [`K_SINGULAR`] (with a factor [`MARGIN`](crate::wrench::qr::MARGIN) to
/// spare), by its Cholesky factor `L`: `λ_min = 1/‖L⁻¹‖₂² ≥ 1/‖L⁻¹‖_F²`
/// and `λ_max ≤ trace`. Where it is not, [`Stiffness::check`] takes the
/// eigenvalues.
fn certified_definite(ks: &Matrix6<f64>) -> bool {
    let Some(chol) = ks.cholesky() else {
        return false;
    };
    let Some(inv) = chol.l().solve_lower_triangular(&Matrix6::identity()) else {
        return false;
    };
    1.0 / inv.norm_squared() > crate::wrench::qr::MARGIN * K_SINGULAR * ks.trace()
}

fn finite_point(p: [f64; 3]) -> Result<(), StiffnessError> {
    if p.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(StiffnessError::NonFinite {
            what: "a reference point coordinate",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wrench::{analyse_poses, tests::home_rps};

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-300)
    }

    /// Seed 004's SI values in N, mm: E = 2.11·10¹¹ N/m² = 2.11·10⁵ N/mm²,
    /// I = 1.256·10⁻⁷ m⁴ = 1.256·10⁵ mm⁴, A = 1.2566·10⁻³ m² = 1256.6 mm²;
    /// a solid round bar of d = 40 mm has A = π·20² = 400π = 1256.64 mm²
    /// and I = π·40⁴/64 = 40 000π = 125 663.7 mm⁴.
    #[test]
    fn units() {
        let Section::Beam { e, area, inertia } = Section::from_si(2.11e11, 1.2566e-3, 1.256e-7, 1e-3) else {
            unreachable!()
        };
        assert!(close(e, 2.11e5, 1e-15) && close(area, 1256.6, 1e-15) && close(inertia, 1.256e5, 1e-15));
        let Section::Beam { area, inertia, .. } = Section::solid_round(2.11e5, 40.0) else {
            unreachable!()
        };
        assert!(close(area, 400.0 * std::f64::consts::PI, 1e-15));
        assert!(close(inertia, 40_000.0 * std::f64::consts::PI, 1e-15));
    }

    /// The home 3-RPS (legs vertical, length h, balls at radius r, platform
    /// at (0, 0, h)) by hand: the three vertical legs give K_zz = 3k_a, the
    /// three tangential constraint forces K_xx = K_yy = k_b Σ sin²θᵢ =
    /// 1.5 k_b; about z, each tangent force has arm r: K_θzθz = 3 k_b r²;
    /// at the platform centre, a vertical force loads the legs alike and
    /// turns nothing, so the directional stiffness along z there is 3k_a;
    /// about z there, the constraint forces alone: 3 k_b r².
    #[test]
    fn home_rps_by_hand() {
        let (r, h) = (100.0, 75.0);
        let (model, poses, values) = home_rps(r, h);
        let a = analyse_poses(&model, &poses, &values, 7).unwrap();
        let (e, area, inertia) = (2.11e5, 1256.6, 1.256e5);
        let props = [LimbProperties {
            section: Section::Beam { e, area, inertia },
            actuator: None,
        }];
        let s = stiffness(&a, &props).unwrap();
        let (ka, kb) = (e * area / h, 3.0 * e * inertia / h.powi(3));
        assert!(close(s.k[(2, 2)], 3.0 * ka, 1e-13));
        assert!(close(s.k[(0, 0)], 1.5 * kb, 1e-13));
        assert!(close(s.k[(1, 1)], 1.5 * kb, 1e-13));
        let kc = s.at([0.0, 0.0, h]);
        assert!(close(kc[(5, 5)], 3.0 * kb * r * r, 1e-13));
        let d = s.directional([0.0, 0.0, h]).unwrap();
        assert!(close(d[2], 3.0 * ka, 1e-12), "{} {}", d[2], 3.0 * ka);
        assert!(close(d[5], 3.0 * kb * r * r, 1e-12));
        // A vertical load at the centre moves it down F/(3k_a), turns nothing.
        let x = s.deflection(&[0.0, 0.0, -30.0, 0.0, 0.0, 0.0], [0.0, 0.0, h]).unwrap();
        assert!(close(x[2], -30.0 / (3.0 * ka), 1e-12));
        assert!(x[3].abs() < 1e-18 && x[4].abs() < 1e-18);
        // An actuator of stiffness k_a in series halves each leg's axial stiffness.
        let soft = [LimbProperties {
            section: Section::Beam { e, area, inertia },
            actuator: Some(ka),
        }];
        let s2 = stiffness(&a, &soft).unwrap();
        assert!(close(s2.k[(2, 2)], 1.5 * ka, 1e-13));
        // Springs given outright.
        let springs = [LimbProperties {
            section: Section::Springs {
                axial: 2.0,
                bending: 3.0,
                couple: Some(5.0),
            },
            actuator: None,
        }];
        let s3 = stiffness(&a, &springs).unwrap();
        assert_eq!(s3.springs, vec![2.0, 2.0, 2.0, 3.0, 3.0, 3.0]);
    }

    /// K at a point against the deflection at the origin carried there:
    /// the same wrench (its moment moved) gives the same rotation, and the
    /// displacement of the point is δp + δθ × p.
    #[test]
    fn reference_point() {
        let (model, poses, values) = home_rps(100.0, 75.0);
        let a = analyse_poses(&model, &poses, &values, 7).unwrap();
        let props = [LimbProperties {
            section: Section::solid_round(2.11e5, 40.0),
            actuator: None,
        }];
        let s = stiffness(&a, &props).unwrap();
        let p = Vector3::new(10.0, -20.0, 75.0);
        let (f, mp) = (Vector3::new(10.0, -15.0, 20.0), Vector3::new(-20e3, 10e3, 15e3));
        let m0 = mp + p.cross(&f);
        let x0 = s.deflection(&[f.x, f.y, f.z, m0.x, m0.y, m0.z], [0.0; 3]).unwrap();
        let xp = s.deflection(&[f.x, f.y, f.z, mp.x, mp.y, mp.z], p.into()).unwrap();
        let th = Vector3::new(x0[3], x0[4], x0[5]);
        let dp = Vector3::new(x0[0], x0[1], x0[2]) + th.cross(&p);
        for i in 0..3 {
            assert!(close(xp[i], dp[i], 1e-10), "{xp:?} {dp}");
            assert!(close(xp[3 + i], th[i], 1e-10));
        }
        // K δX = W at the point.
        let w = s.at(p.into()) * Vector6::from(xp);
        let wp = [f.x, f.y, f.z, mp.x, mp.y, mp.z];
        for i in 0..6 {
            assert!((w[i] - wp[i]).abs() < 1e-9 * 2e4, "{w} {wp:?}");
        }
    }

    #[test]
    fn bad_input_is_typed() {
        let (model, poses, values) = home_rps(100.0, 75.0);
        let a = analyse_poses(&model, &poses, &values, 7).unwrap();
        let beam = |e, area, inertia| LimbProperties {
            section: Section::Beam { e, area, inertia },
            actuator: None,
        };
        for (p, what) in [
            (beam(0.0, 1.0, 1.0), "E"),
            (beam(-1.0, 1.0, 1.0), "E"),
            (beam(f64::NAN, 1.0, 1.0), "E"),
            (beam(1.0, 0.0, 1.0), "A"),
            (beam(1.0, 1.0, -2.0), "I"),
            (beam(1.0, 1.0, f64::INFINITY), "I"),
        ] {
            match stiffness(&a, &[p]) {
                Err(StiffnessError::BadProperty { what: w, .. }) => assert_eq!(w, what),
                other => panic!("{other:?}"),
            }
        }
        let soft = LimbProperties {
            actuator: Some(0.0),
            ..beam(1.0, 1.0, 1.0)
        };
        assert!(matches!(
            stiffness(&a, &[soft]),
            Err(StiffnessError::BadProperty { .. })
        ));
        assert!(matches!(
            stiffness(&a, &[beam(1.0, 1.0, 1.0); 2]),
            Err(StiffnessError::PropertyCount { limbs: 3, got: 2 })
        ));
        let s = stiffness(&a, &[beam(2e5, 1e3, 1e5)]).unwrap();
        assert_eq!(
            s.deflection(&[1.0; 5], [0.0; 3]),
            Err(StiffnessError::WrongWrenchSize { got: 5 })
        );
        assert!(matches!(
            s.deflection(&[1.0, f64::NAN, 0.0, 0.0, 0.0, 0.0], [0.0; 3]),
            Err(StiffnessError::NonFinite { .. })
        ));
        assert!(matches!(
            s.directional([0.0, f64::NAN, 0.0]),
            Err(StiffnessError::NonFinite { .. })
        ));
        // Springs so far apart that K is singular to rounding.
        let lopsided = LimbProperties {
            section: Section::Springs {
                axial: 1e30,
                bending: 1e-30,
                couple: Some(1.0),
            },
            actuator: None,
        };
        assert!(matches!(
            stiffness(&a, &[lopsided]),
            Err(StiffnessError::Singular { .. })
        ));
    }
}
