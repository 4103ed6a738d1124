//! A mechanism with no closed-form forward plan (κ ≠ 0) but an inverse
//! one, from outputs of any kind (a full pose, a point, pose parts such as
//! `pose (z, rx, ry)`, joints): what the inverse solution shows instead of
//! the input sweep. The mechanism at a sample pose with every branch
//! there; the constant-orientation workspace of its output point (its
//! position values swept, the others held) and the orientation workspace
//! (its angles swept, the position held), each followed by continuity from
//! the sample; the inverse singularity map over one of them; and the motion
//! along a pose trajectory with the actuators' values and rates.

use super::follow;
use super::html::{html_escape, sign_text, tuple_text, Page};
use super::loaded::{default_point, joint_unit, point_of, reach, signs, Loaded, Plan};
use super::settings::{check_duration, check_nodes};
use super::singularities::{self, Drawn, Measured, Plane};
use super::workspace::{cloud_figures, largest_pair, measure};
use super::{invalid, io, ReportError, ReportOptions};
use crate::drawing::{self, View};
use crate::plots;
use pkm_dsl::study::Resolved;
use pkm_runtime::model::JointType;
use pkm_runtime::newton::{self, Output};
use pkm_runtime::velocity;
use pkm_runtime::workspace::{Continuity, Followed, Grid};
use std::f64::consts::PI;
use std::fmt::Write as _;

/// What one output value is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// A world coordinate (0, 1, 2) of the followed point.
    Position(usize),
    /// Another length (a slide's value, another point's coordinate).
    Length,
    /// An angle.
    Angle,
}

/// One output value: its name, its unit, its name with its unit, and its kind.
struct Value {
    name: String,
    unit: String,
    column: String,
    kind: Kind,
}

/// The declared outputs' values in order, each with its kind; the first
/// output that places a point gives the followed point's coordinates.
fn values(l: &Loaded, unit: &str) -> Vec<Value> {
    let planar = l.model.planar;
    let mut kinds = Vec::new();
    let mut first_point = true;
    for o in &l.outputs {
        let places = o.point().is_some() && first_point;
        let position = |axis: usize| if places { Kind::Position(axis) } else { Kind::Length };
        match *o {
            Output::Pose { about, .. } => {
                kinds.extend((0..if planar { 2 } else { 3 }).map(position));
                // A planar pose's angle is always given; a spatial one's when it turns.
                if planar || about.is_some() {
                    kinds.push(Kind::Angle);
                }
            }
            Output::Point { .. } => kinds.extend((0..if planar { 2 } else { 3 }).map(position)),
            Output::Parts { parts, .. } => {
                kinds.extend(parts.given().map(|i| if i < 3 { position(i) } else { Kind::Angle }))
            }
            Output::Joint(j) => kinds.push(if l.model.joints[j].kind == JointType::P {
                Kind::Length
            } else {
                Kind::Angle
            }),
        }
        if o.point().is_some() {
            first_point = false;
        }
    }
    let names = l.analysis.geometry.outputs.iter().flat_map(|o| o.names.iter().cloned());
    names
        .zip(kinds)
        .map(|(name, kind)| {
            let unit = if kind == Kind::Angle { "rad" } else { unit }.to_string();
            Value {
                column: format!("{name} ({unit})"),
                name,
                unit,
                kind,
            }
        })
        .collect()
}

