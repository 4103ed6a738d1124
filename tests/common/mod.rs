//! Helpers shared by integration tests (each test file uses part of them).
//! The root package's tests declare it as `mod common;`, pkm-cli's include
//! this same file by `#[path]`.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The workspace's root, where `README.md` and `examples/` are: the
/// including package's directory or the nearest one above it that holds
/// `examples/mechanisms` (pkm-cli's tests run in `pkm-cli/`).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .find(|d| d.join("examples/mechanisms").is_dir())
        .expect("examples/mechanisms in the package's directory or above it")
}

/// The path of an example mechanism of `examples/mechanisms/` by its file
/// stem, or of any mechanism file by its path from the root (`….pkm`: a
/// fixture).
pub fn example_path(stem: &str) -> PathBuf {
    if stem.ends_with(".pkm") {
        return root().join(stem);
    }
    root().join(format!("examples/mechanisms/{stem}.pkm"))
}

/// An example mechanism's text and its path as text (the name its errors show).
pub fn example_text(stem: &str) -> (String, String) {
    let path = example_path(stem).display().to_string();
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    (text, path)
}

/// An example mechanism's text with `extra` statements added inside its
/// `mechanism { … }` (masses, loads: what a test declares on top of it).
/// Where `extra` declares `units`, `masses`, `gravity` or `loads`, the
/// example's own statement of that kind is left out: the test's replaces it.
pub fn example_with(stem: &str, extra: &str) -> String {
    let (mut text, path) = example_text(stem);
    for keyword in ["units", "masses", "gravity", "loads"] {
        if declares(extra, keyword) {
            text = without_statement(&text, keyword);
        }
    }
    let end = text.rfind('}').unwrap_or_else(|| panic!("{path}: no closing brace"));
    format!("{}{extra}\n}}\n", &text[..end])
}

/// Whether a line of `text` starts with the statement `keyword`.
fn declares(text: &str, keyword: &str) -> bool {
    statement_start(text, keyword).is_some()
}

/// Where a line's statement `keyword` (followed by a space, `{` or `(`) begins.
fn statement_start(text: &str, keyword: &str) -> Option<usize> {
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix(keyword) {
            if rest.starts_with([' ', '{', '(']) {
                return Some(at + line.len() - trimmed.len());
            }
        }
        at += line.len();
    }
    None
}

/// `text` without its statement `keyword`: a `{ … }` block (braces
/// matched) or, for `gravity`, up to its `;`.
fn without_statement(text: &str, keyword: &str) -> String {
    let Some(start) = statement_start(text, keyword) else {
        return text.to_string();
    };
    let mut depth = 0;
    let mut end = text.len();
    for (i, c) in text[start..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    end = start + i + 1;
                    break;
                }
            }
            ';' if depth == 0 => {
                end = start + i + 1;
                break;
            }
            _ => {}
        }
    }
    format!("{}{}", &text[..start], &text[end..])
}

/// An example mechanism of `examples/mechanisms/` by its file stem: its
/// analysis and its model at the nominal parameters.
pub fn example(stem: &str) -> (pkm::dsl::Analysis, pkm::runtime::model::Model) {
    let (text, path) = example_text(stem);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{path}: {}", d.render(&text, &path)));
    let model = c
        .model()
        .cloned()
        .unwrap_or_else(|d| panic!("{path}: {}", d.render(&text, &path)));
    (c.analysis, model)
}

/// A mechanism whose legs each end in a ball (`pkm::runtime::ball_legs`),
/// compiled at its nominal parameters.
pub struct BallLegged {
    pub model: pkm::runtime::model::Model,
    pub inverse: pkm::runtime::plan::Plan,
    pub outputs: Vec<pkm::runtime::newton::Output>,
    pub legs: pkm::runtime::ball_legs::BallLegs,
}

/// The example `stem` (or fixture, [`example_path`]) as a [`BallLegged`].
pub fn ball_legged(stem: &str) -> BallLegged {
    let (text, path) = example_text(stem);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = c.model().unwrap().clone();
    let outputs = c.outputs().unwrap().to_vec();
    let legs =
        pkm::runtime::ball_legs::BallLegs::for_outputs(&model, &outputs).unwrap_or_else(|why| panic!("{stem}: {why}"));
    BallLegged {
        inverse: c.inverse().unwrap().clone(),
        model,
        outputs,
        legs,
    }
}

