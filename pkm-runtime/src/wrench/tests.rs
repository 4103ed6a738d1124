//! The wrench analysis's tests, by hand.

use super::*;
use crate::model::{Joint, Place};
use nalgebra::Translation3;

/// A 3-RPS at its home pose, its legs vertical: base revolute i at
/// (r cos θᵢ, r sin θᵢ, 0), θᵢ = 120°·i, axis tangent (−sin θᵢ, cos θᵢ, 0);
/// the leg's slide along z; the ball i at height h above it, on the
/// platform (at (0, 0, h)) at radius r. Links: base, then (Ai1, Ai2)
/// per leg, then the platform. Poses by hand.
pub(crate) fn home_rps(r: f64, h: f64) -> (Model, Vec<Isometry3<f64>>, Vec<f64>) {
    let mut links = vec!["base".to_string()];
    let mut joints = Vec::new();
    let mut poses = vec![Isometry3::identity()];
    let platform = 7;
    for i in 0..3 {
        let t = (120.0 * i as f64).to_radians();
        let at = [r * t.cos(), r * t.sin(), 0.0];
        let axis = [-t.sin(), t.cos(), 0.0];
        let (a1, a2) = (1 + 2 * i, 2 + 2 * i);
        links.push(format!("A{i}1"));
        links.push(format!("A{i}2"));
        poses.push(Isometry3::from_parts(Translation3::from(at), Default::default()));
        poses.push(Isometry3::from_parts(
            Translation3::new(at[0], at[1], h),
            Default::default(),
        ));
        joints.push(Joint {
            name: format!("R{i}"),
            kind: JointType::R,
            links: [0, a1],
            places: [Place::Axis { at, axis }, Place::Axis { at: [0.0; 3], axis }],
            actuated: false,
        });
        joints.push(Joint {
            name: format!("P{i}"),
            kind: JointType::P,
            links: [a1, a2],
            places: [
                Place::Line {
                    through: [0.0; 3],
                    along: [0.0, 0.0, 1.0],
                },
                Place::Point { at: [0.0; 3] },
            ],
            actuated: true,
        });
        joints.push(Joint {
            name: format!("S{i}"),
            kind: JointType::S,
            links: [a2, platform],
            places: [Place::Point { at: [0.0; 3] }, Place::Point { at }],
            actuated: false,
        });
    }
    links.push("platform".into());
    poses.push(Isometry3::from_parts(
        Translation3::new(0.0, 0.0, h),
        Default::default(),
    ));
    let values = (0..9).map(|j| if j % 3 == 1 { h } else { 0.0 }).collect();
    let model = Model {
        name: "rps".into(),
        planar: false,
        links,
        joints,
        points: vec![],
    };
    (model, poses, values)
}

/// The 3-SPR at its home pose: as [`home_rps`] with each leg turned
/// over, the ball on the base at (r cos θᵢ, r sin θᵢ, 0), the slide
/// along z, the revolute (axis tangent) at height h on the platform.
fn home_spr(r: f64, h: f64) -> (Model, Vec<Isometry3<f64>>, Vec<f64>) {
    let (mut model, poses, values) = home_rps(r, h);
    for i in 0..3 {
        let t = (120.0 * i as f64).to_radians();
        let at = [r * t.cos(), r * t.sin(), 0.0];
        let axis = [-t.sin(), t.cos(), 0.0];
        let (a1, a2) = (1 + 2 * i, 2 + 2 * i);
        model.joints[3 * i] = Joint {
            name: format!("S{i}"),
            kind: JointType::S,
            links: [0, a1],
            places: [Place::Point { at }, Place::Point { at: [0.0; 3] }],
            actuated: false,
        };
        model.joints[3 * i + 2] = Joint {
            name: format!("R{i}"),
            kind: JointType::R,
            links: [a2, 7],
            places: [Place::Axis { at: [0.0; 3], axis }, Place::Axis { at, axis }],
            actuated: false,
        };
    }
    (model, poses, values)
}

