//! Inverse dynamics by the principle of virtual work (seed 000 §3.3): the
//! actuators' forces are the generalized forces that balance every body's
//! inertial wrench and the external ones along each input's virtual
//! motion,
//!
//! `τ_k = Σ_bodies [m (a_c − g)·v_c^k + (I α + ω × I ω)·ω^k] − Σ_loads [F·v_p^k + M·ω^k]`,
//!
//! with `(ω^k, v^k)` every link's twist for a unit rate of input `k` and
//! nothing else (the loop-closure velocity equations, [`crate::velocity`]);
//! a parallelogram's bar moves with its arm-carrying link and turns with
//! the parallelogram's rate about its hinge.
//! It shares no dynamics with the Newton–Euler or the Lagrange paths.

use crate::mass_properties::{Carrier, Loading};
use crate::model::Model;
use crate::velocity::{self, point_acceleration, BarTurn, Loops, Twist, VelocityError};
use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

/// A wrench on a body: a force through a world point and a moment. The
/// body is a link, or a parallelogram's bar (`bar`: its turn on its
/// arm-carrying link), whose virtual twist is the link's plus the
/// parallelogram's rate about the bar's hinge.
struct Wrench {
    link: usize,
    bar: Option<BarTurn>,
    at: Vector3<f64>,
    force: Vector3<f64>,
    moment: Vector3<f64>,
}

impl Wrench {
    /// Its power along the rates `rates` (every joint's).
    fn power(&self, loops: &Loops, rates: &[f64]) -> f64 {
        let t = match self.bar {
            None => loops.link_twist(self.link, rates),
            Some(b) => {
                let tc = loops.link_twist(b.carrier, rates);
                Twist {
                    w: tc.w + b.xi.w * rates[b.rate],
                    v: tc.v + b.xi.v * rates[b.rate],
                }
            }
        };
        self.force.dot(&t.at(&self.at)) + self.moment.dot(&t.w)
    }
}

/// The actuators' forces (N for a slide, N·L for a turn, in input order)
/// that drive the mechanism at joint values `values` with the inputs'
/// rates and accelerations, against gravity and the loads.
pub fn actuator_forces(
    model: &Model,
    loading: &Loading,
    values: &[f64],
    input_rates: &[f64],
    input_accels: &[f64],
) -> Result<Vec<f64>, VelocityError> {
    let loops = velocity::loops(model, values)?;
    // An S–S link's idle spin does no work (see `Loading::idle_spins_dropped`).
    let loading = &*loading
        .idle_spins_dropped(model)
        .map_err(|(link, problem)| VelocityError::IdleSpin {
            link: model.links[link].clone(),
            problem,
        })?;
    let motion = velocity::accelerations_on(&loops, model, values, input_rates, input_accels)?;
    let columns = loops.input_columns(crate::kinematics::model_scale(model))?;
    let poses = &loops.poses;
    let world = |link: usize, p: &Vector3<f64>| (poses[link] * Point3::from(*p)).coords;
    // Each body's inertial wrench less gravity, at its centroid (world).
    let inertial: Vec<Wrench> = loading
        .bodies
        .iter()
        .map(|b| {
            let m = velocity::body_motion(model, &loops, &motion, values, &b.carrier)?;
            let c = (m.pose * Point3::from(b.centroid)).coords;
            let (t, dt) = (&m.twist, &m.rate);
            let i = world_inertia(&m.pose, &b.inertia);
            Ok(Wrench {
                link: match b.carrier {
                    Carrier::Link(l) => l,
                    Carrier::Bar { .. } => 0,
                },
                bar: m.bar,
                at: c,
                force: b.mass * (point_acceleration(t, dt, &c) - loading.gravity),
                moment: i * dt.w + t.w.cross(&(i * t.w)),
            })
        })
        .collect::<Result<_, VelocityError>>()?;
    let external: Vec<Wrench> = loading
        .loads
        .iter()
        .map(|l| Wrench {
            link: l.link,
            bar: None,
            at: world(l.link, &l.at),
            force: l.force,
            moment: l.moment,
        })
        .collect();
    let power = |list: &[Wrench], rates: &[f64]| -> f64 { list.iter().map(|w| w.power(&loops, rates)).sum() };
    Ok(columns
        .iter()
        .map(|rates| loading.to_newtons(power(&inertial, rates) - power(&external, rates)))
        .collect())
}

/// An inertia tensor in a link's frame turned into base axes: `R I Rᵀ`.
fn world_inertia(pose: &Isometry3<f64>, local: &Matrix3<f64>) -> Matrix3<f64> {
    let r = pose.rotation.to_rotation_matrix();
    r.matrix() * local * r.matrix().transpose()
}