/// The largest difference of `a` from `b`: angles (where `angle` says so)
/// modulo 2π, in radians; lengths relative to `scale`.
pub fn max_error(a: &[f64], b: &[f64], angle: &[bool], scale: f64) -> f64 {
    a.iter()
        .zip(b)
        .zip(angle)
        .map(|((a, b), &angle)| {
            if angle {
                pkm::runtime::solution::wrap_angle(a - b).abs()
            } else {
                (a - b).abs() / scale
            }
        })
        .fold(0.0, f64::max)
}

/// How far a solution's joint values are from closing the mechanism and
/// reproducing the given pose, by the Newton reference's own model (joint
/// transforms along a spanning tree; the generated code's kernels play no
/// part): the largest loop-closure mismatch and output difference, lengths
/// over `extent`, angles in radians.
pub fn inconsistency(
    model: &pkm::runtime::model::Model,
    q: &[f64],
    point: &str,
    axis: [f64; 3],
    given: &[f64; 4],
    extent: f64,
) -> f64 {
    use pkm::runtime::newton;
    let closure = newton::loop_residual(model, q)
        .unwrap()
        .chunks(6)
        .flat_map(|r| [r[0] / extent, r[1] / extent, r[2] / extent, r[3], r[4], r[5]])
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let poses = newton::link_poses(model, q).unwrap();
    let at = newton::point(model, &poses, point).unwrap();
    let link = model.points.iter().find(|p| p.name == point).unwrap().link;
    let angle = pkm::runtime::plan::angle_about(&poses[link], axis);
    let output = (0..3)
        .map(|i| (at[i] - given[i]).abs() / extent)
        .fold(pkm::runtime::solution::wrap_angle(angle - given[3]).abs(), f64::max);
    closure.max(output)
}

/// A reachable pose `(x, y, z, alpha)` pushed off by a distance `d` drawn
/// log-uniformly from 1e-9 to 10 in a random direction (the angle as an arc
/// of radius `extent`): the pose and `d`.
pub fn pushed_off(rng: &mut pkm::dsl::screw::SplitMix, outputs: &[f64; 4], extent: f64) -> ([f64; 4], f64) {
    let d = 10f64.powf(-9.0 + 10.0 * (rng.symmetric() + 1.0) / 2.0);
    let dir: [f64; 4] = std::array::from_fn(|_| rng.symmetric());
    let n = dir.iter().map(|x| x * x).sum::<f64>().sqrt();
    let given = std::array::from_fn(|i| outputs[i] + d * dir[i] / n / if i == 3 { extent } else { 1.0 });
    (given, d)
}

/// A PRP tangent mechanism (a block slides in the crank's slot, pinned to a
/// slider on the guide y = h = 80): `slide_to_line`'s PRP form, whose slide
/// is s = h/tan θ and h/sin θ along the slot by hand.
pub const TANGENT_MECHANISM: &str = "mechanism tangent {
    capabilities fk;
    planar;
    base R1* [crank] ⊥ P1 [block] ⊥ R2 [slider] ⊥ P2 base;
    x ∥ P2;
    parameters { h = 80; }
    geometry {
        base   { R1 = (0, 0); P2 = through (0, h) along x; }
        crank  { R1 = (0, 0); P1 = through (0, 0) along x; }
        block  { P1 = (0, 0); R2 = (0, 0); }
        slider { R2 = (0, 0); P2 = (0, 0); }
    }
}";

use pkm::dsl::screw::SplitMix;
use pkm::runtime::kinematics;
use pkm::runtime::model::{JointType, Model};
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan::{self, Solution};
use std::collections::HashMap;

/// One value per R and P joint of a full joint-value vector (an S joint's
/// three left out as 0).
pub fn per_joint(model: &Model, full: &[f64]) -> Vec<f64> {
    let (offsets, _) = model.value_offsets();
    model
        .joints
        .iter()
        .zip(offsets)
        .map(|(j, o)| if j.kind == JointType::S { 0.0 } else { full[o] })
        .collect()
}

/// A plan solution's values with its S joints' as 0, as [`per_joint`].
pub fn per_joint_of(model: &Model, values: &[f64]) -> Vec<f64> {
    model
        .joints
        .iter()
        .zip(values)
        .map(|(j, v)| if j.kind == JointType::S { 0.0 } else { *v })
        .collect()
}

