//! Seed 000, mechanisms A and B: the spatial plans against Tables 1 and 2,
//! the paper's equations (11)–(17) evaluated independently here, and round
//! trips fk∘ik and ik∘fk; every plan solution also closes the loops of the
//! numeric model (the Newton reference's residual).

use crate::common;

use pkm::runtime::kinematics;
use pkm::runtime::model::Model;
use pkm::runtime::plan::{self, Plan, Solution};

struct Mech {
    model: Model,
    fk: Plan,
    ik: Plan,
    platform: usize,
    /// The output point on the platform and the axis α turns about.
    point: [f64; 3],
    about: [f64; 3],
}

fn load(file: &str, point: &str, about: [f64; 3]) -> Mech {
    let (a, model) = common::example(file);
    let platform = model.links.iter().position(|l| l == "platform").unwrap();
    let point = model.points.iter().find(|p| p.name == point).unwrap().at;
    Mech {
        fk: pkm::dsl::planner::forward_plan(&a).unwrap(),
        ik: pkm::dsl::planner::inverse_plan(&a).unwrap(),
        model,
        platform,
        point,
        about,
    }
}

impl Mech {
    /// (x, y, z, α) of a solution.
    fn pose(&self, s: &Solution) -> [f64; 4] {
        let p = plan::at(&s.poses[self.platform], self.point);
        [p[0], p[1], p[2], plan::angle_about(&s.poses[self.platform], self.about)]
    }

    fn inputs(&self, s: &Solution) -> Vec<f64> {
        self.model.inputs().iter().map(|&j| s.values[j]).collect()
    }

    fn solved(&self, plan: &Plan, given: &[f64]) -> Vec<Solution> {
        self.solved_fast(plan, given)
            .into_iter()
            .inspect(|s| {
                let r = kinematics::loop_residual(&self.model, &s.values).unwrap();
                let worst = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(worst < 1e-9, "{} loop residual {worst}", self.model.name);
            })
            .collect()
    }

    /// As `solved`, without the loop-closure check.
    fn solved_fast(&self, plan: &Plan, given: &[f64]) -> Vec<Solution> {
        plan::run_all(&self.model, plan, given)
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .collect()
    }
}

fn a() -> Mech {
    load("seed000_a", "o", [1.0, 0.0, 0.0])
}

fn b() -> Mech {
    load("seed000_b", "E", [-1.0, 0.0, 0.0])
}

#[test]
fn mechanism_a_table_1() {
    let m = a();
    let poses: Vec<[f64; 4]> = m
        .solved(&m.fk, &[-106.09, 181.67, -70.29])
        .iter()
        .map(|s| m.pose(s))
        .collect();
    // The paper takes the five-bar's C above its sliders (H = +√…): two
    // solutions. pkm lists the other assembly of the five-bar too (z = −38.92),
    // and each pose twice: the R5–parallelogram leg's two postures
    // (`mechanism_a_both_postures_of_the_parallelogram_leg`).
    assert_eq!(poses.len(), 8);
    for alpha in [-0.7097, 0.2547] {
        let hit = poses
            .iter()
            .find(|p| (p[2] - 238.9192).abs() < 5e-5 && (p[3] - alpha).abs() < 5e-5);
        let p = hit.unwrap_or_else(|| panic!("no solution with α = {alpha}: {poses:?}"));
        assert!((p[0] - 37.79).abs() < 5e-3 && (p[1] + 300.0).abs() < 1e-9);
    }
    assert_eq!(poses.iter().filter(|p| (p[2] + 38.9192).abs() < 5e-5).count(), 4);
}

