//! Inverse dynamics by Lagrange's equations (seed 003 §4), in the inputs
//! q as generalized coordinates:
//!
//! `τ_k = d/dt(∂T/∂q̇_k) − ∂T/∂q_k + ∂U/∂q_k − Q_k`,
//!
//! `T = Σ ½ m |ċ|² + ½ Ωᵀ I Ω` over the links' and the parallelograms'
//! bars' bodies (Ω the body's angular velocity in its own
//! axes, `[Ω]× = Rᵀ Ṙ`), `U = −Σ m g·c`, and `Q_k` the loads' generalized
//! forces (an S–S link's moment about its line dropped: its idle spin does
//! no work, `Loading::idle_spins_dropped`). Every derivative of the link
//! poses R(q), c(q) is exact: the
//! plan's closed-form steps run on hyper-dual inputs ([`HyperDual`]),
//! `ε₁` along q̇ and `ε₂` along q̇, q̈ or one input's unit vector. It shares
//! no code with the virtual-work path ([`crate::virtual_work`]), which
//! reads the loop-closure velocity equations instead, nor with Newton–Euler.

use crate::frame::Frame;
use crate::hyper_dual::HyperDual;
use crate::mass_properties::{arm_side, Carrier, Loading};
use crate::model::Model;
use crate::plan::Plan;
use crate::primitives::Sign;
use crate::scalar::Scalar;
use crate::solution::SolveError;
use crate::steps::{self, Geometry, Given};
use nalgebra::{Matrix3, Vector3};
use std::borrow::Cow;

/// The actuators' forces (N for a slide, N·L for a turn, in the plan's
/// input order) that drive the mechanism along `inputs` on the branch
/// `signs` with the inputs' rates and accelerations, against gravity and
/// the loads. The branch is not verified here (solve it with
/// [`Plan::solve`] first): this is a reference path.
pub fn actuator_forces(
    model: &Model,
    plan: &Plan,
    loading: &Loading,
    inputs: &[f64],
    signs: &[Sign],
    rates: &[f64],
    accels: &[f64],
) -> Result<Vec<f64>, SolveError> {
    let n = inputs.len();
    let wanted = plan.n_inputs;
    if n != wanted || rates.len() != n || accels.len() != n || signs.len() != plan.branches {
        return Err(SolveError::BadInput {
            what: Cow::Owned(format!(
                "expected {wanted} inputs, rates and accelerations and {} signs; got {n}, {}, {} and {}",
                plan.branches,
                rates.len(),
                accels.len(),
                signs.len()
            )),
        });
    }
    // An S–S link's idle spin does no work (see `Loading::idle_spins_dropped`).
    let loading = &*loading
        .idle_spins_dropped(model)
        .map_err(|(link, problem)| SolveError::BadInput {
            what: Cow::Owned(format!("link `{}`: {problem}", model.links[link])),
        })?;
    let geometry = Geometry::<HyperDual>::of(model);
    let name = |_: usize| Cow::Borrowed("");
    // The link poses with ε₁ along `d1` and ε₂ along `d2`, then every
    // body's frame (a link's pose, or a parallelogram bar's).
    let poses = |d1: &[f64], d2: &[f64]| -> Result<Vec<Frame<HyperDual>>, SolveError> {
        let values: Vec<HyperDual> = (0..n).map(|i| HyperDual::variable(inputs[i], d1[i], d2[i])).collect();
        let given = Given {
            values: &values,
            signs,
            name: &name,
            sites: 0,
        };
        let solved = steps::run(plan, &geometry, model.links.len(), &given)?;
        let mut frames = solved.poses.clone();
        for b in &loading.bodies {
            frames.push(body_frame(model, &geometry, &solved, &b.carrier)?);
        }
        Ok(frames)
    };
    // Body k's frame is at `links + k`.
    let links = model.links.len();
    let zero = vec![0.0; n];
    // R, c; their rates; their second derivatives along the rates.
    let along_rates = poses(rates, rates)?;
    // Their derivatives along the accelerations.
    let along_accels = poses(accels, &zero)?;
    // Per input k: the derivatives along e_k, and along the rates and e_k.
    let along_inputs: Vec<Vec<Frame<HyperDual>>> = (0..n)
        .map(|k| {
            let e: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == k))).collect();
            poses(rates, &e)
        })
        .collect::<Result<_, _>>()?;
    let g = loading.gravity;
    let mut tau = vec![0.0; n];
    for (k, b) in loading.bodies.iter().enumerate() {
        let frame = links + k;
        let at = |f: &Frame<HyperDual>| Body::of(f, &b.centroid);
        let m = b.mass;
        let a = at(&along_rates[frame]);
        let q2 = at(&along_accels[frame]);
        let (r, rdot) = (&a.r0, &a.r1);
        // c̈ and R̈ along the motion.
        let c_dd = a.c12 + q2.c1;
        let r_dd = a.r12 + q2.r1;
        // Ω = vee(Rᵀ Ṙ) and its rate.
        let omega = vee(&(r.transpose() * rdot));
        let omega_dot = vee(&(rdot.transpose() * rdot + r.transpose() * r_dd));
        let i = b.inertia;
        for (k, t) in tau.iter_mut().enumerate() {
            let d = at(&along_inputs[k][frame]);
            // ∂c/∂q_k and ∂R/∂q_k (ε₂), ∂²/∂q̇∂q_k (ε₁ε₂).
            let (c_k, r_k, c_k_dot, r_k_dot) = (d.c2, d.r2, d.c12, d.r12);
            // d/dt ∂T/∂q̇_k: ∂T/∂q̇_k = m ċ·∂c/∂q_k + Ωᵀ I vee(Rᵀ ∂R/∂q_k).
            let w_k = vee(&(r.transpose() * r_k));
            let w_k_dot = vee(&(rdot.transpose() * r_k + r.transpose() * r_k_dot));
            let ddt = m * (c_dd.dot(&c_k) + a.c1.dot(&c_k_dot)) + (i * omega_dot).dot(&w_k) + (i * omega).dot(&w_k_dot);
            // ∂T/∂q_k = m ċ·∂ċ/∂q_k + Ωᵀ I ∂Ω/∂q_k.
            let omega_k = vee(&(r_k.transpose() * rdot + r.transpose() * r_k_dot));
            let dq = m * a.c1.dot(&c_k_dot) + (i * omega).dot(&omega_k);
            // ∂U/∂q_k with U = −m g·c.
            let du = -m * g.dot(&c_k);
            *t += ddt - dq + du;
        }
    }
    for l in &loading.loads {
        for (k, t) in tau.iter_mut().enumerate() {
            let d = Body::of(&along_inputs[k][l.link], &l.at);
            // The load's virtual rotation in base axes: vee(∂R/∂q_k Rᵀ).
            let w = vee(&(d.r2 * d.r0.transpose()));
            *t -= l.force.dot(&d.c2) + l.moment.dot(&w);
        }
    }
    if tau.iter().any(|t| !t.is_finite()) {
        // Given finite values, this is a kernel's intermediate that passes
        // through a non-smooth point (a distance that is exactly 0, a norm
        // of a zero vector): it has no derivative there, although the
        // position solution is smooth.
        return Err(SolveError::BadInput {
            what: Cow::Borrowed(
                "the forces are not finite: a value given is not, or a derivative through the position solution is not defined here (an intermediate distance of the plan is 0)",
            ),
        });
    }
    Ok(tau.into_iter().map(|t| loading.to_newtons(t)).collect())
}

