//! Seed 003 (the decoupled punching eight-bar, `examples/mechanisms/
//! seed003_punch.pkm` with Table 1's masses and inertias): the crank torque
//! M(φ) over a full turn at ω = 1 rad/s with gravity, by Newton–Euler over
//! the SKCs in reverse order (SKC₃, SKC₂, SKC₁, as §3.1 orders them), by
//! virtual work and by Lagrange's equations; and the change points where
//! SKC₃'s force equations are singular.
//!
//! The paper's typos, as the example file's comments say: S₂ is printed
//! ⅓(B + C + G) and S₅ ½(G + C), but G is not on link 2 nor C on link 5
//! (they are ⅓(B + C + D) and ½(G + F)); I₁ and I₇ are about the pivots A
//! and H (uniform rods give m l²/3 = 0.629 and 10.96 kg·mm² there), so the
//! file subtracts m (l/2)² for the centroidal values.

use crate::common;
// `Punch` here is the test's own model and plan; the generated solver is `PunchGenerated`.
use crate::mechanisms::{Punch as PunchGenerated, PunchDynamics, PunchPrepared};

use pkm::runtime::mass_properties::Loading;
use pkm::runtime::model::Model;
use pkm::runtime::newton_euler::{inverse_dynamics, DynamicsError, JointReaction, Reactions, SkcParts};
use pkm::runtime::plan::Plan;
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use pkm::runtime::{lagrange, virtual_work};

struct Punch {
    model: Model,
    loading: Loading,
    skcs: Vec<SkcParts>,
    plan: Plan,
}

fn punch() -> Punch {
    let (text, path) = common::example_text("seed003_punch");
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).unwrap();
    let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
    let plan = c.forward().unwrap().clone();
    Punch {
        model,
        loading,
        skcs,
        plan,
    }
}

impl Punch {
    fn joint(&self, name: &str) -> usize {
        self.model.joints.iter().position(|j| j.name == name).unwrap()
    }

    /// The paper's branch at φ: C below B, G by the + arccos (signs − −),
    /// and F the intersection other than H (the larger |X_F|; the other is
    /// F at H, X_F = 0).
    fn branch(&self, phi: f64) -> (Vec<f64>, [Sign; 3]) {
        let p2 = self.joint("P2");
        [Plus, Minus]
            .into_iter()
            .filter_map(|s| {
                let signs = [Minus, Minus, s];
                self.plan.solve(&self.model, &[phi], &signs).ok().map(|v| (v, signs))
            })
            .max_by(|a, b| a.0[p2].abs().total_cmp(&b.0[p2].abs()))
            .expect("the paper's assembly")
    }

    fn newton_euler(&self, values: &[f64]) -> Result<Reactions, DynamicsError> {
        inverse_dynamics(&self.model, &self.loading, &self.skcs, values, &[1.0], &[0.0])
    }
}

/// Where B is on slider 3's line (φ = 90°, 270°) the Lagrange path says
/// its derivatives are not defined, a typed error, never NaN; Newton–Euler
/// and virtual work agree there.
#[test]
fn lagrange_refuses_where_a_distance_through_the_plan_is_zero() {
    let p = punch();
    for k in [90.0f64, 270.0] {
        let phi = k.to_radians();
        let (values, signs) = p.branch(phi);
        let lg = lagrange::actuator_forces(&p.model, &p.plan, &p.loading, &[phi], &signs, &[1.0], &[0.0]);
        assert!(lg.is_err(), "φ = {k}°: {lg:?}");
        let ne = p.newton_euler(&values).unwrap().actuators[0];
        let vw = virtual_work::actuator_forces(&p.model, &p.loading, &values, &[1.0], &[0.0]).unwrap()[0];
        assert!(
            (ne - vw).abs() < 1e-12 * vw.abs().max(1.0),
            "φ = {k}°: {ne} against {vw}"
        );
    }
}

/// Whether a crank angle (degrees) is within 2° of a change point
/// (154.5189° and 234.6346°, where F passes through H).
fn near_change_point(degrees: f64) -> bool {
    [154.5189, 234.6346].iter().any(|c| (degrees - c).abs() < 2.0)
}

