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

/// The declared outputs at `t` ∈ [0, 1] along the test paths of the
/// spatial coupled examples: the 6-UPS's six pose values, the 3-UPU's
/// point, the others' height and two tilts.
pub(crate) fn path_pose(stem: &str, t: f64) -> Vec<f64> {
    match stem {
        "ups_6" => vec![
            20.0 * t.sin(),
            10.0 * t.cos(),
            250.0 + 20.0 * t,
            0.1 * t.sin(),
            -0.1 * t,
            0.2 * t,
        ],
        "upu_3" => vec![20.0 * t.sin(), 10.0 * t, 250.0 + 20.0 * t],
        _ => vec![300.0 + 20.0 * t, 0.1 * t.sin(), -0.1 * t],
    }
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
        let pose = |t: f64| path_pose(stem, t);
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

/// The platform's point where three spheres (centre `c[k]`, radius `r[k]`)
/// meet, by hand (trilateration in the frame the first two centres and
/// the third span): both roots, `None` where they do not meet.
fn three_spheres(c: [[f64; 3]; 3], r: [f64; 3]) -> Option<[[f64; 3]; 2]> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let unit = |a: [f64; 3]| {
        let n = dot(a, a).sqrt();
        [a[0] / n, a[1] / n, a[2] / n]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (u, w) = (sub(c[1], c[0]), sub(c[2], c[0]));
    let d = dot(u, u).sqrt();
    let ex = unit(u);
    let i = dot(ex, w);
    let ey = unit([w[0] - i * ex[0], w[1] - i * ex[1], w[2] - i * ex[2]]);
    let ez = cross(ex, ey);
    let j = dot(ey, w);
    let x = (r[0] * r[0] - r[1] * r[1] + d * d) / (2.0 * d);
    let y = (r[0] * r[0] - r[2] * r[2] + i * i + j * j) / (2.0 * j) - i * x / j;
    let z2 = r[0] * r[0] - x * x - y * y;
    (z2 >= 0.0).then(|| {
        [1.0, -1.0].map(|s| {
            let z = s * z2.sqrt();
            std::array::from_fn(|k| c[0][k] + x * ex[k] + y * ey[k] + z * ez[k])
        })
    })
}

/// The two robots whose forward problem is three spheres, the Delta-type
/// 3-RUU (κ = 2) and the Orthoglide-type 3-PRPaR (κ = 1), followed by
/// the inverse plan's pose (`by_pose_or_forward`: an unproven step is
/// resolved by their closed-form forward plan) along a path of poses from
/// the working assembly (the Delta's elbows out, the Orthoglide's
/// carriages on the negative side of their axes). At every step the
/// platform's point is one of the two where the three spheres meet, by
/// hand: the Orthoglide's about (P1 + e, 0, h), (h, P2 + e, 0),
/// (0, h, P3 + e), radius m; the Delta's about each elbow less the
/// wrist's offset on the platform, radius l2, each elbow checked by hand
/// on its arm's circle (l1 from the base joint, in the plane normal to
/// the axis); and always the same of the two (the side of the centres'
/// plane the start is on), the path's own pose to 1e-9 of the size.
#[test]
fn three_sphere_robots_keep_their_assembly() {
    let deg = |d: f64| d.to_radians();
    for stem in ["delta_3ruu", "orthoglide"] {
        let (text, path) = common::example_text(stem);
        let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
        let model = c.model().unwrap().clone();
        let inverse = c.inverse().unwrap().clone();
        let forward = c.forward().unwrap().clone();
        let scale = kinematics::model_scale(&model);
        let joint = |name: &str| model.joints.iter().position(|j| j.name == name).unwrap();
        let pose = |t: f64| -> Vec<f64> {
            // The Orthoglide's path keeps off the slides' axes, where a
            // leg's parallelogram lies along its revolutes (their angle
            // undetermined: the inverse solution says degenerate).
            let (a, c) = if stem == "delta_3ruu" {
                (60.0, [0.0, 0.0, -420.0])
            } else {
                (40.0, [30.0, -25.0, -60.0])
            };
            vec![
                c[0] + a * (2.0 * std::f64::consts::PI * t).sin(),
                c[1] + a * (2.0 * std::f64::consts::PI * t).cos() - a,
                c[2] + 0.5 * a * (4.0 * std::f64::consts::PI * t).sin(),
            ]
        };
        // The spheres at an assembly, by hand from the inputs (and, for
        // the Delta, the elbows, each checked on its arm's circle).
        let spheres = |s: &pkm::runtime::plan::Solution| -> ([[f64; 3]; 3], [f64; 3]) {
            if stem == "orthoglide" {
                let (m, e, h) = (300.0, 40.0, 30.0);
                let p = ["P1", "P2", "P3"].map(|n| s.values[joint(n)] + e);
                ([[p[0], 0.0, h], [h, p[1], 0.0], [0.0, h, p[2]]], [m; 3])
            } else {
                let (a, b, l1, l2) = (200.0, 50.0, 200.0, 450.0);
                let at = [0.0, 120.0, 240.0].map(deg);
                let centres = std::array::from_fn(|k| {
                    let elbow = kinematics::joint_point(&model, &s.poses, joint(["U11.a", "U21.a", "U31.a"][k]));
                    let base = [a * at[k].cos(), a * at[k].sin(), 0.0];
                    let axis = [-at[k].sin(), at[k].cos(), 0.0];
                    let arm: [f64; 3] = std::array::from_fn(|i| elbow[i] - base[i]);
                    let along: f64 = (0..3).map(|i| arm[i] * axis[i]).sum();
                    let length = arm.iter().map(|v| v * v).sum::<f64>().sqrt();
                    assert!(
                        along.abs() <= 1e-9 * scale && (length - l1).abs() <= 1e-9 * scale,
                        "{stem}: elbow {k}"
                    );
                    [elbow[0] - b * at[k].cos(), elbow[1] - b * at[k].sin(), elbow[2]]
                });
                (centres, [l2; 3])
            }
        };
        // The side of the centres' plane a point is on.
        let side = |c: [[f64; 3]; 3], o: [f64; 3]| {
            let (u, w, p): ([f64; 3], [f64; 3], [f64; 3]) = (
                std::array::from_fn(|i| c[1][i] - c[0][i]),
                std::array::from_fn(|i| c[2][i] - c[0][i]),
                std::array::from_fn(|i| o[i] - c[0][i]),
            );
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]).signum()
        };
        let platform = c
            .analysis
            .mechanism
            .links
            .iter()
            .position(|l| l.name == "platform")
            .unwrap();
        let point = |s: &pkm::runtime::plan::Solution| -> [f64; 3] {
            let t = s.poses[platform].translation.vector;
            [t[0], t[1], t[2]]
        };
        let working = |s: &fk_follow::Followed| {
            let q: Vec<f64> = model.inputs().iter().map(|&j| s.solution.values[j]).collect();
            if stem == "orthoglide" {
                q.iter().all(|&p| p < 0.0)
            } else {
                (0..3).all(|k| {
                    let e = kinematics::joint_point(&model, &s.solution.poses, joint(["U11.a", "U21.a", "U31.a"][k]));
                    e[0].hypot(e[1]) > 200.0
                })
            }
        };
        let mut previous = (0..1usize << inverse.branches)
            .filter_map(|b| fk_follow::at_pose(&model, &inverse, &pose(0.0), b).ok())
            .find(working)
            .unwrap_or_else(|| panic!("{stem}: no working assembly at the path's start"));
        let (c0, _) = spheres(&previous.solution);
        let start_side = side(c0, point(&previous.solution));
        let inputs = model.inputs();
        let steps = 40;
        let (mut tracked, mut worst) = (0, 0.0f64);
        for k in 1..=steps {
            let t = k as f64 / steps as f64;
            let want = truth(&model, &inverse, &pose(t), &previous.signs).unwrap();
            let q: Vec<f64> = inputs.iter().map(|&j| want.solution.values[j]).collect();
            let got = fk_follow::by_pose_or_forward(&model, &inverse, &forward, &[false; 3], &q, &previous)
                .unwrap_or_else(|e| panic!("{stem} at t = {t}: {e}"));
            // The path's pose, and every link where it was a step before
            // (no leg turned over: the Orthoglide's path crosses the line
            // where its inverse plan's label for a leg's two
            // configurations flips, at t = 0.5).
            let off_path = got
                .unknowns
                .iter()
                .zip(pose(t))
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                off_path <= 1e-9 * scale,
                "{stem} at t = {t}: off the path by {off_path:e}"
            );
            let moved = fk_follow::distance(&got.solution, &previous.solution, scale);
            assert!(moved <= 1.0, "{stem} at t = {t}: a link turned by {moved}");
            let (centres, radii) = spheres(&got.solution);
            let roots = three_spheres(centres, radii).unwrap_or_else(|| panic!("{stem} at t = {t}: no meeting"));
            let o = point(&got.solution);
            let off = roots.map(|r| (0..3).map(|i| (r[i] - o[i]).abs()).fold(0.0, f64::max));
            let near = if off[0] < off[1] { 0 } else { 1 };
            worst = worst.max(off[near]);
            assert!(
                off[near] <= 1e-9 * scale,
                "{stem} at t = {t}: {o:?} is not where the spheres meet: {roots:?}"
            );
            assert_eq!(side(centres, o), start_side, "{stem} at t = {t}: the other assembly");
            assert!(
                off[1 - near] >= 1e-3 * scale,
                "{stem} at t = {t}: the two assemblies meet"
            );
            // Never left unproven: tracked, or resolved by the closed-form
            // forward solution (three spheres) as the nearest assembly.
            assert!(
                matches!(got.how, How::Tracked | How::Resolved { .. }),
                "{stem} at t = {t}: {}",
                got.how.text()
            );
            tracked += usize::from(got.how == How::Tracked);
            previous = got;
        }
        eprintln!(
            "{stem}: {steps} steps, {tracked} tracked and certified, the rest resolved by the forward solution, \
             within {worst:e} mm of the spheres' meeting"
        );
        assert!(tracked >= steps / 2, "{stem}: {tracked}");
    }
}