/// Issue 29, item 3: at Table 1's inputs `pkm fk` listed four assemblies,
/// one posture of the R5–parallelogram leg each (R5 = 1.0329, 0.5778,
/// −0.5778, −1.0329, Pa = 0.3445 or 2.7971). The leg's other posture turns
/// R5 and its bar half a turn about R5's axis (x) and swings the
/// parallelogram to π − Pa: the bar's end D is where it was (the arm l4
/// along (0, −sin(R5 + Pa'), cos(R5 + Pa')) from B3, turned by R5 + π and
/// π − Pa: the same vector), so the platform is too, and R6 turns the
/// coupler pc, now half a turn about x from before, back onto it. By hand,
/// each of the four is listed again with R5 + π, π − Pa and R6 + π, the
/// platform's pose unchanged; and the model's loop equations (not the
/// plan) close at all eight (`solved`).
#[test]
fn mechanism_a_both_postures_of_the_parallelogram_leg() {
    use pkm::runtime::solution::wrap_angle;
    use std::f64::consts::PI;
    let m = a();
    let joint = |n: &str| m.model.joints.iter().position(|j| j.name == n).unwrap();
    let (r5, pa, r6) = (joint("R5"), joint("Pa"), joint("R6"));
    let all = plan::run_all(&m.model, &m.fk, &[-106.09, 181.67, -70.29]);
    assert_eq!(all.len(), 8);
    assert!(all.iter().all(|(_, r)| r.is_ok()), "{all:?}");
    let fk = m.solved(&m.fk, &[-106.09, 181.67, -70.29]);
    // The four the plan listed before, branches 0–3, by their R5 and Pa.
    let listed = [(1.0329, 0.3445), (0.5778, 0.3445), (-0.5778, 2.7971), (-1.0329, 2.7971)];
    for (b, (r, p)) in listed.iter().enumerate() {
        let s = &fk[b];
        assert!(
            (s.values[r5] - r).abs() < 5e-5 && (s.values[pa] - p).abs() < 5e-5,
            "branch {b}"
        );
        // Branch b + 4: the same choices and the parallelogram plane's other root.
        let t = &fk[b + 4];
        assert!(
            wrap_angle(t.values[r5] - (s.values[r5] + PI)).abs() < 1e-12,
            "branch {}",
            b + 4
        );
        assert!(wrap_angle(t.values[pa] - (PI - s.values[pa])).abs() < 1e-12);
        assert!(wrap_angle(t.values[r6] - (s.values[r6] + PI)).abs() < 1e-12);
        let (ps, pt) = (m.pose(s), m.pose(t));
        assert!((0..4).all(|k| (ps[k] - pt[k]).abs() < 1e-9), "{ps:?} vs {pt:?}");
        // Another assembly: the bar DB3 turned half a turn about x.
        let bar = m.model.links.iter().position(|l| l == "r5").unwrap();
        let turn = s.poses[bar].rotation.angle_to(&t.poses[bar].rotation);
        assert!((turn - PI).abs() < 1e-9, "branch {b}: the bar turns {turn}");
    }
}

#[test]
fn mechanism_a_table_2() {
    let m = a();
    let fk = m.solved(&m.fk, &[-106.09, 181.67, -70.29]);
    let first = fk
        .iter()
        .map(|s| m.pose(s))
        .find(|p| (p[3] + 0.7097).abs() < 5e-5 && p[2] > 0.0)
        .unwrap();
    // Eq. (14), evaluated here at the pose.
    let (a_, l1, l2, l3, l4) = (300.0f64, 100.0, 200.0, 450.0, 320.0);
    let eq14 = |p: [f64; 4]| {
        let (xc, z, al) = (p[0], p[2], p[3]);
        let u = (l2 * l2 - (z - l1).powi(2)).sqrt();
        let v = (l4 * l4 - (l3 * al.cos() - 2.0 * a_).powi(2) - (l3 * al.sin() + z - l1).powi(2)).sqrt();
        [xc + u, xc - u, xc + v, xc - v]
    };
    for pose in [first, [37.79, -300.0, 238.9192, -0.7097]] {
        let ik: Vec<Vec<f64>> = m.solved(&m.ik, &pose).iter().map(|s| m.inputs(s)).collect();
        // Eight assemblies of the legs' actuated joints, each with the
        // R5–parallelogram leg in either posture.
        assert_eq!(ik.len(), 16);
        let [u1, u2, v1, v2] = eq14(pose);
        // The paper's four rows: x2 = 2·x_C3 − x1, x3 either root of eq. (14).
        for (x1, x2) in [(u1, u2), (u2, u1)] {
            for x3 in [v1, v2] {
                assert!(
                    ik.iter()
                        .any(|q| (q[0] - x1).abs() < 1e-9 && (q[1] - x2).abs() < 1e-9 && (q[2] - x3).abs() < 1e-9),
                    "{pose:?}: no ik ({x1}, {x2}, {x3}) in {ik:?}"
                );
            }
        }
        // The other four (eight with the leg's postures) put both sliders of
        // the five-bar at one place (x1 = x2), which the paper leaves out.
        assert_eq!(ik.iter().filter(|q| (q[0] - q[1]).abs() < 1e-9).count(), 8);
    }
    // At the exact pose the inputs come back: x3 = −70.29 (row 4) and the
    // other root 145.8700. The paper prints 145.8604 and −70.2804; its own
    // eq. (14) gives 145.9149 / −70.3349 at the printed α = −0.7097 and
    // 145.8700 / −70.2900 at the exact one, so arithmetic wins here.
    let ik: Vec<Vec<f64>> = m.solved(&m.ik, &first).iter().map(|s| m.inputs(s)).collect();
    assert!(ik
        .iter()
        .any(|q| (q[0] + 106.09).abs() < 1e-9 && (q[1] - 181.67).abs() < 1e-9 && (q[2] + 70.29).abs() < 1e-9));
    assert!(ik.iter().any(|q| (q[2] - 145.87).abs() < 1e-4));
    let printed: Vec<Vec<f64>> = m
        .solved(&m.ik, &[37.79, -300.0, 238.9192, -0.7097])
        .iter()
        .map(|s| m.inputs(s))
        .collect();
    assert!(printed.iter().any(|q| (q[2] - 145.9149).abs() < 1e-4));
    assert!(printed.iter().any(|q| (q[2] + 70.3349).abs() < 1e-4));
}