#[test]
fn the_skcs_are_the_papers() {
    let p = punch();
    let names = |js: &[usize]| {
        js.iter()
            .map(|&j| p.model.joints[j].name.clone())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let skcs: Vec<String> = p.skcs.iter().map(|s| names(&s.joints)).collect();
    // SKC₁ A–B–C–P₁ with the crank, SKC₂ D–G–H, SKC₃ G–F–P₂ (Figs. 5–7).
    assert_eq!(skcs, ["A B C P1", "D G H", "G.2 F P2"]);
    assert!(p.skcs.iter().all(|s| s.undetermined == 0));
}

/// M(φ) at 360 angles, every half degree off the whole ones, ω = 1 rad/s:
/// the three methods agree to 1e-9 of the largest |M| over the turn, and
/// every link's balance holds to 1e-12; Newton–Euler refuses the angles
/// within 2° of a change point (`change_points_accurate_or_refused`). (At exactly 90° and 270° the
/// crank pin B is on slider 3's line, where the plan's distance from the
/// line is 0 and has no derivative: Lagrange's derivatives through the
/// plan are not defined there; see the next test.)
#[test]
fn crank_torque_three_ways_over_a_turn() {
    let p = punch();
    let mut rows = Vec::new();
    for k in 0..360 {
        let phi = (k as f64 + 0.5).to_radians();
        let (values, signs) = p.branch(phi);
        let ne = match p.newton_euler(&values) {
            Ok(ne) => ne,
            // Within 2° of a change point: fewer than six digits.
            Err(DynamicsError::NearChangePoint { .. }) if near_change_point(k as f64 + 0.5) => continue,
            Err(e) => panic!("φ = {k}°: {e}"),
        };
        let vw = virtual_work::actuator_forces(&p.model, &p.loading, &values, &[1.0], &[0.0]).unwrap()[0];
        let lg = lagrange::actuator_forces(&p.model, &p.plan, &p.loading, &[phi], &signs, &[1.0], &[0.0]).unwrap()[0];
        assert!(ne.balance < 1e-12, "φ = {k}°: balance {:e}", ne.balance);
        rows.push((k, ne.actuators[0], vw, lg));
    }
    let largest = rows.iter().fold(0.0f64, |a, r| a.max(r.1.abs()));
    for (k, ne, vw, lg) in &rows {
        assert!(
            (ne - vw).abs() < 1e-9 * largest && (ne - lg).abs() < 1e-9 * largest,
            "φ = {k}°: Newton–Euler {ne}, virtual work {vw}, Lagrange {lg} (N·mm)"
        );
    }
    // About ±10 N·mm, nearly all of it gravity at this speed.
    assert!((5.0..20.0).contains(&largest), "largest |M| {largest} N·mm");
}

/// SKC₃ (rod GF and slider 6) balances three equations in R_G and R_F
/// whose determinant is X_F − X_G = l₇ cos φ₃ (moments about G): zero
/// where F passes through H, twice a turn. There its conditioning falls
/// to 0 and the reactions at G (on link 5), F and H grow like 1/(φ − φ*),
/// while M stays finite: the pair does no work. Next to φ* the answer is
/// refused in motion (`NearChangePoint`: fewer than six digits); at rest
/// the forces do not grow and keep their digits to 0.035° from φ*.
#[test]
fn change_points_where_f_passes_through_h() {
    let p = punch();
    let skc3 = 2;
    let conditioning = |phi: f64| {
        let (v, _) = p.branch(phi);
        match p.newton_euler(&v) {
            Ok(r) => r.conditioning[skc3],
            Err(DynamicsError::NearChangePoint {
                skc: 2, conditioning, ..
            }) => conditioning,
            // At φ* itself F's two assembly branches meet (the circle about
            // G touches slider 6's line at H): the motion is singular too.
            Err(DynamicsError::Velocity(_)) => 0.0,
            Err(e) => panic!("{e}"),
        }
    };
    for (lo, hi) in [(150.0f64, 158.0f64), (230.0, 238.0)] {
        // Golden-section search for the conditioning's minimum.
        let (mut a, mut b) = (lo.to_radians(), hi.to_radians());
        let r = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..80 {
            let (c, d) = (b - r * (b - a), a + r * (b - a));
            if conditioning(c) < conditioning(d) {
                b = d;
            } else {
                a = c;
            }
        }
        let star = 0.5 * (a + b);
        // Where F is at H: X_F = 0 on the paper's branch.
        let (v, _) = p.branch(star);
        assert!(
            v[p.joint("P2")].abs() < 1e-4,
            "X_F = {} mm at the minimum",
            v[p.joint("P2")]
        );
        // Beside φ*, where the motion itself is regular, it is refused.
        let (v_at, _) = p.branch(star + 1e-7);
        let at = p.newton_euler(&v_at);
        assert!(
            matches!(at, Err(DynamicsError::NearChangePoint { conditioning, moving: true, .. }) if conditioning < 1e-5),
            "{at:?} 1e-7 rad from {}°",
            star.to_degrees()
        );
        // At rest 0.05° away (a statics' forces keep six digits to 0.035°),
        // M agrees with virtual work.
        let (v_near, _) = p.branch(star - 0.05f64.to_radians());
        let near = inverse_dynamics(&p.model, &p.loading, &p.skcs, &v_near, &[0.0], &[0.0]).unwrap();
        let vw = virtual_work::actuator_forces(&p.model, &p.loading, &v_near, &[0.0], &[0.0]).unwrap()[0];
        assert!(
            (near.actuators[0] - vw).abs() < 1e-9 * vw.abs().max(1.0),
            "M {} against {vw}",
            near.actuators[0]
        );
        eprintln!(
            "change point at φ* = {:.4}°: conditioning {:e}",
            star.to_degrees(),
            conditioning(star)
        );
    }
    // In motion the pair's reactions grow like 1/(φ − φ*): the 60-digit
    // reference's R_G (link 7 on link 5) at 1 rad/s, on the branch with F
    // at 2 x_G, a thousand times larger 1e-4° away than 0.1° away.
    let rows = change_point_rows();
    let r_g = |point: usize, degrees: f64| {
        rows.iter()
            .filter(|r| r.point == point && r.omega == 1.0 && r.alpha == 0.0 && r.offset_deg < 0.0)
            .filter(|r| r.signs[..2] == [Minus, Minus])
            .filter(|r| (r.offset_deg.abs() / degrees - 1.0).abs() < 1e-3)
            .filter_map(|r| r.answer.as_ref())
            .max_by(|a, b| a.x_f[0].abs().total_cmp(&b.x_f[0].abs()))
            .map(|a| a.joints[6].0[1].abs())
            .expect("the row")
    };
    for point in [1, 2] {
        let (near, far) = (r_g(point, 1e-4), r_g(point, 0.1));
        assert!(
            (900.0..1100.0).contains(&(near / far)),
            "R_G: {near} N at 1e-4°, {far} N at 0.1°"
        );
    }
}

/// The shape of M(φ) against a separate implementation of the paper's
/// equations (5)–(11) (Python, written from the paper for the issue's
/// notes, with the same corrections and g = 9.80665 m/s²): M is nearly one
/// sinusoid, its largest +10.2343 N·mm at φ ≈ 340.13° and its smallest
/// −10.2075 N·mm at φ ≈ 184.47°, about 99.6 % gravity at this speed.
#[test]
fn crank_torque_extremes_as_computed_from_the_paper() {
    let p = punch();
    let m = |deg: f64| {
        let (values, _) = p.branch(deg.to_radians());
        p.newton_euler(&values).unwrap().actuators[0]
    };
    let extreme = |from: f64, sign: f64| {
        (0..=200)
            .map(|k| from + k as f64 / 100.0)
            .map(|d| (d, m(d)))
            .max_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)))
            .unwrap()
    };
    let (at_max, max) = extreme(339.0, 1.0);
    let (at_min, min) = extreme(183.5, -1.0);
    assert!(
        (max - 10.2343).abs() < 1e-3 && (at_max - 340.13).abs() < 0.02,
        "max {max} at {at_max}°"
    );
    assert!(
        (min + 10.2075).abs() < 1e-3 && (at_min - 184.47).abs() < 0.02,
        "min {min} at {at_min}°"
    );
}

