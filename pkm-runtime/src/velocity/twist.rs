//! Twists and the joints' unit twists: [`Twist`] (`f64`, nalgebra) and
//! [`Screw`] (any [`Scalar`]), each joint's twists per unit rate of its
//! variables ([`unit_twists`], written once over [`Scalar`]; [`joint_twists`]
//! at `f64`) and their time derivatives ([`joint_twist_rates`]).

use crate::frame::Frame;
use crate::model::{canonical_frame, JointType, Model, Place};
use crate::scalar::{cross, unit, Scalar};
use crate::steps::{place_axis, JointGeometry, JointValue};
use nalgebra::{Isometry3, Vector3};

/// A twist: angular velocity and the velocity of the body point at the
/// world origin, world axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    /// Angular velocity.
    pub w: Vector3<f64>,
    /// Velocity of the body point at the world origin.
    pub v: Vector3<f64>,
}

impl Twist {
    /// The zero twist.
    pub fn zero() -> Self {
        Twist {
            w: Vector3::zeros(),
            v: Vector3::zeros(),
        }
    }

    /// The velocity of the body point at `p`.
    pub fn at(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.v + self.w.cross(p)
    }

    /// `self · k`.
    pub fn scale(&self, k: f64) -> Twist {
        Twist {
            w: self.w * k,
            v: self.v * k,
        }
    }

    /// The Lie bracket `[self, other]`: the rate of change of `other`, carried
    /// by a body moving with `self`.
    pub fn bracket(&self, other: &Twist) -> Twist {
        Twist {
            w: self.w.cross(&other.w),
            v: self.w.cross(&other.v) - other.w.cross(&self.v),
        }
    }

    pub(super) fn add(&self, o: &Twist) -> Twist {
        Twist {
            w: self.w + o.w,
            v: self.v + o.v,
        }
    }

    pub(super) fn rows(&self) -> [f64; 6] {
        [self.w.x, self.w.y, self.w.z, self.v.x, self.v.y, self.v.z]
    }
}

/// A twist over any [`Scalar`]: the angular velocity `w` and the velocity
/// `v` of the body point at the world origin, world axes, as arrays. The
/// generic dynamics ([`crate::skc_reactions`]) and the code generator's
/// traces compute with it; [`Twist`] is its `f64` form on nalgebra's vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw<T> {
    /// Angular velocity.
    pub w: [T; 3],
    /// Velocity of the body point at the world origin.
    pub v: [T; 3],
}

impl From<Screw<f64>> for Twist {
    fn from(s: Screw<f64>) -> Twist {
        Twist {
            w: Vector3::from(s.w),
            v: Vector3::from(s.v),
        }
    }
}

