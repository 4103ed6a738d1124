//! No wrong answer marked ok: declared outputs that over-determine the
//! mechanism (seed 000's four pose values for three DOF; a four-bar given a
//! coupler point and its rocker angle) are checked, and a pose the
//! mechanism cannot reach is a typed error naming the output the others
//! contradict, with the nearest reachable value. The independent check of
//! every `ok` answer: the forward solution at its inputs must reproduce
//! the given outputs to 1e-9 of the mechanism's extent.

use crate::common;
use crate::mechanisms::{
    FiveBarPa, FiveBarPaParams, FourBarOver, FourBarOverParams, SeedA, SeedAParams, SeedB, SeedBParams,
};

use pkm::runtime::consistency::Contradicted;
use pkm::runtime::solution::SolveError;
use std::f64::consts::PI;

/// The case: y is fixed at −300 for mechanism A (its platform's POC
/// set has no translation along y); y = −250 must be refused on every
/// branch, naming y and the reachable −300.
#[test]
fn seed000_a_refuses_a_y_it_cannot_reach() {
    let p = SeedAParams::default();
    for b in SeedA::ik(&p, &[37.79, -250.0, 238.9192, -0.7097]) {
        match b.result {
            Err(SolveError::Inconsistent {
                contradicted: Some(c),
                gap,
                ..
            }) => {
                let Contradicted {
                    name, given, nearest, ..
                } = *c;
                assert_eq!((name.as_ref(), given), ("y", -250.0));
                assert!((nearest + 300.0).abs() < 1e-9, "nearest y = {nearest}");
                assert!((gap - 50.0).abs() < 1e-6, "gap {gap}");
            }
            other => panic!("branch {:?}: {other:?}", b.signs),
        }
    }
    // At y = −300 the same pose is reached on every branch (eight, each
    // with the R5–parallelogram leg in either posture).
    let ok = SeedA::ik(&p, &[37.79, -300.0, 238.9192, -0.7097]);
    assert_eq!(ok.iter().filter(|b| b.result.is_ok()).count(), 16);
}

/// Random reachable poses pushed 1e-9 … 10 length units off in a random
/// direction of the output space: every ok answer closes and reproduces its
/// pose to 1e-9 by the Newton reference's model; every refusal is typed.
macro_rules! held_out {
    ($ty:ident, $params:ident, $file:expr, $point:expr, $axis:expr, $ranges:expr, $seed:expr) => {{
        let p = $params::default();
        let (_, model) = common::example($file);
        let ranges: [(f64, f64); 3] = $ranges;
        let mut rng = pkm::dsl::screw::SplitMix::new($seed);
        let (mut ok, mut refused, mut worst) = (0usize, 0usize, 0.0f64);
        let mut poses = 0;
        while poses < 300 {
            let q = ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
            let Some(s) = $ty::fk(&p, &q).into_iter().find_map(|b| b.result.ok()) else {
                continue;
            };
            poses += 1;
            let extent = pkm::runtime::consistency::extent(&s.points);
            let (given, d) = common::pushed_off(&mut rng, &s.outputs, extent);
            for b in $ty::ik(&p, &given) {
                match b.result {
                    Ok(sol) => {
                        let e = common::inconsistency(&model, &sol.q, $point, $axis, &given, extent);
                        worst = worst.max(e);
                        assert!(
                            e <= 1e-9,
                            "{}: pose {given:?} ({d:e} off) ok but inconsistent by {e:e}",
                            stringify!($ty)
                        );
                        ok += 1;
                    }
                    Err(
                        SolveError::Inconsistent { .. }
                        | SolveError::Unreachable { .. }
                        | SolveError::DoubleRoot { .. },
                    ) => refused += 1,
                    Err(e) => panic!("{}: {e}", stringify!($ty)),
                }
            }
        }
        eprintln!("{}: {ok} ok (worst {worst:.1e}), {refused} refused", stringify!($ty));
        assert!(ok > 0 && refused > 0);
    }};
}