/// Example `name`'s generated inverse solution (each branch's joint
/// values, `generated`) against the interpreter's, and every interpreted
/// branch against Newton's inverse solution started 1e-3 away from it,
/// over 200 poses drawn by `pose` (at least `min` branches, 99 % of them
/// nearest their own branch).
pub fn inverse_agrees_with_newton(
    name: &str,
    min: usize,
    mut pose: impl FnMut(&mut SplitMix) -> [f64; 3],
    generated: impl Fn(&[f64; 3]) -> Vec<Result<Vec<f64>, ()>>,
) {
    let (a, model) = example(name);
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(&a, &model, &HashMap::new()).unwrap();
    let scale = kinematics::model_scale(&model);
    let options = NewtonOptions {
        tolerance: 1e-14,
        ..NewtonOptions::default()
    };
    let revolute: Vec<bool> = model.joints.iter().map(|j| j.kind == JointType::R).collect();
    let mut rng = SplitMix::new(5);
    let (mut compared, mut same, mut worst_gen, mut worst_newton) = (0, 0, 0.0f64, 0.0f64);
    for _ in 0..200 {
        let given = pose(&mut rng);
        let generated = generated(&given);
        let interpreted = plan::run_all(&model, &plan, &given);
        assert_eq!(generated.len(), interpreted.len(), "{name}");
        let solved: Vec<&Solution> = interpreted.iter().filter_map(|(_, r)| r.as_ref().ok()).collect();
        for ((_, r), g) in interpreted.iter().zip(&generated) {
            let (Ok(sol), Ok(gen)) = (r, g) else {
                assert_eq!(r.is_ok(), g.is_ok(), "{name}");
                continue;
            };
            let e = max_error(gen, &sol.values, &revolute, scale);
            worst_gen = worst_gen.max(e);
            assert!(e < 1e-12, "{name}: generated {e:e} from interpreted");
        }
        for (i, s) in solved.iter().enumerate() {
            let guess: Vec<f64> = s
                .model_values(&model)
                .iter()
                .map(|v| v + 1e-3 * rng.symmetric())
                .collect();
            let reference = newton::solve_ik(&model, &outputs, &given, &guess, &options)
                .unwrap_or_else(|e| panic!("{name}: Newton ik failed at {given:?}: {e}"));
            let newton = per_joint(&model, &reference.values);
            let (best, e) = solved
                .iter()
                .map(|t| max_error(&per_joint_of(&model, &t.values), &newton, &revolute, scale))
                .enumerate()
                .fold((0, f64::INFINITY), |b, (k, e)| if e < b.1 { (k, e) } else { b });
            worst_newton = worst_newton.max(e);
            assert!(e <= 1e-9, "{name}: at {given:?} Newton is {e:e} from every branch");
            compared += 1;
            same += usize::from(best == i);
        }
    }
    eprintln!(
        "{name}: {compared} branches against Newton (worst {worst_newton:e}), {same} on the same branch; \
         generated within {worst_gen:e} of interpreted"
    );
    assert!(
        compared >= min && same * 100 >= compared * 99,
        "{name}: {compared}, {same}"
    );
}

/// Random poses of the spatial examples, shared by the tests that draw them.
pub mod poses {
    use pkm::dsl::screw::SplitMix;

    /// A seed 004 pose (Z_A, α, β) of rps_3 or spr_3: Z_A in 60..120 mm,
    /// α and β in ±0.35 rad (±20°).
    pub fn seed(rng: &mut SplitMix) -> [f64; 3] {
        [
            90.0 + 30.0 * rng.symmetric(),
            0.35 * rng.symmetric(),
            0.35 * rng.symmetric(),
        ]
    }

    /// A 3-RPS (rps_3_tilt) or 3-PRS pose (z, rx, ry): z in 120..220 mm,
    /// rx and ry in ±0.35 rad.
    pub fn tilt(rng: &mut SplitMix) -> [f64; 3] {
        [
            170.0 + 50.0 * rng.symmetric(),
            0.35 * rng.symmetric(),
            0.35 * rng.symmetric(),
        ]
    }

    /// A Stewart (ups_6) pose: x, y in ±40 mm, z in 150..250 mm, angles
    /// in ±0.3 rad.
    pub fn ups(rng: &mut SplitMix) -> [f64; 6] {
        [
            40.0 * rng.symmetric(),
            40.0 * rng.symmetric(),
            200.0 + 50.0 * rng.symmetric(),
            0.3 * rng.symmetric(),
            0.3 * rng.symmetric(),
            0.3 * rng.symmetric(),
        ]
    }

    /// A 3-UPU (upu_3) position: x, y in ±60 mm, z in 120..280 mm.
    pub fn upu(rng: &mut SplitMix) -> [f64; 3] {
        [
            60.0 * rng.symmetric(),
            60.0 * rng.symmetric(),
            200.0 + 80.0 * rng.symmetric(),
        ]
    }
}
