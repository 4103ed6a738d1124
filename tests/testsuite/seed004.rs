//! Seed 004 (3-RPS and 3-SPR, §1.1 and §2): the inverse position solution
//! from the seed's (α, β, Z_A) with the parasitic (x, y, γ) the legs
//! impose. Base joints on a circle of RB = 100 mm, platform joints on one
//! of RA = 80 mm, 120° apart, joint 1 on the x (and u) axis; every R axis
//! tangent to its circle (examples/mechanisms/rps_3.pkm, spr_3.pkm).
//!
//! Checked against the seed's closed forms written out here (eq. 2 with its
//! row 1 column 3 corrected, eq. 3, eq. 4), against a hand derivation of
//! the 3-SPR's parasitic motion (the seed gives none), against Newton's
//! inverse solution, and generated against interpreted. The forward
//! solution (κ = 2, no closed-form plan) is Newton's from the home pose,
//! labelled numeric.

use crate::common;
use crate::mechanisms::{Rps, Spr};

use pkm::dsl::screw::SplitMix;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan;

/// Base radius (mm).
const RB: f64 = 100.0;
/// Platform radius (mm).
const RA: f64 = 80.0;
/// Initial height (mm).
const H: f64 = 75.0;

type M3 = [[f64; 3]; 3];
type V3 = [f64; 3];

/// The seed's eq. 2, entry by entry, with row 1 column 3 as the product
/// R_z(γ)·R_y(β)·R_x(α) has it (`sβ cγ cα + sγ sα`; printed
/// `sβ cγ sα = sγ sα`).
fn eq2(al: f64, be: f64, ga: f64) -> M3 {
    let (sa, ca, sb, cb, sg, cg) = (al.sin(), al.cos(), be.sin(), be.cos(), ga.sin(), ga.cos());
    [
        [cb * cg, sb * cg * sa - sg * ca, sb * cg * ca + sg * sa],
        [sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa],
        [-sb, cb * sa, cb * ca],
    ]
}

