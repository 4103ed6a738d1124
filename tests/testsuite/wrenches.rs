//! Wrench analysis and stiffness (pkm_runtime::wrench, ::stiffness) on
//! example mechanisms at configurations their inverse solutions give
//! through the plan interpreter: seed 004's 3-RPS and 3-SPR (rps_3, spr_3),
//! the 3-RPS given by height and tilt (rps_3_tilt), the 6-UPS Stewart platform (ups_6), the 3-PRS (prs_3) and
//! the translational 3-UPU (upu_3, whose legs' constraints are couples).
//! Checked against what is written here by hand from the link poses: each
//! joint's twist (a revolute's axis through its point, a slide's
//! direction, a ball's three rotations about its centre), each leg's length
//! and each constraint's direction moved by finite differences of the
//! platform's displacement, and for the 3-RPS the closed forms of seed 004
//! (eqs. 8–12) and K = Jᵀ K_p J (eqs. 13–17) written out.

use crate::common;

use pkm::dsl::screw::SplitMix;
use pkm::runtime::model::{JointType, Model, Place};
use pkm::runtime::nalgebra::{DMatrix, Isometry3, Matrix6, Rotation3, Vector3, Vector6};
use pkm::runtime::plan::{self, Solution};
use pkm::runtime::stiffness::{self, LimbProperties, Section};
use pkm::runtime::wrench::{self, RowKind, WrenchAnalysis};

/// An example, how to draw its poses, its legs' joints by name (the one
/// whose point is the leg's proximal centre, the one on the platform, the
/// revolute whose axis a constraint force runs along or the two whose axes
/// a constraint couple is normal to), and what each leg has: constraint
/// forces, couples.
struct Case {
    name: &'static str,
    pose: fn(&mut SplitMix) -> Vec<f64>,
    legs: Vec<Leg>,
    forces: usize,
    couples: usize,
}

struct Leg {
    proximal: String,
    distal: String,
    /// A constraint force's revolute, or a couple's two revolutes.
    constraint: Vec<String>,
    /// The ball whose centre a constraint force passes through (on the
    /// platform for a 3-RPS or 3-PRS, on the base for a 3-SPR).
    ball: String,
}

fn cases() -> Vec<Case> {
    let rps = |k: usize| Leg {
        proximal: format!("R{k}"),
        distal: format!("S{k}"),
        constraint: vec![format!("R{k}")],
        ball: format!("S{k}"),
    };
    let spr = |k: usize| Leg {
        proximal: format!("S{k}"),
        distal: format!("R{k}"),
        constraint: vec![format!("R{k}")],
        ball: format!("S{k}"),
    };
    let ups = |k: usize| Leg {
        proximal: format!("U{k}.a"),
        distal: format!("S{k}"),
        constraint: vec![],
        ball: format!("S{k}"),
    };
    let upu = |k: usize| Leg {
        proximal: format!("U{k}1.a"),
        distal: format!("U{k}2.b"),
        constraint: vec![format!("U{k}1.a"), format!("U{k}1.b")],
        ball: String::new(),
    };
    vec![
        Case {
            name: "rps_3",
            pose: |r| common::poses::seed(r).to_vec(),
            legs: (1..=3).map(rps).collect(),
            forces: 3,
            couples: 0,
        },
        Case {
            name: "spr_3",
            pose: |r| common::poses::seed(r).to_vec(),
            legs: (1..=3).map(spr).collect(),
            forces: 3,
            couples: 0,
        },
        Case {
            name: "rps_3_tilt",
            pose: |r| common::poses::tilt(r).to_vec(),
            legs: (1..=3).map(rps).collect(),
            forces: 3,
            couples: 0,
        },
        Case {
            name: "ups_6",
            pose: |r| common::poses::ups(r).to_vec(),
            legs: (1..=6).map(ups).collect(),
            forces: 0,
            couples: 0,
        },
        Case {
            name: "prs_3",
            pose: |r| common::poses::tilt(r).to_vec(),
            legs: (1..=3).map(rps).collect(),
            forces: 3,
            couples: 0,
        },
        Case {
            name: "upu_3",
            pose: |r| common::poses::upu(r).to_vec(),
            legs: (1..=3).map(upu).collect(),
            forces: 0,
            couples: 3,
        },
    ]
}

