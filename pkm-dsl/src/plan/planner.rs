//! Solution plans of every mechanism, planar and spatial (see
//! `pkm_runtime::plan`): links are solved one joint at a time, each
//! joint value from what the rest of the mechanism fixes about one point or
//! direction of the new link. This is the driver: it builds the search
//! (`pkm_runtime::steps::search::Search`) from the analysis (the nominal
//! model, the given joints, the links a pose output places or a point
//! output pins), adds steps until every link is known, and turns a search
//! that stalls into a diagnostic. Each step kind's structural match (when
//! the planner may use it) is its `find`, in its file in
//! `pkm_runtime::steps`; `steps::FIND_ORDER` is the order they are tried
//! in. No mechanism is named here.

use crate::diagnostics::{Diagnostic, Diagnostics};
use crate::semantics::geometry::OutputKind;
use crate::topology::analysis::Analysis;
use pkm_runtime::model::Model;
use pkm_runtime::plan::{self, Plan, Step, Turn};
use pkm_runtime::solution::PointRef;
use pkm_runtime::steps::parasitic;
use pkm_runtime::steps::place::PoseParts;
use pkm_runtime::steps::search::Search;
use std::collections::HashMap;

/// A link an output gives in part: the link, its point, the index of its
/// first value, the parts given.
type Partial = (usize, PointRef, usize, PoseParts);

#[allow(clippy::too_many_arguments)]
pub(crate) fn solve(
    a: &Analysis,
    model: &Model,
    given: Vec<Option<usize>>,
    start: Vec<Step>,
    partial: &[Partial],
    n_inputs: usize,
    inputs: Vec<usize>,
    what: &str,
) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    let mut known = vec![false; model.links.len()];
    known[0] = true;
    let mut pinned = vec![None; model.links.len()];
    for s in &start {
        if let Step::Place { link, point, turn, .. } = s {
            match turn {
                Turn::Free => {
                    let at = plan::local_point(model, *point, *link)
                        .map_err(|e| Diagnostics::from(Diagnostic::new(a.mechanism.name_span(), e.to_string())))?;
                    pinned[*link] = Some(at);
                }
                Turn::Fixed | Turn::About(_) | Turn::Angles => known[*link] = true,
            }
        }
    }
    let mut search = Search::new(model, given, known, pinned, start);
    if what == "forward" {
        search.set_translating(translating(a, model));
    }
    for &(link, point, input, parts) in partial {
        parasitic::start(&mut search, link, point, input, parts).map_err(|e| {
            Diagnostics::from(
                Diagnostic::new(
                    m.name_span(),
                    format!("no closed-form {what} plan for link {}: {e}", m.links[link].name),
                )
                .label("in this mechanism"),
            )
        })?;
    }
    while !search.known().iter().all(|k| *k) {
        if !search.step() {
            return Err(stalled(a, &search, what).into());
        }
    }
    Ok(search.into_plan(n_inputs, inputs))
}

/// The links that keep the base's orientation: those a spatial
/// mechanism's outputs give as a pose without a turn (`pose of L at P`,
/// the POC set of a translating platform), as the inverse plan places
/// them ([`Turn::Fixed`]).
fn translating(a: &Analysis, model: &Model) -> Vec<bool> {
    let mut out = vec![false; model.links.len()];
    if a.mechanism.planar {
        return out;
    }
    for o in &a.geometry.outputs {
        if let OutputKind::Pose { link, about: None, .. } = o.kind {
            out[link] = true;
        }
    }
    out
}

