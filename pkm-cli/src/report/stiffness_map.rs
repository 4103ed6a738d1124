//! The static stiffness map: for a file that declares its units and its
//! `limbs` and has an inverse plan from a pose (or pose parts) of the
//! platform, the platform's stiffness over a grid of two of the pose's
//! values, the others held (docs/stiffness.md, "Report").

use super::follow;
use super::html::{html_escape, sign_text, tuple_text, Page};
use super::loaded::{default_point, output_columns, reach, signs, Loaded, Plan};
use super::{invalid, ReportError};
use crate::drawing::{self, View};
use crate::plots;
use pkm_dsl::limb_properties::ResolvedLimb;
use pkm_runtime::newton::Output;
use pkm_runtime::primitives::Sign;
use pkm_runtime::stiffness::{LimbProperties, PlatformStiffness};
use pkm_runtime::workspace::Grid;
use std::fmt::Write as _;

/// Grid nodes along each of the map's two values.
pub const MAP_NODES: usize = 41;

/// The half-width of the map's grid over two angles, in rad.
pub const TILT_RANGE: f64 = 0.3;

/// The half-width of the map's grid over two positions, as a fraction of
/// the mechanism's reach ([`reach`]).
pub const SHIFT_RANGE: f64 = 0.25;

/// Below this σ_min/σ_max of `J` a node of the map is ill-conditioned.
pub const ILL_CONDITIONED: f64 = 1e-2;

/// Heights tried for a held z (evenly over (0, reach]).
const HEIGHTS: usize = 200;

/// The stiffness at one pose: directional stiffness along z at the
/// reference point, the least eigenvalue of K's translational block there,
/// the legs' total length and the conditioning of `J`.
#[derive(Debug, Clone, Copy)]
struct Node {
    along_z: f64,
    least: f64,
    legs: f64,
    sigma: f64,
}

/// What every node needs: the model, plan, platform, its reference point and the legs.
struct Map<'a> {
    l: &'a Loaded,
    plan: &'a Plan,
    link: usize,
    local: [f64; 3],
    limbs: &'a [ResolvedLimb],
}

impl Map<'_> {
    /// The stiffness at `pose` on the branch `signs`: `Err` with the cause
    /// where the pose is not reached or the configuration is singular.
    fn node(&self, pose: &[f64], signs: &[Sign]) -> Result<Node, String> {
        let model = &self.l.model;
        let solution = pkm_runtime::plan::run(model, self.plan, pose, signs).map_err(|e| e.to_string())?;
        let analysis = pkm_runtime::wrench::analyse(model, &solution, self.link).map_err(|e| e.to_string())?;
        let properties: Vec<LimbProperties> = pkm_dsl::limb_properties::in_analysis_order(self.limbs, &analysis.limbs)
            .map_err(|_| "a limb has no entry in the `limbs` block".to_string())?
            .into_iter()
            .map(ResolvedLimb::properties)
            .collect();
        let point = pkm_runtime::plan::at(&solution.poses[self.link], self.local);
        let k = PlatformStiffness::new(analysis, &properties, point).map_err(|e| e.to_string())?;
        let along_z = k.directional().map_err(|e| e.to_string())?[2];
        let translational = k.k().fixed_view::<3, 3>(0, 0).into_owned();
        let least = translational.symmetric_eigenvalues().min();
        Ok(Node {
            along_z,
            least,
            legs: k.wrenches.limbs.iter().map(|l| l.length().unwrap_or(0.0)).sum(),
            sigma: k.wrenches.sigma(),
        })
    }

    /// The branch with the shortest legs (their lengths summed) that has a
    /// stiffness at `pose`, and its node.
    fn shortest(&self, pose: &[f64]) -> Option<(usize, Node)> {
        let choices = self.plan.choices();
        (0..1usize << choices)
            .filter_map(|b| self.node(pose, &signs(choices, b)).ok().map(|n| (b, n)))
            .min_by(|a, b| a.1.legs.total_cmp(&b.1.legs))
    }
}

/// Which of x, y, z, rx, ry, rz (0 to 5) of `link` each declared output
/// value is, if it is one.
fn parts_of(l: &Loaded, link: usize) -> Vec<Option<usize>> {
    let mut parts = Vec::new();
    for o in &l.outputs {
        match *o {
            Output::Pose { link: k, about, .. } => {
                parts.extend((0..3).map(|i| (k == link).then_some(i)));
                if let Some(axis) = about {
                    let basis = (0..3).find(|&i| (axis[i] - 1.0).abs() < 1e-12 && (axis[(i + 1) % 3]).abs() < 1e-12);
                    parts.push(basis.filter(|_| k == link).map(|i| 3 + i));
                }
            }
            Output::Point { link: k, .. } => parts.extend((0..3).map(|i| (k == link).then_some(i))),
            Output::Parts { link: k, parts: p, .. } => parts.extend(p.given().map(|i| (k == link).then_some(i))),
            Output::Joint(_) => parts.push(None),
        }
    }
    parts
}