/// The unit twists of joint `jg`'s second link relative to its first, per
/// unit rate of each of its variables, world axes, its first link at `pu`
/// and its value `value` (a parallelogram's turn; `None` reads as 0): a
/// turn about the hinge's z axis (R), the guide's unit direction (P, its
/// sign from the side that holds the guide), the other hinge point's rate
/// on its circle (Pa, `d/dθ` of the arm turned by θ), and the three world
/// axes through the ball's centre (S: an S joint's rates are its angular
/// velocity). Written once over [`Scalar`]: [`joint_twists`] evaluates it
/// at `f64`, the code generator traces it.
pub fn unit_twists<T: Scalar>(jg: &JointGeometry<T>, value: Option<JointValue<T>>, pu: &Frame<T>) -> Vec<Screw<T>> {
    let z = T::c(0.0);
    let zero = [z; 3];
    let column = |f: &Frame<T>, i: usize| [f.r[0][i], f.r[1][i], f.r[2][i]];
    match jg.kind {
        JointType::R => {
            let w = pu.rotate(column(&jg.frames[0], 2));
            let p = pu.apply(jg.frames[0].t);
            vec![Screw { w, v: cross(p, w) }]
        }
        JointType::P => {
            let (guide, sign) = match jg.places[0] {
                Place::Line { along, .. } => (along, 1.0),
                _ => (
                    match jg.places[1] {
                        Place::Line { along, .. } => along,
                        other => place_axis(&other),
                    },
                    -1.0,
                ),
            };
            // Both links keep one orientation, so u's axes serve for a guide on v too.
            let d = pu.rotate(unit(guide)).map(|x| x * T::c(sign));
            vec![Screw { w: zero, v: d }]
        }
        JointType::Pa => {
            let (c, s) = match value {
                Some(JointValue::Turn(c, s, _)) => (c, s),
                Some(JointValue::Slide(t)) => (t.cos(), t.sin()),
                None => (T::c(1.0), z),
            };
            // d/dθ of the arm turned by θ about the hinge's z: ẑ × Rz(θ)·a.
            let rate = |f: &Frame<T>, arm: [T; 3]| {
                let local = f.rotate_back(arm);
                let turned = [c * local[0] - s * local[1], s * local[0] + c * local[1], local[2]];
                f.rotate([-turned[1], turned[0], z])
            };
            let (fu, fv) = (&jg.frames[0], &jg.frames[1]);
            let v = match (jg.places[0], jg.places[1]) {
                (Place::Arm { arm, .. }, _) => rate(fu, arm),
                // The arm on v: T_v = T_u·F_u·Trans(−R(θ)a)·F_v⁻¹ in v's (parallel) axes.
                (_, Place::Arm { arm, .. }) => fu.rotate(fv.rotate_back(rate(fv, arm))).map(|x| -x),
                _ => zero,
            };
            vec![Screw {
                w: zero,
                v: pu.rotate(v),
            }]
        }
        JointType::S => {
            // The centre on u stays still: about axis i in world axes through it.
            let c = pu.apply(jg.places[0].at());
            (0..3)
                .map(|i| {
                    let e: [T; 3] = core::array::from_fn(|k| T::c(if k == i { 1.0 } else { 0.0 }));
                    Screw { w: e, v: cross(c, e) }
                })
                .collect()
        }
    }
}

/// The twist of joint `j`'s second link relative to its first, per unit rate
/// of each of its variables, at its values, in world axes given the first
/// link's pose `tu`: [`unit_twists`] at `f64`.
pub fn joint_twists(model: &Model, j: usize, values: &[f64], tu: &Isometry3<f64>) -> Vec<Twist> {
    let joint = &model.joints[j];
    let jg = JointGeometry::new(joint.kind, joint.links, joint.places);
    let value = (joint.kind == JointType::Pa).then(|| JointValue::given(JointType::Pa, values[0]));
    unit_twists(&jg, value, &crate::plan::frame_of(tu))
        .into_iter()
        .map(Twist::from)
        .collect()
}

/// The time derivative of joint `j`'s unit twists (world), given the
/// twist `vu` of its first link and its own rates: a twist mounted on the
/// first link is carried by it (`[V_u, ξ]`); a parallelogram's also turns
/// with its own value; an S joint's are fixed world axes through a centre
/// that moves with the first link.
pub fn joint_twist_rates(
    model: &Model,
    j: usize,
    values: &[f64],
    rates: &[f64],
    tu: &Isometry3<f64>,
    vu: &Twist,
) -> Vec<Twist> {
    let joint = &model.joints[j];
    let xi = joint_twists(model, j, values, tu);
    match joint.kind {
        JointType::S => {
            let c = tu.transform_point(&joint.places[0].at().into()).coords;
            let cd = vu.at(&c);
            (0..3)
                .map(|i| Twist {
                    w: Vector3::zeros(),
                    v: -Vector3::ith(i, 1.0).cross(&cd),
                })
                .collect()
        }
        JointType::Pa => {
            // ∂ξ/∂θ: the arm's rate turns a further quarter turn, ẑ × (ẑ × a) = −a⊥.
            let frame = |p: &Place| canonical_frame(p.at(), p.axis());
            let axis = tu.rotation * (frame(&joint.places[0]).rotation * Vector3::z());
            let own = Twist {
                w: Vector3::zeros(),
                v: axis.cross(&xi[0].v) * rates[0],
            };
            vec![vu.bracket(&xi[0]).add(&own)]
        }
        _ => xi.iter().map(|x| vu.bracket(x)).collect(),
    }
}
