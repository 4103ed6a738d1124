//! The description in numbers: every parameter's value ([`parameter_values`]),
//! the numeric model the interpreter and Newton's method run on ([`model`]),
//! and the declared outputs for Newton's inverse solution ([`newton_outputs`]).

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::limb_properties::{LegStiffness, LimbValue, ResolvedLimb, KEYS};
use crate::semantics::mechanism::JointKind;
use crate::topology::analysis::Analysis;
use pkm_runtime::model::{Joint, JointType, Model, NamedPoint};
use std::collections::HashMap;

/// The declared outputs in numbers (for Newton's inverse solution) at the
/// given parameter values, points read from `model`.
pub fn newton_outputs(
    a: &Analysis,
    model: &Model,
    values: &HashMap<String, f64>,
) -> Result<Vec<pkm_runtime::newton::Output>, Diagnostics> {
    use crate::semantics::geometry::OutputKind;
    use pkm_runtime::newton::Output;
    // Derived parameters follow the overrides, as in `model`.
    let all = parameter_values(a, values)?;
    let local = |point, link| {
        pkm_runtime::plan::local_point(model, point, link)
            .map_err(|e| Diagnostics::from(Diagnostic::new(a.mechanism.name_span(), e.to_string())))
    };
    a.geometry
        .outputs
        .iter()
        .map(|o| {
            Ok(match &o.kind {
                OutputKind::Pose { link, point, about } => Output::Pose {
                    link: *link,
                    local: local(*point, *link)?,
                    about: match about {
                        Some(k) => Some(crate::semantics::geometry::eval_vec3(k, &all)),
                        None if a.mechanism.planar => Some([0.0, 0.0, 1.0]),
                        None => None,
                    },
                },
                OutputKind::Point { link, point } => Output::Point {
                    link: *link,
                    local: local(*point, *link)?,
                },
                OutputKind::Parts { link, point, parts } => Output::Parts {
                    link: *link,
                    local: local(*point, *link)?,
                    parts: *parts,
                },
                OutputKind::Joint(j) => Output::Joint(*j),
            })
        })
        .collect()
}

/// Every parameter's value: those in `values` as given, the others computed
/// from their expressions (so a parameter that reads an overridden one
/// follows it). A value that is not a finite number is an error naming the
/// parameter and its expression.
pub fn parameter_values(a: &Analysis, values: &HashMap<String, f64>) -> Result<HashMap<String, f64>, Diagnostics> {
    let g = &a.geometry;
    if values.is_empty() {
        return Ok(g.nominal());
    }
    if let Some(k) = values.keys().find(|k| !g.parameters.iter().any(|p| &p.name == *k)) {
        return Err(Diagnostic::global(format!("unknown parameter `{k}`")).into());
    }
    let definitions: Vec<crate::syntax::expr::Definition> = g
        .parameters
        .iter()
        .map(|p| crate::syntax::expr::Definition {
            name: &p.name,
            span: p.span,
            expr: &p.expr,
        })
        .collect();
    let (params, errors) = crate::syntax::expr::resolve(&definitions, values);
    Diagnostics(errors).into_result(params)
}

/// The numeric model at the given parameter values (the nominal ones for
/// names not in `values`).
pub fn model(a: &Analysis, values: &HashMap<String, f64>) -> Result<Model, Diagnostics> {
    let m = &a.mechanism;
    let g = &a.geometry;
    if !g.complete {
        return Err(
            Diagnostic::new(m.joints[0].span, format!("mechanism `{}` has no geometry", m.name))
                .label("add a `parameters` and a `geometry` block")
                .into(),
        );
    }
    let params = parameter_values(a, values)?;
    let eval = |v: &crate::semantics::geometry::Vec3| crate::semantics::geometry::eval_vec3(v, &params);
    let mut joints = Vec::new();
    for (j, joint) in m.joints.iter().enumerate() {
        let kind = match joint.kind {
            JointKind::R => JointType::R,
            JointKind::P => JointType::P,
            JointKind::S => JointType::S,
            JointKind::Pa => JointType::Pa,
            k => {
                return Err(
                    Diagnostic::new(joint.span, format!("{} joints have no numeric model yet", k.symbol()))
                        .label("not supported by the solvers yet")
                        .into(),
                )
            }
        };
        let place = |s: usize| {
            g.places[j][s]
                .as_ref()
                .expect("complete geometry places every joint")
                .place(eval)
        };
        joints.push(Joint {
            name: joint.name.clone(),
            kind,
            links: joint.links,
            places: [place(0), place(1)],
            actuated: joint.actuated,
        });
    }
    Ok(Model {
        name: m.name.clone(),
        planar: m.planar,
        links: m.links.iter().map(|l| l.name.clone()).collect(),
        joints,
        points: g
            .points
            .iter()
            .map(|p| NamedPoint {
                name: p.name.clone(),
                link: p.link,
                at: eval(&p.at),
            })
            .collect(),
    })
}