/// Says in a paragraph why there is no map.
fn not_mapped(page: &mut Page, why: &str) {
    let _ = writeln!(
        page,
        "<h2>Static stiffness</h2><p>The file declares its legs, but no stiffness map is drawn: {}.</p>",
        html_escape(why)
    );
}

/// The "Static stiffness" section: nothing for a file without `units` and
/// `limbs`; else the directional stiffness along z and the least
/// eigenvalue of K's translational block at the platform's reference
/// point over a [`MAP_NODES`]² grid of two of the pose's values (rx and ry
/// ±[`TILT_RANGE`] if both are outputs, else x and y ±[`SHIFT_RANGE`] of the
/// reach), the other outputs held: angles and x, y at 0 and z at the height
/// where `J` is best conditioned (level, shortest legs); on the branch with
/// the shortest legs at the held pose, followed by its signs over the grid.
/// `hold` (`--hold`) sets output values of the held pose by name.
pub(super) fn stiffness_map(
    page: &mut Page,
    l: &Loaded,
    hold: &[(String, f64)],
    file: &str,
) -> Result<(), ReportError> {
    let a = &l.analysis;
    let declared = a.mass_and_loads.units.is_some() && !a.limbs.is_empty();
    if !declared && !hold.is_empty() {
        return Err(invalid(format!(
            "{file}: --hold sets the stiffness map's pose, and the file declares no `units` and `limbs`"
        )));
    }
    let Some(units) = a.mass_and_loads.units.filter(|_| declared) else {
        return Ok(());
    };
    let limbs = match pkm_dsl::numeric::limb_properties(a, &l.values) {
        Ok(limbs) => limbs,
        Err(d) => {
            let why = d.0.first().map(|x| x.message.clone()).unwrap_or_default();
            not_mapped(page, &format!("its limb properties do not resolve ({why})"));
            return Ok(());
        }
    };
    let plan = match &l.inverse {
        Ok(plan) => plan,
        Err(why) => {
            not_mapped(page, &format!("it has no inverse plan from its outputs ({why})"));
            return Ok(());
        }
    };
    let platform = l.outputs.iter().find_map(Output::point);
    let Some((link, local)) = platform.filter(|_| !l.model.planar) else {
        not_mapped(page, "no output places a point of a platform in space");
        return Ok(());
    };
    let parts = parts_of(l, link);
    let find = |p: usize| parts.iter().position(|&x| x == Some(p));
    let size = reach(&l.model);
    let (axes, half) = match (find(3), find(4), find(0), find(1)) {
        (Some(i), Some(j), _, _) => ([i, j], TILT_RANGE),
        (_, _, Some(i), Some(j)) => ([i, j], SHIFT_RANGE * size),
        _ => {
            not_mapped(
                page,
                "its outputs give neither the platform's rx and ry nor its x and y",
            );
            return Ok(());
        }
    };
    let map = Map {
        l,
        plan,
        link,
        local,
        limbs: &limbs,
    };
    let unit = units.length.symbol();
    let columns = output_columns(l, unit);
    let mut held = vec![0.0; parts.len()];
    let names: Vec<&str> = a
        .geometry
        .outputs
        .iter()
        .flat_map(|o| o.names.iter().map(String::as_str))
        .collect();
    for (name, v) in hold {
        let Some(i) = names.iter().position(|n| n == name) else {
            return Err(invalid(format!(
                "{file}: --hold {name}: no such output (the outputs: {})",
                names.join(", ")
            )));
        };
        if !v.is_finite() {
            return Err(invalid(format!("--hold {name}={v}: not a finite number")));
        }
        held[i] = *v;
    }
    let given = |i: usize| hold.iter().any(|(n, _)| names.get(i) == Some(&n.as_str()));
    // The held height: the best-conditioned level pose (shortest legs).
    let scanned = find(2).filter(|&z| !given(z));
    if let Some(z) = scanned {
        let best = (1..=HEIGHTS)
            .filter_map(|k| {
                held[z] = size * k as f64 / HEIGHTS as f64;
                map.shortest(&held).map(|(_, n)| (held[z], n.sigma))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        held[z] = best.map_or(0.0, |b| b.0);
    }
    let Some((branch, centre)) = map.shortest(&held) else {
        not_mapped(
            page,
            &format!(
                "no branch of the inverse solution has a stiffness at the held pose {}",
                tuple_text(&held, 3)
            ),
        );
        return Ok(());
    };
    let branch_signs = signs(plan.choices(), branch);
    let grid = Grid {
        ranges: axes.iter().map(|&i| (held[i] - half, held[i] + half)).collect(),
        counts: vec![MAP_NODES; 2],
    };
    // The held pose's assembly followed over the grid by continuity; at
    // each node reached, its stiffness, or the cause where it has none.
    let seed = plan
        .solve(&l.model, &held, &branch_signs)
        .map_err(|e| invalid(format!("{file}: the held pose on branch {branch}: {e}")))?;
    let given = |q: &[f64]| {
        let mut pose = held.clone();
        pose[axes[0]] = q[0];
        pose[axes[1]] = q[1];
        pose
    };
    let followed = follow::followed(l, plan, &grid, given, &[held[axes[0]], held[axes[1]]], &seed, |_, _| ());
    let mut q = [0.0; 2];
    let nodes: Vec<Option<Result<Node, String>>> = followed
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let f = f.as_ref()?;
            grid.node(k, &mut q);
            Some(map.node(&given(&q), &signs(plan.choices(), f.branch)))
        })
        .collect();
    let xs: Vec<f64> = (0..MAP_NODES).map(|k| grid.value(0, k)).collect();
    let ys: Vec<f64> = (0..MAP_NODES).map(|k| grid.value(1, k)).collect();
    let value = |n: &Option<Result<Node, String>>, of: fn(&Node) -> f64| match n {
        Some(Ok(n)) => of(n),
        _ => f64::NAN,
    };
    let along_z: Vec<f64> = nodes.iter().map(|n| value(n, |n| n.along_z)).collect();
    let least: Vec<f64> = nodes.iter().map(|n| value(n, |n| n.least)).collect();
    let ill: Vec<bool> = nodes.iter().map(|n| value(n, |n| n.sigma) < ILL_CONDITIONED).collect();
    let stiff = along_z.iter().filter(|v| v.is_finite()).count();
    let singular = nodes.iter().filter(|n| matches!(n, Some(Err(_)))).count();
    let unreached = nodes.iter().filter(|n| n.is_none()).count();
    let ill_count = ill.iter().filter(|&&b| b).count();
    let sigmas = nodes.iter().map(|n| value(n, |n| n.sigma)).filter(|v| v.is_finite());
    let (sigma_lo, sigma_hi) = sigmas.fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let (cx, cy) = (columns[axes[0]].as_str(), columns[axes[1]].as_str());
    let held_text: Vec<String> = (0..held.len())
        .filter(|i| !axes.contains(i))
        .map(|i| format!("{} = {:.4}", columns[i], held[i]))
        .collect();
    let _ = writeln!(
        page,
        "<h2>Static stiffness</h2><p>The platform's stiffness <code>K = Jᵀ K_p J</code> from the file's \
         <code>limbs</code> (docs/stiffness.md), at its reference point, over a {MAP_NODES} × {MAP_NODES} grid of \
         {} and {} (± {half:.3} about the held pose), the other outputs held: {}{}. At the held pose, branch \
         {branch} ({}) of the inverse solution: the one with the shortest legs there. {} Of {} nodes, {stiff} \
         have a stiffness, {singular} are reached at a singular configuration and {unreached} are not reached: both \
         left blank. σ_min/σ_max of J runs from {sigma_lo:.2e} to {sigma_hi:.2e} over the grid; {ill_count} \
         nodes are ill-conditioned (below {ILL_CONDITIONED:e}: a load there moves the platform far in some \
         direction, and the value is sensitive to the dimensions), crossed red. \
         The colour scales are logarithmic. At the held pose the directional stiffness along z is {:.1} N/{unit} \
         and the least eigenvalue of the translational block {:.1} N/{unit}.</p>",
        html_escape(cx),
        html_escape(cy),
        html_escape(&held_text.join(", ")),
        if scanned.is_some() {
            " (the height where J is best conditioned, σ_min/σ_max, level and on the shortest legs, among 200 \
             over (0, the mechanism's reach])"
        } else {
            ""
        },
        sign_text(&branch_signs),
        html_escape(&follow::meetings(
            &grid,
            &followed,
            &[(cx.to_string(), String::new()), (cy.to_string(), String::new())],
            plan.choices()
        )),
        grid.len(),
        centre.along_z,
        centre.least,
    );
    // The mechanism at the held pose on the mapped branch.
    let poses = plan
        .solve(&l.model, &held, &branch_signs)
        .ok()
        .and_then(|v| pkm_runtime::newton::link_poses(&l.model, &v).ok());
    if let Some(poses) = poses {
        let point_name = default_point(l);
        let f = drawing::draw(
            &page.dir.join("stiffness_pose"),
            &format!(
                "{} at the held pose {}, branch {branch}",
                l.model.name,
                tuple_text(&held, 3)
            ),
            &drawing::scene(&l.model, &poses, (link, local)),
            View::Axonometric,
            unit,
            &point_name,
        )?;
        page.figure(
            &f,
            &format!(
                "The mechanism at the held pose ({}), on the mapped branch; {point_name} is the reference point",
                html_escape(&columns.join(", "))
            ),
        );
    }
    let stiffness_unit = format!("N/{unit}");
    let quantities = [
        (
            "stiffness_z",
            "Directional stiffness along z",
            &along_z,
            "1/(e_zᵀ K⁻¹ e_z): the force along z over the displacement along z it causes, the platform otherwise free",
        ),
        (
            "stiffness_least",
            "Least translational stiffness",
            &least,
            "the least eigenvalue of K's translational 3 × 3 block: the least force per displacement over every \
             direction, the rotations held",
        ),
    ];
    let _ = writeln!(
        page,
        "<table><tr><th class=\"l\">quantity (N/{unit})</th><th>least</th><th>at ({}, {})</th><th>greatest</th>\
         <th>at ({}, {})</th></tr>",
        html_escape(cx),
        html_escape(cy),
        html_escape(cx),
        html_escape(cy)
    );
    let mut shows = Vec::new();
    for (_, name, values, _) in &quantities {
        let extreme = |better: fn(f64, f64) -> bool| {
            (0..values.len()).filter(|&n| values[n].is_finite()).reduce(|a, b| {
                if better(values[b], values[a]) {
                    b
                } else {
                    a
                }
            })
        };
        if let (Some(lo), Some(hi)) = (extreme(|a, b| a < b), extreme(|a, b| a > b)) {
            shows.push(format!(
                "the {} falls from {:.4e} N/{unit} at ({:.3}, {:.3}) to {:.4e} N/{unit} at ({:.3}, {:.3}), {:.1} times less",
                name.to_lowercase(),
                values[hi],
                xs[hi / MAP_NODES],
                ys[hi % MAP_NODES],
                values[lo],
                xs[lo / MAP_NODES],
                ys[lo % MAP_NODES],
                values[hi] / values[lo]
            ));
        }
        let cell = |n: Option<usize>| match n {
            Some(n) => format!(
                "<td>{:.1}</td><td>({:.3}, {:.3})</td>",
                values[n],
                xs[n / MAP_NODES],
                ys[n % MAP_NODES]
            ),
            None => "<td>—</td><td>—</td>".into(),
        };
        let _ = writeln!(
            page,
            "<tr><td class=\"l\">{name}</td>{}{}</tr>",
            cell(extreme(|a, b| a < b)),
            cell(extreme(|a, b| a > b))
        );
    }
    let _ = writeln!(page, "</table>");
    if !shows.is_empty() {
        let _ = writeln!(
            page,
            "<p>What the maps show: over the grid, {}. A small value means that a load moves the platform far: \
             the directional stiffness counts the rotations a z force also causes, the least eigenvalue holds them \
             and takes the softest direction of translation.</p>",
            html_escape(&shows.join("; "))
        );
    }
    for (stem, name, values, meaning) in quantities {
        let f = plots::heat_map(
            &page.dir.join(stem),
            &format!("{name} at the reference point ({stiffness_unit})"),
            [cx, cy],
            &xs,
            &ys,
            values,
            &format!("stiffness ({stiffness_unit})"),
            &plots::HeatStyle {
                log: true,
                marked: &ill,
                mark_label: "ill-conditioned",
                counts: false,
            },
        )?;
        page.figure(
            &f,
            &format!(
                "{name}, {meaning}, over the grid of {cx} and {cy}, colour on a log scale (white: not reached or singular; red cross: ill-conditioned). It shows how \
                 much stiffer or softer the platform is away from the held pose, and where it is softest"
            ),
        );
    }
    Ok(())
}