fn joint(model: &Model, name: &str) -> usize {
    model
        .joints
        .iter()
        .position(|j| j.name == name)
        .unwrap_or_else(|| panic!("{}: no joint {name}", model.name))
}

fn platform(model: &Model) -> usize {
    model.links.iter().position(|l| l == "platform").unwrap()
}

/// `n` configurations of example `name`: for random poses, a random solved
/// branch of its inverse solution run by the interpreter.
fn configurations(name: &str, pose: fn(&mut SplitMix) -> Vec<f64>, n: usize) -> (Model, Vec<Solution>) {
    let (a, model) = common::example(name);
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let mut rng = SplitMix::new(14);
    let mut out = Vec::with_capacity(n);
    let mut tries = 0;
    while out.len() < n {
        tries += 1;
        assert!(tries < 10 * n, "{name}: too few poses solve");
        let given = pose(&mut rng);
        let mut solved: Vec<Solution> = plan::run_all(&model, &plan, &given)
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .collect();
        if solved.is_empty() {
            continue;
        }
        let k = ((rng.symmetric() + 1.0) * 0.5 * solved.len() as f64) as usize;
        out.push(solved.swap_remove(k.min(solved.len() - 1)));
    }
    (model, out)
}

/// World position of joint `j`'s point: its place on its first link (a
/// slide's: the slider's point).
fn point(model: &Model, s: &Solution, j: usize) -> Vector3<f64> {
    let joint = &model.joints[j];
    let side = usize::from(matches!(joint.places[0], Place::Line { .. }));
    s.poses[joint.links[side]]
        .transform_point(&joint.places[side].at().into())
        .coords
}

/// A revolute's world axis (unit), from its place on its first link.
fn axis(model: &Model, s: &Solution, j: usize) -> Vector3<f64> {
    let joint = &model.joints[j];
    s.poses[joint.links[0]].rotation * Vector3::from(joint.places[0].axis()).normalize()
}

/// Joint `j`'s unit twists `(ω, v)` by hand (v the velocity of the body
/// point at the origin): a revolute `(a, p × a)`, a slide `(0, d)`, a ball
/// `(e_i, c × e_i)`.
fn twists(model: &Model, s: &Solution, j: usize) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let joint = &model.joints[j];
    match joint.kind {
        JointType::R => {
            let (p, a) = (point(model, s, j), axis(model, s, j));
            vec![(a, p.cross(&a))]
        }
        JointType::P => {
            let (side, along) = match (joint.places[0], joint.places[1]) {
                (Place::Line { along, .. }, _) => (0, along),
                (_, Place::Line { along, .. }) => (1, along),
                _ => panic!("{}: a slide without a guide", joint.name),
            };
            let d = s.poses[joint.links[side]].rotation * Vector3::from(along).normalize();
            vec![(Vector3::zeros(), d)]
        }
        JointType::S => {
            let c = point(model, s, j);
            (0..3)
                .map(|i| {
                    let e = Vector3::ith(i, 1.0);
                    (e, c.cross(&e))
                })
                .collect()
        }
        JointType::Pa => panic!("{}: no parallelogram in these examples", joint.name),
    }
}

/// The limb holding joint `j`.
fn limb_of(a: &WrenchAnalysis, j: usize) -> usize {
    a.limbs.iter().position(|l| l.joints.contains(&j)).unwrap()
}