#[test]
fn held_out_poses_near_the_reachable_set() {
    let ranges = [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)];
    held_out!(SeedA, SeedAParams, "seed000_a", "o", [1.0, 0.0, 0.0], ranges, 11);
    held_out!(SeedB, SeedBParams, "seed000_b", "E", [-1.0, 0.0, 0.0], ranges, 12);
    let ranges = [(-PI, PI), (-PI, PI), (-300.0, 300.0)];
    held_out!(
        FiveBarPa,
        FiveBarPaParams,
        "five_bar_pa",
        "o",
        [1.0, 0.0, 0.0],
        ranges,
        13
    );
}

/// The planar case: the given point and angle disagree by 1 mm in y.
#[test]
fn four_bar_given_a_point_and_an_angle() {
    let p = FourBarOverParams::default();
    let s = FourBarOver::fk(&p, &[0.3])
        .into_iter()
        .find_map(|b| b.result.ok())
        .unwrap();
    let [x, y, psi] = s.outputs;
    assert!(FourBarOver::ik(&p, &[x, y, psi]).iter().any(|b| b.result.is_ok()));
    for b in FourBarOver::ik(&p, &[x, y + 1.0, psi]) {
        match b.result {
            Err(SolveError::Inconsistent {
                contradicted: Some(c), ..
            }) => {
                // Moving y alone by 1 (or x, if it moves less) makes it consistent.
                assert!(c.name == "y" || c.name == "x" || c.name == "psi", "{c:?}");
                assert!((c.given - c.nearest).abs() <= 1.0 + 1e-9, "{c:?}");
            }
            Err(SolveError::Unreachable { .. }) => {}
            other => panic!("{other:?}"),
        }
    }
}

// A four-bar whose coupler and rocker fold into one line (|R2R4| = l2 + l3 =
// 250) at the crank angle θ* with cos θ* = (l1² + l4² − 250²)/(2·l1·l4) = 0.625.
pkm::mechanism!(
    FoldingFourBar,
    "mechanism folding_four_bar {
    capabilities fk;
    planar;
    base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
    parameters { l1 = 100; l2 = 150; l3 = 100; l4 = 300; }
    geometry {
        base    { R1 = (0, 0); R4 = (l4, 0); }
        crank   { R1 = (0, 0); R2 = (l1, 0); }
        coupler { R2 = (0, 0); R3 = (l2, 0); }
        rocker  { R3 = (l3, 0); R4 = (0, 0); }
    }
}"
);

/// At the fold the dyad's two roots are one (a double root): fk lists it
/// once, flagged `tangent`, and the other branch names it as its twin, in
/// generated code and in the interpreter alike; just inside the fold both
/// branches are distinct solutions again.
#[test]
fn a_double_root_is_flagged_not_repeated() {
    let p = FoldingFourBarParams::default();
    let theta = 0.625f64.acos();
    let all = FoldingFourBar::fk(&p, &[theta]);
    assert!(all[0].result.is_ok() && all[0].tangent, "{:?}", all[0]);
    assert_eq!(all[1].result, Err(SolveError::DoubleRoot { twin: 0 }));
    let a = pkm::dsl::analyze_source(
        "mechanism folding_four_bar { planar; base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
         parameters { l1 = 100; l2 = 150; l3 = 100; l4 = 300; }
         geometry { base { R1 = (0, 0); R4 = (l4, 0); } crank { R1 = (0, 0); R2 = (l1, 0); }
                    coupler { R2 = (0, 0); R3 = (l2, 0); } rocker { R3 = (l3, 0); R4 = (0, 0); } } }",
    )
    .unwrap();
    let model = pkm::dsl::numeric::model(&a, &Default::default()).unwrap();
    let plan = pkm::dsl::planner::forward_plan(&a).unwrap();
    let run = pkm::runtime::plan::run_all(&model, &plan, &[theta]);
    assert!(run[0].1.is_ok());
    assert_eq!(run[1].1, Err(SolveError::DoubleRoot { twin: 0 }));
    // 1e-6 rad inside the fold (a smaller crank angle brings R2 nearer R4):
    // two distinct assemblies.
    let inside = FoldingFourBar::fk(&p, &[theta - 1e-6]);
    assert!(inside.iter().all(|b| b.result.is_ok() && !b.tangent));
}
