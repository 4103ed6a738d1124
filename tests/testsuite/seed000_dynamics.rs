//! Seed 000 §3.4 (mechanisms A and B, `examples/mechanisms/seed000_a.pkm`
//! and `seed000_b.pkm` with §3.4's masses, Table 3's inertias, the 5 kg
//! payload): the driving forces f1, f2, f3 along §3.1's inputs
//! x_i(t) = ρ_i + y_i(t) over 0–5 s by Newton–Euler, virtual work and
//! Lagrange's equations; B only where it assembles, and a typed failure
//! where it does not. Every assumption the paper leaves open is in the
//! files' comments and in docs/dynamics.md ("Seed 000").
//!
//! The paper prints no number for Figs. 21 and 23. The independent checks:
//! the notes' values at t = 0 from a separate re-implementation of the
//! paper's eqs. (19)–(23) (Python, /work/notes/issue12_seeds.md §2.6, not
//! pkm's code), and the statics against differences of the potential energy
//! of the weights and the payload, with DB3's centroid taken as the
//! midpoint of the named points B3 and D (not from the bar's pose).

use crate::common;

use pkm::runtime::mass_properties::Loading;
use pkm::runtime::model::Model;
use pkm::runtime::nalgebra::Vector3;
use pkm::runtime::newton_euler::{inverse_dynamics, SkcParts};
use pkm::runtime::plan::Plan;
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use pkm::runtime::{lagrange, virtual_work};
use std::f64::consts::PI;

/// §3.1: ρ and the sines' amplitudes (mm), the inputs' period 2 s.
const START: [f64; 3] = [-131.07, 181.55, -57.74];
const AMPLITUDE: [f64; 3] = [20.0, -10.0, 20.0];

struct Mechanism {
    model: Model,
    loading: Loading,
    skcs: Vec<SkcParts>,
    plan: Plan,
}