/// The generated `fk`'s joint values on each branch of `$ty` (three
/// inputs), `None` where the branch has no solution.
macro_rules! joint_values {
    ($ty:ident) => {
        |q: &[f64]| -> Vec<Option<Vec<f64>>> {
            $ty::fk(&Default::default(), &[q[0], q[1], q[2]])
                .iter()
                .map(|b| b.result.as_ref().ok().map(|s| s.q.to_vec()))
                .collect()
        }
    };
}

/// A translating platform's forward plan by three spheres
/// (`Step::Trilaterate`), closed form although κ ≠ 0, for `stem`: at 300
/// inputs the inverse solution produces from random poses (`pose`, on an
/// inverse branch `working` accepts), every branch that runs verifies, its
/// platform's point `o` is one of the two points where the spheres that
/// `spheres` works out by hand meet, both points are found, and the
/// generated code (`generated`: each branch's joint values, or `None`)
/// gives the interpreter's joint values on every branch: the platform
/// within 10⁻¹⁴ of the mechanism's size, the joint values equal.
fn three_spheres_forward(
    stem: &str,
    pose: impl Fn(&mut pkm::runtime::random::SplitMix) -> [f64; 3],
    working: impl Fn(&pkm::runtime::model::Model, &fk_follow::Followed) -> bool,
    spheres: impl Fn(&pkm::runtime::model::Model, &[f64], &pkm::runtime::plan::Solution) -> ([[f64; 3]; 3], [f64; 3]),
    generated: impl Fn(&[f64]) -> Vec<Option<Vec<f64>>>,
) {
    let (text, path) = common::example_text(stem);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = c.model().unwrap().clone();
    let (forward, inverse) = (c.forward().unwrap().clone(), c.inverse().unwrap().clone());
    let scale = kinematics::model_scale(&model);
    let platform = model.links.iter().position(|l| l == "platform").unwrap();
    let mut rng = pkm::runtime::random::SplitMix::new(0x0de1_7a00);
    let (mut inputs_checked, mut worst, mut generated_worst) = (0, 0.0f64, 0.0f64);
    while inputs_checked < 300 {
        let p = pose(&mut rng);
        let Some(start) = (0..1usize << inverse.branches)
            .filter_map(|k| fk_follow::at_pose(&model, &inverse, &p, k).ok())
            .find(|s| working(&model, s))
        else {
            continue;
        };
        inputs_checked += 1;
        let q: Vec<f64> = model.inputs().iter().map(|&j| start.solution.values[j]).collect();
        let (centres, radii) = spheres(&model, &q, &start.solution);
        let roots = three_spheres(centres, radii).unwrap_or_else(|| panic!("{stem} {p:?}: the spheres do not meet"));
        let mut found = [false; 2];
        let by_code = generated(&q);
        for (k, (_, solved)) in
            pkm::runtime::solution::every_branch(forward.branches, |s| pkm::runtime::plan::run(&model, &forward, &q, s))
                .into_iter()
                .enumerate()
        {
            let Ok(s) = solved else {
                assert!(
                    by_code[k].is_none(),
                    "{stem} {p:?} branch {k}: generated ok, interpreter not"
                );
                continue;
            };
            let t = s.poses[platform].translation.vector;
            let off = roots.map(|r| (0..3).map(|i| (r[i] - t[i]).abs()).fold(0.0, f64::max));
            let near = usize::from(off[1] < off[0]);
            assert!(
                off[near] <= 1e-9 * scale,
                "{stem} {p:?} branch {k}: platform {t:?} off {off:?}"
            );
            worst = worst.max(off[near]);
            found[near] = true;
            let g = by_code[k]
                .as_ref()
                .unwrap_or_else(|| panic!("{stem} {p:?} branch {k}: interpreter ok, generated not"));
            for (j, (&x, &y)) in g.iter().zip(&s.values).enumerate() {
                if x.is_finite() || y.is_finite() {
                    let d = pkm::runtime::solution::wrap_angle(x - y).abs();
                    assert!(
                        d <= 1e-9,
                        "{stem} {p:?} branch {k} joint {j}: generated {x}, interpreted {y}"
                    );
                    generated_worst = generated_worst.max(d);
                }
            }
        }
        assert!(
            found[0] && found[1],
            "{stem} {p:?}: the spheres' points {roots:?}, found {found:?}"
        );
    }
    eprintln!(
        "{stem}: forward plan at {inputs_checked} inputs: both meeting points found, the platform within {worst:e} \
         of the hand solution; generated against interpreted joint values within {generated_worst:e}"
    );
    assert!(
        worst <= 1e-14 * scale && generated_worst == 0.0,
        "{worst:e} {generated_worst:e}"
    );
}

