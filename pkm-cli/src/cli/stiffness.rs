//! `pkm stiffness`: the platform's static stiffness at a pose, every
//! branch of the inverse solution: each limb's actuation and constraint
//! wrenches (`pkm_runtime::wrench`), their stack `J`, the springs `K_p`
//! from the file's `limbs` block, `K = Jᵀ K_p J` at the platform's
//! reference point, the directional stiffnesses and, under a given wrench,
//! the platform's deflection (`pkm_runtime::stiffness`); as a table, JSON
//! or, one pose a row, CSV.
//!
//! Branches that are one physical assembly (the same platform pose, every
//! joint at the same place with its axis on the same line: an R–P–S leg
//! with its R turned by π and its slide negated) are one configuration:
//! its stiffness is computed once, on its first branch, and every branch
//! of it is listed by number with that configuration's values.

use super::failure::{Failure, Kind};
use super::solve::{finite, load, ordered_pose, output_columns, sign_text, solver_pose, Loaded, Request, Units};
use super::table::{self, Branch, Cell, Column};
use pkm_dsl::limb_properties::ResolvedLimb;
use pkm_runtime::model::{JointType, Model, Place};
use pkm_runtime::nalgebra::Vector3;
use pkm_runtime::newton::Output;
use pkm_runtime::plan::{Plan, Solution};
use pkm_runtime::primitives::Sign;
use pkm_runtime::stiffness::PlatformStiffness;
use pkm_runtime::wrench::RowKind;
use serde_json::{json, Value};

fn kind_name(kind: RowKind) -> &'static str {
    match kind {
        RowKind::Actuation { .. } => "actuation",
        RowKind::ConstraintForce => "constraint force",
        RowKind::ConstraintCouple => "constraint couple",
    }
}

/// Two branches are one assembly when they agree to this fraction of the
/// mechanism's size (`pkm_runtime::kinematics::model_scale`) in every joint
/// place and to this much in every unit axis and platform rotation entry.
const SAME_ASSEMBLY: f64 = 1e-9;

/// The six directions of K, the deflection and the directional stiffnesses.
const DIRECTIONS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// `pkm stiffness`: the file loaded, its limbs read and its inverse
/// planned once, solved at any pose.
pub struct Stiffness<'r> {
    r: &'r Request<'r>,
    l: Loaded,
    limbs: Vec<ResolvedLimb>,
    plan: Plan,
    /// The platform: the link the first output that places a point places.
    link: usize,
    /// The reference point on it.
    local: [f64; 3],
    units: Units,
    wrench: Option<[f64; 6]>,
}

/// A configuration's stiffness, computed on its first branch.
struct Computed {
    k: PlatformStiffness,
    directional: [f64; 6],
    deflection: Option<[f64; 6]>,
    /// The limbs' names, in the wrench analysis's order.
    names: Vec<String>,
}

/// Branches that are one physical assembly at one pose.
struct Configuration {
    /// Its branches' numbers, the first the one its stiffness is computed on.
    branches: Vec<usize>,
    /// Each further branch's joint values that differ from the first's.
    differences: Vec<(usize, Vec<String>)>,
    /// Its stiffness, or why it has none (a singular configuration).
    result: Result<Computed, String>,
}

/// One branch at one pose: its solution and configuration, or why it has none.
struct BranchAt {
    number: usize,
    signs: Vec<Sign>,
    solved: Result<(Solution, usize), String>,
}

/// Every branch at one pose, and its configurations.
struct At {
    branches: Vec<BranchAt>,
    configurations: Vec<Configuration>,
}