fn compiled(text: &str, path: &str) -> Mechanism {
    let c = pkm::dsl::compile(text).unwrap_or_else(|d| panic!("{}", d.render(text, path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default())
        .unwrap_or_else(|d| panic!("{}", d.render(text, path)));
    let skcs = pkm::dsl::numeric::skc_parts(&c.analysis);
    let plan = c.forward().unwrap().clone();
    Mechanism {
        model,
        loading,
        skcs,
        plan,
    }
}

fn example(stem: &str) -> Mechanism {
    let (text, path) = common::example_text(stem);
    compiled(&text, &path)
}

/// The example with `edits` (from, to) made to its text.
fn edited(stem: &str, edits: &[(&str, &str)]) -> Mechanism {
    let (mut text, path) = common::example_text(stem);
    for (from, to) in edits {
        assert!(text.contains(from), "{path}: `{from}` not found");
        text = text.replace(from, to);
    }
    compiled(&text, &path)
}

/// §3.1's inputs, rates and accelerations at t (mm, s).
fn inputs(t: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let (s, c) = (PI * t).sin_cos();
    (
        std::array::from_fn(|i| START[i] + AMPLITUDE[i] * s),
        std::array::from_fn(|i| AMPLITUDE[i] * PI * c),
        std::array::from_fn(|i| -AMPLITUDE[i] * PI * PI * s),
    )
}

/// The three paths' forces at t on the branch `signs`, checked to agree to
/// 1e-9 of the largest; `None` where the branch does not assemble.
fn forces(m: &Mechanism, signs: &[Sign], t: f64) -> Option<[f64; 3]> {
    let (q, qd, qdd) = inputs(t);
    let values = m.plan.solve(&m.model, &q, signs).ok()?;
    let ne = inverse_dynamics(&m.model, &m.loading, &m.skcs, &values, &qd, &qdd)
        .unwrap_or_else(|e| panic!("Newton–Euler at t = {t}: {e}"));
    let vw = virtual_work::actuator_forces(&m.model, &m.loading, &values, &qd, &qdd)
        .unwrap_or_else(|e| panic!("virtual work at t = {t}: {e}"));
    let lg = lagrange::actuator_forces(&m.model, &m.plan, &m.loading, &q, signs, &qd, &qdd)
        .unwrap_or_else(|e| panic!("Lagrange at t = {t}: {e}"));
    let scale = vw.iter().fold(1e-12f64, |a, x| a.max(x.abs()));
    for k in 0..3 {
        let e = (ne.actuators[k] - vw[k]).abs().max((lg[k] - vw[k]).abs()) / scale;
        assert!(
            e < 1e-9,
            "t = {t}: f{} by Newton–Euler {}, virtual work {}, Lagrange {} (relative {e:e})",
            k + 1,
            ne.actuators[k],
            vw[k],
            lg[k]
        );
    }
    Some([vw[0], vw[1], vw[2]])
}

/// A's roots at the start: α ≈ +0.30054 (the study's branch 1, where
/// Table 3 was taken) and α ≈ −0.71059 (the text's Fig. 6a configuration).
const A_TABLE_ROOT: [Sign; 3] = [Minus, Plus, Plus];
const A_TEXT_ROOT: [Sign; 3] = [Minus, Minus, Plus];
/// B's study branch: z_E = 409.05, α = 1.3272 at the start.
const B_ROOT: [Sign; 3] = [Minus, Minus, Plus];

/// 501 samples over 0–5 s.
fn samples() -> impl Iterator<Item = f64> {
    (0..=500).map(|k| f64::from(k) * 0.01)
}

#[test]
fn mechanism_a_three_ways_over_five_seconds_on_both_roots() {
    let a = example("seed000_a");
    for (signs, root) in [(A_TABLE_ROOT, "α ≈ +0.30"), (A_TEXT_ROOT, "α ≈ −0.71")] {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for t in samples() {
            let f = forces(&a, &signs, t).unwrap_or_else(|| panic!("A assembles at t = {t} ({root})"));
            for k in 0..3 {
                lo[k] = lo[k].min(f[k]);
                hi[k] = hi[k].max(f[k]);
            }
        }
        eprintln!("A, {root}: f from {lo:?} to {hi:?} N");
    }
}

/// f depends on q, q̇² and q̈, all functions of sin(πt): f(t) = f(1 − t),
/// and the period is 2 s (f(t + 2) = f(t)).
#[test]
fn mechanism_a_forces_are_symmetric_about_half_a_second_and_periodic() {
    let a = example("seed000_a");
    for t in [0.0, 0.13, 0.37, 0.81, 1.4, 1.93] {
        let f = forces(&a, &A_TABLE_ROOT, t).unwrap();
        for other in [1.0 - t, t + 2.0] {
            let g = forces(&a, &A_TABLE_ROOT, other).unwrap();
            for k in 0..3 {
                assert!(
                    (f[k] - g[k]).abs() < 1e-9 * f[k].abs().max(1.0),
                    "t = {t}, {other}: {f:?} {g:?}"
                );
            }
        }
    }
}

/// The notes' values (issue12_seeds.md §2.6) from an independent Python
/// re-implementation of eqs. (19)–(23), at t = 0, printed to 1e-3 N.
#[test]
fn mechanism_a_at_the_start_matches_an_independent_re_implementation() {
    let close = |got: [f64; 3], want: [f64; 3], tolerance: f64, what: &str| {
        eprintln!("{what}: {got:?} against {want:?}");
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < tolerance,
                "{what}: f = {got:?} N, the notes' {want:?} N"
            );
        }
    };
    // The notes' full defaults: m_RaRb on r5 at B3, m_RcRd on pc at D, the
    // payload. Their rounding and their inertia reading (rotational terms
    // < 0.01 N in all) leave 2e-3 N; pkm is within 5e-4 N of them.
    let full = edited(
        "seed000_a",
        &[(
            "massless cross, r5, pc;",
            "massless cross; r5 { mass = 0.07183; centroid = (0, 0, 0); } pc { mass = 0.06241; centroid = (0, 0, 0); }",
        )],
    );
    close(
        forces(&full, &A_TABLE_ROOT, 0.0).unwrap(),
        [16.832, -24.455, 7.624],
        2e-3,
        "α ≈ +0.30 with RaRb, RcRd",
    );
    close(
        forces(&full, &A_TEXT_ROOT, 0.0).unwrap(),
        [30.809, -24.758, -6.051],
        2e-3,
        "α ≈ −0.71 with RaRb, RcRd",
    );
    // The equations' bodies only, no payload, on the α ≈ +0.30 root: pkm is
    // 0.4 % (≤ 0.009 N) below the notes here, which the notes' description
    // of this case does not pin down; 0.01 N is the bound they give for the
    // inertia reading.
    let bare = edited(
        "seed000_a",
        &[("loads { payload = force (0, 0, -50) on platform at G; }", "")],
    );
    close(
        forces(&bare, &A_TABLE_ROOT, 0.0).unwrap(),
        [1.876, -2.662, 0.786],
        0.01,
        "no payload",
    );
}