/// A mechanism with no closed-form forward plan (κ ≠ 0): its inverse
/// solution's figures (see the module's header), or why there are none.
pub(super) fn inverse_only(
    page: &mut Page,
    l: &Loaded,
    study: &Resolved,
    o: &ReportOptions,
    unit: &str,
    file: &str,
    why: &str,
) -> Result<(), ReportError> {
    let model = &l.model;
    let _ = writeln!(
        page,
        "<h2>No forward solution</h2><p>There is no closed-form forward plan ({}), so the input sweep and the \
         input trajectory are not available. The inverse solution gives what follows: the pose of the outputs is \
         chosen, and every joint follows.</p>",
        html_escape(why)
    );
    let plan = match &l.inverse {
        Ok(plan) => plan,
        Err(no) => {
            let _ = writeln!(
                page,
                "<p>There is no closed-form inverse plan either ({}): no drawing, workspace or motion to show{}.</p>",
                html_escape(no),
                if l.analysis.geometry.outputs.is_empty() {
                    "; declare outputs (`outputs { … }`) for an inverse solution"
                } else {
                    ""
                }
            );
            return Ok(());
        }
    };
    // A κ = 1 file that asks for `fk_numeric` solves its forward position
    // at one input: its sample may be an input.
    let numeric = pkm_dsl::planner_numeric::by_virtual_variable(&l.analysis);
    if !o.ranges.is_empty() || (o.start.is_some() && !numeric) || o.amplitude.is_some() || o.speed.is_some() {
        return Err(invalid(format!(
            "{file} has no forward plan ({why}): --ranges, --start, --amplitude and --speed sample its inputs, \
             which it cannot solve from{}",
            if numeric {
                " (--start it can: the forward solution's first assembly there is the sample)"
            } else {
                ""
            }
        )));
    }
    let values = values(l, unit);
    let point_name = default_point(l);
    let point = point_of(model, &point_name).ok_or_else(|| invalid(format!("no point `{point_name}`")))?;
    let size = reach(model);
    let start = o.start.clone().or_else(|| study.start.clone()).filter(|_| numeric);
    let (pose, chosen, at_start) = match (&start, &study.pose) {
        (Some(q), _) => {
            let (pose, chosen) = start_pose(l, q, file)?;
            (pose, chosen, Some(q.as_slice()))
        }
        (None, Some(pose)) => (pose.clone(), "the study's `pose`".to_string(), None),
        (None, None) => {
            let (pose, chosen) = sample_pose(l, plan, &values, size, file)?;
            (pose, chosen, None)
        }
    };
    let branch = match (o.branch.or(study.branch), at_start) {
        (None, Some(q)) => start_branch(l, plan, &pose, q, file)?,
        (given, _) => sample_branch(l, plan, &pose, given, file)?,
    };
    let choices = plan.choices();
    let branch_signs = signs(choices, branch);
    let sample = plan.solve(model, &pose, &branch_signs).map_err(|e| {
        invalid(format!(
            "{file}: branch {branch} at the pose {}: {e}",
            tuple_text(&pose, 3)
        ))
    })?;
    let held = Held {
        l,
        plan,
        values,
        pose,
        branch,
        sample,
        point,
        point_name,
        unit,
    };
    let pose_text = held.pose_text(&held.pose);
    let _ = writeln!(
        page,
        "<h2>The mechanism at the sample pose</h2><p>The sample pose: {} ({chosen}).</p>",
        html_escape(&pose_text)
    );
    branches_table(page, &held)?;
    let poses = newton::link_poses(model, &held.sample).map_err(|e| invalid(e.to_string()))?;
    let view = if model.planar { View::Plane } else { View::Axonometric };
    let f = drawing::draw(
        &page.dir.join("mechanism"),
        &format!("{} at the sample pose, branch {branch}", model.name),
        &drawing::scene(model, &poses, point),
        view,
        unit,
        &held.point_name,
    )?;
    page.figure(
        &f,
        &format!(
            "The mechanism at the sample pose ({pose_text}) on branch {branch}: links as lines between their joints \
             (a link with three or more joints filled), joints by type, the base hatched"
        ),
    );
    // A coupled mechanism's forward solution, where the file asks for it:
    // its assembly modes over two inputs.
    let (offsets, _) = model.value_offsets();
    let given: Vec<f64> = model.inputs().iter().map(|&j| held.sample[offsets[j]]).collect();
    super::assembly_modes::assembly_modes(page, l, &given, unit)?;
    let nodes = o.nodes.or(study.nodes);
    let positions = held.indices(|k| matches!(k, Kind::Position(_)));
    let angles = held.indices(|k| k == Kind::Angle);
    let at_position = held.sweep(page, &positions, nodes, Space::Positions)?;
    let at_angles = held.sweep(page, &angles, nodes, Space::Angles)?;
    // The singularity map over the sweep of more values (positions on a tie).
    let mapped = match (&at_position, &at_angles) {
        (Some(p), Some(a)) if a.indices.len() > p.indices.len() => Some(a),
        (Some(p), _) => Some(p),
        (None, a) => a.as_ref(),
    };
    if let Some(swept) = mapped {
        held.singularities(page, swept)?;
    }
    let duration = o.duration.or(study.duration).unwrap_or(5.0);
    check_duration(duration)?;
    let amplitudes: Vec<f64> = (0..held.pose.len())
        .map(|i| {
            [&at_position, &at_angles]
                .into_iter()
                .flatten()
                .find_map(|s| s.indices.iter().position(|&k| k == i).map(|k| 0.1 * s.extent[k]))
                .unwrap_or(0.0)
        })
        .collect();
    held.motion(page, &amplitudes, view, duration)
}