/// Joint values that do not close the loops (a passive joint turned by
/// 0.1 rad off its solution) are no configuration: a typed error, not
/// reactions (the tree's links would balance all the same).
#[test]
fn values_that_do_not_close_are_refused() {
    let p = punch();
    let (mut values, _) = p.branch(0.5);
    values[p.joint("D")] += 0.1;
    let r = p.newton_euler(&values);
    assert!(
        matches!(r, Err(DynamicsError::NotClosed { residual }) if residual > 1e-3),
        "{r:?}"
    );
}

/// One row of `tests/fixtures/seed003_change_points.csv`
/// (`tests/reference/punch_mp.py`, 60-digit kinematics and Newton–Euler
/// written from the paper's geometry): a state beside a change point on
/// one branch, and the exact answer where the branch assembles.
struct Exact {
    point: usize,
    offset_deg: f64,
    q: f64,
    omega: f64,
    alpha: f64,
    signs: [Sign; 3],
    answer: Option<ExactAnswer>,
}

struct ExactAnswer {
    /// The crank torque (N·mm).
    torque: f64,
    /// Per joint of [`FIXTURE_JOINTS`], its force (N) and moment (N·mm:
    /// the torque for A, 0 for a passive revolute).
    joints: Vec<([f64; 2], f64)>,
    /// x_F and y_C: value, rate, acceleration (mm, mm/s, mm/s²), and G (mm).
    x_f: [f64; 3],
    y_c: [f64; 3],
    g: [f64; 2],
}

