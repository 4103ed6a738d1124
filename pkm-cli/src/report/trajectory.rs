//! The trajectory: the inputs along a sine or at constant speed, the
//! branch followed by continuity, the point's velocity and acceleration from
//! the differentiated loop equations, the driving forces and reactions where
//! the file has masses, and the mechanism's animation.

use super::follow::every_branch;
use super::html::{sign_text, tuple_text, Page};
use super::loaded::signs;
use super::{invalid, io, ReportError, Sampling};
use crate::drawing::{self, Scene};
use crate::plots;
use pkm_dsl::study::Motion;
use pkm_runtime::newton;
use pkm_runtime::velocity;
use pkm_runtime::workspace::Continuity;
use std::fmt::Write as _;

/// The trajectory: the point's velocity and acceleration along it, and the
/// mechanism's animation (inserted into the page at `animation_at`).
pub(super) fn trajectory(page: &mut Page, at: &Sampling, animation_at: usize) -> Result<(), ReportError> {
    const STEPS: usize = 500;
    const FRAMES: usize = 100;
    let (model, plan, s, point, unit) = (&at.l.model, at.plan, at.s, at.point, at.unit);
    let n = s.start.0.len();
    let continuity = Continuity::of(model);
    let (start, (motion, rates)) = (&s.start.0, (s.motion.0, &s.motion.1));
    let dt = s.duration.0 / STEPS as f64;
    let mut previous: Option<Vec<f64>> = None;
    let mut before_previous: Option<Vec<f64>> = None;
    let (mut ts, mut vel, mut acc) = (Vec::new(), vec![Vec::new(); 4], vec![Vec::new(); 4]);
    let mut frames: Vec<Scene> = Vec::new();
    let mut stopped = String::new();
    // The branch the followed assembly is on, and where it passes to another.
    let mut on = s.branch.0;
    let mut passes: Vec<String> = Vec::new();
    let mut dynamics = super::dynamics::Recorder::new(at.l)?;
    for k in 0..=STEPS {
        let t = k as f64 * dt;
        let w = std::f64::consts::PI;
        let (q, qd, qdd): (Vec<f64>, Vec<f64>, Vec<f64>) = match motion {
            Motion::Sine => (
                (0..n).map(|i| start[i] + rates[i] * (w * t).sin()).collect(),
                (0..n).map(|i| rates[i] * w * (w * t).cos()).collect(),
                (0..n).map(|i| -rates[i] * w * w * (w * t).sin()).collect(),
            ),
            Motion::ConstantSpeed => (
                (0..n).map(|i| start[i] + rates[i] * t).collect(),
                rates.clone(),
                vec![0.0; n],
            ),
        };
        // The first step on the followed branch; then the solution nearest
        // the last step's continuation, whichever branch it is.
        let chosen = match &previous {
            None => plan
                .solve(model, &q, &signs(plan.choices(), s.branch.0))
                .ok()
                .map(|v| (s.branch.0, v)),
            Some(p) => {
                let predicted = continuity.predict(p, before_previous.as_deref());
                let candidates = every_branch(at.l, plan, &q);
                continuity.nearest(&candidates, &predicted).cloned()
            }
        };
        let Some((branch, v)) = chosen else {
            stopped = format!(
                "; it stops at t = {t:.3} s, where no branch reaches q = {}",
                tuple_text(&q, 4)
            );
            break;
        };
        let a = match velocity::accelerations(model, &v, &qd, &qdd) {
            Ok(a) => a,
            Err(e) => {
                stopped = format!("; it stops at t = {t:.3} s: {e}");
                break;
            }
        };
        if let Some(d) = dynamics.as_mut() {
            d.record(model, t, &v, &qd, &qdd);
        }
        let poses = newton::link_poses(model, &v).map_err(|e| invalid(e.to_string()))?;
        let p = poses[point.0].transform_point(&point.1.into()).coords;
        let twist = a.velocities.twists[point.0];
        let pv = twist.at(&p);
        let pa = velocity::point_acceleration(&twist, &a.twists[point.0], &p);
        if k % (STEPS / FRAMES) == 0 {
            frames.push(drawing::scene(model, &poses, point));
        }
        ts.push(t);
        for i in 0..3 {
            vel[i].push(pv[i]);
            acc[i].push(pa[i]);
        }
        vel[3].push(pv.norm());
        acc[3].push(pa.norm());
        if branch != on {
            passes.push(format!(
                "from branch {on} ({}) to branch {branch} ({}) at t = {t:.3} s",
                sign_text(&signs(plan.choices(), on)),
                sign_text(&signs(plan.choices(), branch))
            ));
            on = branch;
        }
        before_previous = previous.replace(v);
    }
    let point_name = s.point.0.as_str();
    let law = match motion {
        Motion::Sine => format!("q(t) = {} + {}·sin(πt)", tuple_text(start, 4), tuple_text(rates, 4)),
        Motion::ConstantSpeed => format!("q(t) = {} + {}·t", tuple_text(start, 4), tuple_text(rates, 4)),
    };
    let _ = writeln!(
        page,
        "<h2>Velocity and acceleration of {point_name}</h2><p>Inputs {law}, 0 ≤ t ≤ {:.4} s, along the branch that \
         continues from branch {} ({} steps){stopped}; rates from the differentiated loop equations. {}</p>",
        s.duration.0,
        s.branch.0,
        ts.len(),
        if passes.is_empty() {
            "It stays on that branch throughout.".to_string()
        } else {
            format!(
                "The assembly passes {}: two roots of a step meet there, and the branches' signs swap which \
                 physical assembly they are.",
                passes.join("; ")
            )
        }
    );
    let components: &[usize] = if model.planar { &[0, 1, 3] } else { &[0, 1, 2, 3] };
    let names = ["x", "y", "z", "magnitude"];
    for (stem, title, axis, data) in [
        ("velocity", "Velocity", format!("v ({unit}/s)"), &vel),
        ("acceleration", "Acceleration", format!("a ({unit}/s²)"), &acc),
    ] {
        let series: Vec<(String, Vec<f64>)> = components
            .iter()
            .map(|&i| (names[i].to_string(), data[i].clone()))
            .collect();
        let f = plots::curves(
            &page.dir.join(stem),
            &format!("{title} of {point_name}"),
            ["t (s)", &axis],
            &ts,
            &series,
        )?;
        page.figure(&f, &format!("{title} of {point_name}: components and magnitude"));
    }
    if let Some(d) = dynamics {
        d.write(page, model, unit)?;
    }
    if frames.len() >= 2 {
        let path = page.dir.join("animation.svg");
        let played = ts.last().copied().unwrap_or(s.duration.0).max(1e-3);
        drawing::animation(&path, &frames, at.view, played, point_name)?;
        let svg = std::fs::read_to_string(&path).map_err(io(&path))?;
        let html = format!(
            "<figure>{svg}<figcaption>The mechanism along the trajectory, {} frames over {played:.2} s, repeated \
             (<a href=\"animation.svg\">SVG</a>)</figcaption></figure>\n",
            frames.len()
        );
        page.html.insert_str(animation_at, &html);
    }
    Ok(())
}
