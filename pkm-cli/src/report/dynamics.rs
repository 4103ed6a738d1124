//! The trajectory's inverse dynamics, where the file declares its units and
//! masses: the actuators' forces and every joint's reaction along it by
//! Newton–Euler over the ordered SKCs, and the change points it passes.

use super::html::{html_escape, Page};
use super::loaded::Loaded;
use super::ReportError;
use crate::plots;
use pkm_runtime::mass_properties::Loading;
use pkm_runtime::model::{JointType, Model};
use pkm_runtime::newton_euler::{inverse_dynamics, DynamicsError, SkcParts};
use std::fmt::Write as _;

/// Below this an SKC's conditioning marks a step as next to a change point.
const NEAR_CHANGE_POINT: f64 = 1e-4;

/// What the trajectory records for the dynamics section.
pub(super) struct Recorder {
    loading: Loading,
    skcs: Vec<SkcParts>,
    t: Vec<f64>,
    /// Per step, the actuators' forces.
    actuators: Vec<Vec<f64>>,
    /// Per step, every joint's reaction force (NaN next to a change point).
    forces: Vec<Vec<[f64; 3]>>,
    /// The steps next to a change point: step, time, conditioning and why.
    change_points: Vec<(usize, f64, f64, String)>,
    /// The steps where Newton–Euler failed for another reason: how many, and the first's time and reason.
    failed: (usize, Option<(f64, String)>),
}

impl Recorder {
    /// A recorder, if the file declares its units and masses (gravity and
    /// loads then come with them); none where it declares units alone (for
    /// its length's name: the Delta's), an error where the masses do not
    /// make numbers.
    pub(super) fn new(l: &Loaded) -> Result<Option<Recorder>, ReportError> {
        let ml = &l.analysis.mass_and_loads;
        if ml.units.is_none() || (ml.masses.is_empty() && ml.massless.is_empty() && ml.bars.is_empty()) {
            return Ok(None);
        }
        let loading = pkm_dsl::numeric::loading(&l.analysis, &l.model, &l.values)
            .map_err(|d| super::invalid(d.0.first().map(|x| x.message.clone()).unwrap_or_default()))?;
        Ok(Some(Recorder {
            loading,
            skcs: pkm_dsl::numeric::skc_parts(&l.analysis),
            t: Vec::new(),
            actuators: Vec::new(),
            forces: Vec::new(),
            change_points: Vec::new(),
            failed: (0, None),
        }))
    }

    /// One step of the trajectory.
    pub(super) fn record(&mut self, model: &Model, t: f64, values: &[f64], qd: &[f64], qdd: &[f64]) {
        let n = model.joints.len();
        let nan = [f64::NAN; 3];
        match inverse_dynamics(model, &self.loading, &self.skcs, values, qd, qdd) {
            Ok(r) => {
                let near = r.conditioning.iter().position(|&c| c < NEAR_CHANGE_POINT);
                if let Some(k) = near {
                    let step = self.t.len();
                    self.change_points
                        .push((step, t, r.conditioning[k], format!("SKC {}", k + 1)));
                }
                self.actuators.push(r.actuators);
                self.forces.push(match near {
                    Some(_) => vec![nan; n],
                    None => r.joints.iter().map(|j| j.force).collect(),
                });
            }
            Err(e) => {
                if let DynamicsError::ForceSingular { skc, conditioning, .. } = e {
                    self.change_points
                        .push((self.t.len(), t, conditioning, format!("SKC {}", skc + 1)));
                } else {
                    self.failed.0 += 1;
                    self.failed.1.get_or_insert((t, e.to_string()));
                }
                self.actuators.push(vec![f64::NAN; model.inputs().len()]);
                self.forces.push(vec![nan; n]);
            }
        }
        self.t.push(t);
    }