/// The refusal of a search that stalled: the links not reached, the last
/// link a step placed, and each joint left open between a known and a new
/// link, where the next step would have to start (a pinned link's pin too).
fn stalled(a: &Analysis, search: &Search<'_>, what: &str) -> Diagnostic {
    let m = &a.mechanism;
    let known = search.known();
    let name = |l: usize| m.links[l].name.as_str();
    let left: Vec<&str> = (0..m.links.len()).filter(|&l| !known[l]).map(name).collect();
    let stall = search.stall();
    let mut d = Diagnostic::new(
        m.name_span(),
        format!(
            "no closed-form {what} plan: links {} are not reached by the step catalogue \
             (aim, align, parallelogram plane, circle or line against sphere, plane, cylinder or pin, \
             guide through a point, point beyond a given joint, slide onto a line, axes through one \
             centre, a link between known spherical centres, a plane through a point, two turns \
             about meeting axes)",
            left.join(", ")
        ),
    )
    .label("in this mechanism");
    d = d.note(match stall.last {
        Some(l) => format!("the last link a step placed is {}", name(l)),
        None => "no step placed a link beyond those the start places (the base, the given inputs and outputs)".into(),
    });
    let open: Vec<String> = stall
        .open
        .iter()
        .map(|&(j, from, to, given)| {
            let given = if given { ", its value given" } else { "" };
            format!("{} ({} known, {} not{given})", m.joints[j].name, name(from), name(to))
        })
        .collect();
    if !open.is_empty() {
        d = d.note(format!(
            "left open between known and unreached links: {}; no step kind solves any of them from \
             what is known",
            open.join(", ")
        ));
    }
    // One note per group: the same links seen from both their ends once.
    let mut seen: Vec<Vec<usize>> = Vec::new();
    for g in &stall.groups {
        let mut links = g.links.clone();
        links.sort_unstable();
        if !seen.contains(&links) {
            d = d.note(group_note(a, g));
            seen.push(links);
        }
    }
    for (l, p) in stall.pinned {
        d = d.note(format!(
            "{} is pinned by a point output at ({}, {}) of its frame, its angle unknown",
            name(l),
            p[0],
            p[1]
        ));
    }
    d
}

/// What the nearest group of unknown links beyond an open joint needs:
/// which step kinds come closest, why none applies, and the declaration
/// that would let one.
fn group_note(a: &Analysis, g: &pkm_runtime::steps::search::Group) -> String {
    use pkm_runtime::steps::search::Shape;
    let m = &a.mechanism;
    let link = |l: usize| m.links[l].name.as_str();
    let joint = |j: usize| m.joints[j].name.as_str();
    let joints: Vec<&str> = g.joints.iter().map(|&j| joint(j)).collect();
    let links: Vec<&str> = g.links.iter().map(|&l| link(l)).collect();
    let [from, to] = g.ends;
    let head = format!(
        "beyond {}: {} unknown link{} ({}) through {} from {} to {}",
        joints[0],
        links.len(),
        if links.len() == 1 { "" } else { "s" },
        links.join(", "),
        joints.join(", "),
        link(from),
        link(to)
    );
    let why = match g.shape {
        Shape::Chain => format!(
            "more than two unknown links in a row: each step places one link from known ones (a dyad \
             closes on two), and none of these is held by known links alone; a plan exists with one of \
             them placed first, by an input on one of {} or a pose output on one of {}; a group of \
             class III or higher with neither needs a virtual variable (κ > 0)",
            joints.join(", "),
            links.join(", ")
        ),
        Shape::Planar => "a planar dyad (its axes parallel): circle and line steps close such a dyad once the \
             points they meet are known; here none was"
            .to_string(),
        Shape::Concurrent => "a spherical dyad (three axes through one point): the cone step closes it once the axis \
             beyond is known; here it was not"
            .to_string(),
        Shape::Spherical(s) => format!(
            "a dyad with the spherical joint {}: the sphere steps need the centre's other side known; here \
             it was not",
            joint(s)
        ),
        Shape::Spatial => {
            let [j, q, h] = [joints[0], joints[1], joints[2]];
            format!(
                "a spatial dyad, its axes neither parallel nor through one point, and no step matched its joints' \
                 kinds and places: the circle and line steps meet a point of {q} on one link with a locus (sphere, \
                 plane, cylinder) of the other about {j} or {h}, the cone step needs the three axes through one \
                 point, the sphere steps a spherical joint at {q} or {h}; a plan exists if the geometry has `{j} ∥ \
                 {q} ∥ {h}` or `{j} ∧ {q} ∧ {h}` declared, or {q} or {h} is an S"
            )
        }
    };
    format!("{head}: {why}")
}