/// The sample pose: every output 0 if the branch nearest home that reaches
/// it ([`by_home`]) is well conditioned there (σ_in and σ_out at least 10⁻²); else the
/// best-conditioned pose (so measured) with one value scanned, the others
/// 0: z over (0, the reach] (above the base), else another length over ±
/// the reach, else an angle over ± π. Returns the pose
/// and how it was chosen.
fn sample_pose(
    l: &Loaded,
    plan: &Plan,
    values: &[Value],
    size: f64,
    file: &str,
) -> Result<(Vec<f64>, String), ReportError> {
    const WELL: f64 = 1e-2;
    const SCANNED: usize = 100;
    let model = &l.model;
    // The conditioning at `pose` of the branch nearest home that reaches
    // it: the least of σ_in and σ_out.
    let quality = |pose: &[f64]| -> Option<f64> {
        let (_, v) = by_home(l, plan, pose).into_iter().next()?;
        let j = velocity::jacobians(model, &v, &l.outputs).ok()?;
        Some(j.input_sigma.min(j.output_sigma))
    };
    let zeros = vec![0.0; values.len()];
    let at_zero = quality(&zeros);
    if at_zero.is_some_and(|q| q >= WELL) {
        return Ok((zeros, "every output 0".into()));
    }
    // Scanned in turn until one gives a well-conditioned pose: z, the other
    // lengths, the angles (a 3-RPR with similar base and platform is
    // singular at every translation with its platform unturned).
    let groups: [Vec<usize>; 3] = [
        (0..values.len())
            .filter(|&i| values[i].kind == Kind::Position(2))
            .collect(),
        (0..values.len())
            .filter(|&i| !matches!(values[i].kind, Kind::Angle | Kind::Position(2)))
            .collect(),
        (0..values.len()).filter(|&i| values[i].kind == Kind::Angle).collect(),
    ];
    let mut best: Option<(f64, Vec<f64>, usize)> = at_zero.map(|q| (q, zeros.clone(), usize::MAX));
    for group in &groups {
        if best.as_ref().is_some_and(|b| b.0 >= WELL) {
            break;
        }
        for &i in group {
            for k in 0..=2 * SCANNED {
                let t = k as f64 / SCANNED as f64 - 1.0;
                let mut pose = zeros.clone();
                pose[i] = match values[i].kind {
                    // z above the base, as the platform is built.
                    Kind::Position(2) if k == 0 => continue,
                    Kind::Position(2) => size * k as f64 / (2 * SCANNED) as f64,
                    Kind::Angle => PI * t,
                    _ => size * t,
                };
                if let Some(q) = quality(&pose) {
                    if best.as_ref().is_none_or(|b| q > b.0) {
                        best = Some((q, pose, i));
                    }
                }
            }
        }
    }
    let (q, pose, i) = best.ok_or_else(|| {
        invalid(format!(
            "{file}: no branch of the inverse solution reaches the pose with every output 0, nor any with one of \
             its lengths over ± the mechanism's reach ({size:.4}) and the others 0"
        ))
    })?;
    let how = match values.get(i) {
        Some(v) => format!(
            "every output 0 but {}, the value among {} over {}, where the branch nearest the home configuration \
             that reaches the pose is best conditioned: σ_in and σ_out at least {q:.3e}",
            v.name,
            2 * SCANNED + 1,
            match v.kind {
                Kind::Position(2) => "(0, the mechanism's reach], above the base",
                Kind::Angle => "± π",
                _ => "± the mechanism's reach",
            }
        ),
        None => format!("every output 0; no pose scanned is better conditioned (σ {q:.3e})"),
    };
    Ok((pose, how))
}

/// The sample pose of a κ = 1 file from its study's (or `--start`'s)
/// input `q`: the first certified assembly of its forward solution there
/// (else the first possible one), the declared outputs' values on it.
fn start_pose(l: &Loaded, q: &[f64], file: &str) -> Result<(Vec<f64>, String), ReportError> {
    let model = &l.model;
    let vp = pkm_dsl::planner_numeric::forward_numeric_plan(&l.analysis).map_err(|_| {
        invalid(format!(
            "{file}: no virtual-variable forward plan to solve the start from"
        ))
    })?;
    let found = pkm_runtime::fk_numeric::solve(model, &vp, q).map_err(|e| invalid(format!("{file}: start: {e}")))?;
    let n = found.len();
    let (k, first) = found
        .iter()
        .enumerate()
        .find(|(_, a)| a.kind.certified())
        .or_else(|| found.iter().enumerate().next())
        .ok_or_else(|| {
            invalid(format!(
                "{file}: the forward solution has no assembly at the start {}",
                tuple_text(q, 4)
            ))
        })?;
    let mut pose = Vec::new();
    for (o, spec) in l.analysis.geometry.outputs.iter().zip(&l.outputs) {
        let these = pkm_runtime::plan::output_values(&first.solution.poses, &first.solution.values, model.planar, spec);
        pose.extend(these.into_iter().chain(std::iter::repeat(0.0)).take(o.names.len()));
    }
    let how = format!(
        "the forward solution at the start {}: assembly {} of {n}, {}",
        tuple_text(q, 4),
        k + 1,
        if first.kind.certified() {
            "certified"
        } else {
            "possible"
        }
    );
    Ok((pose, how))
}

/// The inverse branch at the sample `pose` of a start `q` whose actuated
/// joints take the start's values (a leg's other sense reaches the pose
/// too, with its slide negative).
fn start_branch(l: &Loaded, plan: &Plan, pose: &[f64], q: &[f64], file: &str) -> Result<usize, ReportError> {
    let model = &l.model;
    let (offsets, _) = model.value_offsets();
    let inputs = model.inputs();
    // A slide's value to 10⁻⁹ of the size, a revolute's to 10⁻⁹ rad (as
    // the arc of that radius, as `fk_follow` verifies its inputs).
    let scale = pkm_runtime::kinematics::model_scale(model);
    follow::every_branch(l, plan, pose)
        .into_iter()
        .find(|(_, v)| {
            inputs.iter().zip(q).all(|(&j, &want)| {
                let arc = (model.joints[j].kind != JointType::P).then_some(scale);
                pkm_runtime::fk_numeric::Compatibility::input_residual(arc, v[offsets[j]], want).abs() <= 1e-9 * scale
            })
        })
        .map(|(b, _)| b)
        .ok_or_else(|| {
            invalid(format!(
                "{file}: no branch of the inverse solution at the start's pose {} takes the start's inputs",
                tuple_text(pose, 3)
            ))
        })
}