    /// The section: the driving forces, then every joint's reaction.
    pub(super) fn write(self, page: &mut Page, model: &Model, unit: &str) -> Result<(), ReportError> {
        let steps = self.t.len();
        let marks = if self.change_points.is_empty() {
            "No step is next to a change point.".to_string()
        } else if self.change_points.len() == steps {
            let (_, _, c, skc) = &self.change_points[0];
            format!(
                "The force equations of {skc} are singular at every step (conditioning {c:.1e} at t = 0): not a \
                 change point of the motion but a freedom they cannot fix (such as a link between two spherical \
                 joints spinning about its own axis), so no force or reaction is drawn."
            )
        } else {
            // Runs of consecutive steps, each by its lowest conditioning.
            let mut runs: Vec<Vec<&(usize, f64, f64, String)>> = Vec::new();
            for c in &self.change_points {
                match runs.last_mut() {
                    Some(run) if run.last().is_some_and(|p| p.0 + 1 == c.0) => run.push(c),
                    _ => runs.push(vec![c]),
                }
            }
            let list: Vec<String> = runs
                .iter()
                .map(|run| {
                    let low = run
                        .iter()
                        .min_by(|a, b| a.2.total_cmp(&b.2))
                        .expect("a run is not empty");
                    let (first, last) = (run[0].1, run[run.len() - 1].1);
                    format!(
                        "t = {first:.3}–{last:.3} s ({}, conditioning down to {:.1e} at t = {:.3} s)",
                        low.3, low.2, low.1
                    )
                })
                .collect();
            format!(
                "Next to a change point (an SKC's force equations nearly singular; reactions there grow without \
                 bound and are left out of the curves): {}.",
                list.join("; ")
            )
        };
        let failed = match &self.failed {
            (0, _) => String::new(),
            (k, Some((t, why))) => format!(
                " Newton–Euler gives no answer at {k} of the {} steps (left out of the curves), the first at t = \
                 {t:.3} s: {why}.",
                self.t.len()
            ),
            (k, None) => format!(" Newton–Euler gives no answer at {k} steps."),
        };
        let _ = writeln!(
            page,
            "<h2>Driving forces and joint reactions</h2><p>Newton–Euler over the ordered SKCs along the same \
             trajectory, with the file's masses, gravity and loads. Forces in N, torques in N·{unit}. A joint's \
             reaction is the force its first link exerts on its second, base axes. {marks}{}</p>",
            html_escape(&failed)
        );
        if self.failed.0 + self.change_points.len() >= steps && self.actuators.iter().flatten().all(|a| !a.is_finite())
        {
            return Ok(());
        }
        // One chart per unit: the slides' forces in N, the turns' torques in N·length unit.
        let inputs = model.inputs();
        let torque = format!("N·{unit}");
        for (stem, title, axis, slides) in [
            ("driving_forces", "Driving forces", "N", true),
            ("driving_torques", "Driving torques", torque.as_str(), false),
        ] {
            let series: Vec<(String, Vec<f64>)> = inputs
                .iter()
                .enumerate()
                .filter(|(_, &j)| (model.joints[j].kind == JointType::P) == slides)
                .map(|(k, &j)| {
                    (
                        model.joints[j].name.clone(),
                        self.actuators.iter().map(|a| a[k]).collect(),
                    )
                })
                .collect();
            if series.iter().all(|(_, v)| v.iter().all(|x| !x.is_finite())) {
                continue;
            }
            let f = plots::curves(
                &page.dir.join(stem),
                title,
                [
                    "t (s)",
                    &format!("{} ({axis})", if slides { "force" } else { "torque" }),
                ],
                &self.t,
                &series,
            )?;
            page.figure(
                &f,
                &if slides {
                    "The slide actuators' forces (N)".to_string()
                } else {
                    format!("The turning actuators' torques (N·{unit})")
                },
            );
        }
        let components: &[(usize, &str)] = if model.planar {
            &[(0, "x"), (1, "y")]
        } else {
            &[(0, "x"), (1, "y"), (2, "z")]
        };
        let mut without = Vec::new();
        for (j, joint) in model.joints.iter().enumerate() {
            if self.forces.iter().all(|f| f[j].iter().all(|x| !x.is_finite())) {
                without.push(joint.name.as_str());
                continue;
            }
            let series: Vec<(String, Vec<f64>)> = components
                .iter()
                .map(|&(c, name)| (format!("R{name}"), self.forces.iter().map(|f| f[j][c]).collect()))
                .collect();
            let (by, on) = (&model.links[joint.links[0]], &model.links[joint.links[1]]);
            let f = plots::curves(
                &page.dir.join(format!("reaction_{}", joint.name.replace('.', "_"))),
                &format!("Reaction at {}", joint.name),
                ["t (s)", "force (N)"],
                &self.t,
                &series,
            )?;
            page.figure(
                &f,
                &format!("Joint {}: the force link {by} exerts on link {on}", joint.name),
            );
        }
        if !without.is_empty() {
            let _ = writeln!(
                page,
                "<p>No step gives a reaction at {} (every step next to a change point or without an answer): not \
                 drawn.</p>",
                html_escape(&without.join(", "))
            );
        }
        Ok(())
    }
}