/// Each actuation wrench reciprocal to every other joint twist of its
/// limb, each constraint wrench to every one, at 1000 configurations per
/// mechanism: |f·v + m·ω| ≤ 1e-12 of |f||v| + |m||ω|; each actuation
/// wrench does positive work on its own joint's twist, equal to its
/// `transmission`; the rows are as many as each mechanism has.
#[test]
fn wrenches_are_reciprocal() {
    for case in cases() {
        let (model, configs) = configurations(case.name, case.pose, 1000);
        let p = platform(&model);
        let inputs = model.inputs();
        let (mut worst, mut worst_own, mut least_own) = (0.0f64, 0.0f64, f64::INFINITY);
        for s in &configs {
            let a = wrench::analyse(&model, s, p).unwrap_or_else(|e| panic!("{}: {e}", case.name));
            assert_eq!(a.limbs.len(), case.legs.len(), "{}", case.name);
            assert_eq!(a.actuation, inputs.len(), "{}", case.name);
            let count = |k: RowKind| a.rows.iter().filter(|r| r.kind == k).count();
            assert_eq!(count(RowKind::ConstraintForce), case.forces, "{}", case.name);
            assert_eq!(count(RowKind::ConstraintCouple), case.couples, "{}", case.name);
            for row in &a.rows {
                let w = &row.wrench;
                let own = match row.kind {
                    RowKind::Actuation { joint, .. } => Some(joint),
                    _ => None,
                };
                for &j in &a.limbs[row.limb].joints {
                    for (om, v) in twists(&model, s, j) {
                        let product = w.f.dot(&v) + w.m.dot(&om);
                        let size = w.f.norm() * v.norm() + w.m.norm() * om.norm();
                        if Some(j) == own {
                            worst_own = worst_own.max((product - row.transmission).abs() / size);
                            least_own = least_own.min(product / size);
                        } else {
                            worst = worst.max(product.abs() / size);
                        }
                    }
                }
            }
        }
        eprintln!(
            "{}: worst reciprocal product {worst:e}; own twist: transmission within {worst_own:e}, least {least_own:e}",
            case.name
        );
        assert!(worst <= 1e-12, "{}: {worst:e}", case.name);
        assert!(worst_own <= 1e-12 && least_own > 0.0, "{}", case.name);
    }
}

/// The platform point now at `c` after the small displacement `x` = (δp,
/// δθ) of the platform about the base origin: rotated by δθ, then moved by δp.
fn moved(c: &Vector3<f64>, x: &Vector6<f64>) -> Vector3<f64> {
    let r = Rotation3::new(Vector3::new(x[3], x[4], x[5]));
    r * c + Vector3::new(x[0], x[1], x[2])
}

/// The central-difference gradient of `g` over the six platform
/// displacements (1e-3 mm, 1e-5 rad).
fn gradient(g: impl Fn(&Vector6<f64>) -> f64) -> Vector6<f64> {
    Vector6::from_fn(|k, _| {
        let h = if k < 3 { 1e-3 } else { 1e-5 };
        let e = Vector6::ith(k, h);
        (g(&e) - g(&-e)) / (2.0 * h)
    })
}

/// The smaller of `|row − g|` and `|row + g|`, relative to `1 + |g|`.
fn up_to_sign(row: &Vector6<f64>, g: &Vector6<f64>) -> f64 {
    (row - g).norm().min((row + g).norm()) / (1.0 + g.norm())
}