const FIXTURE_JOINTS: [&str; 10] = ["A", "B", "C", "P1", "D", "G", "G.2", "F", "P2", "H"];

fn change_point_rows() -> Vec<Exact> {
    let path = common::root().join("tests/fixtures/seed003_change_points.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    lines
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            let number = |name: &str| {
                cells[column(name)]
                    .parse::<f64>()
                    .unwrap_or_else(|e| panic!("{name} in {line}: {e}"))
            };
            let signs: Vec<Sign> = cells[column("signs")]
                .chars()
                .map(|c| if c == '+' { Plus } else { Minus })
                .collect();
            let answer = (cells[column("reaches")] == "1").then(|| {
                let torque = number("torque");
                let joints = FIXTURE_JOINTS
                    .iter()
                    .map(|j| {
                        let moment = match *j {
                            "A" => torque,
                            "P1" | "P2" => number(&format!("{j}_m")),
                            _ => 0.0,
                        };
                        ([number(&format!("{j}_fx")), number(&format!("{j}_fy"))], moment)
                    })
                    .collect();
                ExactAnswer {
                    torque,
                    joints,
                    x_f: ["x_F", "v_F", "a_F"].map(number),
                    y_c: ["y_C", "v_C", "a_C"].map(number),
                    g: ["x_G", "y_G"].map(number),
                }
            });
            Exact {
                point: number("point") as usize,
                offset_deg: number("offset_deg"),
                q: number("q"),
                omega: number("omega"),
                alpha: number("alpha"),
                signs: signs.try_into().expect("three choices"),
                answer,
            }
        })
        .collect()
}

/// How far an answer (the crank torque and every joint's reaction) is
/// from the exact one: the torque relative to itself, each force
/// component relative to the largest exact force, each moment relative
/// to the largest exact moment (the torque's among them).
fn error_of(p: &Punch, exact: &ExactAnswer, torque: f64, joints: &[JointReaction]) -> f64 {
    let forces = exact
        .joints
        .iter()
        .flat_map(|(f, _)| f)
        .fold(0.0f64, |a, x| a.max(x.abs()));
    let moments = exact.joints.iter().fold(0.0f64, |a, (_, m)| a.max(m.abs()));
    let mut worst = (torque - exact.torque).abs() / exact.torque.abs();
    for (name, (f, m)) in FIXTURE_JOINTS.iter().zip(&exact.joints) {
        let j = &joints[p.joint(name)];
        worst = worst
            .max((j.force[0] - f[0]).abs() / forces)
            .max((j.force[1] - f[1]).abs() / forces)
            .max(j.force[2].abs() / forces)
            .max((j.moment[2] - m).abs() / moments)
            .max(j.moment[0].abs().max(j.moment[1].abs()) / moments);
    }
    worst
}

fn rates_of(row: &Exact) -> [f64; 1] {
    [row.omega]
}

fn accels_of(row: &Exact) -> [f64; 1] {
    [row.alpha]
}

/// The runtime's answer as `pkm dynamics` computes it (every branch of the
/// plan, then Newton–Euler on the branch's joint values) and the generated
/// `inverse_dynamics`, at one row's state.
fn both_paths(
    p: &Punch,
    generated: &PunchPrepared,
    row: &Exact,
) -> (
    Result<pkm::runtime::plan::Solution, pkm::runtime::solution::SolveError>,
    Result<Reactions, DynamicsError>,
    Result<PunchDynamics, DynamicsError>,
) {
    let (rates, accels) = (rates_of(row), accels_of(row));
    let position = pkm::runtime::plan::run_all(&p.model, &p.plan, &[row.q])
        .into_iter()
        .find(|(s, _)| s[..] == row.signs[..])
        .expect("every branch")
        .1;
    let runtime = match &position {
        Ok(s) => inverse_dynamics(&p.model, &p.loading, &p.skcs, &s.values, &rates, &accels),
        Err(e) => Err(DynamicsError::Position(e.clone())),
    };
    let generated = generated.inverse_dynamics(&[row.q], row.signs, &rates, &accels);
    (position, runtime, generated)
}