/// The home 3-SPR by hand: leg i's actuation force is the same vertical
/// line as the 3-RPS's, through the revolute's point (r cos θ, r sin θ,
/// h); its constraint force runs along the revolute's axis u through
/// the ball on the base, moment (r cos θ, r sin θ, 0) × u = (0, 0, r):
/// a line that misses the limb's distal centre, found all the same.
#[test]
fn home_spr_rows_by_hand() {
    let (r, h) = (100.0, 75.0);
    let (model, poses, values) = home_spr(r, h);
    let a = analyse_poses(&model, &poses, &values, 7).unwrap();
    assert_eq!((a.actuation, a.rows.len()), (3, 6));
    for i in 0..3 {
        let t = (120.0 * i as f64).to_radians();
        let (s, c) = t.sin_cos();
        assert!(
            close(&a.rows[i].wrench, [0.0, 0.0, 1.0], [r * s, -r * c, 0.0]),
            "{:?}",
            a.rows[i]
        );
        let sign = if s.abs() > c.abs() { -s.signum() } else { c.signum() };
        let con = &a.rows[3 + i];
        assert_eq!(con.kind, RowKind::ConstraintForce);
        assert!(
            close(&con.wrench, [-s * sign, c * sign, 0.0], [0.0, 0.0, r * sign]),
            "{con:?}"
        );
        assert!((a.limbs[i].length().unwrap() - h).abs() < 1e-12);
    }
}

fn close(a: &Wrench, f: [f64; 3], m: [f64; 3]) -> bool {
    (a.f - Vector3::from(f)).norm() < 1e-12 && (a.m - Vector3::from(m)).norm() < 1e-10
}

/// The legs of the home 3-RPS by hand: leg i's actuation force is
/// (0, 0, 1) through its ball (r cos θ, r sin θ, h), moment
/// c × e_z = (r sin θ, −r cos θ, 0); its constraint force is the unit
/// tangent u = (−sin θ, cos θ, 0) through the ball, moment
/// c × u = (−h cos θ, −h sin θ, r).
#[test]
fn home_rps_rows_by_hand() {
    let (r, h) = (100.0, 75.0);
    let (model, poses, values) = home_rps(r, h);
    let a = analyse_poses(&model, &poses, &values, 7).unwrap();
    assert_eq!(a.limbs.len(), 3);
    assert_eq!(a.actuation, 3);
    assert_eq!(a.rows.len(), 6);
    for i in 0..3 {
        let t = (120.0 * i as f64).to_radians();
        let (s, c) = t.sin_cos();
        let act = &a.rows[i];
        assert!(close(&act.wrench, [0.0, 0.0, 1.0], [r * s, -r * c, 0.0]), "{act:?}");
        assert!((act.transmission - 1.0).abs() < 1e-12);
        let con = &a.rows[3 + i];
        assert_eq!(con.kind, RowKind::ConstraintForce);
        assert_eq!(con.limb, i);
        // The sign: the largest component of the chosen axis positive.
        let sign = if s.abs() > c.abs() { -s.signum() } else { c.signum() };
        assert!(
            close(
                &con.wrench,
                [-s * sign, c * sign, 0.0],
                [-h * c * sign, -h * s * sign, r * sign]
            ),
            "{con:?}"
        );
        assert!((a.limbs[i].length().unwrap() - h).abs() < 1e-12);
    }
}

/// One leg alone leaves the platform five freedoms: its one constraint
/// force spans 1 of the 6 − 1 = 5 needed directions.
#[test]
fn one_leg_is_a_constraint_singularity() {
    let (mut model, mut poses, mut values) = home_rps(100.0, 75.0);
    model.joints.truncate(3);
    model.links = vec!["base".into(), "A1".into(), "A2".into(), "platform".into()];
    model.joints[2].links = [2, 3];
    poses = vec![poses[0], poses[1], poses[2], poses[7]];
    values.truncate(3);
    let e = analyse_poses(&model, &poses, &values, 3).unwrap_err();
    assert!(
        matches!(e, WrenchError::ConstraintSingularity { rank: 1, needed: 5, .. }),
        "{e}"
    );
}

/// Leg 0's slide turned to run along x, normal to its leg (vertical,
/// from a = (100, 0, 0) to c = (100, 0, 75)) in the leg's plane: the
/// revolute about y through a less the ball's rotation about y through
/// c is the translation (a − c) × e_y = 75·e_x, so the slide moves
/// within its other joints' twists and has no actuation wrench.
#[test]
fn slide_within_the_others_is_an_actuation_singularity() {
    let (mut model, poses, values) = home_rps(100.0, 75.0);
    model.joints[1].places[0] = Place::Line {
        through: [0.0; 3],
        along: [1.0, 0.0, 0.0],
    };
    let e = analyse_poses(&model, &poses, &values, 7).unwrap_err();
    assert!(
        matches!(e, WrenchError::ActuationSingularity { limb: Some(0), .. }),
        "{e}"
    );
}