/// J's rows against finite differences of the platform's displacement, at
/// 200 configurations per mechanism: each actuation row is the gradient of
/// its leg's length |c − a| (c the distal centre moving with the platform,
/// a the proximal one held), each constraint force the gradient of the
/// distal centre's displacement along the revolute's axis u (held), and a
/// constraint couple (the 3-UPU's) the unit (0, a × b) of its base U's two
/// axes, up to sign.
#[test]
fn jacobian_against_finite_differences() {
    for case in cases() {
        let (model, configs) = configurations(case.name, case.pose, 200);
        let p = platform(&model);
        let (mut worst_a, mut worst_c) = (0.0f64, 0.0f64);
        for s in &configs {
            let a = wrench::analyse(&model, s, p).unwrap();
            let j = a.jacobian();
            for leg in &case.legs {
                let (jp, jd) = (joint(&model, &leg.proximal), joint(&model, &leg.distal));
                let (base, c) = (point(&model, s, jp), point(&model, s, jd));
                let limb = limb_of(&a, jd);
                let rows: Vec<(usize, RowKind)> = a
                    .rows
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| r.limb == limb)
                    .map(|(i, r)| (i, r.kind))
                    .collect();
                let row = |i: usize| Vector6::from_fn(|k, _| j[(i, k)]);
                for (i, kind) in rows {
                    let e = match kind {
                        RowKind::Actuation { .. } => {
                            let g = gradient(|x| (moved(&c, x) - base).norm());
                            up_to_sign(&row(i), &g)
                        }
                        RowKind::ConstraintForce => {
                            let u = axis(&model, s, joint(&model, &leg.constraint[0]));
                            let b = point(&model, s, joint(&model, &leg.ball));
                            let g = gradient(|x| u.dot(&moved(&b, x)));
                            up_to_sign(&row(i), &g)
                        }
                        RowKind::ConstraintCouple => {
                            let ua = axis(&model, s, joint(&model, &leg.constraint[0]));
                            let ub = axis(&model, s, joint(&model, &leg.constraint[1]));
                            let n = ua.cross(&ub).normalize();
                            up_to_sign(&row(i), &Vector6::new(0.0, 0.0, 0.0, n.x, n.y, n.z))
                        }
                    };
                    if matches!(kind, RowKind::Actuation { .. }) {
                        worst_a = worst_a.max(e);
                    } else {
                        worst_c = worst_c.max(e);
                    }
                }
            }
        }
        eprintln!(
            "{}: actuation rows within {worst_a:e}, constraint rows within {worst_c:e} of finite differences",
            case.name
        );
        assert!(worst_a < 1e-8 && worst_c < 1e-8, "{}", case.name);
    }
}

/// Seed 004's closed forms for the 3-RPS at its platform centre o, written
/// out (eqs. 8, 11, 12): J_A's row i is [l_iᵀ, (r_i × l_i)ᵀ] with l_i the
/// unit leg from revolute i's point a_i to ball i's centre c_i and r_i =
/// c_i − o; J_C's row i is [u_iᵀ, (r_i × u_i)ᵀ] with u_i revolute i's axis.
/// The actuation row's sign is the slide's (its value the signed leg
/// length); a constraint row's, the basis's choice. Then K at o against
/// J_seedᵀ K_p J_seed with K_p = diag(E·A/q_i, 3·E·I/q_i³) (eqs. 13–17, q_i
/// the leg length), the seed's steel (E = 2.11·10¹¹ N/m², I = 1.256·10⁻⁷
/// m⁴) in N and mm, A of the solid round leg of that I (d = 40 mm); and
/// with the seed's load (F = (10, −15, 20) N, T = (−20, 10, 15) N·m at o),
/// K·δX = W.
#[test]
fn rps_against_the_seed() {
    let (model, configs) = configurations("rps_3_tilt", |r| common::poses::tilt(r).to_vec(), 1000);
    let p = platform(&model);
    let o = model.points.iter().find(|q| q.name == "o").unwrap().at;
    let Section::Beam { e, area, inertia } = Section::solid_round(2.11e5, 40.0) else {
        unreachable!()
    };
    let props = [LimbProperties {
        section: Section::from_si(2.11e11, area * 1e-6, 1.256e-7, 1e-3),
        actuator: None,
    }];
    let inertia_seed = 1.256e5;
    assert!((inertia - inertia_seed).abs() < 1e-3 * inertia_seed);
    let (mut worst_j, mut worst_k, mut worst_w) = (0.0f64, 0.0f64, 0.0f64);
    for s in &configs {
        let a = wrench::analyse(&model, s, p).unwrap();
        let centre = s.poses[p].transform_point(&o.into()).coords;
        let j = a.jacobian_at(centre.into());
        let mut seed = DMatrix::zeros(6, 6);
        let mut kp = Vec::new();
        for k in 1..=3 {
            let (r, ball, slide) = (
                joint(&model, &format!("R{k}")),
                joint(&model, &format!("S{k}")),
                joint(&model, &format!("P{k}")),
            );
            let (ai, ci) = (point(&model, s, r), point(&model, s, ball));
            let q = (ci - ai).norm();
            let l = (ci - ai) / q * s.values[slide].signum();
            let u = axis(&model, s, r);
            let ri = ci - centre;
            let (ra, rc) = (ri.cross(&l), ri.cross(&u));
            let (act, con) = (limb_of(&a, r), 3 + limb_of(&a, r));
            seed.row_mut(act).copy_from_slice(&[l.x, l.y, l.z, ra.x, ra.y, ra.z]);
            seed.row_mut(con).copy_from_slice(&[u.x, u.y, u.z, rc.x, rc.y, rc.z]);
            kp.push((act, e * area / q));
            kp.push((con, 3.0 * e * inertia_seed / q.powi(3)));
            // Rows in limb order: the analysis's actuation row of this
            // limb is its number, its constraint row 3 more.
            let mine_a = Vector6::from_fn(|c, _| j[(act, c)]);
            let theirs_a = Vector6::from_fn(|c, _| seed[(act, c)]);
            worst_j = worst_j.max((mine_a - theirs_a).norm() / (1.0 + theirs_a.norm()));
            let mine_c = Vector6::from_fn(|c, _| j[(con, c)]);
            let theirs_c = Vector6::from_fn(|c, _| seed[(con, c)]);
            worst_j = worst_j.max(up_to_sign(&mine_c, &theirs_c));
        }
        let mut kp_m = DMatrix::zeros(6, 6);
        for (i, k) in kp {
            kp_m[(i, i)] = k;
        }
        let k_seed = seed.transpose() * kp_m * &seed;
        let st = stiffness::stiffness(&a, &props).unwrap();
        let k = st.at(centre.into());
        let scale = k.abs().max();
        let dk = DMatrix::from_fn(6, 6, |r, c| k[(r, c)] - k_seed[(r, c)]).abs().max();
        worst_k = worst_k.max(dk / scale);
        let w = [10.0, -15.0, 20.0, -20e3, 10e3, 15e3];
        let x = st.deflection(&w, centre.into()).unwrap();
        let back = k * Vector6::from(x);
        let wv = Vector6::from(w);
        worst_w = worst_w.max((back - wv).norm() / wv.norm());
    }
    eprintln!(
        "rps_3_tilt: J within {worst_j:e} of seed 004's eqs. 8-12; K within {worst_k:e} of J_seedᵀ K_p J_seed; \
         K·δX = W within {worst_w:e}"
    );
    assert!(worst_j < 1e-12 && worst_k < 1e-12 && worst_w < 1e-10);
}

