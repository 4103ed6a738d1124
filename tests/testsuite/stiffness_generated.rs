//! Generated `stiffness` (capability `stiffness`: twists and centres traced
//! from the inverse solution, written out) against the interpreter's path,
//! which shares no generated code: the plan interpreter's inverse solution,
//! `wrench::analyse` on its link poses, the file's limbs evaluated by
//! `limb_properties` and `stiffness::stiffness`, as `pkm stiffness` runs it.
//! On every branch at random poses of 3-RPS and 3-SPR (seed 004) and the
//! 6-UPS: the same reference point, rows of `J`, springs, `K`, directional
//! stiffnesses and deflection, or the same kind of failure; the deflection
//! helper checked against `K δ = W`; bad input typed.

use crate::common;
use crate::mechanisms::{
    Prs, PrsParams, Rps, RpsParameters, RpsParametersParams, RpsParams, Spr, SprParams, Ups, UpsParams, Upu, UpuParams,
};

use pkm::dsl::screw::SplitMix;
use pkm::runtime::nalgebra::{Matrix6, Vector6};
use pkm::runtime::plan;
use pkm::runtime::primitives::Sign;
use pkm::runtime::stiffness::{PlatformStiffness, Stiffness, StiffnessError};
use pkm::runtime::wrench::{self, WrenchAnalysis};
use std::collections::HashMap;

/// The seed's load, F = (10, −15, 20) N and T = (−20, 10, 15) N·m = (−2, 1,
/// 1.5)·10⁴ N·mm, about the reference point.
const W: [f64; 6] = [10.0, -15.0, 20.0, -2.0e4, 1.0e4, 1.5e4];

type Generated<'a> = &'a dyn Fn(&[f64], &[Sign]) -> Result<PlatformStiffness, StiffnessError>;

/// The interpreter's stiffness of the mechanism `a` at the parameters
/// `values` at every branch of `given`: per branch, its signs and the wrench analysis, the stiffness
/// and the reference point, or why there is none.
#[allow(clippy::type_complexity)]
fn interpreted(
    a: &pkm::dsl::Analysis,
    values: &HashMap<String, f64>,
    given: &[f64],
) -> Vec<(Vec<Sign>, Result<(WrenchAnalysis, Stiffness, [f64; 3]), String>)> {
    let model = pkm::dsl::numeric::model(a, values).unwrap();
    let plan = pkm::dsl::planner::inverse_plan(a).unwrap();
    let outputs = pkm::dsl::numeric::newton_outputs(a, &model, values).unwrap();
    let (link, local) = outputs.iter().find_map(|o| o.point()).unwrap();
    let limbs = pkm::dsl::numeric::limb_properties(a, values).unwrap();
    plan::run_all(&model, &plan, given)
        .into_iter()
        .map(|(signs, solution)| {
            let result = solution.map_err(|e| format!("position: {e}")).and_then(|s| {
                let analysis = wrench::analyse(&model, &s, link).map_err(|e| e.to_string())?;
                let declared = pkm::dsl::limb_properties::in_analysis_order(&limbs, &analysis.limbs).unwrap();
                let properties: Vec<_> = declared.iter().map(|d| d.properties()).collect();
                let k = pkm::runtime::stiffness::stiffness(&analysis, &properties).map_err(|e| e.to_string())?;
                Ok((analysis, k, plan::at(&s.poses[link], local)))
            });
            (signs, result)
        })
        .collect()
}

/// `D M D`, `D = diag(s, s, s, 1, 1, 1)`: a stiffness matrix's entries all
/// in force × length, to compare them on one scale.
fn scaled(m: &Matrix6<f64>, s: f64) -> Matrix6<f64> {
    let d = Vector6::new(s, s, s, 1.0, 1.0, 1.0);
    Matrix6::from_fn(|i, j| m[(i, j)] * d[i] * d[j])
}

/// Generated against interpreted on every branch at `n` random poses of
/// example `name`: both succeed or fail together and fail alike, and
/// where they succeed they agree within 1e-9 (relative).
fn agreement(name: &str, pose: fn(&mut SplitMix) -> Vec<f64>, n: usize, generated: Generated) {
    let (a, _) = common::example(name);
    agreement_of(name, &a, pose, n, generated)
}