impl<'r> Stiffness<'r> {
    /// Loads the file of `r`, reads its limbs, plans its inverse solution,
    /// checks `wrench` (none, or six finite values).
    pub fn new(r: &'r Request<'r>, wrench: &[f64]) -> Result<Stiffness<'r>, Failure> {
        let l = load(r)?;
        let a = &l.compiled.analysis;
        if a.mass_and_loads.units.is_none() {
            return Err(Failure::input(
                "stiffness needs the file's units and limbs: `units { length = mm; mass = kg; }` and a `limbs` block giving every limb's E, A, I (or its springs)",
            ));
        }
        let limbs = pkm_dsl::numeric::limb_properties(a, &l.values).map_err(|d| r.parse_failure(d))?;
        if limbs.is_empty() {
            return Err(Failure::input(
                "stiffness needs a `limbs` block giving every limb's E, A, I (or its springs)",
            ));
        }
        if !wrench.is_empty() && wrench.len() != 6 {
            return Err(Failure::input(format!(
                "--wrench takes 6 values (fx, fy, fz, mx, my, mz), not {}",
                wrench.len()
            )));
        }
        for (k, &w) in wrench.iter().enumerate() {
            finite(&format!("wrench component {}", k + 1), w)?;
        }
        let Some((link, local)) = l.outputs.iter().find_map(Output::point) else {
            return Err(Failure::input(
                "stiffness needs the platform's pose or a point of it among the outputs",
            ));
        };
        let plan = l.compiled.inverse().cloned().map_err(|d| r.parse_failure(d))?;
        let units = Units::of(r, &l);
        Ok(Stiffness {
            r,
            l,
            limbs,
            plan,
            link,
            local,
            units,
            wrench: <[f64; 6]>::try_from(wrench).ok(),
        })
    }

    /// The stiffness of the configuration `solution` is, or why it has
    /// none; a limb the `limbs` block does not give fails the command.
    fn compute(&self, solution: &Solution) -> Result<Result<Computed, String>, Failure> {
        let model = &self.l.model;
        let point = pkm_runtime::plan::at(&solution.poses[self.link], self.local);
        let analysis = match pkm_runtime::wrench::analyse(model, solution, self.link) {
            Ok(w) => w,
            Err(e) => return Ok(Err(e.to_string())),
        };
        let declared = pkm_dsl::limb_properties::in_analysis_order(&self.limbs, &analysis.limbs).map_err(|k| {
            let path: Vec<&str> = analysis.limbs[k]
                .joints
                .iter()
                .map(|&j| model.joints[j].name.as_str())
                .collect();
            Failure::input(format!("the limb {} has no entry in the `limbs` block", path.join("–")))
        })?;
        let properties: Vec<_> = declared.iter().map(|d| d.properties()).collect();
        let names = declared.iter().map(|d| d.name.clone()).collect();
        // The stiffness, its directional values and the deflection: a
        // failure of any (a singular K) is this configuration's, not the command's.
        let solved = PlatformStiffness::new(analysis, &properties, point).and_then(|k| {
            let directional = k.directional()?;
            let deflection = match &self.wrench {
                Some(w) => Some(k.deflection(w)?),
                None => None,
            };
            Ok(Computed {
                k,
                directional,
                deflection,
                names,
            })
        });
        Ok(solved.map_err(|e| e.to_string()))
    }

    /// Every branch at the declared outputs' values `ordered` (as the
    /// solver takes them), grouped into configurations.
    fn at(&self, ordered: &[f64]) -> Result<At, Failure> {
        let model = &self.l.model;
        let tolerance = SAME_ASSEMBLY * pkm_runtime::kinematics::model_scale(model);
        let mut branches = Vec::new();
        let mut configurations: Vec<Configuration> = Vec::new();
        let mut firsts: Vec<Solution> = Vec::new();
        for (signs, solution) in pkm_runtime::plan::run_all(model, &self.plan, ordered) {
            let number = table::number_of(&signs);
            let solved = match solution {
                Err(e) => Err(e.to_string()),
                Ok(s) => {
                    let same = firsts
                        .iter()
                        .position(|f| same_assembly(model, self.link, f, &s, tolerance));
                    let c = match same {
                        Some(c) => {
                            let differences = differences(model, &firsts[c], &s, tolerance);
                            configurations[c].branches.push(number);
                            configurations[c].differences.push((number, differences));
                            c
                        }
                        None => {
                            configurations.push(Configuration {
                                branches: vec![number],
                                differences: Vec::new(),
                                result: self.compute(&s)?,
                            });
                            firsts.push(s.clone());
                            configurations.len() - 1
                        }
                    };
                    Ok((s, c))
                }
            };
            branches.push(BranchAt { number, signs, solved });
        }
        Ok(At {
            branches,
            configurations,
        })
    }

    /// The failure of a pose at which no branch has a stiffness: the
    /// distinct reasons.
    fn none_has(&self, at: &At) -> Option<Failure> {
        let mut reasons: Vec<&str> = Vec::new();
        for b in &at.branches {
            let why = self.result(at, b).err()?;
            if !reasons.contains(&why) {
                reasons.push(why);
            }
        }
        let reached = at.branches.iter().any(|b| b.solved.is_ok());
        let what = if reached {
            "no branch has a stiffness here"
        } else {
            "no branch reaches the pose"
        };
        Some(Failure::new(
            Kind::Unreachable,
            format!("{what}: {}", reasons.join("; ")),
        ))
    }

    /// Every branch at the declared outputs `pose` (by name), as JSON
    /// (`json`) or as a table with each configuration's K under it.
    pub fn answer(&self, pose: &[(String, f64)], json: bool) -> Result<String, Failure> {
        let ordered = ordered_pose(self.r, &self.l, pose)?;
        let at = self.at(&ordered)?;
        if let Some(f) = self.none_has(&at) {
            return Err(f);
        }
        if json {
            return Ok(format!("{}\n", self.json(pose, &at)));
        }
        let given: Vec<String> = pose.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        let ok = at.branches.iter().filter(|b| self.result(&at, b).is_ok()).count();
        let mut out = format!(
            "{}: static stiffness at {}, about the platform's point {}; {} branches, {ok} ok, {} configuration{}\n\n",
            self.l.model.name,
            given.join(", "),
            self.reference_name(),
            at.branches.len(),
            at.configurations.len(),
            if at.configurations.len() == 1 { "" } else { "s" }
        );
        out += &table::branch_table(&self.columns(), &self.rows(&at));
        for c in &at.configurations {
            out += &format!("\n{}", self.configuration_text(c));
        }
        Ok(out)
    }

    /// Branch `b`'s solution, configuration and stiffness, or why it has none.
    fn result<'a>(&self, at: &'a At, b: &'a BranchAt) -> Result<(&'a Solution, usize, &'a Computed), &'a str> {
        let (solution, c) = b.solved.as_ref().map_err(String::as_str)?;
        let k = at.configurations[*c].result.as_ref().map_err(String::as_str)?;
        Ok((solution, *c, k))
    }

    /// The reference point's name (the first output's point), for titles.
    fn reference_name(&self) -> String {
        let m = &self.l.model;
        m.points
            .iter()
            .find(|p| p.link == self.link && p.at == self.local)
            .map_or_else(
                || format!("{:?} of {}", self.local, m.links[self.link]),
                |p| p.name.clone(),
            )
    }

    /// What a configuration is, which branches it is and how they differ,
    /// and its K as a matrix.
    fn configuration_text(&self, c: &Configuration) -> String {
        let first = c.branches[0];
        let numbers: Vec<String> = c.branches.iter().map(usize::to_string).collect();
        let mut text = if c.branches.len() == 1 {
            format!("Configuration {first}: branch {first} alone.\n")
        } else {
            let tolerance = SAME_ASSEMBLY * pkm_runtime::kinematics::model_scale(&self.l.model);
            let mut text = format!(
                "Configuration {first}: branches {} are one assembly: the same platform pose, and every joint at the same place with its axis on the same line, within {} {} ({SAME_ASSEMBLY:e} of the mechanism's size). They differ from branch {first} only in joint values that move no joint:\n",
                numbers.join(", "),
                Cell::Num(tolerance).short(),
                self.units.length,
            );
            for (n, d) in &c.differences {
                let what = if d.is_empty() {
                    "none (the same joint values)".to_string()
                } else {
                    d.join(", ")
                };
                text += &format!("  {n}: {what}\n");
            }
            text + &format!("Its stiffness is computed once, on branch {first}.\n")
        };
        match &c.result {
            Ok(k) => {
                let u = &self.units.length;
                text += &format!(
                    "K about {} [N/{u}, N, N·{u}/rad; rows and columns x, y, z, rx, ry, rz], conditioning {}:\n",
                    self.reference_name(),
                    Cell::Num(k.k.wrenches.sigma()).short()
                );
                let m = k.k.k();
                let cells: Vec<Vec<String>> = (0..6)
                    .map(|i| (0..6).map(|j| Cell::Num(m[(i, j)]).short()).collect())
                    .collect();
                let width = cells.iter().flatten().map(String::len).max().unwrap_or(1);
                for row in cells {
                    let padded: Vec<String> = row.iter().map(|x| format!("{x:>width$}")).collect();
                    text += &format!("  {}\n", padded.join("  "));
                }
            }
            Err(why) => text += &format!("No stiffness: {why}\n"),
        }
        text
    }

    /// The columns of a branch: the actuated joints' values, the
    /// configuration, the conditioning, the limbs' lengths, the
    /// directional stiffnesses, the deflection (with `--wrench`), and K's
    /// upper triangle (CSV only).
    fn columns(&self) -> Vec<Column> {
        let m = &self.l.model;
        let u = &self.units.length;
        let mut columns: Vec<Column> = m
            .inputs()
            .into_iter()
            .map(|j| {
                Column::new(
                    &m.joints[j].name,
                    self.units.of_kind(super::solve::angular(m.joints[j].kind)),
                )
            })
            .collect();
        columns.push(Column::bare("configuration"));
        columns.push(Column::bare("conditioning"));
        columns.extend(
            self.limbs
                .iter()
                .map(|l| Column::new(format!("length {}", l.name), u.as_str())),
        );
        let k_unit = |i: usize, j: usize| match (i < 3, j < 3) {
            (true, true) => format!("N/{u}"),
            (false, false) => format!("N·{u}/rad"),
            _ => "N".to_string(),
        };
        columns.extend((0..6).map(|i| Column::new(format!("k_{}", DIRECTIONS[i]), k_unit(i, i))));
        if self.wrench.is_some() {
            columns.extend((0..6).map(|i| {
                let unit = if i < 3 { u.as_str() } else { "rad" };
                Column::new(format!("d_{}", DIRECTIONS[i]), unit)
            }));
        }
        for (i, a) in DIRECTIONS.iter().enumerate() {
            for (j, b) in DIRECTIONS.iter().enumerate().skip(i) {
                columns.push(Column::new(format!("K_{a}{b}"), k_unit(i, j)).csv_only());
            }
        }
        columns
    }

    /// Every branch as rows of [`Stiffness::columns`]; the limbs' lengths
    /// in the `limbs` block's order.
    fn rows(&self, at: &At) -> Vec<Branch> {
        let m = &self.l.model;
        at.branches
            .iter()
            .map(|b| {
                let values = match self.result(at, b) {
                    Ok((solution, c, k)) => {
                        let mut row: Vec<Cell> = m
                            .inputs()
                            .into_iter()
                            .map(|j| {
                                let angle = super::solve::angular(m.joints[j].kind);
                                Cell::Num(self.r.shown_value(solution.values[j], angle))
                            })
                            .collect();
                        row.push(Cell::Int(at.configurations[c].branches[0] as i64));
                        row.push(Cell::Num(k.k.wrenches.sigma()));
                        row.extend(self.limbs.iter().map(|l| {
                            let analysed = k.names.iter().position(|n| *n == l.name);
                            let length = analysed.and_then(|i| k.k.wrenches.limbs[i].length());
                            length.map_or(Cell::Empty, Cell::Num)
                        }));
                        row.extend(k.directional.iter().map(|&v| Cell::Num(v)));
                        if let Some(d) = k.deflection {
                            row.extend(d.iter().map(|&v| Cell::Num(v)));
                        }
                        let matrix = k.k.k();
                        for i in 0..6 {
                            row.extend((i..6).map(|j| Cell::Num(matrix[(i, j)])));
                        }
                        Ok(row)
                    }
                    Err(why) => Err(why.to_string()),
                };
                Branch {
                    number: b.number,
                    signs: b.signs.clone(),
                    values,
                }
            })
            .collect()
    }

    /// Every branch as JSON: each with its number, and its configuration's
    /// values (computed once per configuration), its own limbs' joints.
    fn json(&self, pose: &[(String, f64)], at: &At) -> Value {
        let model = &self.l.model;
        let unit = &self.units.length;
        let branches: Vec<Value> = at
            .branches
            .iter()
            .map(|b| {
                let signs = sign_text(&b.signs);
                let (solution, c, k) = match self.result(at, b) {
                    Ok(r) => r,
                    Err(why) => return json!({ "branch": b.number, "signs": signs, "ok": false, "reason": why }),
                };
                let point = k.k.point;
                let deflection = k
                    .deflection
                    .map_or(Value::Null, |d| json!({ "translation": &d[..3], "rotation": &d[3..] }));
                let m = k.k.k();
                let matrix: Vec<Vec<f64>> = (0..6).map(|i| (0..6).map(|j| m[(i, j)]).collect()).collect();
                let analysis = &k.k.wrenches;
                let p = Vector3::from(point);
                let rows: Vec<Value> = analysis
                    .rows
                    .iter()
                    .zip(&k.k.stiffness.springs)
                    .map(|(row, spring)| {
                        json!({
                            "kind": kind_name(row.kind),
                            "limb": k.names[row.limb],
                            "force": row.wrench.f.as_slice(),
                            "moment": row.wrench.moment_about(&p).as_slice(),
                            "spring": spring,
                        })
                    })
                    .collect();
                let legs: Vec<Value> = analysis
                    .limbs
                    .iter()
                    .zip(&k.names)
                    .map(|(limb, name)| {
                        let joints: Vec<Value> = limb
                            .joints
                            .iter()
                            .map(|&j| {
                                let joint = &model.joints[j];
                                let first = &solution.poses[joint.links[0]];
                                let axis = first.rotation * Vector3::from(joint.places[0].axis());
                                json!({
                                    "name": joint.name,
                                    "kind": format!("{:?}", joint.kind),
                                    "point": pkm_runtime::kinematics::joint_point(model, &solution.poses, j),
                                    "axis": axis.normalize().as_slice(),
                                })
                            })
                            .collect();
                        json!({ "name": name, "joints": joints, "length": limb.length() })
                    })
                    .collect();
                let d = k.directional;
                json!({
                    "branch": b.number,
                    "signs": signs,
                    "ok": true,
                    "configuration": at.configurations[c].branches[0],
                    "reference": point,
                    "limbs": legs,
                    "rows": rows,
                    "K": matrix,
                    "directional": {
                        "x": d[0], "y": d[1], "z": d[2],
                        "rx": d[3], "ry": d[4], "rz": d[5],
                    },
                    "deflection": deflection,
                    "conditioning": analysis.sigma(),
                })
            })
            .collect();
        let configurations: Vec<Value> = at
            .configurations
            .iter()
            .map(|c| {
                let differences: serde_json::Map<String, Value> =
                    c.differences.iter().map(|(n, d)| (n.to_string(), json!(d))).collect();
                json!({
                    "branches": c.branches,
                    "computed_on": c.branches[0],
                    "differences": differences,
                })
            })
            .collect();
        let as_given: serde_json::Map<String, Value> = pose.iter().map(|(n, v)| (n.clone(), json!(v))).collect();
        json!({
            "name": model.name,
            "pose": as_given,
            "units": {
                "length": unit,
                "force": "N",
                "moment": format!("N·{unit}"),
                "angle": if self.r.degrees { "deg (given)" } else { "rad" },
                "K": format!("about the reference point, (δx, δy, δz, δθx, δθy, δθz) ↦ (Fx, Fy, Fz, Mx, My, Mz): N/{unit}, N, N·{unit}/rad blocks"),
                "directional": format!("1/(eᵢᵀ K⁻¹ eᵢ): N/{unit} along x, y, z; N·{unit}/rad about them"),
                "deflection": format!("{unit} and rad, of the reference point, under --wrench (N, N·{unit} about the reference point)"),
            },
            "configurations": configurations,
            "same_configuration": format!(
                "branches are one configuration when they have the same platform pose and every joint at the same place with its axis on the same line, to {SAME_ASSEMBLY:e} of the mechanism's size; its stiffness is computed once, on its first branch"
            ),
            "branches": branches,
        })
    }
}