/// The spatial forward-position plan.
///
/// κ ≠ 0 is refused, except where the steps close the coupled loops in
/// closed form all the same: a translating platform held on three spheres
/// ([`Step::Trilaterate`]: the forward problem of a Delta, a 3-UPU, an
/// Orthoglide), the coupling's virtual variables then not needed.
pub fn forward_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    let refuse_coupled = || {
        let mut d = Diagnostic::new(
            m.name_span(),
            format!("a closed-form forward plan needs κ = 0 (κ = {})", a.topology.kappa),
        )
        .label("in this mechanism");
        for note in a.topology.coupling_notes() {
            d = d.note(note);
        }
        Diagnostics::from(d)
    };
    let model = crate::lowering::numeric::model(a, &HashMap::new())?;
    // Only a translating link's three spheres close coupled loops.
    if a.topology.kappa != 0 && !translating(a, &model).contains(&true) {
        return Err(refuse_coupled());
    }
    let inputs = model.inputs();
    let mut given = vec![None; model.joints.len()];
    for (i, &j) in inputs.iter().enumerate() {
        given[j] = Some(i);
    }
    let planned = solve(a, &model, given, vec![], &[], inputs.len(), inputs, "forward");
    let spheres = |p: &Plan| p.steps.iter().any(|s| matches!(s, Step::Trilaterate { .. }));
    if a.topology.kappa != 0 && !planned.as_ref().is_ok_and(spheres) {
        return Err(refuse_coupled());
    }
    let mut plan = planned?;
    // The outputs read their links' poses; a joint output, both of its links'.
    let mut needed = vec![false; model.links.len()];
    for o in &a.geometry.outputs {
        match o.kind {
            OutputKind::Pose { link, .. } | OutputKind::Point { link, .. } | OutputKind::Parts { link, .. } => {
                needed[link] = true
            }
            OutputKind::Joint(j) => model.joints[j].links.iter().for_each(|&l| needed[l] = true),
        }
    }
    plan.check_by_miss(&model, &needed);
    Ok(plan)
}

/// The spatial inverse-position plan from the declared outputs.
pub fn inverse_plan(a: &Analysis) -> Result<Plan, Diagnostics> {
    let m = &a.mechanism;
    if a.geometry.outputs.is_empty() {
        return Err(
            Diagnostic::new(m.name_span(), "an inverse solution needs `outputs { … }`")
                .label("in this mechanism")
                .into(),
        );
    }
    let model = crate::lowering::numeric::model(a, &HashMap::new())?;
    let nominal = a.geometry.nominal();
    let mut given = vec![None; model.joints.len()];
    let mut start = Vec::new();
    let mut partial = Vec::new();
    let mut next = 0;
    let planar = m.planar;
    for o in &a.geometry.outputs {
        match &o.kind {
            OutputKind::Pose { link, point, about } => {
                let turn = match about {
                    Some(k) => Turn::About(crate::semantics::geometry::eval_vec3(k, &nominal)),
                    None if planar => Turn::About([0.0, 0.0, 1.0]),
                    None => Turn::Fixed,
                };
                start.push(Step::Place {
                    link: *link,
                    point: *point,
                    input: next,
                    planar,
                    turn,
                });
            }
            OutputKind::Point { link, point } => start.push(Step::Place {
                link: *link,
                point: *point,
                input: next,
                planar,
                turn: Turn::Free,
            }),
            OutputKind::Parts { link, point, parts } if parts.all() => start.push(Step::Place {
                link: *link,
                point: *point,
                input: next,
                planar,
                turn: Turn::Angles,
            }),
            OutputKind::Parts { link, point, parts } => partial.push((*link, *point, next, *parts)),
            OutputKind::Joint(j) => given[*j] = Some(next),
        }
        next += o.names.len();
    }
    let mut plan = solve(a, &model, given, start, &partial, next, vec![], "inverse")?;
    // The actuators' values read both of their links' poses.
    let mut needed = vec![false; model.links.len()];
    for j in model.joints.iter().filter(|j| j.actuated) {
        j.links.iter().for_each(|&l| needed[l] = true);
    }
    plan.check_by_miss(&model, &needed);
    Ok(plan)
}

