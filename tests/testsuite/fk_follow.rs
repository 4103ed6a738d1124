//! Forward positions along trajectories of coupled mechanisms
//! (`pkm::runtime::fk_follow`): the assembly at each input is the previous
//! one's continuation, proven (tracked) or said not to be (resolved,
//! possible), never a silent jump. Checked against the trajectory's own
//! truth: the inputs are the inverse solution's at poses along a path, so
//! the assembly the mechanism is in is known at every step.

use crate::common;
use pkm::runtime::fk_follow::{self, FollowError, How};
use pkm::runtime::fk_numeric;
use pkm::runtime::kinematics;

/// The inverse solution's assembly at `pose` on the branch with `signs`.
fn truth(
    model: &pkm::runtime::model::Model,
    inverse: &pkm::runtime::plan::Plan,
    pose: &[f64],
    signs: &[pkm::runtime::primitives::Sign],
) -> Option<fk_follow::Followed> {
    (0..1usize << inverse.branches)
        .filter_map(|b| fk_follow::at_pose(model, inverse, pose, b).ok())
        .find(|s| s.signs == signs)
}

/// Along a path of poses of each spatial κ = 2 and κ = 4 example, the
/// slides the inverse solution gives are followed from the first pose's
/// assembly: each step's assembly is the path's to 1e-9 of the size (the
/// same assembly mode, no jump). Where the interval enclosure of the
/// inverse plan is tight enough (3-RPS, 3-PRS, 3-UPU) every step is
/// tracked, proven; where it is not (the 6-UPS: its Jacobian's enclosure
/// on a box 10⁻⁹ wide is 5·10⁻⁶ wide, twenty times the true variation;
/// the 3-SPR's 8·10⁻⁵), every step says possible, never tracked.
#[test]
fn spatial_trajectories_keep_their_assembly() {
    for (stem, angles, tracked) in [
        ("rps_3", vec![false, true, true], true),
        ("prs_3", vec![false, true, true], true),
        ("upu_3", vec![false, false, false], true),
        ("spr_3", vec![false, true, true], false),
        ("ups_6", vec![false, false, false, true, true, true], false),
    ] {
        let (text, path) = common::example_text(stem);
        let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
        let model = c.model().unwrap().clone();
        let inverse = c.inverse().unwrap().clone();
        let scale = kinematics::model_scale(&model);
        let pose = |t: f64| -> Vec<f64> {
            match angles.len() {
                6 => vec![
                    20.0 * t.sin(),
                    10.0 * t.cos(),
                    250.0 + 20.0 * t,
                    0.1 * t.sin(),
                    -0.1 * t,
                    0.2 * t,
                ],
                _ if stem == "upu_3" => vec![20.0 * t.sin(), 10.0 * t, 250.0 + 20.0 * t],
                _ => vec![300.0 + 20.0 * t, 0.1 * t.sin(), -0.1 * t],
            }
        };
        let mut previous = (0..1usize << inverse.branches)
            .find_map(|b| fk_follow::at_pose(&model, &inverse, &pose(0.0), b).ok())
            .unwrap_or_else(|| panic!("{stem}: no assembly at the path's start"));
        let inputs = model.inputs();
        // An unproven step tries every subdivision first (about 0.2 s for
        // the 6-UPS): fewer of them.
        let steps = if tracked { 40 } else { 8 };
        let (mut worst, mut proven) = (0.0f64, 0);
        for k in 1..=steps {
            let t = k as f64 / steps as f64;
            let want = truth(&model, &inverse, &pose(t), &previous.signs).unwrap();
            let q: Vec<f64> = inputs.iter().map(|&j| want.solution.values[j]).collect();
            let got = fk_follow::by_pose(&model, &inverse, &angles, &q, &previous)
                .unwrap_or_else(|e| panic!("{stem} at t = {t}: {e}"));
            let d = fk_follow::distance(&got.solution, &want.solution, scale);
            worst = worst.max(d);
            assert!(
                d <= 1e-9,
                "{stem} at t = {t}: {} off the path's assembly by {d:e}",
                got.how.text()
            );
            match got.how {
                How::Tracked => {
                    proven += 1;
                    for (x, c) in got.unknowns.iter().zip(&got.cert) {
                        assert!(c.contains(*x) && c.width() <= 1e-6 * scale, "{stem}: {c:?}");
                    }
                }
                How::Possible(_) => {}
                How::Resolved { .. } => panic!("{stem}: no full solution to resolve by"),
            }
            previous = got;
        }
        eprintln!("{stem}: {steps} steps, {proven} tracked and certified, off the path by {worst:e} of the size");
        assert_eq!(proven, if tracked { steps } else { 0 }, "{stem}");
    }
}

/// The six assemblies of the 3-RPR with six real ones, each followed as
/// the third leg shortens from 120 mm to 40 mm (where assemblies meet in
/// pairs and vanish): at every step the assembly reached is one the full
/// forward solution finds there; a tracked one is the full solution's
/// nearest to the previous (the same mode); where the followed assembly
/// vanishes, the step says so (resolved to the nearest survivor, or no
/// assembly), never tracked.
#[test]
fn planar_3rpr_six_followed_through_its_folds() {
    let (a, model) = common::example("planar_3rpr_six");
    let vp = pkm::dsl::planner_numeric::forward_numeric_plan(&a).unwrap();
    let scale = kinematics::model_scale(&model);
    let start = fk_numeric::solve(&model, &vp, &[149.8, 153.8, 120.0]).unwrap();
    assert_eq!(start.len(), 6);
    let steps = 20;
    let (mut tracked, mut resolved, mut lost) = (0, 0, 0);
    for first in start.iter() {
        let mut previous = fk_follow::Followed::from_assembly(first);
        for k in 1..=steps {
            let q = [149.8, 153.8, 120.0 - 80.0 * k as f64 / steps as f64];
            let all = fk_numeric::solve(&model, &vp, &q).unwrap();
            let next = match fk_follow::by_virtual(&model, &vp, &q, &previous) {
                Ok(n) => n,
                Err(FollowError::NoAssembly) => {
                    assert!(all.is_empty());
                    lost += 1;
                    break;
                }
                Err(e) => panic!("{q:?}: {e}"),
            };
            let near = |s: &pkm::runtime::plan::Solution| fk_follow::distance(s, &next.solution, scale);
            assert!(
                all.iter().any(|x| near(&x.solution) <= 1e-9),
                "{q:?}: {} is not an assembly",
                next.how.text()
            );
            match next.how {
                How::Tracked => {
                    tracked += 1;
                    let nearest =
                        all.iter()
                            .min_by(|x, y| {
                                fk_follow::distance(&x.solution, &previous.solution, scale)
                                    .total_cmp(&fk_follow::distance(&y.solution, &previous.solution, scale))
                            })
                            .unwrap();
                    assert!(near(&nearest.solution) <= 1e-9, "{q:?}: tracked, not the nearest");
                }
                How::Resolved { assemblies } => {
                    assert_eq!(assemblies, all.len());
                    resolved += 1;
                }
                How::Possible(_) => panic!("κ = 1 resolves, never says possible"),
            }
            previous = next;
        }
    }
    eprintln!("planar_3rpr_six: 6 × {steps} steps: {tracked} tracked, {resolved} resolved, {lost} lost");
    assert!(tracked > 0 && resolved + lost > 0, "{tracked} {resolved} {lost}");
}