/// [`agreement`] for the mechanism `a` at its default parameters.
fn agreement_of(
    name: &str,
    a: &pkm::dsl::Analysis,
    pose: fn(&mut SplitMix) -> Vec<f64>,
    n: usize,
    generated: Generated,
) {
    let values = HashMap::new();
    let mut rng = SplitMix::new(2026);
    let mut worst = 0.0f64;
    let mut solved = 0;
    for _ in 0..n {
        let given = pose(&mut rng);
        for (signs, want) in interpreted(a, &values, &given) {
            let got = generated(&given, &signs);
            let (analysis, k, point, g) = match (want, got) {
                (Ok(w), Ok(g)) => {
                    solved += 1;
                    let (analysis, k, point) = w;
                    let s = k.scale;
                    let size = |p: &[f64; 3]| p.iter().map(|x| x.abs()).fold(s, f64::max);
                    // The reference point.
                    let dp = (0..3).map(|i| (g.point[i] - point[i]).abs()).fold(0.0, f64::max);
                    worst = worst.max(dp / size(&point));
                    // The rows of J (moments over the size) and their springs.
                    assert_eq!(g.wrenches.rows.len(), analysis.rows.len(), "{name} {given:?}");
                    for (a, b) in g.wrenches.rows.iter().zip(&analysis.rows) {
                        assert_eq!(a.kind, b.kind, "{name} {given:?}");
                        let (ra, rb) = (a.wrench.row(), b.wrench.row());
                        let d = (0..6)
                            .map(|c| (ra[c] - rb[c]).abs() / if c < 3 { 1.0 } else { s })
                            .fold(0.0, f64::max);
                        worst = worst.max(d);
                    }
                    for (a, b) in g.stiffness.springs.iter().zip(&k.springs) {
                        worst = worst.max((a - b).abs() / b.abs());
                    }
                    // K at the reference point, on one scale.
                    let (kg, kw) = (scaled(&g.k(), s), scaled(&k.at(point), s));
                    worst = worst.max((kg - kw).amax() / kw.amax());
                    (analysis, k, point, g)
                }
                (Err(w), Err(g)) => {
                    // Both fail: alike (both in the position, or the same singularity).
                    let same = match &g {
                        StiffnessError::Position(_) => w.starts_with("position: "),
                        other => w == other.to_string(),
                    };
                    assert!(same, "{name} {given:?} {signs:?}: interpreted `{w}`, generated `{g}`");
                    continue;
                }
                (w, g) => panic!(
                    "{name} {given:?} {signs:?}: interpreted {:?}, generated {:?}",
                    w.map(|_| "ok"),
                    g.map(|_| "ok")
                ),
            };
            // The deflection helper: K δ = W, and as the interpreter's.
            let delta = g.deflection(&W).unwrap();
            let back = g.k() * Vector6::from(delta);
            let residual = (0..6).map(|i| (back[i] - W[i]).abs()).fold(0.0, f64::max);
            let load = W.iter().map(|x| x.abs()).fold(0.0, f64::max);
            assert!(residual <= 1e-8 * load, "{name} {given:?}: K δ − W = {residual:e}");
            let want = k.deflection(&W, point).unwrap();
            let s = analysis.scale;
            let d = (0..6)
                .map(|i| (delta[i] - want[i]).abs() * if i < 3 { 1.0 / s } else { 1.0 })
                .fold(0.0, f64::max);
            let size = want[..3]
                .iter()
                .map(|x| x.abs() / s)
                .chain(want[3..].iter().map(|x| x.abs()))
                .fold(0.0, f64::max);
            worst = worst.max(d / size);
            let (dg, dw) = (g.directional().unwrap(), k.directional(point).unwrap());
            for i in 0..6 {
                worst = worst.max((dg[i] - dw[i]).abs() / dw[i]);
            }
        }
    }
    assert!(solved >= n, "{name}: only {solved} branches solved at {n} poses");
    eprintln!("{name}: {solved} branches at {n} poses, generated against interpreted within {worst:e}");
    assert!(worst <= 1e-9, "{name}: {worst:e}");
}