#[cfg(test)]
mod tests {
    /// `(joint, a plane's sphere stands in, the turns skipped)`.
    type Misses<'a> = &'a [(&'a str, bool, bool)];

    /// The open joints each plan of `file` checks by a miss
    /// ([`pkm_runtime::plan::Plan::by_miss`]), by name: `(forward, inverse)`.
    fn check(file: &str, want: (Misses<'_>, Misses<'_>)) {
        let path = format!("{}/../examples/mechanisms/{file}", env!("CARGO_MANIFEST_DIR"));
        let c = crate::compile(&std::fs::read_to_string(path).unwrap()).unwrap();
        let joints = &c.analysis.mechanism.joints;
        let names = |p: &pkm_runtime::plan::Plan| -> Vec<(String, bool, bool)> {
            p.by_miss
                .iter()
                .map(|b| (joints[b.joint].name.clone(), b.plane.is_some(), b.skipped))
                .collect()
        };
        let owned =
            |w: Misses<'_>| -> Vec<(String, bool, bool)> { w.iter().map(|&(n, p, s)| (n.into(), p, s)).collect() };
        assert_eq!(names(c.forward().unwrap()), owned(want.0), "{file} forward");
        assert_eq!(names(c.inverse().unwrap()), owned(want.1), "{file} inverse");
    }

    /// A search that stalls says where: a four-bar searched with nothing
    /// given and nothing placed but the base stalls at once; the refusal
    /// names the links not reached, that no step placed one, and the two
    /// joints left open at the base.
    /// The compiled file (a path under the repository's root).
    fn compiled(file: &str) -> crate::Compiled {
        let path = format!("{}/../{file}", env!("CARGO_MANIFEST_DIR"));
        crate::compile(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// A search of `c` that starts from the base alone, the joints
    /// `given` given (input k for the k-th).
    fn from_the_base<'a>(c: &'a crate::Compiled, given: &[usize]) -> super::Search<'a> {
        let model = c.model().unwrap();
        let n_links = model.links.len();
        let mut known = vec![false; n_links];
        known[0] = true;
        let mut inputs = vec![None; model.joints.len()];
        for (k, &j) in given.iter().enumerate() {
            inputs[j] = Some(k);
        }
        super::Search::new(model, inputs, known, vec![None; n_links], vec![])
    }

    #[test]
    fn a_stall_names_the_joints_left_open() {
        let c = compiled("examples/mechanisms/four_bar.pkm");
        let mut search = from_the_base(&c, &[]);
        assert!(!search.step());
        let d = super::stalled(&c.analysis, &search, "forward");
        let text = format!("{}\n{}", d.message, d.notes.join("\n"));
        expect_test::expect![[r#"
            no closed-form forward plan: links crank, coupler, rocker are not reached by the step catalogue (aim, align, parallelogram plane, circle or line against sphere, plane, cylinder or pin, guide through a point, point beyond a given joint, slide onto a line, axes through one centre, a link between known spherical centres, a plane through a point, two turns about meeting axes)
            no step placed a link beyond those the start places (the base, the given inputs and outputs)
            left open between known and unreached links: R1 (base known, crank not), R4 (base known, rocker not); no step kind solves any of them from what is known
            beyond R1: 3 unknown links (crank, coupler, rocker) through R1, R2, R3, R4 from base to base: more than two unknown links in a row: each step places one link from known ones (a dyad closes on two), and none of these is held by known links alone; a plan exists with one of them placed first, by an input on one of R1, R2, R3, R4 or a pose output on one of crank, coupler, rocker; a group of class III or higher with neither needs a virtual variable (κ > 0)"#]]
        .assert_eq(&text);
    }

    /// A Bennett linkage searched with R1 given: the catalogue closes its
    /// spatial dyad l2, l3 (R2, R3, R4 on skew axes): R3's centre, on a
    /// circle about R2, meets the plane normal to R4 it turns in; l3 aims
    /// at it; R3's closure checks the rest (its distance from R4's axis and
    /// its axis). What the topology's F = 0 refuses (mobility from special
    /// geometry) the steps would solve.
    #[test]
    fn a_bennett_dyad_closes_by_circle_and_plane() {
        let c = compiled("tests/fixtures/bennett.pkm");
        let mut search = from_the_base(&c, &[0]);
        while search.step() {}
        assert!(search.known().iter().all(|k| *k));
        let steps: Vec<String> = search
            .into_plan(1, vec![0])
            .steps
            .iter()
            .map(|s| format!("{s:?}").split([' ', '{']).next().unwrap().to_string())
            .collect();
        assert_eq!(steps, ["Transfer", "Locus", "Aim"]);
    }

    #[test]
    fn misses_check_the_joints_aims_leave_open() {
        // The rod turned onto the slider's pin, which nothing reads after.
        check("slider_crank.pkm", (&[("R3", false, true)], &[("R3", false, true)]));
        // Seed 000 A. Forward: c2 turns about R12 onto R13, whose axis the
        // turn keeps, but the alignment of R3 starts from c2 (R13's miss
        // checks it, the turn stays); R5 turns the parallelogram's plane
        // through R6 and the parallelogram swings onto it: its arm (l4) is
        // normal to its axis, its axis normal to R5, R6 ∥ R5, so the two
        // reach the sphere of radius l4 about B3 and keep R6's axis, and
        // nothing reads r5 or pc. Inverse: c2 turns about R3 (its hinge
        // with the cross link, coaxial with R12) onto R13, whose axis the
        // turn keeps, and P1's circle reads R12's axis from c2 (the turn
        // stays, R13's miss checks it); c1 turns about R11 onto R12, whose
        // axis R11's keeps, and nothing reads c1 after; R6 as before.
        check(
            "seed000_a.pkm",
            (
                &[("R13", false, false), ("R6", true, true)],
                &[("R13", false, false), ("R12", false, true), ("R6", true, true)],
            ),
        );
    }
}