/// The branches that reach `pose`, nearest the geometry's home
/// configuration first (every joint value 0, as the `geometry` block places
/// the links; by [`Continuity`]): the least turned assembly, not the one a
/// sign order happens to put first.
fn by_home(l: &Loaded, plan: &Plan, pose: &[f64]) -> Vec<(usize, Vec<f64>)> {
    let continuity = Continuity::of(&l.model);
    let mut all = follow::every_branch(l, plan, pose);
    let home = vec![0.0; all.first().map_or(0, |b| b.1.len())];
    all.sort_by(|a, b| {
        continuity
            .distance(&a.1, &home)
            .total_cmp(&continuity.distance(&b.1, &home))
    });
    all
}

/// The branch shown at the sample `pose`: the `given` one, else the one
/// nearest the home configuration that is regular there, else the nearest
/// that reaches it.
fn sample_branch(
    l: &Loaded,
    plan: &Plan,
    pose: &[f64],
    given: Option<usize>,
    file: &str,
) -> Result<usize, ReportError> {
    let choices = plan.choices();
    if let Some(b) = given {
        if b >= 1 << choices {
            return Err(invalid(format!(
                "--branch {b}: {file}'s inverse solution has {} branches (0 to {})",
                1usize << choices,
                (1usize << choices) - 1
            )));
        }
        return Ok(b);
    }
    let reached = by_home(l, plan, pose);
    let regular = reached.iter().find(|(_, v)| {
        velocity::jacobians(&l.model, v, &l.outputs).is_ok_and(|j| j.singularity == velocity::Singularity::None)
    });
    regular.or(reached.first()).map(|(b, _)| *b).ok_or_else(|| {
        invalid(format!(
            "{file}: the inverse solution reaches no branch at the pose {}",
            tuple_text(pose, 3)
        ))
    })
}

/// Which values a sweep runs over.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Space {
    /// The followed point's position values, the orientation held.
    Positions,
    /// The angles, the position held.
    Angles,
}

/// A sweep of some output values, the others held at the sample pose: the
/// values swept, the grid, each node's followed configuration's point
/// (world positions, or the swept angles), and the reached extent of each
/// swept value.
struct Swept {
    space: Space,
    indices: Vec<usize>,
    grid: Grid,
    extent: Vec<f64>,
}

/// What the inverse-only sections share: the file, its inverse plan, the
/// outputs' values, the sample pose and branch with its configuration, and
/// the point followed.
struct Held<'a> {
    l: &'a Loaded,
    plan: &'a Plan,
    values: Vec<Value>,
    /// The sample pose: every output's value.
    pose: Vec<f64>,
    branch: usize,
    /// The joint values at the sample pose on the branch.
    sample: Vec<f64>,
    /// The output point: its link and place on it.
    point: (usize, [f64; 3]),
    point_name: String,
    unit: &'a str,
}