impl super::csv::Solver for Stiffness<'_> {
    fn given(&self) -> Vec<Column> {
        output_columns(self.r, &self.l)
    }

    fn columns(&self) -> Vec<Column> {
        Stiffness::columns(self)
    }

    fn choices(&self) -> usize {
        self.plan.branches
    }

    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure> {
        let at = self.at(&solver_pose(self.r, &self.l, given))?;
        Ok(self.rows(&at))
    }
}

/// Whether two solutions are one physical assembly: the platform `link`
/// at the same pose, and every joint's place on each of its links at the
/// same point (within `tolerance`, a length) with its axis (a revolute's,
/// a slide's guide, a parallelogram's hinge and arm) on the same line,
/// either way.
fn same_assembly(model: &Model, link: usize, a: &Solution, b: &Solution, tolerance: f64) -> bool {
    let near = |p: [f64; 3], q: [f64; 3]| (Vector3::from(p) - Vector3::from(q)).norm() <= tolerance;
    let (pa, pb) = (&a.poses[link], &b.poses[link]);
    let turned = (pa.rotation.to_rotation_matrix().matrix() - pb.rotation.to_rotation_matrix().matrix()).amax();
    if (pa.translation.vector - pb.translation.vector).norm() > tolerance || turned > SAME_ASSEMBLY {
        return false;
    }
    let line = |pose: &pkm_runtime::plan::Pose3, v: [f64; 3]| (pose.rotation * Vector3::from(v)).normalize();
    let parallel = |u: Vector3<f64>, v: Vector3<f64>| u.cross(&v).norm() <= SAME_ASSEMBLY;
    let places = model.joints.iter().all(|j| {
        (0..2).all(|s| {
            let (l, place) = (j.links[s], &j.places[s]);
            let (ta, tb) = (&a.poses[l], &b.poses[l]);
            let at = |pose| pkm_runtime::plan::at(pose, place.at());
            near(at(ta), at(tb))
                && match *place {
                    Place::Point { .. } => true,
                    Place::Axis { axis, .. } => parallel(line(ta, axis), line(tb, axis)),
                    Place::Line { along, .. } => parallel(line(ta, along), line(tb, along)),
                    Place::Arm { axis, arm, .. } => {
                        parallel(line(ta, axis), line(tb, axis))
                            && (line(ta, arm) - line(tb, arm)).norm() <= SAME_ASSEMBLY
                    }
                }
        })
    });
    let points = model.points.iter().all(|p| {
        near(
            pkm_runtime::plan::at(&a.poses[p.link], p.at),
            pkm_runtime::plan::at(&b.poses[p.link], p.at),
        )
    });
    places && points
}