#[test]
fn mechanism_b_equations_15_to_17() {
    let m = b();
    let (a_, l1, l2, l3, l4, l5) = (300.0f64, 100.0, 200.0, 180.0, 450.0, 320.0);
    let q = [-106.09, 181.67, -70.29];
    let poses: Vec<[f64; 4]> = m.solved(&m.fk, &q).iter().map(|s| m.pose(s)).collect();
    // Eq. (15): z_E by n, then α by m, both as the paper writes them.
    let xc = (q[0] + q[1]) / 2.0;
    let h = (l2 * l2 - ((q[1] - q[0]) / 2.0).powi(2)).sqrt();
    let mut expected = Vec::new();
    for n in [1.0, -1.0] {
        let ze = l1 + n * (l5 * l5 - (xc - q[2]).powi(2)).sqrt();
        let j = ze - l1 - h;
        let (n1, n2, n3) = (4.0 * a_ * l4, 2.0 * j * l4, l4 * l4 + j * j + 4.0 * a_ * a_ - l3 * l3);
        for mm in [1.0, -1.0] {
            let disc = n1 * n1 + n2 * n2 - n3 * n3;
            if disc >= 0.0 {
                expected.push([xc, a_, ze, 2.0 * ((n1 + mm * disc.sqrt()) / (n2 + n3)).atan()]);
            }
        }
    }
    // Of the four sign choices (n, m) two are real at these inputs; pkm finds
    // them and the two with the five-bar's C below its sliders, which
    // eq. (15) leaves out (its J takes C above).
    assert_eq!(expected.len(), 2);
    assert_eq!(poses.len(), 4);
    for e in &expected {
        assert!(
            poses.iter().any(|p| (0..4).all(|k| (p[k] - e[k]).abs() < 1e-9)),
            "eq. (15) solution {e:?} not among {poses:?}"
        );
    }
    // Eqs. (16)–(17): the eight inverse solutions of each pose.
    for p in &expected {
        let ik: Vec<Vec<f64>> = m.solved(&m.ik, p).iter().map(|s| m.inputs(s)).collect();
        let (xe, ye, ze, al) = (p[0], p[1], p[2], p[3]);
        let mut paper = 0;
        for w in [1.0, -1.0] {
            let k = (ze - l4 * al.cos() - l1 + w * (l3 * l3 - (ye - l4 * al.sin() + a_).powi(2)).sqrt()).powi(2);
            for u in [1.0, -1.0] {
                let x1 = xe + u * (l2 * l2 - k).sqrt();
                let x2 = 2.0 * xe - x1;
                for v in [1.0, -1.0] {
                    let x3 = xe + v * (l5 * l5 - (ze - l1).powi(2)).sqrt();
                    if x1.is_finite() && (x1 - x2).abs() > 1e-9 {
                        paper += 1;
                        assert!(
                            ik.iter().any(|q| (q[0] - x1).abs() < 1e-8
                                && (q[1] - x2).abs() < 1e-8
                                && (q[2] - x3).abs() < 1e-8),
                            "eqs. (16)-(17) ({x1}, {x2}, {x3}) not among {ik:?}"
                        );
                    }
                }
            }
        }
        // The rest put both five-bar sliders at one place (x1 = x2).
        assert!(paper > 0);
        assert_eq!(
            ik.iter().filter(|q| (q[0] - q[1]).abs() < 1e-9).count(),
            ik.len() - paper
        );
    }
}

// Round trips at 10⁵ configurations: tests/testsuite/round_trips.rs (generated code).