/// The Delta's forward plan, closed form although κ = 2: the platform on
/// the three spheres, each about an elbow (checked on its arm's circle by
/// hand) less the wrist's offset, of the rod's length; then each forearm
/// between its centres (16 branches).
#[test]
fn the_delta_forward_plan_is_its_three_spheres() {
    use crate::mechanisms::Delta;
    let (a, b, l1, l2) = (200.0f64, 50.0, 200.0, 450.0);
    let at = [0.0f64, 120.0, 240.0].map(f64::to_radians);
    let elbow = |model: &pkm::runtime::model::Model, s: &pkm::runtime::plan::Solution, k: usize| {
        let j = model
            .joints
            .iter()
            .position(|j| j.name == ["U11.a", "U21.a", "U31.a"][k])
            .unwrap();
        kinematics::joint_point(model, &s.poses, j)
    };
    three_spheres_forward(
        "delta_3ruu",
        |rng| {
            [
                150.0 * rng.symmetric(),
                150.0 * rng.symmetric(),
                -420.0 + 120.0 * rng.symmetric(),
            ]
        },
        |model, s| (0..3).all(|k| elbow(model, &s.solution, k)[0].hypot(elbow(model, &s.solution, k)[1]) > a),
        |model, _, s| {
            let centres = std::array::from_fn(|k| {
                let e = elbow(model, s, k);
                let base = [a * at[k].cos(), a * at[k].sin(), 0.0];
                let axis = [-at[k].sin(), at[k].cos(), 0.0];
                let arm: [f64; 3] = std::array::from_fn(|i| e[i] - base[i]);
                let along: f64 = (0..3).map(|i| arm[i] * axis[i]).sum();
                let length = arm.iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!(along.abs() <= 1e-9 && (length - l1).abs() <= 1e-9, "elbow {k}");
                [e[0] - b * at[k].cos(), e[1] - b * at[k].sin(), e[2]]
            });
            (centres, [l2; 3])
        },
        joint_values!(Delta),
    );
}