impl Held<'_> {
    /// The values whose kind passes `which`.
    fn indices(&self, which: impl Fn(Kind) -> bool) -> Vec<usize> {
        (0..self.values.len()).filter(|&i| which(self.values[i].kind)).collect()
    }

    /// `name = value unit, …` for a pose.
    fn pose_text(&self, pose: &[f64]) -> String {
        self.values
            .iter()
            .zip(pose)
            .map(|(v, x)| format!("{} = {x:.4} {}", v.name, v.unit))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The sample pose with the values `indices` set to `q`.
    fn with(&self, indices: &[usize], q: &[f64]) -> Vec<f64> {
        let mut p = self.pose.clone();
        for (k, &i) in indices.iter().enumerate() {
            p[i] = q[k];
        }
        p
    }

    /// The followed assembly over `grid` of the values `indices`, keeping `keep`.
    fn follow<T: Send>(
        &self,
        indices: &[usize],
        grid: &Grid,
        keep: impl Fn(&[f64], &[f64]) -> T + Sync,
    ) -> Vec<Option<Followed<T>>> {
        let start: Vec<f64> = indices.iter().map(|&i| self.pose[i]).collect();
        follow::followed(
            self.l,
            self.plan,
            grid,
            |q| self.with(indices, q),
            &start,
            &self.sample,
            keep,
        )
    }

    /// Where node `q` (values `indices`) is drawn: the point's world
    /// position for positions, the swept values (then zeros) for angles.
    fn drawn_at(&self, space: Space, q: &[f64], v: &[f64]) -> Option<[f64; 3]> {
        match space {
            Space::Positions => super::loaded::world(&self.l.model, v, self.point.0, self.point.1),
            Space::Angles => Some(std::array::from_fn(|k| q.get(k).copied().unwrap_or(0.0))),
        }
    }

    /// The workspace over the values `indices` (1 to 3 of them), the others
    /// held: a first sweep over the sample ± the reach (positions) or ± π
    /// (angles) finds the reached box, a second as fine as `nodes` (721,
    /// 200 or 40 per value by default) draws it. `None` without values.
    fn sweep(
        &self,
        page: &mut Page,
        indices: &[usize],
        nodes: Option<usize>,
        space: Space,
    ) -> Result<Option<Swept>, ReportError> {
        let n = indices.len();
        if n == 0 || n > 3 {
            if n > 3 {
                let _ = writeln!(page, "<p>{n} values of one kind: the report sweeps 1 to 3.</p>");
            }
            return Ok(None);
        }
        let (l, unit) = (self.l, self.unit);
        // Two or three spatial angles (rx, ry, rz) to a right angle either
        // way: beyond it the angles' triple turns back on itself (ry = ±π/2).
        let half = match space {
            Space::Positions => reach(&l.model),
            Space::Angles if l.model.planar || n == 1 => PI,
            Space::Angles => PI / 2.0,
        };
        let per = nodes.unwrap_or(match n {
            1 => 721,
            2 => 200,
            _ => 40,
        });
        check_nodes(per, n)?;
        let coarse = Grid {
            ranges: indices
                .iter()
                .map(|&i| (self.pose[i] - half, self.pose[i] + half))
                .collect(),
            counts: vec![[361, 81, 25][n - 1]; n],
        };
        let found = self.follow(indices, &coarse, |q, _| q.to_vec());
        let reached: Vec<&Vec<f64>> = found.iter().flatten().map(|f| &f.kept).collect();
        let swept_names: Vec<&str> = indices.iter().map(|&i| self.values[i].name.as_str()).collect();
        if reached.len() <= 1 {
            let _ = writeln!(
                page,
                "<p>With the other outputs held at the sample, {} cannot change: the assembly at the sample reaches no \
                 other node of a sweep over the sample ± {half:.4} ({} nodes each). The {} is the sample alone.</p>",
                swept_names.join(", "),
                coarse.counts[0],
                match space {
                    Space::Positions => "constant-orientation workspace",
                    Space::Angles => "orientation workspace",
                }
            );
            return Ok(None);
        }
        let bound = |k: usize| {
            let (lo, hi) = reached.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                (a.min(q[k]), b.max(q[k]))
            });
            let step = 2.0 * half / (coarse.counts[k] - 1) as f64;
            let (r0, r1) = coarse.ranges[k];
            ((lo - step).max(r0), (hi + step).min(r1))
        };
        let grid = Grid {
            ranges: (0..n).map(bound).collect(),
            counts: vec![per; n],
        };
        // A set that reaches the first sweep's box on every side is bounded by
        // the box, not by the mechanism.
        let fills = (0..n).all(|k| grid.ranges[k] == coarse.ranges[k]);
        let followed = self.follow(indices, &grid, |q, v| self.drawn_at(space, q, v));
        let points: Vec<Option<[f64; 3]>> = followed.iter().map(|f| f.as_ref().and_then(|f| f.kept)).collect();
        let cloud: Vec<[f64; 3]> = points.iter().flatten().copied().collect();
        let mut q = vec![0.0; n];
        let mut extent = vec![(f64::INFINITY, f64::NEG_INFINITY); n];
        for (k, f) in followed.iter().enumerate() {
            if f.is_some() {
                grid.node(k, &mut q);
                for i in 0..n {
                    extent[i] = (extent[i].0.min(q[i]), extent[i].1.max(q[i]));
                }
            }
        }
        let extent: Vec<f64> = extent.iter().map(|(a, b)| if b > a { b - a } else { 0.0 }).collect();
        let swept: Vec<&Value> = indices.iter().map(|&i| &self.values[i]).collect();
        let held_values: Vec<usize> = (0..self.values.len()).filter(|i| !indices.contains(i)).collect();
        let held_text = if held_values.is_empty() {
            "nothing held".to_string()
        } else {
            held_values
                .iter()
                .map(|&i| format!("{} = {:.4} {}", self.values[i].name, self.pose[i], self.values[i].unit))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let names: Vec<(String, String)> = swept
            .iter()
            .map(|v| {
                (
                    v.name.clone(),
                    v.column
                        .strip_prefix(&v.name)
                        .unwrap_or("")
                        .trim()
                        .trim_matches(['(', ')'])
                        .to_string(),
                )
            })
            .collect();
        let over = swept
            .iter()
            .zip(&grid.ranges)
            .map(|(v, (a, b))| format!("{} over [{a:.4}, {b:.4}]", v.column))
            .collect::<Vec<_>>()
            .join(", ");
        let (title, stem, what) = match space {
            Space::Positions => (
                format!("Workspace of {} at constant orientation", self.point_name),
                "workspace",
                measure(&grid, &points, unit).replace("input grid", "grid of poses"),
            ),
            Space::Angles => (
                format!("Orientation workspace of {}", self.point_name),
                "orientation",
                angle_measure(&grid, &followed),
            ),
        };
        let _ = writeln!(
            page,
            "<h2>{title}</h2><p>The poses with {over} ({per} nodes each; the box of the set found by a first sweep \
             over the sample ± {}), {held_text} held at the sample, that the assembly of branch {} ({}) at the \
             sample reaches: {} of {} nodes. The set is {}.{}</p><p>{}</p>",
            match space {
                Space::Positions => format!("the mechanism's reach, {half:.4} {unit}"),
                Space::Angles => format!("{half:.4} rad"),
            },
            self.branch,
            sign_text(&signs(self.plan.choices(), self.branch)),
            cloud.len(),
            grid.len(),
            html_escape(&what),
            if fills {
                " It reaches the first sweep's box on every side: nothing the file declares (no stroke or joint \
                 limit) bounds these values there, so the set drawn is the box, not a limit of the mechanism."
            } else {
                ""
            },
            html_escape(&follow::meetings(&grid, &followed, &names, self.plan.choices()))
        );
        if cloud.is_empty() {
            return Ok(None);
        }
        if n == 1 {
            self.inputs_against(page, indices[0], &grid, &followed, stem)?;
        }
        match space {
            Space::Positions => {
                cloud_figures(page, l.model.planar, &self.point_name, unit, &cloud, n, n == 1)?;
            }
            Space::Angles if n == 2 => page.scatter(
                "orientation_workspace",
                &format!("Orientation workspace of {}", self.point_name),
                [&swept[0].column, &swept[1].column],
                &[(self.point_name.clone(), cloud.iter().map(|p| [p[0], p[1]]).collect())],
                false,
                "The orientation workspace: the angles reached, the position held",
            )?,
            Space::Angles if n == 3 => {
                let f = plots::solid3d(
                    &page.dir.join("orientation_workspace"),
                    &format!("Orientation workspace of {}", self.point_name),
                    [&swept[0].column, &swept[1].column, &swept[2].column],
                    &cloud,
                )?;
                page.figure(
                    &f,
                    "The orientation workspace as a solid in its three angles: the cells of a grid over it that hold a \
                     reached node, their outer faces shaded and coloured by the third angle, seen from two sides",
                );
            }
            Space::Angles => {}
        }
        Ok(Some(Swept {
            space,
            indices: indices.to_vec(),
            grid,
            extent,
        }))
    }

    /// One swept value: the actuators' values against it (one chart per unit).
    fn inputs_against<T>(
        &self,
        page: &mut Page,
        index: usize,
        grid: &Grid,
        followed: &[Option<Followed<T>>],
        stem: &str,
    ) -> Result<(), ReportError> {
        let model = &self.l.model;
        let inputs = model.inputs();
        let (offsets, _) = model.value_offsets();
        // The followed configuration at each reached node, solved again on its branch.
        let mut x = Vec::new();
        let mut series: Vec<(String, String, Vec<f64>)> = inputs
            .iter()
            .map(|&j| {
                (
                    model.joints[j].name.clone(),
                    joint_unit(model, j, self.unit),
                    Vec::new(),
                )
            })
            .collect();
        for (k, f) in followed.iter().enumerate() {
            let Some(f) = f else { continue };
            let q = grid.value(0, k);
            let Ok(v) = self
                .plan
                .solve(model, &self.with(&[index], &[q]), &signs(self.plan.choices(), f.branch))
            else {
                continue;
            };
            x.push(q);
            for (s, &j) in series.iter_mut().zip(&inputs) {
                s.2.push(v[offsets[j]]);
            }
        }
        let value = &self.values[index];
        page.curves_per_unit(
            &format!("{stem}_inputs"),
            &format!("The actuators against {}", value.name),
            &value.column,
            &x,
            &series,
            &format!(
                "The actuators' values against {} over the sweep, on the followed assembly",
                value.name
            ),
        )
    }

    /// The inverse singularity map over a coarser copy of `swept`'s grid.
    fn singularities(&self, page: &mut Page, swept: &Swept) -> Result<(), ReportError> {
        let n = swept.indices.len();
        let coarse = Grid {
            ranges: swept.grid.ranges.clone(),
            counts: vec![swept.grid.counts[0].min([721, 60, 14][n - 1]); n],
        };
        let measured: Vec<Measured> = self
            .follow(&swept.indices, &coarse, |q, v| {
                singularities::measure(self.l, None, self.point, v, self.drawn_at(swept.space, q, v))
            })
            .into_iter()
            .filter_map(|f| f.and_then(|f| f.kept))
            .collect();
        let poses = newton::link_poses(&self.l.model, &self.sample).map_err(|e| invalid(e.to_string()))?;
        let named = singularities::named_factors(self.l, None, &poses);
        let columns: Vec<String> = swept.indices.iter().map(|&i| self.values[i].column.clone()).collect();
        let drawn = match swept.space {
            _ if n == 1 => Drawn::Line(columns[0].clone()),
            Space::Positions if self.l.model.planar => Drawn::Plane(Plane::world([0, 1], self.unit)),
            Space::Positions => {
                let cloud: Vec<[f64; 3]> = measured.iter().map(|m| m.at).collect();
                Drawn::Plane(Plane::world(largest_pair(&cloud), self.unit))
            }
            Space::Angles => Drawn::Plane(Plane {
                pair: [0, 1],
                labels: [columns[0].clone(), columns[1].clone()],
                name: format!("the plane of {} and {}", columns[0], columns[1]),
            }),
        };
        let _ = writeln!(
            page,
            "<h2>Singularities of the inverse solution</h2><p>Over the {} sweep ({}), coarser: σ_in (0 where a \
             motion leaves the outputs still: an inverse or input singularity, det J_i = 0) and σ_out (0 where the \
             legs no longer hold the platform: a direct singularity), and the inverse plan's determinant factors at \
             the sample and over the nodes.</p>",
            match swept.space {
                Space::Positions => "constant-orientation",
                Space::Angles => "orientation",
            },
            columns.join(", ")
        );
        if !named.is_empty() {
            let _ = writeln!(
                page,
                "<table><tr><th>factor</th><th>at the sample (1)</th><th class=l>vanishes when</th></tr>{}</table>",
                named
                    .iter()
                    .map(|(label, value, what)| format!(
                        "<tr><td>{label}</td><td>{value:.4}</td><td class=l>{}</td></tr>",
                        html_escape(what)
                    ))
                    .collect::<String>()
            );
        }
        singularities::loci(
            page,
            self.l,
            &measured,
            &named,
            &drawn,
            &format!("{} per value", coarse.counts[0]),
        )
    }

    /// The motion: every swept value along `value + amplitude·sin(πt)` over
    /// `duration` s from the sample, the assembly followed by continuity;
    /// the actuators' values and rates (the inverse velocity map J_i times
    /// the outputs' rates), and the animation.
    fn motion(&self, page: &mut Page, amplitudes: &[f64], view: View, duration: f64) -> Result<(), ReportError> {
        const STEPS: usize = 400;
        const FRAMES: usize = 100;
        let (l, plan) = (self.l, self.plan);
        let model = &l.model;
        if amplitudes.iter().all(|a| *a == 0.0) {
            return Ok(());
        }
        let inputs = model.inputs();
        let (offsets, _) = model.value_offsets();
        let continuity = Continuity::of(model);
        let w = PI;
        let (mut ts, mut frames) = (Vec::new(), Vec::new());
        let mut values: Vec<Vec<f64>> = vec![Vec::new(); inputs.len()];
        let mut rates: Vec<Vec<f64>> = vec![Vec::new(); inputs.len()];
        let (mut previous, mut before): (Vec<f64>, Option<Vec<f64>>) = (self.sample.clone(), None);
        let mut stopped = String::new();
        for k in 0..=STEPS {
            let t = duration * k as f64 / STEPS as f64;
            let pose: Vec<f64> = self
                .pose
                .iter()
                .zip(amplitudes)
                .map(|(p, a)| p + a * (w * t).sin())
                .collect();
            let pose_rate: Vec<f64> = amplitudes.iter().map(|a| a * w * (w * t).cos()).collect();
            let v = if k == 0 {
                self.sample.clone()
            } else {
                let predicted = continuity.predict(&previous, before.as_deref());
                let candidates = follow::every_branch(l, plan, &pose);
                match continuity.nearest(&candidates, &predicted) {
                    Some((_, v)) => v.clone(),
                    None => {
                        stopped = format!("; it stops at t = {t:.3} s, where no branch reaches the pose");
                        break;
                    }
                }
            };
            let rate = velocity::jacobians(model, &v, &l.outputs)
                .ok()
                .and_then(|j| j.inverse)
                .map(|ji| ji * pkm_runtime::nalgebra::DVector::from_vec(pose_rate));
            ts.push(t);
            for (i, &j) in inputs.iter().enumerate() {
                values[i].push(v[offsets[j]]);
                rates[i].push(rate.as_ref().map_or(f64::NAN, |r| r[i]));
            }
            if k % (STEPS / FRAMES) == 0 {
                let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
                frames.push(drawing::scene(model, &poses, self.point));
            }
            before = Some(std::mem::replace(&mut previous, v));
        }
        let moving: Vec<String> = amplitudes
            .iter()
            .enumerate()
            .filter(|(_, a)| **a != 0.0)
            .map(|(i, a)| format!("{} + {a:.4}·sin(πt)", self.values[i].name))
            .collect();
        let _ = writeln!(
            page,
            "<h2>Motion</h2><p>From the sample pose, {} (each a tenth of the value's reached extent), the other \
             outputs held, 0 ≤ t ≤ {duration:.4} s ({} steps){stopped}; at each step the solution nearest the \
             continued configuration, whichever branch. The actuators' rates are the inverse velocity map J_i times \
             the outputs' rates (left out where J_i is singular).</p>",
            html_escape(&moving.join(", ")),
            ts.len()
        );
        let names_units: Vec<(String, String)> = inputs
            .iter()
            .map(|&j| (model.joints[j].name.clone(), joint_unit(model, j, self.unit)))
            .collect();
        let series = |data: &[Vec<f64>], per_second: bool| -> Vec<(String, String, Vec<f64>)> {
            names_units
                .iter()
                .zip(data)
                .map(|((n, u), d)| {
                    (
                        n.clone(),
                        if per_second { format!("{u}/s") } else { u.clone() },
                        d.clone(),
                    )
                })
                .collect()
        };
        page.curves_per_unit(
            "motion_inputs",
            "The actuators along the motion",
            "t (s)",
            &ts,
            &series(&values, false),
            "The actuators' values along the motion, from the inverse solution",
        )?;
        if rates.iter().flatten().all(|r| !r.is_finite()) {
            let _ = writeln!(
                page,
                "<p>No actuator rates: J_i is singular at every step (σ_in 0: the declared outputs do not fix every \
                 motion of the mechanism).</p>"
            );
            return self.animate(page, &frames, &ts, view, duration);
        }
        page.curves_per_unit(
            "motion_rates",
            "The actuators' rates along the motion",
            "t (s)",
            &ts,
            &series(&rates, true),
            "The actuators' rates along the motion: J_i times the outputs' rates",
        )?;
        self.animate(page, &frames, &ts, view, duration)
    }

    /// The motion's animation: `frames` at the times `ts`.
    fn animate(
        &self,
        page: &mut Page,
        frames: &[drawing::Scene],
        ts: &[f64],
        view: View,
        duration: f64,
    ) -> Result<(), ReportError> {
        if frames.len() >= 2 {
            let path = page.dir.join("animation.svg");
            let played = ts.last().copied().unwrap_or(duration).max(1e-3);
            drawing::animation(&path, frames, view, played, &self.point_name)?;
            let svg = std::fs::read_to_string(&path).map_err(io(&path))?;
            let _ = writeln!(
                page,
                "<figure>{svg}<figcaption>The mechanism along the motion, {} frames over {played:.2} s, repeated \
                 (<a href=\"animation.svg\">SVG</a>)</figcaption></figure>",
                frames.len()
            );
        }
        Ok(())
    }
}