#[test]
fn rps_3_generated_agrees_with_the_interpreter() {
    let p = Rps::prepare(&RpsParams::default());
    agreement("rps_3", |r| common::poses::seed(r).to_vec(), 40, &|g, s| {
        p.stiffness(g.try_into().unwrap(), s.try_into().unwrap())
    });
}

#[test]
fn spr_3_generated_agrees_with_the_interpreter() {
    let p = Spr::prepare(&SprParams::default());
    agreement("spr_3", |r| common::poses::seed(r).to_vec(), 40, &|g, s| {
        p.stiffness(g.try_into().unwrap(), s.try_into().unwrap())
    });
}

#[test]
fn ups_6_generated_agrees_with_the_interpreter() {
    let p = Ups::prepare(&UpsParams::default());
    agreement("ups_6", |r| common::poses::ups(r).to_vec(), 5, &|g, s| {
        p.stiffness(g.try_into().unwrap(), s.try_into().unwrap())
    });
}

/// Other joints: the 3-PRS (actuated slides on the base, an R–S leg of
/// fixed length, the drive in series through the transmission) and the
/// translational 3-UPU (each leg's constraint a couple, its spring E·I/L).
#[test]
fn prs_3_and_upu_3_generated_agree_with_the_interpreter() {
    let p = Prs::prepare(&PrsParams::default());
    agreement("prs_3", |r| common::poses::tilt(r).to_vec(), 20, &|g, s| {
        p.stiffness(g.try_into().unwrap(), s.try_into().unwrap())
    });
    let p = Upu::prepare(&UpuParams::default());
    agreement("upu_3", |r| common::poses::upu(r).to_vec(), 20, &|g, s| {
        p.stiffness(g.try_into().unwrap(), s.try_into().unwrap())
    });
    // The couples: one per leg, their springs E·I/L.
    let k = Upu::stiffness(
        &UpuParams::default(),
        &[0.0, 0.0, 200.0],
        signs_of_first(&Upu::ik(&UpuParams::default(), &[0.0, 0.0, 200.0])),
    )
    .unwrap();
    let couples: Vec<usize> = k
        .wrenches
        .rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.kind == wrench::RowKind::ConstraintCouple)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(couples.len(), 3);
    for i in couples {
        let limb = &k.wrenches.limbs[k.wrenches.rows[i].limb];
        let hand = 2.11e5 * std::f64::consts::PI * 40f64.powi(4) / 64.0 / limb.length().unwrap();
        let got = k.stiffness.springs[i];
        assert!((got - hand).abs() <= 1e-12 * hand, "{got} vs E·I/L = {hand}");
    }
}

/// The signs of the first solved branch.
fn signs_of_first<S, const B: usize>(all: &[pkm::runtime::solution::Branch<S, B>]) -> [Sign; B] {
    all.iter().find(|b| b.result.is_ok()).map(|b| b.signs).unwrap()
}

/// The signs of the branch with the shortest legs at a pose (the
/// assembly the seed means: the platform above the base, level at home).
fn rps_up(given: &[f64; 3]) -> [Sign; 4] {
    let legs = |q: &[f64; 9]| q[1].abs() + q[4].abs() + q[7].abs();
    Rps::ik(&RpsParams::default(), given)
        .iter()
        .filter_map(|b| b.result.as_ref().ok().map(|s| (legs(&s.q), b.signs)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, signs)| signs)
        .unwrap()
}

/// What the generated function says of bad input and of singular
/// configurations: typed errors, never NaN.
#[test]
fn bad_input_and_singularities_are_typed() {
    let params = RpsParams::default();
    // A pose that is not finite.
    let signs = rps_up(&[75.0, 0.0, 0.0]);
    let e = Rps::stiffness(&params, &[f64::NAN, 0.0, 0.0], signs).unwrap_err();
    assert!(
        matches!(
            e,
            StiffnessError::Position(pkm::runtime::solution::SolveError::BadInput { .. })
        ),
        "{e}"
    );
    // The platform level in the base plane: the legs (20 mm) lie in it
    // with the constraint forces, and all six wrenches are forces in that
    // plane; a typed actuation singularity.
    let signs = rps_up(&[0.0, 0.0, 0.0]);
    let e = Rps::stiffness(&params, &[0.0, 0.0, 0.0], signs).unwrap_err();
    assert!(
        matches!(
            e,
            StiffnessError::Wrench(wrench::WrenchError::ActuationSingularity { limb: None, .. })
        ),
        "{e}"
    );
    // A deflection under a wrench that is not finite.
    let k = Rps::stiffness(&params, &[75.0, 0.0, 0.0], rps_up(&[75.0, 0.0, 0.0])).unwrap();
    let e = k.deflection(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, StiffnessError::NonFinite { .. }), "{e}");
}