/// Item 1 of issue 29, `pkm dynamics seed003_punch.pkm --q=2.6968633537
/// --rates=1`: φ* + 1e-5° on the branch (− − −), where F's two roots
/// nearly meet, was ok with a crank torque of 2670.10 N·mm (the generated
/// code 2690.99) against the exact −8.914887. Now, at every row of the
/// 60-digit reference (both change points, φ* ± 3°, 1°, 0.3° and 10^-k°
/// for k = 1 … 10, every branch of the plan, at rest, at 1 rad/s and at
/// 10 rad/s with 50 rad/s²), the runtime's and the generated inverse
/// dynamics both answer or both refuse, and every answer holds six digits
/// of the torque and of every reaction. A branch that does not assemble
/// is refused by both; the branches' signs are the reference's (their
/// points agree).
#[test]
fn change_points_accurate_or_refused() {
    let p = punch();
    let size = pkm::runtime::kinematics::model_scale(&p.model);
    let generated = PunchGenerated::prepare(&Default::default());
    let rows = change_point_rows();
    assert_eq!(
        rows.len(),
        2 * 15 * 2 * 3 * 8,
        "two points, 15 offsets a side, three states, eight branches"
    );
    // Per state (ω, α): answered, refused, the worst error of an answer and of its motion.
    type Tally = ((f64, f64), usize, usize, f64, f64);
    let mut tally: Vec<Tally> = Vec::new();
    for row in &rows {
        let (position, runtime, gen) = both_paths(&p, &generated, row);
        let at = format!(
            "change point {} {:+e}° (q = {}), ω = {}, α = {}, signs {:?}",
            row.point, row.offset_deg, row.q, row.omega, row.alpha, row.signs
        );
        let Some(exact) = &row.answer else {
            assert!(position.is_err(), "{at}: the reference has no assembly, pkm has one");
            assert!(
                matches!(gen, Err(DynamicsError::Position(_))),
                "{at}: generated {gen:?}"
            );
            continue;
        };
        // The plan's signs pick the reference's roots.
        if let Ok(s) = &position {
            let point = |name: &str| {
                let j = p.joint(name);
                pkm::runtime::newton::joint_point(&p.model, &s.poses, j)
            };
            let (f, c, g) = (point("F"), point("C"), point("G"));
            for (a, b) in [
                (f[0], exact.x_f[0]),
                (c[1], exact.y_c[0]),
                (g[0], exact.g[0]),
                (g[1], exact.g[1]),
            ] {
                assert!(
                    (a - b).abs() < 1e-7 * size,
                    "{at}: a point at {a} mm, the reference's at {b} mm"
                );
            }
        }
        let state = (row.omega, row.alpha);
        let k = match tally.iter().position(|t| t.0 == state) {
            Some(k) => k,
            None => {
                tally.push((state, 0, 0, 0.0, 0.0));
                tally.len() - 1
            }
        };
        match (&runtime, &gen) {
            (Ok(r), Ok(g)) => {
                let e =
                    error_of(&p, exact, r.actuators[0], &r.joints).max(error_of(&p, exact, g.actuators[0], &g.joints));
                assert!(
                    e <= 1e-6,
                    "{at}: an answer off by {e:.1e} (torque {} and {} against {} N·mm; conditioning {:?})",
                    r.actuators[0],
                    g.actuators[0],
                    exact.torque,
                    r.conditioning
                );
                // The motion `pkm dynamics` prints beside an answer
                // (`velocity::accelerations`): six digits too, against
                // the scale of the crank's own (size·ω, size·(ω² + |α|)).
                let values = &position.as_ref().expect("a position").values;
                let a = pkm::runtime::velocity::accelerations(&p.model, values, &rates_of(row), &accels_of(row))
                    .unwrap_or_else(|e| panic!("{at}: {e}"));
                let (v_scale, a_scale) = (size * row.omega.abs(), size * (row.omega.powi(2) + row.alpha.abs()));
                for (joint, exact) in [("P2", exact.x_f), ("P1", exact.y_c)] {
                    // The sliders' values run along their guides: x_F, and y_C from the base.
                    let j = p.joint(joint);
                    let (v, acc) = (a.velocities.rates[j].abs(), a.rates[j].abs());
                    for (got, want, scale) in [(v, exact[1].abs(), v_scale), (acc, exact[2].abs(), a_scale)] {
                        if scale > 0.0 {
                            let m = (got - want).abs() / scale;
                            assert!(
                                m <= 1e-6,
                                "{at}: {joint}'s motion off by {m:.1e} ({got} against {want})"
                            );
                            tally[k].4 = tally[k].4.max(m);
                        }
                    }
                }
                tally[k].1 += 1;
                tally[k].3 = tally[k].3.max(e);
            }
            (Err(_), Err(_)) => {
                tally[k].2 += 1;
                // The motion alone (`velocity::accelerations`, the generated
                // `acceleration`) answers, with a conditioning that says so.
                if let (Ok(s), Err(DynamicsError::NearChangePoint { moving: true, .. })) = (&position, &runtime) {
                    let a = pkm::runtime::velocity::accelerations(&p.model, &s.values, &rates_of(row), &accels_of(row));
                    let c = a.map_or(0.0, |a| a.velocities.conditioning);
                    assert!(
                        c < pkm::runtime::force_system::LEAST_IN_MOTION,
                        "{at}: the motion's conditioning {c}"
                    );
                }
            }
            _ => panic!("{at}: the runtime {runtime:?}, the generated code {gen:?}"),
        }
    }
    for ((omega, alpha), answered, refused, worst, motion) in &tally {
        eprintln!(
            "ω = {omega}, α = {alpha}: {answered} answers (worst {worst:.1e}, motion {motion:.1e}), {refused} refused"
        );
    }
    // The issue's state is refused by both, saying why.
    let issue = Exact {
        point: 1,
        offset_deg: 1e-5,
        q: 2.6968633537,
        omega: 1.0,
        alpha: 0.0,
        signs: [Minus, Minus, Minus],
        answer: None,
    };
    let (_, runtime, gen) = both_paths(&p, &generated, &issue);
    for e in [runtime.unwrap_err(), gen.unwrap_err()] {
        assert!(
            matches!(
                &e,
                DynamicsError::NearChangePoint {
                    skc: 2,
                    moving: true,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains("fewer than 6 digits"), "{e}");
    }
}

/// Where the refusal begins: on the branch where F's roots cross (− − +),
/// the angle beside each change point at which the kinematic conditioning
/// reaches the least that keeps six digits, found by bisection on each
/// side for a state in motion and one at rest. The runtime and the
/// generated code refuse from the same angle (to 1e-9°), and the band is
/// what docs/dynamics.md states.
#[test]
fn the_refused_band() {
    let p = punch();
    let generated = PunchGenerated::prepare(&Default::default());
    let stars = [2.6968631790545615f64, 4.095146710260344];
    for (moving, (omega, alpha), widest) in [(true, (1.0, 0.0), 2.0f64), (false, (0.0, 0.0), 0.05)] {
        for (point, star) in stars.iter().enumerate() {
            for side in [-1.0f64, 1.0] {
                let refused = |runtime: bool, degrees: f64| {
                    let row = Exact {
                        point: point + 1,
                        offset_deg: degrees,
                        q: star + side * degrees.to_radians(),
                        omega,
                        alpha,
                        signs: [Minus, Minus, Plus],
                        answer: None,
                    };
                    let (_, r, g) = both_paths(&p, &generated, &row);
                    match if runtime { r.err() } else { g.err() } {
                        None => false,
                        Some(DynamicsError::NearChangePoint { moving: m, .. }) => {
                            assert_eq!(m, moving);
                            true
                        }
                        Some(e) => panic!("{degrees}°: {e}"),
                    }
                };
                let edge = |runtime: bool| {
                    let (mut inside, mut outside) = (1e-3f64, 10.0f64);
                    assert!(refused(runtime, inside) && !refused(runtime, outside));
                    while outside - inside > 1e-10 {
                        let mid = 0.5 * (inside + outside);
                        if refused(runtime, mid) {
                            inside = mid;
                        } else {
                            outside = mid;
                        }
                    }
                    outside
                };
                let (r, g) = (edge(true), edge(false));
                assert!(
                    (r - g).abs() < 1e-9,
                    "the runtime refuses to {r}°, the generated code to {g}°"
                );
                assert!(r < widest, "refused to {r}° from the change point");
                eprintln!(
                    "change point {} ({:.4}°), {} side, {}: refused within {r:.4}°",
                    point + 1,
                    star.to_degrees(),
                    if side < 0.0 { "lower" } else { "upper" },
                    if moving { "in motion" } else { "at rest" }
                );
            }
        }
    }
}