/// The joint values of `b` that differ from `a`'s, in words: `R1 + π`,
/// `P1 negated`, `S1 turned by π`.
fn differences(model: &Model, a: &Solution, b: &Solution, tolerance: f64) -> Vec<String> {
    use std::f64::consts::{PI, TAU};
    // A turn in (−π, π], in words (`π`, `-0.25 rad`), unless it is none.
    let turn = |t: f64| {
        let t = (t + PI).rem_euclid(TAU) - PI;
        if t.abs() <= SAME_ASSEMBLY {
            None
        } else if (t.abs() - PI).abs() <= SAME_ASSEMBLY {
            Some("π".to_string())
        } else {
            Some(format!("{} rad", Cell::Num(t).short()))
        }
    };
    model
        .joints
        .iter()
        .enumerate()
        .filter_map(|(j, joint)| {
            let (u, v) = (a.values[j], b.values[j]);
            match joint.kind {
                JointType::R | JointType::Pa => turn(v - u).map(|t| format!("{} + {t}", joint.name)),
                JointType::P if (v - u).abs() <= tolerance => None,
                JointType::P if (v + u).abs() <= tolerance => Some(format!("{} negated", joint.name)),
                JointType::P => Some(format!(
                    "{} {} → {}",
                    joint.name,
                    Cell::Num(u).short(),
                    Cell::Num(v).short()
                )),
                JointType::S => {
                    let [p, q] = joint.links;
                    let relative = |s: &Solution| s.poses[p].rotation.inverse() * s.poses[q].rotation;
                    turn(relative(a).angle_to(&relative(b))).map(|t| format!("{} turned by {t}", joint.name))
                }
            }
        })
        .collect()
}
