//! Mobility from special geometry. The topology counts F at generic
//! instances of the declared axis relations; a mechanism whose dimensions
//! satisfy a further condition (a Bennett linkage: a / sin α = b / sin β)
//! moves where those instances do not. This compares the rank of the
//! loop-closure equations at an assembly of the declared geometry with
//! the generic one, and where it is lower follows the motion it allows
//! for a finite distance: an instantaneous mobility alone (a shaky
//! configuration) is not reported as one.

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::mechanism::{DirectionClasses, DirectionItem, Mechanism};
use crate::topology::analysis::Analysis;
use crate::topology::screw::{rotation_about, twist, Instance};
use crate::topology::Topology;
use nalgebra::{DMatrix, Vector3};
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::newton::{solve_fk, NewtonOptions};
use std::collections::HashMap;

/// Steps of the followed motion, and each step's size (rad, or sizes of
/// the mechanism for a slide), along the lost rank's direction.
pub const FOLLOW_STEPS: usize = 5;
/// The size of each step.
pub const FOLLOW_STEP: f64 = 0.05;
/// A singular value below this fraction of the largest is a lost rank.
pub const RANK_TOL: f64 = 1e-8;

/// Where the declared geometry moves more than the topology says.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecialMobility {
    /// F of the topology, at generic instances of the declared relations.
    pub generic: usize,
    /// The mobility at the declared geometry: the joint rates less the
    /// loops' rank at an assembly of it.
    pub declared: usize,
    /// The loops' rank there, and the rank F = `generic` would leave.
    pub rank: [usize; 2],
    /// The joint whose value was stepped to follow the motion.
    pub followed: usize,
    /// How many of [`FOLLOW_STEPS`] steps stayed assembled with the lower rank.
    pub steps: usize,
    /// The joint values of the assembly and of each step followed from it.
    pub configurations: Vec<Vec<f64>>,
}

impl SpecialMobility {
    /// Whether the motion was followed through every step: a finite motion.
    pub fn finite(&self) -> bool {
        self.steps == FOLLOW_STEPS
    }
}

/// The loops' rank at `values`, rates of lengths taken in sizes of the
/// mechanism, their rows in sizes too (as the loop residual), and the
/// right singular vectors of the rank lost.
fn rank(model: &Model, values: &[f64], scale: f64) -> Option<(usize, Vec<Vec<f64>>)> {
    let a = pkm_runtime::velocity::loops(model, values).ok()?.scaled(scale);
    let n = a.ncols();
    // Square, so that V holds a basis of the whole rate space.
    let mut square = DMatrix::zeros(a.nrows().max(n), n);
    square.view_mut((0, 0), (a.nrows(), n)).copy_from(&a);
    let svd = square.svd(false, true);
    let largest = svd.singular_values.max();
    let v_t = svd.v_t?;
    let lost: Vec<Vec<f64>> = (0..n)
        .filter(|&k| svd.singular_values[k] <= RANK_TOL * largest.max(f64::MIN_POSITIVE))
        .map(|k| v_t.row(k).iter().copied().collect())
        .collect();
    Some((n - lost.len(), lost))
}

/// The mechanism's mobility at its declared geometry (`model`, the
/// analysis's at the file's parameters) where it exceeds the topology's F,
/// checked along a finite motion; `None` where it does not, where the
/// geometry is incomplete, or where no assembly of it is found (from the
/// zero configuration and 40 deterministic starts).
pub fn special_mobility(a: &Analysis, model: &Model) -> Option<SpecialMobility> {
    if !a.geometry.complete {
        return None;
    }
    let mut model = model.clone();
    model.joints.iter_mut().for_each(|j| j.actuated = false);
    let (offsets, n) = model.value_offsets();
    let scale = pkm_runtime::kinematics::model_scale(&model);
    let options = NewtonOptions::default();
    let mut rng = pkm_runtime::random::SplitMix::new(0x5eed_0b1e);
    let mut next = || rng.symmetric();
    let lengths = model.length_values();
    let assembly = (0..=40).find_map(|k| {
        let guess: Vec<f64> = (0..n)
            .map(|i| {
                if k == 0 {
                    0.0
                } else if lengths[i] {
                    scale * next()
                } else {
                    std::f64::consts::PI * next()
                }
            })
            .collect();
        solve_fk(&model, &[], &guess, &options).ok().map(|s| s.values)
    })?;
    let generic = a.topology.dof;
    let (r, lost) = rank(&model, &assembly, scale)?;
    let declared = n - r;
    if declared <= generic {
        return None;
    }
    // Follow the first lost direction: step the joint that moves most along it.
    // The direction in rates (a slide's in lengths, not sizes).
    let unit = |k: usize| if lengths[k] { scale } else { 1.0 };
    let dir: Vec<f64> = lost[0].iter().enumerate().map(|(k, d)| d * unit(k)).collect();
    let i = (0..n).max_by(|&x, &y| lost[0][x].abs().total_cmp(&lost[0][y].abs()))?;
    let followed = (0..model.joints.len()).find(|&j| offsets[j] <= i && i < offsets[j] + model.joints[j].kind.dof())?;
    if model.joints[followed].kind.dof() != 1 {
        return None;
    }
    let mut stepped = model.clone();
    stepped.joints[followed].actuated = true;
    let h = FOLLOW_STEP * unit(i) * dir[i].signum();
    let mut values = assembly;
    let mut configurations = vec![values.clone()];
    let mut steps = 0;
    for _ in 0..FOLLOW_STEPS {
        let target = values[i] + h;
        let guess: Vec<f64> = values.iter().zip(&dir).map(|(v, d)| v + h * d / dir[i]).collect();
        let Ok(s) = solve_fk(&stepped, &[target], &guess, &options) else {
            break;
        };
        match rank(&model, &s.values, scale) {
            Some((r_here, _)) if n - r_here >= declared => {}
            _ => break,
        }
        values = s.values;
        configurations.push(values.clone());
        steps += 1;
    }
    Some(SpecialMobility {
        generic,
        declared,
        rank: [r, n - generic],
        followed,
        steps,
        configurations,
    })
}

