//! Singularities: the determinants' factors of the forward and inverse
//! plans, named, and over a coarser sweep of the followed branch the
//! near-singular nodes by σ_in and σ_out and by each factor.

use super::follow;
use super::html::{html_escape, Page};
use super::loaded::{Loaded, Plan};
use super::workspace::{largest_pair, plane_name, AXES};
use super::{ReportError, Sampling};
use pkm_runtime::newton;
use pkm_runtime::plan::Pose3;
use pkm_runtime::workspace::Grid;
use pkm_runtime::{singular, velocity};
use std::fmt::Write as _;

/// One measure of a node, by which a chart draws it.
type Measure = dyn Fn(&Measured) -> f64;

/// A factor below this is near vanishing (the factors are normalised to [0, 1]).
const NEAR: f64 = 0.05;

/// Every factor of det J_o (the forward plan's, if there is one) and det
/// J_i (the inverse plan's) at `poses`: a label (`J_o step 3`), its value,
/// what it says.
pub(super) fn named_factors(l: &Loaded, forward: Option<&Plan>, poses: &[Pose3]) -> Vec<(String, f64, String)> {
    plan_factors(l, forward, poses)
        .map(|(jacobian, f)| {
            (
                format!("{jacobian} step {}", f.step),
                f.value,
                f.describe(&l.model, poses),
            )
        })
        .collect()
}