/// The 3-UPU's (κ = 2): each sphere about a base U's centre less the
/// platform U's offset, of radius the leg's slide, by hand from the inputs
/// alone; two platform positions mirrored through the base's plane.
#[test]
fn the_3upu_forward_plan_is_its_three_spheres() {
    use crate::mechanisms::Upu;
    let (a, b) = (200.0f64, 100.0);
    let at = [0.0f64, 120.0, 240.0].map(f64::to_radians);
    three_spheres_forward(
        "upu_3",
        |rng| {
            [
                60.0 * rng.symmetric(),
                60.0 * rng.symmetric(),
                250.0 + 50.0 * rng.symmetric(),
            ]
        },
        |model, s| model.inputs().iter().all(|&j| s.solution.values[j] > 0.0),
        |_, q, _| {
            let centres = std::array::from_fn(|k| [(a - b) * at[k].cos(), (a - b) * at[k].sin(), 0.0]);
            (centres, [q[0].abs(), q[1].abs(), q[2].abs()])
        },
        joint_values!(Upu),
    );
}

/// The Orthoglide's (κ = 1): each sphere about the carriage's hinge moved
/// by the platform hinge's offset, (P1 + e, 0, h), (h, P2 + e, 0),
/// (0, h, P3 + e), of radius the parallelogram's arm m, by hand from the
/// inputs alone.
#[test]
fn the_orthoglide_forward_plan_is_its_three_spheres() {
    use crate::mechanisms::Orthoglide;
    let (m, e, h) = (300.0, 40.0, 30.0);
    three_spheres_forward(
        "orthoglide",
        |rng| {
            [
                30.0 + 40.0 * rng.symmetric(),
                -25.0 + 40.0 * rng.symmetric(),
                -60.0 + 40.0 * rng.symmetric(),
            ]
        },
        |model, s| model.inputs().iter().all(|&j| s.solution.values[j] < 0.0),
        |_, q, _| ([[q[0] + e, 0.0, h], [h, q[1] + e, 0.0], [0.0, h, q[2] + e]], [m; 3]),
        joint_values!(Orthoglide),
    );
}