#[test]
fn bad_input_is_typed() {
    let (model, poses, mut values) = home_rps(100.0, 75.0);
    assert!(matches!(
        analyse_poses(&model, &poses, &values, 0),
        Err(WrenchError::BadInput { .. })
    ));
    assert!(matches!(
        analyse_poses(&model, &poses[..3], &values, 7),
        Err(WrenchError::BadInput { .. })
    ));
    values[1] = f64::NAN;
    assert!(matches!(
        analyse_poses(&model, &poses, &values, 7),
        Err(WrenchError::BadInput { .. })
    ));
    // A platform that some joint does not reach through a limb.
    values[1] = 75.0;
    assert!(matches!(
        analyse_poses(&model, &poses, &values, 2),
        Err(WrenchError::NotLimbs { .. })
    ));
}

/// The null space of one S joint's three rotations about c: the three
/// forces through c, canonically along x, y, z.
#[test]
fn a_ball_joint_admits_the_forces_through_its_centre() {
    let c = Vector3::new(3.0, -2.0, 5.0);
    // Written at p = c, the rotations are (0, s e_i): the forces (e_i, 0).
    let hats: Vec<Vector6<f64>> = (0..3).map(|i| Vector6::ith(3 + i, 1.0)).collect();
    let n = null_space(&hats);
    assert_eq!(n.len(), 3);
    let (couples, forces) = constraint_basis(&n);
    assert!(couples.is_empty());
    for (i, w) in forces.iter().enumerate() {
        let wr = from_hat(w, &c, 10.0, false);
        let e = Vector3::ith(i, 1.0);
        assert!(close(&wr, e.into(), c.cross(&e).into()), "{wr:?}");
    }
}

/// The orthogonal projector onto the span of the orthonormal `basis`.
fn projector(basis: &[Vector6<f64>]) -> Matrix6<f64> {
    basis.iter().map(|b| b * b.transpose()).sum()
}

/// Unit twists of a random limb: `rank` random independent directions and
/// `n − rank` random combinations of them, shuffled by `seed`.
fn random_limb(n: usize, rank: usize, rnd: &mut impl FnMut() -> f64) -> Vec<Vector6<f64>> {
    let base: Vec<Vector6<f64>> = (0..rank).map(|_| Vector6::from_fn(|_, _| rnd())).collect();
    (0..n)
        .map(|i| {
            let v = if i < rank {
                base[i]
            } else {
                base.iter().fold(Vector6::zeros(), |acc, b| acc + b * rnd())
            };
            v.normalize()
        })
        .collect()
}

/// The QR path (certified) and the SVD path give the same null spaces and
/// actuation wrenches on random limbs of every size and rank; near the
/// threshold (the actuated twist within ε of the others' span, ε from
/// 1e-13 to 1e-5) the certified path either declines or agrees with the
/// SVD (to ε_mach/ε, as well as either is determined there), and never
/// answers where the SVD refuses.
#[test]
fn certified_and_svd_paths_agree() {
    let mut rng = crate::random::SplitMix::new(11);
    let mut rnd = || rng.symmetric();
    let mut certified = 0;
    for n in 1..=MAX_LIMB_VARIABLES {
        for rank in 1..=n.min(6) {
            for _ in 0..20 {
                let hats = random_limb(n, rank, &mut rnd);
                let (fast, svd) = (null_space(&hats), svd_null_space(&hats));
                assert_eq!(fast.len(), svd.len(), "n {n} rank {rank}");
                assert!((projector(&fast) - projector(&svd)).norm() < 1e-12, "n {n} rank {rank}");
                for col in 0..n {
                    let exact = svd_actuation(&hats, col, &svd);
                    if let Some(w) = certified_actuation(&hats, col, fast.len()) {
                        certified += 1;
                        let e = exact.expect("the SVD finds the actuation wrench the QR certifies");
                        assert!((w - e).norm() < 1e-12, "n {n} rank {rank} col {col}");
                    }
                }
            }
        }
    }
    assert!(certified > 300, "{certified}");
    for _ in 0..50 {
        let others = random_limb(4, 4, &mut rnd);
        let inside = others.iter().fold(Vector6::zeros(), |acc, o| acc + o * rnd());
        let away = Vector6::from_fn(|_, _| rnd());
        for k in 0..=32 {
            let eps = 1e-13 * 10f64.powf(k as f64 / 4.0);
            let mut hats = others.clone();
            hats.push((inside.normalize() + away * eps).normalize());
            let c = svd_null_space(&hats);
            let exact = svd_actuation(&hats, 4, &c);
            if let Some(w) = certified_actuation(&hats, 4, null_space(&hats).len()) {
                let e = exact.unwrap_or_else(|s| panic!("ε {eps:e}: certified where the SVD refuses (σ {s:e})"));
                // Either is the answer to about ε_mach/ε (the actuated
                // twist's distance from the others' span).
                assert!((w - e).norm() < 1e-14 / eps, "ε {eps:e}: {:e}", (w - e).norm());
            }
        }
    }
}