/// The moving links that neither have mass properties nor are declared
/// massless, by name. A U joint's cross is massless.
pub fn links_without_mass(a: &Analysis) -> Vec<&str> {
    let d = &a.mass_and_loads;
    let cross = |l: usize| a.mechanism.universals.iter().any(|u| u.cross == l);
    let described = |l: usize| d.masses.iter().any(|b| b.link == l) || d.massless.contains(&l) || cross(l);
    (1..a.mechanism.links.len())
        .filter(|&l| !described(l))
        .map(|l| a.mechanism.links[l].name.as_str())
        .collect()
}

/// The bodies, gravity and loads in numbers at the given parameter values,
/// in the units the dynamics computes in (kg, the file's length unit, s;
/// see [`pkm_runtime::mass_properties`]). A mass or an inertia that the
/// parameters make negative or not a rigid body's is an error naming the link.
pub fn loading(
    a: &Analysis,
    model: &Model,
    values: &HashMap<String, f64>,
) -> Result<pkm_runtime::mass_properties::Loading, Diagnostics> {
    use crate::semantics::mass_and_loads::Inertia;
    use nalgebra::Vector3;
    use pkm_runtime::mass_properties::{Body, Carrier, Loading, PointLoad};
    let d = &a.mass_and_loads;
    let span = a.mechanism.name_span();
    let Some(units) = d.units else {
        return Err(Diagnostic::new(
            span,
            "dynamics needs the file's units: `units { length = mm; mass = kg; }`",
        )
        .into());
    };
    let missing = links_without_mass(a);
    if !missing.is_empty() {
        return Err(Diagnostic::new(
            span,
            format!(
                "dynamics needs every moving link's mass: {} ha{} none (give a `mass` and `centroid` in `masses`, or declare it `massless`)",
                missing.join(", "),
                if missing.len() == 1 { "s" } else { "ve" }
            ),
        )
        .into());
    }
    let all = parameter_values(a, values)?;
    let eval = |e: &crate::syntax::expr::Expr| e.eval(&all);
    let vec3 = |v: &[crate::syntax::expr::Expr; 3]| Vector3::new(eval(&v[0]), eval(&v[1]), eval(&v[2]));
    let not_finite = |what: String| {
        Diagnostics::from(Diagnostic::new(
            span,
            format!("{what} is not finite at these parameters"),
        ))
    };
    let l = units.length.metres();
    let kg = units.mass.kilograms();
    let gravity = d.gravity_declared.as_ref().map_or(Vector3::from(d.gravity), &vec3);
    if gravity.iter().any(|x| !x.is_finite()) {
        return Err(not_finite("gravity".into()));
    }
    // Every body, a link's or a parallelogram bar's, in the runtime's units.
    let body = |carrier: Carrier,
                who: String,
                mass: &crate::syntax::expr::Expr,
                centroid: &[crate::syntax::expr::Expr; 3],
                inertia: &Inertia|
     -> Result<Body, Diagnostics> {
        let mass = eval(mass);
        if !mass.is_finite() || mass < 0.0 {
            return Err(Diagnostic::new(span, format!("the mass of {who} is {mass} at these parameters")).into());
        }
        let moments: Vec<f64> = match inertia {
            Inertia::Point => vec![0.0; 3],
            Inertia::Planar(e) => vec![eval(e)],
            Inertia::Principal(e) => e.iter().map(eval).collect(),
            Inertia::Full(e) => e.iter().map(eval).collect(),
        };
        if let Some(problem) = crate::semantics::mass_and_loads::inertia_problem(&moments) {
            return Err(Diagnostic::new(span, format!("{who}: {problem} at these parameters")).into());
        }
        let inertia = crate::semantics::mass_and_loads::inertia_tensor(&moments);
        let centroid = vec3(centroid);
        if centroid.iter().any(|x| !x.is_finite()) {
            return Err(not_finite(format!("the centroid of {who}")));
        }
        Ok(Body {
            carrier,
            mass: mass * kg,
            centroid,
            inertia: inertia * kg,
        })
    };
    let mut bodies = Vec::new();
    for b in &d.masses {
        let who = format!("link `{}`", a.mechanism.links[b.link].name);
        bodies.push(body(Carrier::Link(b.link), who, &b.mass_expr, &b.centroid, &b.inertia)?);
    }
    for b in &d.bars {
        let who = format!("the bar of `{}`", a.mechanism.joints[b.joint].name);
        let hinge = vec3(&b.hinge);
        if hinge.iter().any(|x| !x.is_finite()) {
            return Err(not_finite(format!("the hinge of {who}")));
        }
        let carrier = Carrier::Bar { joint: b.joint, hinge };
        bodies.push(body(carrier, who, &b.mass_expr, &b.centroid, &b.inertia)?);
    }
    let loads = d
        .loads
        .iter()
        .map(|p| {
            let at = match p.at {
                Some(point) => pkm_runtime::plan::local_point(model, point, p.link)
                    .map_err(|e| Diagnostics::from(Diagnostic::new(span, e.to_string())))?,
                None => [0.0; 3],
            };
            let (force, moment) = (vec3(&p.force), vec3(&p.moment));
            if force.iter().chain(moment.iter()).any(|x| !x.is_finite()) {
                return Err(not_finite(format!("load `{}`", p.name)));
            }
            Ok(PointLoad {
                link: p.link,
                at: Vector3::from(at),
                force: force / l,
                moment: moment / l,
            })
        })
        .collect::<Result<_, Diagnostics>>()?;
    Ok(Loading {
        bodies,
        gravity: gravity / l,
        loads,
        metres_per_unit: l,
    })
}