/// The topology counted at configurations of the declared geometry, for a
/// mechanism that declares `mobility by geometry;`: the assembly and the
/// motion followed from it ([`special_mobility`]), every other one for the
/// ranks and the rest for the cross-check. F, ξ_L, Δ, κ and the POC sets
/// are then those of the declared dimensions, and the actuators are
/// counted against that F.
///
/// # Errors
/// Where the geometry is incomplete or has no assembly, where it moves
/// as generic instances of its relations do (nothing to accept), where
/// the extra motion was not followed to the end (a shaky configuration),
/// and for joints whose configuration is not modelled here (a
/// parallelogram, a plane named in a relation).
pub fn accept(a: &Analysis) -> Result<Topology, Diagnostics> {
    let m = &a.mechanism;
    let span = m.mobility_by_geometry.unwrap_or_else(|| m.name_span());
    let refuse = |message: String, note: &str| -> Diagnostics {
        Diagnostic::new(span, message)
            .label("declared here")
            .note(note.to_string())
            .into()
    };
    let model = super::numeric::model(a, &HashMap::new())?;
    let Some(special) = special_mobility(a, &model) else {
        return Err(refuse(
            format!(
                "`mobility by geometry`: the declared geometry moves as generic instances of its relations do (F = {}), \
                 or no assembly of it was found",
                a.topology.dof
            ),
            "remove the statement: the topology's F already holds for these dimensions",
        ));
    };
    if !special.finite() {
        return Err(refuse(
            format!(
                "`mobility by geometry`: the loops lose rank at an assembly of the declared geometry, but the motion \
                 stops after {} of {FOLLOW_STEPS} steps: a shaky configuration, not a mobility",
                special.steps
            ),
            "the declared dimensions do not make the mechanism move more than F",
        ));
    }
    let instances = special
        .configurations
        .iter()
        .map(|values| instance(m, &model, values))
        .collect::<Result<Vec<_>, String>>()
        .map_err(|e| refuse(format!("`mobility by geometry`: {e}"), "not supported yet"))?;
    // The assembly and every other step for the ranks, the rest for the cross-check.
    let (primary, check): (Vec<_>, Vec<_>) = instances.into_iter().enumerate().partition(|(k, _)| k % 2 == 0);
    let mut t = crate::topology::analyze_at(
        m,
        primary.into_iter().map(|(_, i)| i).collect(),
        check.into_iter().map(|(_, i)| i).collect(),
    )?;
    t.generic_dof = Some(a.topology.dof);
    Ok(t)
}

/// The screw instance of the mechanism at joint values `values` of
/// `model`: each joint's axis, point and twists in the base frame, and the
/// direction of each item the relations name.
fn instance(m: &Mechanism, model: &Model, values: &[f64]) -> Result<Instance, String> {
    let poses = pkm_runtime::kinematics::link_poses(model, values).map_err(|e| e.to_string())?;
    let v = |a: [f64; 3]| Vector3::new(a[0], a[1], a[2]);
    let mut points = Vec::new();
    let mut axes = Vec::new();
    let mut twists = Vec::new();
    for (j, joint) in model.joints.iter().enumerate() {
        // The side that holds the joint's line (a guide, an axis), else the first.
        let side = (0..2)
            .find(|&s| matches!(joint.places[s], Place::Axis { .. } | Place::Line { .. }))
            .unwrap_or(0);
        let pose = poses[joint.links[side]];
        let p = (pose * nalgebra::Point3::from(v(joint.places[side].at()))).coords;
        let d = (pose.rotation * v(joint.places[side].axis())).normalize();
        let about = |w: Vector3<f64>| rotation_about(w, p);
        let t = match joint.kind {
            JointType::R => vec![about(d)],
            JointType::P => vec![twist(Vector3::zeros(), d)],
            JointType::S => vec![about(Vector3::x()), about(Vector3::y()), about(Vector3::z())],
            JointType::Pa => {
                return Err(format!(
                    "the parallelogram {} is not modelled at a configuration",
                    m.joints[j].name
                ))
            }
        };
        points.push(p);
        axes.push(d);
        twists.push(t);
    }
    let classes = DirectionClasses::new(&m.joints, &m.relations);
    let directions = classes
        .items()
        .iter()
        .map(|item| match *item {
            DirectionItem::Joint(j) => Ok(axes[j]),
            DirectionItem::Frame(k) => Ok(Vector3::ith(k, 1.0)),
            DirectionItem::USecond(j) => Err(format!(
                "the U joint {} is not modelled at a configuration",
                m.joints[j].name
            )),
            DirectionItem::PlaneNormal(_) => {
                Err("a plane `◇(A, B)` in a relation is not modelled at a configuration".into())
            }
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Instance {
        directions,
        points,
        twists,
        frame: [Vector3::x(), Vector3::y(), Vector3::z()],
    })
}