/// The measure of a sweep over angles: its reached nodes' grid cells, as
/// an interval's length, an area or a volume in rad, rad² or rad³.
fn angle_measure<T>(grid: &Grid, followed: &[Option<Followed<T>>]) -> String {
    let reached = followed.iter().flatten().count();
    if reached == 0 {
        return "empty: no node reached".into();
    }
    let cell: f64 = grid
        .ranges
        .iter()
        .zip(&grid.counts)
        .map(|((a, b), n)| (b - a) / (*n as f64 - 1.0).max(1.0))
        .product();
    let power = match grid.ranges.len() {
        1 => "",
        2 => "²",
        _ => "³",
    };
    format!(
        "{} in angle space, about {:.4e} rad{power} (the grid cells of the reached nodes)",
        ["an interval", "a region", "a solid"][grid.ranges.len() - 1],
        reached as f64 * cell
    )
}

/// Every branch of the inverse solution at the sample pose, as `pkm ik`
/// numbers and lists them: the actuators' values, the point, σ_in, σ_out
/// and the class, or why the branch has no solution.
fn branches_table(page: &mut Page, h: &Held) -> Result<(), ReportError> {
    let (l, unit) = (h.l, h.unit);
    let model = &l.model;
    let inputs = model.inputs();
    let (offsets, _) = model.value_offsets();
    let point_axes = if model.planar { "x, y" } else { "x, y, z" };
    let _ = writeln!(
        page,
        "<p>Every branch of the inverse solution at the sample pose, numbered as <code>pkm ik</code> lists them. \
         σ_in and σ_out are the relative smallest singular values of the velocity equations (0 at an input or \
         output singularity).</p><table><tr><th>branch</th><th>signs</th>{}<th>{} ({point_axes}) ({unit})</th>\
         <th>σ_in</th><th>σ_out</th><th class=l>class</th></tr>",
        inputs
            .iter()
            .map(|&j| format!(
                "<th>{} ({})</th>",
                html_escape(&model.joints[j].name),
                joint_unit(model, j, unit)
            ))
            .collect::<String>(),
        html_escape(&h.point_name)
    );
    for (b, (sg, result)) in pkm_runtime::plan::run_all(model, h.plan, &h.pose)
        .into_iter()
        .enumerate()
    {
        let mark = if b == h.branch { " (followed)" } else { "" };
        match result.map(|s| s.model_values(model)) {
            Ok(v) => {
                let p = super::loaded::world(model, &v, h.point.0, h.point.1).unwrap_or([f64::NAN; 3]);
                let p = if model.planar { &p[..2] } else { &p[..] };
                let (si, so, class) = super::positions::sigma_cells(model, &v, &l.outputs);
                let _ = writeln!(
                    page,
                    "<tr><td>{b}{mark}</td><td>{}</td>{}<td>{}</td><td>{si}</td><td>{so}</td><td class=l>{}</td></tr>",
                    sign_text(&sg),
                    inputs
                        .iter()
                        .map(|&j| format!("<td>{:.6}</td>", v[offsets[j]]))
                        .collect::<String>(),
                    tuple_text(p, 4),
                    html_escape(&class)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    page,
                    "<tr><td>{b}{mark}</td><td>{}</td><td colspan={} class=l>no solution: {}</td></tr>",
                    sign_text(&sg),
                    inputs.len() + 4,
                    html_escape(&e.to_string())
                );
            }
        }
    }
    page.html.push_str("</table>\n");
    Ok(())
}