/// K on every mechanism at 200 configurations: symmetric, positive
/// definite (Cholesky of K with translations in units of 100 mm), K·δX = W
/// for the seed's load at the platform centre, and the directional
/// stiffness 1/(eᵀ K⁻¹ e) at most eᵀ K e and positive.
#[test]
fn stiffness_is_symmetric_positive_definite() {
    let props = [LimbProperties {
        section: Section::solid_round(2.11e5, 40.0),
        actuator: Some(1e5),
    }];
    for case in cases() {
        let (model, configs) = configurations(case.name, case.pose, 200);
        let p = platform(&model);
        let o = model.points.iter().find(|q| q.name == "o").unwrap().at;
        let mut worst = 0.0f64;
        for s in &configs {
            let a = wrench::analyse(&model, s, p).unwrap();
            let st = stiffness::stiffness(&a, &props).unwrap_or_else(|e| panic!("{}: {e}", case.name));
            let centre: [f64; 3] = s.poses[p].transform_point(&o.into()).coords.into();
            let k = st.at(centre);
            assert_eq!(k, k.transpose(), "{}", case.name);
            let d = Matrix6::from_diagonal(&Vector6::new(100.0, 100.0, 100.0, 1.0, 1.0, 1.0));
            assert!((d * k * d).cholesky().is_some(), "{}", case.name);
            let w = [10.0, -15.0, 20.0, -20e3, 10e3, 15e3];
            let x = st.deflection(&w, centre).unwrap();
            let wv = Vector6::from(w);
            worst = worst.max((k * Vector6::from(x) - wv).norm() / wv.norm());
            let dir = st.directional(centre).unwrap();
            for i in 0..6 {
                assert!(dir[i] > 0.0 && dir[i] <= k[(i, i)] * (1.0 + 1e-12), "{}", case.name);
            }
        }
        eprintln!("{}: K·δX = W within {worst:e}", case.name);
        assert!(worst < 1e-10, "{}: {worst:e}", case.name);
    }
}