fn mul(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(r: &M3, v: V3) -> V3 {
    core::array::from_fn(|i| (0..3).map(|k| r[i][k] * v[k]).sum())
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// Joint i's angle θᵢ = 120°·i and the unit radial and tangent there.
fn radial(i: usize) -> (V3, V3) {
    let t = (120.0 * i as f64).to_radians();
    ([t.cos(), t.sin(), 0.0], [-t.sin(), t.cos(), 0.0])
}

/// The seed's eq. 3 γ: tan γ = sα sβ / (cα + cβ) (the principal root; γ + π
/// is the other).
fn gamma(al: f64, be: f64) -> f64 {
    (al.sin() * be.sin() / (al.cos() + be.cos())).atan()
}

/// The 3-RPS by hand (seed eqs. 1–4): platform centre p, rotation R and the
/// three leg lengths qᵢ = |p + R·aᵢ − bᵢ|.
fn rps_hand(za: f64, al: f64, be: f64) -> (V3, M3, [f64; 3]) {
    let ga = gamma(al, be);
    let (sa, ca, sb, cb, sg, cg) = (al.sin(), al.cos(), be.sin(), be.cos(), ga.sin(), ga.cos());
    // Eq. 3 (r = RA, the platform's radius; Y_A read as r (cα sγ − cγ sα sβ)).
    let x = RA * (cb * cg - sa * sb * sg - ca * cg) / 2.0;
    let y = RA * (ca * sg - cg * sa * sb);
    let p = [x, y, za];
    let r = eq2(al, be, ga);
    let legs = [0, 1, 2].map(|i| {
        let (e, _) = radial(i);
        let a = apply(&r, [RA * e[0], RA * e[1], 0.0]);
        norm(sub(
            [p[0] + a[0], p[1] + a[1], p[2] + a[2]],
            [RB * e[0], RB * e[1], 0.0],
        ))
    });
    (p, r, legs)
}

/// The 3-SPR by hand: ball i at bᵢ = RB·eᵢ on the base must lie on the
/// platform's plane through Aᵢ = RA·eᵢ normal to its revolute's axis tᵢ:
/// `tᵢ·Rᵀ(bᵢ − p) = 0`. With `Q = Rᵀ` and `p' = −Rᵀ·p` (the base's pose
/// seen from the platform) that is `tᵢ·(p' + Q·bᵢ) = 0`, the 3-RPS's
/// condition with RB for RA: `Q₁₂ = Q₂₁` (R₁₂ = R₂₁, so γ as the 3-RPS's),
/// `p'ₓ = RB (Q₁₁ − Q₂₂)/2`, `p'ᵧ = −RB·Q₂₁`; `p'_z` from `(−R·p')_z = Z_A`.
fn spr_hand(za: f64, al: f64, be: f64) -> (V3, M3, [f64; 3]) {
    let ga = gamma(al, be);
    let r = eq2(al, be, ga);
    let px = RB * (r[0][0] - r[1][1]) / 2.0;
    let py = -RB * r[0][1];
    let pz = -(za + r[2][0] * px + r[2][1] * py) / r[2][2];
    let p = apply(&r, [-px, -py, -pz]);
    let legs = [0, 1, 2].map(|i| {
        let (e, _) = radial(i);
        let a = apply(&r, [RA * e[0], RA * e[1], 0.0]);
        norm(sub(
            [p[0] + a[0], p[1] + a[1], p[2] + a[2]],
            [RB * e[0], RB * e[1], 0.0],
        ))
    });
    (p, r, legs)
}

/// Eq. 2 with the corrected entry is R_z(γ)·R_y(β)·R_x(α), multiplied out
/// here, and orthonormal; the printed entry read either way (`=` as `−` or
/// `+`: `sβ cγ sα ∓ sγ sα`) leaves column 3 off unit length: at
/// (α, β, γ) = (0.7, 0.5, 0.3) by 0.28 and 0.057.
#[test]
fn eq2_row1_col3_is_sb_cg_ca_plus_sg_sa() {
    let (c, s) = (f64::cos, f64::sin);
    let mut rng = SplitMix::new(4);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let [al, be, ga] = [0, 1, 2].map(|_| 3.0 * rng.symmetric());
        let rz = [[c(ga), -s(ga), 0.0], [s(ga), c(ga), 0.0], [0.0, 0.0, 1.0]];
        let ry = [[c(be), 0.0, s(be)], [0.0, 1.0, 0.0], [-s(be), 0.0, c(be)]];
        let rx = [[1.0, 0.0, 0.0], [0.0, c(al), -s(al)], [0.0, s(al), c(al)]];
        let product = mul(&rz, &mul(&ry, &rx));
        let r = eq2(al, be, ga);
        for i in 0..3 {
            for j in 0..3 {
                worst = worst.max((r[i][j] - product[i][j]).abs());
                let rtr: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
                worst = worst.max((rtr - f64::from(u8::from(i == j))).abs());
            }
        }
    }
    assert!(
        worst < 1e-15,
        "corrected eq. 2 off R_z·R_y·R_x or orthonormality by {worst:e}"
    );
    let [al, be, ga] = [0.7, 0.5, 0.3];
    let r = eq2(al, be, ga);
    for (sign, defect) in [(-1.0, 0.28), (1.0, 0.057)] {
        let printed = s(be) * c(ga) * s(al) + sign * s(ga) * s(al);
        let column = printed * printed + r[1][2] * r[1][2] + r[2][2] * r[2][2];
        assert!(
            ((1.0 - column).abs() - defect).abs() < 5e-3,
            "{sign}: |col 3|² = {column}"
        );
    }
}

/// The hand derivations meet the mechanisms' definitions: each 3-RPS ball
/// on the vertical plane through its base revolute normal to the axis (the
/// seed's eq. 3), each 3-SPR base ball on the platform's plane normal to
/// its revolute; Z_A and the tilt as given.
#[test]
fn hand_solutions_meet_the_definitions() {
    let mut rng = SplitMix::new(8);
    let mut worst = 0.0f64;
    for _ in 0..10_000 {
        let [za, al, be] = common::poses::seed(&mut rng);
        for (spr, (p, r, _)) in [(false, rps_hand(za, al, be)), (true, spr_hand(za, al, be))] {
            worst = worst.max((p[2] - za).abs() / RB);
            for i in 0..3 {
                let (e, t) = radial(i);
                let a = apply(&r, [RA * e[0], RA * e[1], 0.0]);
                let leg = sub([p[0] + a[0], p[1] + a[1], p[2] + a[2]], [RB * e[0], RB * e[1], 0.0]);
                let axis = if spr { apply(&r, t) } else { t };
                worst = worst.max(dot(axis, leg).abs() / RB);
            }
            // The tilt: R's third row is (−sβ, cβ sα, cβ cα) whatever γ.
            worst = worst.max((r[2][0] + be.sin()).abs() + (r[2][1] - be.cos() * al.sin()).abs());
        }
        // Eq. 3's Y_A is −RA sγ cβ (R₂₁ = R₁₂).
        let (p, r, _) = rps_hand(za, al, be);
        worst = worst.max((p[1] + RA * r[1][0]).abs() / RB);
    }
    assert!(worst < 1e-13, "worst {worst:e}");
}

/// Platform centre, rotation and leg lengths of every solved branch of a
/// generated solver, `read` giving the centre, the platform's three joint
/// points and the slides.
fn branches<S>(solutions: &[Result<S, ()>], read: impl Fn(&S) -> (V3, [V3; 3], [f64; 3])) -> Vec<(V3, M3, [f64; 3])> {
    let (c, s) = (120f64.to_radians().cos(), 120f64.to_radians().sin());
    solutions
        .iter()
        .filter_map(|r| r.as_ref().ok())
        .map(|sol| {
            let (o, pts, legs) = read(sol);
            let ex = sub(pts[0], o).map(|v| v / RA);
            let e2 = sub(pts[1], o).map(|v| v / RA);
            let ey = [0, 1, 2].map(|i| (e2[i] - c * ex[i]) / s);
            let ez = [
                ex[1] * ey[2] - ex[2] * ey[1],
                ex[2] * ey[0] - ex[0] * ey[2],
                ex[0] * ey[1] - ex[1] * ey[0],
            ];
            let r = core::array::from_fn(|i| [ex[i], ey[i], ez[i]]);
            (o, r, legs)
        })
        .collect()
}

/// How far the hand solution is from the closest branch (all legs
/// positive): lengths over RB, rotation entries.
fn distance(hand: &(V3, M3, [f64; 3]), found: &[(V3, M3, [f64; 3])]) -> f64 {
    found
        .iter()
        .filter(|(_, _, legs)| legs.iter().all(|q| *q > 0.0))
        .map(|(o, r, legs)| {
            let mut e = norm(sub(*o, hand.0)) / RB;
            for i in 0..3 {
                e = e.max((legs[i] - hand.2[i]).abs() / RB);
                e = r[i].iter().zip(&hand.1[i]).fold(e, |e, (a, b)| e.max((a - b).abs()));
            }
            e
        })
        .fold(f64::INFINITY, f64::min)
}

/// The generated 3-RPS and 3-SPR inverse solutions at 10⁵ random
/// (Z_A, α, β) each: a branch with the hand pose (principal γ) and the hand
/// leg lengths, and every branch real.
#[test]
fn ik_matches_the_hand_closed_forms() {
    let index = |names: &[&str], n: &str| names.iter().position(|p| *p == n).unwrap();
    let (ro, rs) = (
        index(&Rps::POINTS, "o"),
        [1, 2, 3].map(|k| index(&Rps::POINTS, &format!("S{k}"))),
    );
    let rp = [1, 2, 3].map(|k| index(&Rps::JOINTS, &format!("P{k}")));
    let (so, sr) = (
        index(&Spr::POINTS, "o"),
        [1, 2, 3].map(|k| index(&Spr::POINTS, &format!("R{k}"))),
    );
    let sp = [1, 2, 3].map(|k| index(&Spr::JOINTS, &format!("P{k}")));
    let mut rng = SplitMix::new(2026);
    let (mut worst_rps, mut worst_spr, mut solved) = (0.0f64, 0.0f64, [0usize; 2]);
    for _ in 0..100_000 {
        let given = common::poses::seed(&mut rng);
        let [za, al, be] = given;
        let rps: Vec<Result<_, ()>> = Rps::ik(&Default::default(), &given)
            .into_iter()
            .map(|b| b.result.map_err(|_| ()))
            .collect();
        let found = branches(&rps, |s| (s.points[ro], rs.map(|i| s.points[i]), rp.map(|j| s.q[j])));
        solved[0] += found.len();
        worst_rps = worst_rps.max(distance(&rps_hand(za, al, be), &found));
        let spr: Vec<Result<_, ()>> = Spr::ik(&Default::default(), &given)
            .into_iter()
            .map(|b| b.result.map_err(|_| ()))
            .collect();
        let found = branches(&spr, |s| (s.points[so], sr.map(|i| s.points[i]), sp.map(|j| s.q[j])));
        solved[1] += found.len();
        worst_spr = worst_spr.max(distance(&spr_hand(za, al, be), &found));
    }
    eprintln!(
        "seed 004 ik vs hand over 10⁵ poses: 3-RPS {worst_rps:e} ({} branches), 3-SPR {worst_spr:e} ({} branches)",
        solved[0], solved[1]
    );
    assert!(worst_rps < 1e-12 && worst_spr < 1e-12, "{worst_rps:e} {worst_spr:e}");
    // Two parasitic roots (γ, γ + π), each leg in two senses: 16 branches.
    assert_eq!(solved, [16 * 100_000; 2]);
}

/// The seed's home pose (Z_A = H, level): both mechanisms' legs are
/// √((RB − RA)² + H²) = √(20² + 75²) = 77.6209 mm on the branch with the
/// platform unturned, √((RB + RA)² + H²) = 195 mm with it turned by π;
/// no parasitic motion.
#[test]
fn home_pose_legs() {
    let near = ((RB - RA).powi(2) + H * H).sqrt();
    let far = ((RB + RA).powi(2) + H * H).sqrt();
    let slides = |names: &[&str]| [1, 2, 3].map(|k| names.iter().position(|j| *j == format!("P{k}")).unwrap());
    let legs: Vec<[f64; 3]> = Rps::ik(&Default::default(), &[H, 0.0, 0.0])
        .into_iter()
        .map(|b| slides(&Rps::JOINTS).map(|j| b.result.as_ref().unwrap().q[j]))
        .chain(
            Spr::ik(&Default::default(), &[H, 0.0, 0.0])
                .into_iter()
                .map(|b| slides(&Spr::JOINTS).map(|j| b.result.as_ref().unwrap().q[j])),
        )
        .collect();
    assert_eq!(legs.len(), 32);
    let count = |l: f64| {
        legs.iter()
            .filter(|q| q.iter().all(|v| (v.abs() - l).abs() < 1e-12))
            .count()
    };
    assert_eq!((count(near), count(far)), (16, 16), "{legs:?}");
    for (p, _, legs) in [rps_hand(H, 0.0, 0.0), spr_hand(H, 0.0, 0.0)] {
        assert!(p[0].abs() < 1e-15 && p[1].abs() < 1e-15 && legs.iter().all(|q| (q - near).abs() < 1e-12));
    }
}

#[test]
fn rps_inverse_agrees_with_newton() {
    common::inverse_agrees_with_newton("rps_3", 3000, common::poses::seed, |given| {
        Rps::ik(&Default::default(), given)
            .into_iter()
            .map(|b| b.result.map(|s| s.q.to_vec()).map_err(|_| ()))
            .collect()
    });
}

#[test]
fn spr_inverse_agrees_with_newton() {
    common::inverse_agrees_with_newton("spr_3", 3000, common::poses::seed, |given| {
        Spr::ik(&Default::default(), given)
            .into_iter()
            .map(|b| b.result.map(|s| s.q.to_vec()).map_err(|_| ()))
            .collect()
    });
}

/// The forward solution, numeric (κ = 2, no closed-form plan): Newton's
/// from the home pose (Z_A = H, level, legs positive, γ = 0) given the
/// hand leg lengths of 1000 random poses, converges to the hand pose, i.e.
/// the forward solution of the assembly mode the home pose is in.
#[test]
fn numeric_fk_from_home_recovers_the_hand_pose() {
    for (name, hand) in [
        ("rps_3", rps_hand as fn(f64, f64, f64) -> (V3, M3, [f64; 3])),
        ("spr_3", spr_hand),
    ] {
        let (a, model) = common::example(name);
        let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
        let platform = model.links.iter().position(|l| l == "platform").unwrap();
        let home = plan::run_all(&model, &plan, &[H, 0.0, 0.0])
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .find(|s| {
                let frame = plan::frame_of(&s.poses[platform]);
                model.inputs().iter().all(|&j| s.values[j] > 0.0) && frame.r[0][0] > 0.5
            })
            .unwrap_or_else(|| panic!("{name}: no home branch"));
        let start = home.model_values(&model);
        let o = model.points.iter().find(|p| p.name == "o").unwrap().at;
        let options = NewtonOptions {
            tolerance: 1e-13,
            ..NewtonOptions::default()
        };
        let mut rng = SplitMix::new(9);
        let (mut converged, mut worst) = (0, 0.0f64);
        for _ in 0..1000 {
            let [za, al, be] = common::poses::seed(&mut rng);
            let (p, r, legs) = hand(za, al, be);
            let Ok(sol) = newton::solve_fk(&model, &legs, &start, &options) else {
                continue;
            };
            let pose = sol.poses[platform];
            let at = pose * pkm::runtime::nalgebra::Point3::from(o);
            let m = pose.rotation.to_rotation_matrix();
            let mut e = norm(sub([at.x, at.y, at.z], p)) / RB;
            for i in 0..3 {
                for j in 0..3 {
                    e = e.max((m[(i, j)] - r[i][j]).abs());
                }
            }
            worst = worst.max(e);
            converged += usize::from(e < 1e-9);
        }
        eprintln!("{name}: numeric fk from home, {converged}/1000 at the hand pose (worst {worst:e})");
        assert_eq!(converged, 1000, "{name}: worst {worst:e}");
    }
}

/// The 3-SPR given z, rx and rz (x, y and ry left to it): with ry free the
/// rows of its limbs' planes are not linear in the free coordinates, and
/// the planner refuses with a message naming them instead of planning.
#[test]
fn held_limbs_refuse_a_free_ry() {
    let (text, path) = common::example_text("spr_3");
    let bad = text.replace(
        "ZA, alpha, beta = pose (z, rx, ry)",
        "ZA, alpha, gamma = pose (z, rx, rz)",
    );
    assert_ne!(bad, text, "{path}: the outputs line moved");
    let a = pkm::dsl::analyze_source(&bad).unwrap_or_else(|d| panic!("{}", d.render(&bad, &path)));
    let e = pkm::dsl::planner::inverse_plan(&a).unwrap_err().render(&bad, &path);
    assert!(
        e.contains("leave x, y, ry to the mechanism") && e.contains("rz free"),
        "{e}"
    );
}