/// The seed 004 table's first pose (home, H = 75 mm) by the generated
/// function against K = Jᵀ K_p J written out by hand for the 3-RPS: legs
/// vertical-in-plane from Bᵢ (100 mm out) to Aᵢ (80 mm out, 75 up), length
/// L = √(20² + 75²); the actuation force along the leg, the constraint
/// force along the R axis (tangent) through Aᵢ; k_a = E·A/L, k_b = 3·E·I/L³.
#[test]
fn rps_3_home_by_hand() {
    let k = Rps::stiffness(&RpsParams::default(), &[75.0, 0.0, 0.0], rps_up(&[75.0, 0.0, 0.0])).unwrap();
    let (e, area, inertia) = (2.11e5, std::f64::consts::PI * 400.0, 1.256e5);
    let len = 20f64.hypot(75.0);
    let (ka, kb) = (e * area / len, 3.0 * e * inertia / len.powi(3));
    let mut hand = Matrix6::zeros();
    for i in 0..3 {
        let t = (120.0 * i as f64).to_radians();
        let (c, s) = (t.cos(), t.sin());
        let a = pkm::runtime::nalgebra::Vector3::new(80.0 * c, 80.0 * s, 0.0);
        let b = pkm::runtime::nalgebra::Vector3::new(100.0 * c, 100.0 * s, -75.0);
        let along = (a - b).normalize();
        let tangent = pkm::runtime::nalgebra::Vector3::new(-s, c, 0.0);
        // Moments about the reference point (the platform centre, at a's level).
        for (f, kk) in [(along, ka), (tangent, kb)] {
            let m = a.cross(&f);
            let w = Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
            hand += w * w.transpose() * kk;
        }
    }
    let at = [0.0, 0.0, 75.0];
    assert!(
        (0..3).all(|i| (k.point[i] - at[i]).abs() <= 1e-12 * 100.0),
        "{:?}",
        k.point
    );
    let (got, want) = (scaled(&k.k(), 80.0), scaled(&hand, 80.0));
    let d = (got - want).amax() / want.amax();
    assert!(d <= 1e-12, "{d:e}\n{got}\n{want}");
}

/// Limb properties read from parameters: at their defaults the generated
/// function agrees with the interpreter (limbs by section with an actuator
/// in series, and by springs); a Young's modulus that is not positive, or
/// not a number, is a typed error naming the limb and the property.
#[test]
fn limb_properties_from_parameters() {
    let path = format!(
        "{}/tests/fixtures/rps_3_limb_parameters.pkm",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let a = pkm::dsl::analyze_source(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let p = RpsParameters::prepare(&RpsParametersParams::default());
    agreement_of(
        "rps_3_limb_parameters",
        &a,
        |r| common::poses::seed(r).to_vec(),
        20,
        &|g, s| p.stiffness(g.try_into().unwrap(), s.try_into().unwrap()),
    );
    let home = [75.0, 0.0, 0.0];
    let signs = rps_up(&home);
    for bad in [-2.11e5, 0.0, f64::NAN] {
        let params = RpsParametersParams {
            E: bad,
            ..Default::default()
        };
        let e = RpsParameters::stiffness(&params, &home, signs).unwrap_err();
        assert!(
            matches!(e, StiffnessError::BadProperty { limb: 0, what: "E", .. }),
            "E = {bad}: {e}"
        );
    }
    let params = RpsParametersParams {
        k_act: -1.0,
        ..Default::default()
    };
    let e = RpsParameters::stiffness(&params, &home, signs).unwrap_err();
    assert!(
        matches!(
            e,
            StiffnessError::BadProperty {
                what: "the actuator stiffness",
                ..
            }
        ),
        "{e}"
    );
}