/// A body's frame in a run of the plan: its link's pose, or, for a
/// parallelogram's bar, the arm-carrying link's pose moved to the hinge and
/// turned by the parallelogram's value about the hinge axis (the value
/// read from the two links' poses, so that its derivatives are exact too).
fn body_frame(
    model: &Model,
    geometry: &Geometry<HyperDual>,
    solved: &steps::Solved<HyperDual>,
    carrier: &Carrier,
) -> Result<Frame<HyperDual>, SolveError> {
    match *carrier {
        Carrier::Link(l) => Ok(solved.poses[l]),
        Carrier::Bar { joint, hinge } => {
            let Some((c, axis)) = arm_side(model, joint) else {
                return Err(SolveError::BadInput {
                    what: Cow::Owned(format!(
                        "a body is a bar of joint {joint}, which is not a parallelogram with an arm"
                    )),
                });
            };
            let theta = steps::value(geometry, solved, joint);
            let h = Frame::translation([0, 1, 2].map(|i| HyperDual::c(hinge[i])));
            let turn = Frame::about([0, 1, 2].map(|i| HyperDual::c(axis[i])), theta.cos(), theta.sin());
            Ok(solved.poses[c].then(&h).then(&turn))
        }
    }
}

/// A body point's position and its link's rotation, each split into the
/// hyper-dual parts: value, along ε₁, along ε₂, mixed.
struct Body {
    r0: Matrix3<f64>,
    r1: Matrix3<f64>,
    r2: Matrix3<f64>,
    r12: Matrix3<f64>,
    c1: Vector3<f64>,
    c2: Vector3<f64>,
    c12: Vector3<f64>,
}

impl Body {
    fn of(f: &Frame<HyperDual>, local: &Vector3<f64>) -> Body {
        let p = f.apply([0, 1, 2].map(|i| HyperDual::c(local[i])));
        let part = |g: fn(&HyperDual) -> f64| Matrix3::from_fn(|i, j| g(&f.r[i][j]));
        let point = |g: fn(&HyperDual) -> f64| Vector3::from_fn(|i, _| g(&p[i]));
        Body {
            r0: part(|x| x.re),
            r1: part(|x| x.e1),
            r2: part(|x| x.e2),
            r12: part(|x| x.e12),
            c1: point(|x| x.e1),
            c2: point(|x| x.e2),
            c12: point(|x| x.e12),
        }
    }
}

/// The axial vector of a matrix's skew part: `[vee(M)]× = (M − Mᵀ)/2`.
fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    0.5 * Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
}