/// The factors alone, forward plan's then inverse plan's, each with its
/// Jacobian's name (the order of [`named_factors`]).
fn plan_factors<'a>(
    l: &'a Loaded,
    forward: Option<&'a Plan>,
    poses: &'a [Pose3],
) -> impl Iterator<Item = (&'static str, singular::Factor)> + 'a {
    [("J_o", forward), ("J_i", l.inverse.as_ref().ok())]
        .into_iter()
        .flat_map(move |(jacobian, p)| {
            p.map(|p| p.factors(&l.model, poses))
                .unwrap_or_default()
                .into_iter()
                .map(move |f| (jacobian, f))
        })
}

/// One node measured: where it is drawn (three coordinates, two of which a
/// [`Plane`] shows), σ_in and σ_out (NaN without declared outputs), and
/// every determinant factor's value (the order of [`named_factors`]).
pub(super) struct Measured {
    pub(super) at: [f64; 3],
    sigma_in: f64,
    sigma_out: f64,
    factors: Vec<f64>,
}

/// The configuration `values` measured, drawn at `at` (the followed
/// point's world position if `None`); `None` where its velocity equations
/// cannot be formed.
pub(super) fn measure(
    l: &Loaded,
    forward: Option<&Plan>,
    point: (usize, [f64; 3]),
    values: &[f64],
    at: Option<[f64; 3]>,
) -> Option<Measured> {
    let (model, outputs) = (&l.model, &l.outputs);
    let poses = newton::link_poses(model, values).ok()?;
    let p = poses[point.0].transform_point(&point.1.into());
    let (sigma_in, sigma_out) = if outputs.is_empty() {
        (f64::NAN, f64::NAN)
    } else {
        let j = velocity::jacobians(model, values, outputs).ok()?;
        (j.input_sigma, j.output_sigma)
    };
    Some(Measured {
        at: at.unwrap_or([p.x, p.y, p.z]),
        sigma_in,
        sigma_out,
        factors: plan_factors(l, forward, &poses).map(|(_, f)| f.value).collect(),
    })
}

/// The plane the maps are drawn on: two of a [`Measured`]'s coordinates,
/// their axis labels and the plane's name.
pub(super) struct Plane {
    pub(super) pair: [usize; 2],
    pub(super) labels: [String; 2],
    pub(super) name: String,
}

/// Where the measured nodes are drawn: on a plane, or (a sweep of one
/// value) each measure against that value, the node's first coordinate,
/// labelled so.
pub(super) enum Drawn {
    /// Nodes on a plane.
    Plane(Plane),
    /// Curves against one value.
    Line(String),
}

impl Plane {
    /// The world plane `pair` of a point's positions in `unit`.
    pub(super) fn world(pair: [usize; 2], unit: &str) -> Plane {
        Plane {
            pair,
            labels: pair.map(|k| format!("{} ({unit})", AXES[k])),
            name: plane_name(pair),
        }
    }

    fn on(&self, m: &Measured) -> [f64; 2] {
        [m.at[self.pair[0]], m.at[self.pair[1]]]
    }
}

/// Singularity measures over a coarser sweep of the followed branch: the
/// near-singular nodes by σ (when outputs are declared) and by each
/// determinant factor `named`, in the plane where the workspace's `cloud`
/// spreads most.
pub(super) fn singularities(
    page: &mut Page,
    at: &Sampling,
    named: &[(String, f64, String)],
    cloud: &[[f64; 3]],
) -> Result<(), ReportError> {
    let (model, s) = (&at.l.model, at.s);
    let n = s.ranges.0.len();
    let cap = match n {
        1 => s.nodes.0,
        2 => 140,
        3 => 27,
        // About 64 000 nodes over four or more inputs (15 each for four).
        n => super::settings::default_nodes(n),
    };
    let coarse = Grid {
        ranges: s.ranges.0.clone(),
        counts: vec![s.nodes.0.min(cap); n],
    };
    // The nodes the followed assembly reaches (by continuity, as the
    // workspace's sweep) whose velocity equations can be formed.
    let measured: Vec<Measured> = follow::followed(
        at.l,
        at.plan,
        &coarse,
        |q| q.to_vec(),
        &s.start.0,
        &at.sample,
        |_, v| measure(at.l, Some(at.plan), at.point, v, None),
    )
    .into_iter()
    .filter_map(|n| n.and_then(|n| n.kept))
    .collect();
    let plane = Plane::world(if model.planar { [0, 1] } else { largest_pair(cloud) }, at.unit);
    let _ = writeln!(page, "<h2>Singularities</h2>");
    loci(
        page,
        at.l,
        &measured,
        named,
        &Drawn::Plane(plane),
        &format!("{} per input", coarse.counts[0]),
    )
}

/// The maps of `measured` nodes on `plane`: σ_in's and σ_out's lowest
/// nodes (when the file declares outputs), and each factor of `named`
/// near 0; `grid` says how the nodes were laid (`140 per input`).
pub(super) fn loci(
    page: &mut Page,
    l: &Loaded,
    measured: &[Measured],
    named: &[(String, f64, String)],
    drawn: &Drawn,
    grid: &str,
) -> Result<(), ReportError> {
    if l.outputs.is_empty() {
        let _ = writeln!(
            page,
            "<p>This file declares no outputs, so σ_in and σ_out (which measure the outputs' rates) are not defined; \
             the determinant factors below need no outputs. {} nodes of the followed assembly were measured.</p>",
            measured.len()
        );
    } else {
        sigma_loci(page, measured, drawn, grid)?;
    }
    if named.is_empty() {
        return Ok(());
    }
    factor_loci(page, measured, named, drawn)
}

/// Curves of `of` each measured node against its first coordinate, in
/// its order: the figure `stem`.
fn against(
    page: &mut Page,
    stem: &str,
    title: &str,
    value: &str,
    measured: &[Measured],
    of: &[(String, &Measure)],
    caption: &str,
) -> Result<(), ReportError> {
    let mut order: Vec<&Measured> = measured.iter().collect();
    order.sort_by(|a, b| a.at[0].total_cmp(&b.at[0]));
    let x: Vec<f64> = order.iter().map(|m| m.at[0]).collect();
    let series: Vec<(String, Vec<f64>)> = of
        .iter()
        .map(|(name, f)| (name.clone(), order.iter().map(|m| f(m)).collect()))
        .collect();
    let f = crate::plots::curves(&page.dir.join(stem), title, [value, "measure (1)"], &x, &series)?;
    page.figure(&f, caption);
    Ok(())
}

/// The smallest σ_in and σ_out over the `measured` nodes (`per_input` per
/// input), and (figure) the lowest 5 % of each on the plane `pair`.
fn sigma_loci(page: &mut Page, measured: &[Measured], drawn: &Drawn, grid: &str) -> Result<(), ReportError> {
    let sigma = |m: &Measured, k: usize| if k == 0 { m.sigma_in } else { m.sigma_out };
    let quantile = |k: usize| {
        let mut v: Vec<f64> = measured.iter().map(|m| sigma(m, k)).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 20).copied().unwrap_or(0.0)
    };
    let (qi, qo) = (quantile(0), quantile(1));
    let combined = measured
        .iter()
        .filter(|m| m.sigma_in < velocity::SINGULAR && m.sigma_out < velocity::SINGULAR)
        .count();
    let _ = writeln!(
        page,
        "<p>Over {} nodes of the followed assembly ({grid}): the smallest σ_in is {:.3e}, the smallest \
         σ_out {:.3e}; {combined} nodes are singular in both senses at once (threshold {:e}).{}</p>",
        measured.len(),
        measured.iter().map(|m| m.sigma_in).fold(f64::INFINITY, f64::min),
        measured.iter().map(|m| m.sigma_out).fold(f64::INFINITY, f64::min),
        velocity::SINGULAR,
        if !measured.is_empty() && measured.iter().all(|m| m.sigma_in < velocity::SINGULAR) {
            " σ_in is 0 at every node: the declared outputs do not fix every motion of the mechanism (some \
             motion leaves them all still, at every pose), so σ_in does not locate singularities here; σ_out \
             and the determinant factors do."
        } else {
            ""
        }
    );
    let plane = match drawn {
        Drawn::Plane(plane) => plane,
        Drawn::Line(value) => {
            return against(
                page,
                "singularity_loci",
                "σ_in and σ_out",
                value,
                measured,
                &[
                    ("σ_in".into(), &|m: &Measured| m.sigma_in),
                    ("σ_out".into(), &|m: &Measured| m.sigma_out),
                ],
                &format!("σ_in and σ_out against {value}: 0 at an input or output singularity"),
            )
        }
    };
    let on_plane = |m: &Measured| plane.on(m);
    let near = |k: usize, limit: f64| -> Vec<[f64; 2]> {
        measured.iter().filter(|m| sigma(m, k) <= limit).map(on_plane).collect()
    };
    let all: Vec<[f64; 2]> = measured.iter().map(on_plane).collect();
    let [x, y] = &plane.labels;
    page.scatter(
        "singularity_loci",
        "Near-singular configurations (lowest 5 % of each measure)",
        [x, y],
        &[
            ("all measured nodes".to_string(), all),
            (format!("input: σ_in ≤ {qi:.2e}"), near(0, qi)),
            (format!("output: σ_out ≤ {qo:.2e}"), near(1, qo)),
        ],
        false,
        &format!("Near-singular configurations, on {}", plane.name),
    )
}