/// The SKCs for the force analysis, in the position solution's order: each
/// one's new links, its joints (its SOCs'), and the reaction components its
/// loops leave undetermined, Σ (6 − ξ_L) (Σ (3 − ξ_L) planar).
pub fn skc_parts(a: &Analysis) -> Vec<pkm_runtime::newton_euler::SkcParts> {
    let t = &a.topology;
    let d = if a.mechanism.planar { 3 } else { 6 };
    let mut built = vec![false; a.mechanism.links.len()];
    built[0] = true;
    t.skcs
        .iter()
        .map(|skc| {
            let socs = &t.socs[skc.socs.clone()];
            let joints: Vec<usize> = socs.iter().flat_map(|s| s.joints.iter().copied()).collect();
            let mut links = Vec::new();
            for &j in &joints {
                for l in a.mechanism.joints[j].links {
                    if !built[l] {
                        built[l] = true;
                        links.push(l);
                    }
                }
            }
            pkm_runtime::newton_euler::SkcParts {
                links,
                joints,
                undetermined: socs.iter().map(|s| d - s.xi.min(d)).sum(),
            }
        })
        .collect()
}

/// Every declared limb's properties in numbers at the parameters `values`
/// (overrides by name; the others keep the file's values, derived ones
/// follow), one per limb in branch order. A value that is not a positive
/// finite number there is an error at the value, naming the limb.
///
/// Which branches have no entry is not an error here: `stiffness` asks for
/// every branch's ([`crate::check_capabilities`]).
pub fn limb_properties(a: &Analysis, values: &HashMap<String, f64>) -> Result<Vec<ResolvedLimb>, Diagnostics> {
    let params = parameter_values(a, values)?;
    let mut errors = Diagnostics::default();
    let mut out = Vec::with_capacity(a.limbs.len());
    for limb in &a.limbs {
        let name = &a.mechanism.branches[limb.branch].name;
        let mut eval = |key: &str, v: &LimbValue| -> f64 {
            let what = KEYS.iter().find(|(k, _)| *k == key).map_or("value", |(_, w)| w);
            let problem = match v.expr.eval_checked(&params) {
                Ok(x) if x > 0.0 => return x,
                Ok(x) => format!("the {what} `{key}` of limb `{name}` is {x} at these parameters; it must be positive"),
                Err(why) => format!("the {what} `{key}` of limb `{name}` is not a number at these parameters: {why}"),
            };
            errors.push(Diagnostic::new(v.span, problem).label("here"));
            f64::NAN
        };
        let leg = match &limb.leg {
            LegStiffness::Section { e, a, i } => LegStiffness::Section {
                e: eval("E", e),
                a: eval("A", a),
                i: eval("I", i),
            },
            LegStiffness::Direct { axial, bending } => LegStiffness::Direct {
                axial: eval("axial", axial),
                bending: eval("bending", bending),
            },
        };
        let actuator = limb.actuator.as_ref().map(|v| eval("actuator", v));
        out.push(ResolvedLimb {
            branch: limb.branch,
            name: name.clone(),
            joints: limb.joints.clone(),
            actuated: limb.actuated.clone(),
            leg,
            actuator,
        });
    }
    errors.into_result(out)
}