/// The analysis keeps no state (the same configuration twice gives the
/// same rows), and bad input on a real model is a typed error: a joint
/// value missing, a pose not finite.
#[test]
fn rows_are_reproducible() {
    let (model, configs) = configurations("ups_6", |r| common::poses::ups(r).to_vec(), 20);
    let p = platform(&model);
    for s in &configs {
        let a = wrench::analyse(&model, s, p).unwrap();
        let b = wrench::analyse(&model, &s.clone(), p).unwrap();
        assert_eq!(a, b);
        // Bad input stays typed on a real model.
        let mut t = s.clone();
        t.values.pop();
        assert!(matches!(
            wrench::analyse(&model, &t, p),
            Err(wrench::WrenchError::BadInput { .. })
        ));
        let mut t = s.clone();
        t.poses[p] = Isometry3::translation(f64::NAN, 0.0, 0.0);
        assert!(matches!(
            wrench::analyse(&model, &t, p),
            Err(wrench::WrenchError::BadInput { .. })
        ));
    }
}

/// The 3-RPS with its platform in the base plane (z = 0, untilted, the
/// parasitic turn's root rz = 0: each ball radially inside its revolute):
/// every leg lies in that plane, so every actuation and constraint wrench
/// is a force in it. The three constraint forces (tangent, through the
/// balls) span the 3 = 6 − 3 directions they must (x, y, about z), and the
/// legs' forces add nothing out of the plane: the platform rises with its
/// actuators locked, an actuation singularity; typed, not a NaN. Above the
/// plane, by hand: leg i runs from (200 cos θᵢ, 200 sin θᵢ, 0) to
/// (100 cos θᵢ, 100 sin θᵢ, z), q = √(100² + z²), its force's z part z/q;
/// the tangent constraint forces have none, and every coupling of z with
/// the other five directions sums cos θᵢ or sin θᵢ over the three legs,
/// which is 0; so the directional stiffness along z at the centre is
/// K_zz = 3·(E·A/q)·(z/q)².
#[test]
fn rps_in_the_base_plane_is_an_actuation_singularity() {
    let (a, model) = common::example("rps_3_tilt");
    let plan = pkm::dsl::planner::inverse_plan(&a).unwrap();
    let p = platform(&model);
    let solve = |z: f64| {
        plan::run_all(&model, &plan, &[z, 0.0, 0.0])
            .into_iter()
            .filter_map(|(_, r)| r.ok())
            .find(|s| {
                model
                    .inputs()
                    .iter()
                    .all(|&j| (s.values[j] - 100f64.hypot(z)).abs() < 1e-9)
            })
            .unwrap_or_else(|| panic!("no branch with legs of {} at z = {z}", 100f64.hypot(z)))
    };
    let e = wrench::analyse(&model, &solve(0.0), p).unwrap_err();
    assert!(
        matches!(e, wrench::WrenchError::ActuationSingularity { limb: None, .. }),
        "{e}"
    );
    let section = Section::solid_round(2.11e5, 40.0);
    let Section::Beam { e, area, .. } = section else {
        unreachable!()
    };
    let props = [LimbProperties {
        section,
        actuator: None,
    }];
    for z in [1e-3, 1.0, 10.0, 100.0] {
        let an = wrench::analyse(&model, &solve(z), p).unwrap();
        let st = stiffness::stiffness(&an, &props).unwrap();
        let kz = st.directional([0.0, 0.0, z]).unwrap()[2];
        let q = 100f64.hypot(z);
        let hand = 3.0 * e * area / q * (z / q).powi(2);
        eprintln!("rps_3_tilt: k_z at the centre, z = {z}: {kz:e} N/mm, by hand {hand:e}");
        assert!((kz - hand).abs() <= 1e-9 * hand, "z = {z}: {kz:e}, by hand {hand:e}");
    }
}