/// Statics (no motion) against central differences of the potential of the
/// weights and the payload, V = −Σ m g·c − F·p_G: f_k = ∂V/∂x_k. Every
/// centroid from the link poses and the named points; DB3's is the midpoint
/// of B3 (on s3) and D (on the platform), as the bar runs from one to the
/// other; the sliders' (weight normal to their guides) do no work.
#[test]
fn mechanism_a_statics_is_the_gradient_of_the_potential() {
    let a = example("seed000_a");
    let text = common::example_text("seed000_a").0;
    let analysis = pkm::dsl::analyze_source(&text).unwrap();
    let d = &analysis.mass_and_loads;
    let g = Vector3::new(0.0, 0.0, -9.80665);
    let point = |values: &[f64], name: &str| -> Vector3<f64> {
        let poses = pkm::runtime::kinematics::link_poses(&a.model, values).unwrap();
        Vector3::from(pkm::runtime::newton::point(&a.model, &poses, name).unwrap()) / 1000.0
    };
    let link_point = |values: &[f64], link: &str, local: [f64; 3]| -> Vector3<f64> {
        let poses = pkm::runtime::kinematics::link_poses(&a.model, values).unwrap();
        let l = a.model.links.iter().position(|x| x == link).unwrap();
        (poses[l] * pkm::runtime::nalgebra::Point3::from(local)).coords / 1000.0
    };
    // Potential (J) with masses as the file declares them (kg), lengths in m.
    let mass = |link: &str| {
        let l = analysis.mechanism.links.iter().position(|x| x.name == link).unwrap();
        d.masses.iter().find(|b| b.link == l).unwrap().mass
    };
    let potential = |values: &[f64]| -> f64 {
        let mut v = 0.0;
        v -= mass("platform") * g.dot(&link_point(values, "platform", [0.0, 225.0, 0.0]));
        v -= mass("c1") * g.dot(&link_point(values, "c1", [100.0, 0.0, 0.0]));
        v -= mass("c2") * g.dot(&link_point(values, "c2", [100.0, 0.0, 0.0]));
        let db3 = (point(values, "B3") + point(values, "D")) / 2.0;
        v -= d.bars[0].mass * g.dot(&db3);
        v -= Vector3::new(0.0, 0.0, -50.0).dot(&point(values, "G"));
        v
    };
    for signs in [A_TABLE_ROOT, A_TEXT_ROOT] {
        let q = START;
        let values = a.plan.solve(&a.model, &q, &signs).unwrap();
        let got = virtual_work::actuator_forces(&a.model, &a.loading, &values, &[0.0; 3], &[0.0; 3]).unwrap();
        let ne = inverse_dynamics(&a.model, &a.loading, &a.skcs, &values, &[0.0; 3], &[0.0; 3]).unwrap();
        let h = 1e-3;
        for k in 0..3 {
            let at = |dx: f64| {
                let mut qk = q;
                qk[k] += dx;
                potential(&a.plan.solve(&a.model, &qk, &signs).unwrap())
            };
            // ∂V/∂x in J per mm: N·m/mm = 1000 N.
            let want = (at(h) - at(-h)) / (2.0 * h) * 1000.0;
            assert!(
                (got[k] - want).abs() < 1e-5 * want.abs().max(1.0)
                    && (ne.actuators[k] - want).abs() < 1e-5 * want.abs().max(1.0),
                "{signs:?}: f{} by virtual work {}, Newton–Euler {}, by differences {want}",
                k + 1,
                got[k],
                ne.actuators[k]
            );
        }
    }
}

/// B along the same inputs: where it assembles the three agree; for
/// t in (1.1644, 1.8356) s, every 2 s, |C3E| > l3 + l4 and the position
/// solution fails, a typed error (no number), and `pkm dynamics` has no
/// branch there.
#[test]
fn mechanism_b_where_it_assembles_and_a_typed_failure_where_it_does_not() {
    let b = example("seed000_b");
    let (mut solved, mut failed) = (0, 0);
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for t in samples() {
        let phase = t % 2.0;
        let outside = (1.1644..=1.8356).contains(&phase);
        match forces(&b, &B_ROOT, t) {
            Some(f) => {
                assert!(!outside, "t = {t}: B assembles where |C3E| > 630 mm");
                for k in 0..3 {
                    lo[k] = lo[k].min(f[k]);
                    hi[k] = hi[k].max(f[k]);
                }
                solved += 1;
            }
            None => {
                assert!(outside, "t = {t}: B does not assemble");
                let (q, ..) = inputs(t);
                let e = b.plan.solve(&b.model, &q, &B_ROOT).unwrap_err();
                assert!(!e.to_string().is_empty());
                failed += 1;
            }
        }
    }
    // (1.1644, 1.8356) twice in 0–5 s: 2 × 67 samples of 0.01 s.
    assert_eq!((solved, failed), (501 - 134, 134));
    eprintln!(
        "B: {solved} samples solved and agreeing, f from {lo:?} to {hi:?} N; {failed} where it does not assemble"
    );
}

/// At t = 1.5 s (x = (−151.07, 191.55, −77.74)) no branch of B assembles:
/// every choice of signs is a typed error naming the loop that cannot
/// close (what `pkm dynamics` prints for that input, with exit code 1).
#[test]
fn no_branch_of_b_assembles_at_one_and_a_half_seconds() {
    let b = example("seed000_b");
    let (q, ..) = inputs(1.5);
    for bits in 0..8u8 {
        let signs: Vec<Sign> = (0..3).map(|i| if bits >> i & 1 == 1 { Minus } else { Plus }).collect();
        match b.plan.solve(&b.model, &q, &signs) {
            Ok(v) => panic!("{signs:?} assembles at t = 1.5 s: {v:?}"),
            Err(e) => assert!(e.to_string().contains("cannot close"), "{signs:?}: {e}"),
        }
    }
}
