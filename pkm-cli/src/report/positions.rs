//! The mechanism at the sample input: its drawing, every branch's position
//! solution with its singularity measures, and the determinant factors on
//! the followed branch.

use super::html::{class_text, html_escape, sign_text, tuple_text, Page};
use super::loaded::{output_columns, pose_outputs, signs};
use super::{invalid, ReportError, Sampling};
use crate::drawing;
use pkm_runtime::newton;
use pkm_runtime::plan::Pose3;
use pkm_runtime::velocity;
use std::fmt::Write as _;

/// The drawing of the mechanism at the sample input on the followed branch;
/// returns its link poses.
pub(super) fn sample_drawing(page: &mut Page, at: &Sampling) -> Result<Vec<Pose3>, ReportError> {
    let (model, s) = (&at.l.model, at.s);
    let start = &s.start.0;
    let sample_poses = newton::link_poses(model, &at.sample).map_err(|e| invalid(e.to_string()))?;
    let scene = drawing::scene(model, &sample_poses, at.point);
    let f = drawing::draw(
        &page.dir.join("mechanism"),
        &format!("{} at q = {}, branch {}", model.name, tuple_text(start, 3), s.branch.0),
        &scene,
        at.view,
        at.unit,
        &s.point.0,
    )?;
    let _ = writeln!(page, "<h2>The mechanism at the sample input</h2>");
    page.figure(
        &f,
        &format!(
            "Links as lines between their joints (a link with three or more joints filled), joints by type, the base \
             hatched; {}",
            if model.planar {
                "in the mechanism's plane"
            } else {
                "an axonometric view (azimuth 35°, elevation 25°)"
            }
        ),
    );
    Ok(sample_poses)
}

/// Every branch's position solution at the sample input: the point, the
/// declared outputs, σ_in, σ_out and the singularity class.
pub(super) fn solutions(page: &mut Page, at: &Sampling) -> Result<(), ReportError> {
    let (l, s, unit) = (at.l, at.s, at.unit);
    let (model, outputs) = (&l.model, &l.outputs);
    let (plink, plocal) = at.point;
    let point_name = s.point.0.as_str();
    let start = &s.start.0;
    let choices = at.plan.choices();
    let columns = output_columns(l, unit);
    let point_axes = if model.planar { "x, y" } else { "x, y, z" };
    let _ = writeln!(
        page,
        "<h2>Position solutions at q = {}</h2><p>Every branch of the closed-form forward solution. σ_in and σ_out are \
         the relative smallest singular values of the velocity equations (0 at an input or output singularity){}.</p>\
         <table><tr><th>branch</th><th>signs</th><th>{point_name} ({point_axes}) ({unit})</th>{}<th>σ_in</th><th>σ_out</th>\
         <th class=l>class</th></tr>",
        tuple_text(start, 4),
        if outputs.is_empty() { "; they need declared outputs, and this file has none" } else { "" },
        columns.iter().map(|c| format!("<th>{}</th>", html_escape(c))).collect::<String>()
    );
    for b in 0..1usize << choices {
        let sg = signs(choices, b);
        let label = sign_text(&sg);
        let mark = if b == s.branch.0 { " (followed)" } else { "" };
        match at.plan.solve(model, start, &sg) {
            Ok(v) => {
                let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
                let p = poses[plink].transform_point(&plocal.into());
                let p = if model.planar {
                    vec![p.x, p.y]
                } else {
                    vec![p.x, p.y, p.z]
                };
                let outs = pose_outputs(model, &poses, outputs);
                let (si, so, class) = if outputs.is_empty() {
                    ("—".to_string(), "—".to_string(), "— (no outputs)".to_string())
                } else {
                    sigma_cells(model, &v, outputs)
                };
                let _ = writeln!(
                    page,
                    "<tr><td>{b}{mark}</td><td>{label}</td><td>{}</td>{}<td>{si}</td><td>{so}</td><td class=l>{}</td></tr>",
                    tuple_text(&p, 4),
                    outs.iter().map(|x| format!("<td>{x:.6}</td>")).collect::<String>(),
                    html_escape(&class)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    page,
                    "<tr><td>{b}</td><td>{label}</td><td colspan={} class=l>no solution: {}</td></tr>",
                    4 + columns.len(),
                    html_escape(&e.to_string())
                );
            }
        }
    }
    page.html.push_str("</table>\n");
    Ok(())
}

/// The determinants' factors on the followed branch at the sample: `named`
/// as [`super::singularities::named_factors`] gives them.
pub(super) fn factors(page: &mut Page, at: &Sampling, named: &[(String, f64, String)]) {
    if named.is_empty() {
        return;
    }
    let _ = writeln!(
        page,
        "<h3>Determinant factors on branch {} ({})</h3><p>Each step of a closed-form plan solves one joint from \
         one scalar equation; in the plan's order the velocity equations are triangular and each determinant is \
         the product of the steps' derivatives. A factor is a step's derivative normalised to [0, 1] (the sine \
         of the angle at which a point's path meets the surface it must reach): 0 is a singularity, and the \
         condition says where. The forward plan's factors are det J_o's (output singularities), the inverse \
         plan's det J_i's (input singularities).</p><table><tr><th>factor</th><th>value (1)</th>\
         <th class=l>vanishes when</th></tr>",
        at.s.branch.0,
        sign_text(&at.branch_signs)
    );
    for (label, value, what) in named {
        let _ = writeln!(
            page,
            "<tr><td>{label}</td><td>{value:.4}</td><td class=l>{}</td></tr>",
            html_escape(what)
        );
    }
    page.html.push_str("</table>\n");
}

/// A branch table's σ_in, σ_out and class cells at joint values `v`, or
/// dashes and why the velocity equations give none.
pub(super) fn sigma_cells(
    model: &pkm_runtime::model::Model,
    v: &[f64],
    outputs: &[pkm_runtime::newton::Output],
) -> (String, String, String) {
    match velocity::jacobians(model, v, outputs) {
        Ok(j) => (
            format!("{:.3e}", j.input_sigma),
            format!("{:.3e}", j.output_sigma),
            class_text(j.singularity).to_string(),
        ),
        Err(e) => ("—".into(), "—".into(), e.to_string()),
    }
}