/// Each determinant factor's smallest value over the `measured` nodes, and
/// (figure) the nodes where it is below [`NEAR`], on the plane `pair`.
fn factor_loci(
    page: &mut Page,
    measured: &[Measured],
    named: &[(String, f64, String)],
    drawn: &Drawn,
) -> Result<(), ReportError> {
    let on_plane = |m: &Measured| match drawn {
        Drawn::Plane(plane) => plane.on(m),
        Drawn::Line(_) => [m.at[0], 0.0],
    };
    let mut series = vec![(
        "all measured nodes".to_string(),
        measured.iter().map(on_plane).collect::<Vec<_>>(),
    )];
    let _ = writeln!(
        page,
        "<h3>Which factor comes near 0</h3><p>Over the same nodes, each determinant factor's smallest value, and \
         (figure) the nodes where it is below {NEAR}.</p><table><tr><th>factor</th><th>smallest (1)</th>\
         <th>nodes below {NEAR}</th><th class=l>vanishes when</th></tr>"
    );
    for (k, (label, _, what)) in named.iter().enumerate() {
        let value = |m: &Measured| m.factors.get(k).copied().unwrap_or(f64::INFINITY);
        let smallest = measured.iter().map(value).fold(f64::INFINITY, f64::min);
        let near: Vec<[f64; 2]> = measured.iter().filter(|m| value(m) < NEAR).map(on_plane).collect();
        let _ = writeln!(
            page,
            "<tr><td>{label}</td><td>{smallest:.3e}</td><td>{}</td><td class=l>{}</td></tr>",
            near.len(),
            html_escape(what)
        );
        if !near.is_empty() {
            series.push((label.clone(), near));
        }
    }
    page.html.push_str("</table>\n");
    let plane = match drawn {
        Drawn::Plane(plane) => plane,
        Drawn::Line(value) => {
            let of: Vec<(String, Box<Measure>)> = (0..named.len())
                .map(|k| {
                    (
                        named[k].0.clone(),
                        Box::new(move |m: &Measured| m.factors.get(k).copied().unwrap_or(f64::NAN)) as Box<Measure>,
                    )
                })
                .collect();
            let of: Vec<(String, &Measure)> = of.iter().map(|(n, f)| (n.clone(), f.as_ref())).collect();
            return against(
                page,
                "singularity_factors",
                "Determinant factors",
                value,
                measured,
                &of,
                &format!("Each determinant factor against {value}: 0 where it vanishes"),
            );
        }
    };
    if series.len() > 1 {
        let [x, y] = &plane.labels;
        page.scatter(
            "singularity_factors",
            &format!("Nodes where a determinant factor is below {NEAR}"),
            [x, y],
            &series,
            false,
            &format!("Near-vanishing factors, on {} (grey: every node measured)", plane.name),
        )?;
    }
    Ok(())
}
