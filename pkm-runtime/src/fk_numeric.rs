//! Forward position solutions of a mechanism with coupling degree κ = 1 by
//! a virtual variable (seed 003 §1.1: "求解位置正解时需设定一个虚拟变量"):
//! one joint of the coupled SKC is given a value `v` as if it were an
//! input, the closed-form plan solves the rest of the mechanism as a
//! function of it (every ± branch), and the one loop constraint that plan
//! does not impose is left as a scalar compatibility residual `r(v)`
//! (the miss of the aim that closes the last SOC, a length:
//! [`crate::steps::aim::miss`]; or, where the plan leaves no aim open, an
//! actuated joint the plan is not given, its computed value less the given
//! one: [`Compatibility`]). Every real root of `r` on every branch is an
//! assembly.
//!
//! The driver is generic: [`roots`] finds every root of a function of one
//! variable that may be undefined on parts of its range (a branch whose
//! closed form has no real solution there: a gap, never a NaN). It samples
//! the whole range, brackets every sign change and every near-tangency (a
//! local minimum of `|r|` near zero), refines a sign change by Brent's
//! method to full precision and a tangency by golden-section search on
//! `|r|`, and reports a root it cannot bracket as a [`RootKind::Tangency`]
//! rather than drop it. [`solve`] runs it on a [`VirtualPlan`] with the
//! plan interpreter; generated code runs it on its own residual function.

use crate::model::{JointType, Model};
use crate::plan::{self, Plan, Solution};
use crate::primitives::Sign;
use crate::solution::SolveError;

/// How a root was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootKind {
    /// A sign change bracketed and refined: certified.
    Crossing,
    /// A local minimum of `|r|` within the tolerance of zero without a
    /// sign change (a double root, or one at the edge of a gap or of the
    /// range): found, not certified.
    Tangency,
}

/// A root of the residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// Where.
    pub x: f64,
    /// The residual there.
    pub residual: f64,
    /// How it was found.
    pub kind: RootKind,
}

/// Where [`roots`] looks and what it counts as zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sampling {
    /// The range's start.
    pub lo: f64,
    /// The range's end.
    pub hi: f64,
    /// Intervals the range is sampled in.
    pub samples: usize,
    /// `|r| ≤ zero` at a local minimum of `|r|` is a (tangent) root.
    pub zero: f64,
    /// The range is one period (a revolute's turn): `hi` is `lo` again.
    pub periodic: bool,
}

/// A defined sample.
#[derive(Clone, Copy)]
struct Pt {
    x: f64,
    f: f64,
}

/// Every root of `f` on the sampling's range, in increasing order; `f`
/// returns `None` where it is not defined (a gap). See the module's text.
pub fn roots(mut f: impl FnMut(f64) -> Option<f64>, s: &Sampling) -> Vec<Root> {
    let n = s.samples.max(2);
    let h = (s.hi - s.lo) / n as f64;
    let mut eval = |x: f64| f(x).filter(|v| v.is_finite());
    // The samples, a periodic range's extended by one beyond each end so
    // that a minimum or sign change at the seam is seen.
    let (first, last) = if s.periodic { (-1, n as i64 + 1) } else { (0, n as i64) };
    let raw: Vec<(f64, Option<f64>)> = (first..=last)
        .map(|i| {
            let x = if i == n as i64 { s.hi } else { s.lo + h * i as f64 };
            (x, eval(x))
        })
        .collect();
    // Runs of defined samples; each gap's edges found by bisection and
    // added to the run they close.
    let mut runs: Vec<Vec<Pt>> = Vec::new();
    let mut run: Vec<Pt> = Vec::new();
    for w in 0..raw.len() {
        let (x, v) = raw[w];
        match v {
            Some(fx) => {
                if run.is_empty() && w > 0 {
                    // Entering from a gap: the edge between raw[w-1] and x.
                    if let Some(p) = edge(&mut eval, raw[w - 1].0, x) {
                        run.push(p);
                    }
                }
                run.push(Pt { x, f: fx });
            }
            None => {
                if !run.is_empty() {
                    if let Some(p) = edge(&mut eval, raw[w - 1].0, x) {
                        run.push(p);
                    }
                    runs.push(std::mem::take(&mut run));
                }
            }
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    let mut out: Vec<Root> = Vec::new();
    for run in &runs {
        for (i, p) in run.iter().enumerate() {
            if p.f == 0.0 {
                out.push(Root {
                    x: p.x,
                    residual: 0.0,
                    kind: RootKind::Crossing,
                });
            }
            if i + 1 < run.len() {
                let q = run[i + 1];
                if p.f * q.f < 0.0 {
                    out.push(brent(&mut eval, *p, q));
                }
            }
            // A local minimum of |f| without a sign change about it, the
            // run's ends included (a gap's edge, the range's end).
            let prev = i.checked_sub(1).map(|k| run[k]);
            let next = run.get(i + 1).copied();
            let lower = |o: Option<Pt>| o.is_none_or(|o| p.f.abs() <= o.f.abs() && o.f * p.f > 0.0);
            if p.f != 0.0 && lower(prev) && lower(next) && (prev.is_some() || next.is_some()) {
                let a = prev.map_or(p.x, |o| o.x);
                let b = next.map_or(p.x, |o| o.x);
                let m = golden(&mut eval, a, b, *p);
                if m.f * p.f < 0.0 {
                    // Two crossings hidden between samples.
                    out.push(brent(
                        &mut eval,
                        Pt {
                            x: a,
                            f: prev.map_or(p.f, |o| o.f),
                        },
                        m,
                    ));
                    out.push(brent(
                        &mut eval,
                        m,
                        Pt {
                            x: b,
                            f: next.map_or(p.f, |o| o.f),
                        },
                    ));
                } else if m.f.abs() <= s.zero {
                    out.push(Root {
                        x: m.x,
                        residual: m.f,
                        kind: RootKind::Tangency,
                    });
                }
            }
        }
    }
    // Into the range (a periodic one's seam once), in order, each once.
    let period = s.hi - s.lo;
    let mut out: Vec<Root> = out
        .into_iter()
        .filter_map(|mut r| {
            if s.periodic {
                r.x = s.lo + (r.x - s.lo).rem_euclid(period);
                Some(r)
            } else {
                (r.x >= s.lo && r.x <= s.hi).then_some(r)
            }
        })
        .collect();
    out.sort_by(|a, b| a.x.total_cmp(&b.x));
    let same = |a: f64, b: f64| {
        let d = (a - b).abs();
        d <= 1e-9 * (1.0 + a.abs().max(b.abs())) || (s.periodic && (period - d).abs() <= 1e-9 * (1.0 + period))
    };
    let mut merged: Vec<Root> = Vec::new();
    for r in out {
        match merged.iter_mut().find(|m| same(m.x, r.x)) {
            // Keep the certified one, else the smaller residual.
            Some(m) => {
                if (r.kind == RootKind::Crossing && m.kind == RootKind::Tangency)
                    || (r.kind == m.kind && r.residual.abs() < m.residual.abs())
                {
                    *m = r;
                }
            }
            None => merged.push(r),
        }
    }
    merged
}

/// The last defined point between a defined and an undefined sample (in
/// either order), by 60 bisections.
fn edge(eval: &mut impl FnMut(f64) -> Option<f64>, a: f64, b: f64) -> Option<Pt> {
    let (mut inside, mut outside) = match (eval(a), eval(b)) {
        (Some(_), None) => (a, b),
        (None, Some(_)) => (b, a),
        _ => return None,
    };
    let mut best = None;
    for _ in 0..60 {
        let m = 0.5 * (inside + outside);
        if m == inside || m == outside {
            break;
        }
        match eval(m) {
            Some(f) => {
                inside = m;
                best = Some(Pt { x: m, f });
            }
            None => outside = m,
        }
    }
    best.or_else(|| eval(inside).map(|f| Pt { x: inside, f }))
}

/// Brent's method on a bracket `a`, `b` (`f(a)·f(b) < 0`) to full precision.
/// Where `f` is undefined inside (it should not be: a run has no gap), the
/// bisection point stands in.
fn brent(eval: &mut impl FnMut(f64) -> Option<f64>, a: Pt, b: Pt) -> Root {
    let (mut a, mut fa, mut b, mut fb) = (a.x, a.f, b.x, b.f);
    if fa == 0.0 {
        return Root {
            x: a,
            residual: 0.0,
            kind: RootKind::Crossing,
        };
    }
    let (mut c, mut fc) = (a, fa);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..200 {
        if fb * fc > 0.0 {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            break;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = match eval(b) {
            Some(f) => f,
            None => {
                // Undefined: fall back to bisection of what is left.
                b = a + 0.5 * (c - a);
                match eval(b) {
                    Some(f) => f,
                    None => break,
                }
            }
        };
    }
    // The better end of the final bracket.
    let (x, f) = if fc.abs() < fb.abs() && fc * fb <= 0.0 {
        (c, fc)
    } else {
        (b, fb)
    };
    Root {
        x,
        residual: f,
        kind: RootKind::Crossing,
    }
}

/// The minimum of `|f|` on `[a, b]` by golden-section search, starting
/// from the sample `p` (the smallest seen); where `f` changes sign inside,
/// the first point of the other sign.
fn golden(eval: &mut impl FnMut(f64) -> Option<f64>, a: f64, b: f64, p: Pt) -> Pt {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut best = p;
    let (mut a, mut b) = (a, b);
    let mut val = |x: f64, best: &mut Pt| -> f64 {
        match eval(x) {
            Some(f) => {
                if f.abs() < best.f.abs() || (f * best.f < 0.0 && best.f * p.f > 0.0) {
                    *best = Pt { x, f };
                }
                f.abs()
            }
            None => f64::INFINITY,
        }
    };
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (val(c, &mut best), val(d, &mut best));
    for _ in 0..120 {
        if best.f * p.f < 0.0 || (b - a).abs() <= 4.0 * f64::EPSILON * (1.0 + a.abs()) {
            break;
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = val(c, &mut best);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = val(d, &mut best);
        }
    }
    best
}

/// A forward plan with one virtual variable: the closed-form plan with
/// joint `joint` given as its last input, and which row of which of its
/// checks is the compatibility residual.
#[derive(Debug, Clone, PartialEq)]
pub struct VirtualPlan {
    /// The closed-form plan; its inputs are the mechanism's, then `joint`.
    pub plan: Plan,
    /// The joint whose value is the virtual variable.
    pub joint: usize,
    /// The range it is sampled over.
    pub range: [f64; 2],
    /// Whether the range is a whole turn.
    pub periodic: bool,
    /// What the compatibility residual is.
    pub compatibility: Compatibility,
    /// Samples over the range.
    pub samples: usize,
}

/// What a [`VirtualPlan`]'s compatibility residual is (a length either
/// way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Compatibility {
    /// Row `row` of the plan's check `check` ([`Plan::checks`]): the miss
    /// of an aim across a revolute's axis that closes the last SOC.
    Miss {
        /// The check.
        check: usize,
        /// Its row.
        row: usize,
    },
    /// An actuated joint the plan is not given: the value the plan
    /// computes for it less its given value (the plan's input `input`).
    /// Where no aim is left open (a leg of given length between two
    /// known joints, as in the 3-RPR), this is the condition the virtual
    /// variable must meet. An angle's difference is wrapped into
    /// (−π, π] ([`angle_miss`]) and measured as the arc at the
    /// mechanism's size ([`crate::kinematics::model_scale`]); a wrap's
    /// jump is a sign change that is not a root, and verification drops
    /// it.
    Input {
        /// The joint.
        joint: usize,
        /// Its index among the plan's inputs (the mechanism's inputs).
        input: usize,
        /// The arc's radius for a revolute (the model's scale), `None`
        /// for a slide.
        arc: Option<f64>,
    },
}

impl Compatibility {
    /// The residual from the joint value the plan computes for an
    /// [`Compatibility::Input`] and the given value.
    pub fn input_residual(arc: Option<f64>, computed: f64, given: f64) -> f64 {
        match arc {
            Some(radius) => angle_miss(computed - given) * radius,
            None => computed - given,
        }
    }
}

/// An angle's difference wrapped into (−π, π].
pub fn angle_miss(d: f64) -> f64 {
    let turn = 2.0 * std::f64::consts::PI;
    let w = d - turn * (d / turn).round();
    if w <= -std::f64::consts::PI {
        w + turn
    } else {
        w
    }
}

/// One assembly found.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// The ± choices of the plan's branch it was found on.
    pub signs: Vec<Sign>,
    /// The virtual variable's value.
    pub virtual_value: f64,
    /// The compatibility residual there.
    pub residual: f64,
    /// How it was found ([`RootKind::Tangency`]: not certified).
    pub kind: RootKind,
    /// Every link's pose and joint's value, verified.
    pub solution: Solution,
}

/// The range a slide's virtual variable is sampled over: the slide's
/// value is a distance between two points the rest of its loop joins, so
/// at most the sum of every link's span (the largest distance of a joint
/// place or named point from the link's origin, twice) and the slide's
/// own places' offsets; `±` that.
pub fn slide_range(model: &Model) -> f64 {
    let norm = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let mut span = vec![0.0f64; model.links.len()];
    for j in &model.joints {
        for (side, &l) in j.links.iter().enumerate() {
            span[l] = span[l].max(norm(j.places[side].at()));
        }
    }
    for p in &model.points {
        span[p.link] = span[p.link].max(norm(p.at));
    }
    span.iter().map(|s| 2.0 * s).sum::<f64>().max(1.0)
}

/// The range and periodicity of joint `joint` as a virtual variable.
pub fn range_of(model: &Model, joint: usize) -> ([f64; 2], bool) {
    match model.joints[joint].kind {
        JointType::P => {
            let r = slide_range(model);
            ([-r, r], false)
        }
        _ => ([-std::f64::consts::PI, std::f64::consts::PI], true),
    }
}

/// The compatibility residual of branch `signs` at the mechanism's
/// `inputs` and the virtual variable `v`, by the plan interpreter; `None`
/// where the branch's closed form has no real solution.
pub fn residual(model: &Model, vp: &VirtualPlan, inputs: &[f64], v: f64, signs: &[Sign]) -> Option<f64> {
    let geometry = crate::steps::Geometry::of(model);
    residual_with(model, &geometry, vp, inputs, v, signs)
}

fn residual_with(
    model: &Model,
    geometry: &crate::steps::Geometry<f64>,
    vp: &VirtualPlan,
    inputs: &[f64],
    v: f64,
    signs: &[Sign],
) -> Option<f64> {
    let mut given = inputs.to_vec();
    given.push(v);
    let name = |_: usize| -> std::borrow::Cow<'static, str> { std::borrow::Cow::Borrowed("") };
    let g = crate::steps::Given {
        values: &given,
        signs,
        name: &name,
        sites: 0,
    };
    let state = crate::steps::run(&vp.plan, geometry, model.links.len(), &g).ok()?;
    let r = match vp.compatibility {
        Compatibility::Miss { check, row } => {
            let checks = vp.plan.checks(geometry.joints.len());
            let check = checks.get(check)?;
            let rows = crate::steps::check_residual(geometry, &vp.plan, &[*check], &state.poses, &given, 1.0);
            *rows.get(row)?
        }
        Compatibility::Input { joint, input, arc } => {
            Compatibility::input_residual(arc, crate::steps::value(geometry, &state, joint), *given.get(input)?)
        }
    };
    Some(r).filter(|r| r.is_finite())
}

/// A solution of the virtual plan at a root, verified: the plan's own
/// checks ([`plan::run`]) and, for an [`Compatibility::Input`], the
/// computed value meets the given one to the verification tolerance
/// ([`zero_of`]).
fn verified(model: &Model, vp: &VirtualPlan, given: &[f64], signs: &[Sign]) -> Option<Solution> {
    let solution = plan::run(model, &vp.plan, given, signs).ok()?;
    if let Compatibility::Input { joint, input, arc } = vp.compatibility {
        let r = Compatibility::input_residual(arc, solution.values[joint], given[input]);
        if r.is_nan() || r.abs() > zero_of(model) {
            return None;
        }
    }
    Some(solution)
}

/// What [`Sampling::zero`] is for a model: a residual (a length) within
/// [`crate::consistency::VERIFY_TOL`] of the mechanism's size at a minimum
/// of `|r|` is a tangency, the tolerance a solution's checks are verified
/// to (a tangency root is then kept by the verification, not dropped).
pub fn zero_of(model: &Model) -> f64 {
    crate::consistency::VERIFY_TOL * crate::kinematics::model_scale(model)
}

/// Every assembly at the mechanism's `inputs`: on every branch, every root
/// of the compatibility residual over the virtual variable's range,
/// solved and verified by the plan interpreter ([`plan::run`]); an
/// assembly two branches share (where they meet) once.
///
/// # Errors
/// [`SolveError::BadInput`] for inputs of the wrong count or not finite.
pub fn solve(model: &Model, vp: &VirtualPlan, inputs: &[f64]) -> Result<Vec<Assembly>, SolveError> {
    if inputs.len() + 1 != vp.plan.n_inputs {
        return Err(SolveError::BadInput {
            what: format!("expected {} inputs, got {}", vp.plan.n_inputs - 1, inputs.len()).into(),
        });
    }
    if let Some(i) = inputs.iter().position(|v| !v.is_finite()) {
        return Err(SolveError::BadInput {
            what: format!("given value {} is {}", i + 1, inputs[i]).into(),
        });
    }
    let geometry = crate::steps::Geometry::of(model);
    let sampling = Sampling {
        lo: vp.range[0],
        hi: vp.range[1],
        samples: vp.samples,
        zero: zero_of(model),
        periodic: vp.periodic,
    };
    let scale = crate::kinematics::model_scale(model);
    let given = |v: f64| {
        let mut g = inputs.to_vec();
        g.push(v);
        g
    };
    let found = solve_with(
        &sampling,
        vp.plan.branches,
        |v, signs| residual_with(model, &geometry, vp, inputs, v, signs),
        |v, signs| verified(model, vp, &given(v), signs),
        |a: &Solution, b: &Solution| {
            a.poses.iter().zip(&b.poses).all(|(p, q)| {
                (p.translation.vector - q.translation.vector).norm() <= 1e-7 * scale
                    && p.rotation.angle_to(&q.rotation) <= 1e-7
            })
        },
    );
    Ok(found
        .into_iter()
        .map(|(signs, r, solution)| Assembly {
            signs,
            virtual_value: r.x,
            residual: r.residual,
            kind: r.kind,
            solution,
        })
        .collect())
}

/// One assembly found by generated code (`Name::fk_numeric`): `J` joint
/// values, `P` points of `D` coordinates, `B` ± choices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found<const J: usize, const P: usize, const D: usize, const B: usize> {
    /// The ± choices of the plan's branch it was found on.
    pub signs: [Sign; B],
    /// The virtual variable's value.
    pub virtual_value: f64,
    /// The compatibility residual there.
    pub residual: f64,
    /// How it was found ([`RootKind::Tangency`]: not certified).
    pub kind: RootKind,
    /// Every joint's value.
    pub q: [f64; J],
    /// Every joint's point, then the named points.
    pub points: [[f64; D]; P],
}

/// Whether two joint values are one: within `tol`, or a whole number of
/// turns apart to 1e-9 (an angle).
pub fn same_value(x: f64, y: f64, tol: f64) -> bool {
    let d = (x - y).abs();
    let turn = 2.0 * std::f64::consts::PI;
    d <= tol || (d - turn * (d / turn).round()).abs() <= 1e-9
}

/// The driver both the interpreter ([`solve`]) and generated code run: on
/// every branch of a plan with `branches` ± choices, every root of
/// `residual(v, signs)` over `sampling` ([`roots`]), solved by
/// `solution(v, signs)` (`None`: the verification failed, the root is
/// dropped) and kept unless `same` as one found before (where two
/// branches meet).
pub fn solve_with<S>(
    sampling: &Sampling,
    branches: usize,
    residual: impl Fn(f64, &[Sign]) -> Option<f64>,
    solution: impl Fn(f64, &[Sign]) -> Option<S>,
    same: impl Fn(&S, &S) -> bool,
) -> Vec<(Vec<Sign>, Root, S)> {
    let mut out: Vec<(Vec<Sign>, Root, S)> = Vec::new();
    for (signs, ()) in crate::solution::every_branch(branches, |_| ()) {
        for r in roots(|v| residual(v, &signs), sampling) {
            let Some(s) = solution(r.x, &signs) else { continue };
            if out.iter().any(|(_, _, o)| same(o, &s)) {
                continue;
            }
            out.push((signs.clone(), r, s));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The roots `f` has on `[lo, hi]` (periodic or not), and their kinds.
    fn check(f: impl Fn(f64) -> Option<f64>, lo: f64, hi: f64, periodic: bool, want: &[(f64, RootKind)]) {
        let s = Sampling {
            lo,
            hi,
            samples: 100,
            zero: 1e-9,
            periodic,
        };
        let got = roots(f, &s);
        assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
        for (g, &(x, kind)) in got.iter().zip(want) {
            let tol = if kind == RootKind::Tangency { 1e-6 } else { 1e-14 };
            let mut d = (g.x - x).abs();
            if periodic {
                d = d.min((hi - lo - d).abs());
            }
            assert!(d <= tol, "{g:?} vs {x}");
            assert_eq!(g.kind, kind, "{g:?}");
        }
    }

    #[test]
    fn simple_and_double_roots() {
        use RootKind::*;
        // (x − 0.3)(x + 0.7): two crossings.
        check(
            |x| Some((x - 0.3) * (x + 0.7)),
            -1.0,
            1.0,
            false,
            &[(-0.7, Crossing), (0.3, Crossing)],
        );
        // (x − 0.31)²: a double root between samples, a tangency; the
        // crossing at −0.5 as well.
        check(
            |x| Some((x - 0.31) * (x - 0.31) * (x + 0.5)),
            -1.0,
            1.0,
            false,
            &[(-0.5, Crossing), (0.31, Tangency)],
        );
        // Two close roots between two samples (0.02 apart): 0.301, 0.305.
        check(
            |x| Some((x - 0.301) * (x - 0.305)),
            -1.0,
            1.0,
            false,
            &[(0.301, Crossing), (0.305, Crossing)],
        );
        // A minimum of |f| 1e-3 from zero is no root.
        check(|x| Some((x - 0.31) * (x - 0.31) + 1e-3), -1.0, 1.0, false, &[]);
    }

    #[test]
    fn roots_near_the_ends() {
        use RootKind::*;
        // At the very ends, and 1e-7 inside them.
        check(
            |x| Some(x * x - 1.0),
            -1.0,
            1.0,
            false,
            &[(-1.0, Crossing), (1.0, Crossing)],
        );
        let (a, b) = (-1.0 + 1e-7, 1.0 - 1e-7);
        check(
            |x| Some((x - a) * (x - b)),
            -1.0,
            1.0,
            false,
            &[(a, Crossing), (b, Crossing)],
        );
        // Periodic: sin(x − c), c = π − 2.6e-6, crosses near the seam at c
        // and at c − π; a root at the seam (sin x at ±π) is reported once.
        let c = std::f64::consts::PI - 2.6e-6;
        check(
            |x| Some((x - c).sin()),
            -std::f64::consts::PI,
            std::f64::consts::PI,
            true,
            &[(c - std::f64::consts::PI, Crossing), (c, Crossing)],
        );
        check(
            |x| Some(x.sin()),
            -std::f64::consts::PI,
            std::f64::consts::PI,
            true,
            &[(-std::f64::consts::PI, Crossing), (0.0, Crossing)],
        );
    }

    #[test]
    fn gaps() {
        use RootKind::*;
        // Undefined on (−0.2, 0.4): roots at −0.5 and 0.7 found, no NaN
        // read; a root 1e-12 before the gap's edge at 0.4 (between the
        // last sample and the edge) is found too.
        let f = |x: f64| (x <= -0.2 || x >= 0.4).then_some((x + 0.5) * (x - 0.7));
        check(f, -1.0, 1.0, false, &[(-0.5, Crossing), (0.7, Crossing)]);
        let e = 0.4 + 1e-6;
        let f = |x: f64| (x >= 0.4).then_some(x - e);
        check(f, -1.0, 1.0, false, &[(e, Crossing)]);
        // A residual that ends at a gap's edge 1e-12 from zero (two
        // branches meeting where they touch the root): found at the edge,
        // not certified by a sign change.
        let f = |x: f64| (x <= 0.5037).then_some(0.5037 - x + 1e-12);
        check(f, -1.0, 1.0, false, &[(0.5037, Tangency)]);
        // Nowhere defined: no roots.
        check(|_| None, -1.0, 1.0, false, &[]);
    }

    #[test]
    fn input_residuals() {
        use std::f64::consts::PI;
        // A slide's: the difference itself.
        assert_eq!(Compatibility::input_residual(None, 7.5, 2.0), 5.5);
        // An angle's: wrapped into (−π, π], as an arc of the given radius.
        for (computed, given, want) in [
            (0.3, 0.1, 0.2),
            (3.0, -3.0, 6.0 - 2.0 * PI),
            (-3.0, 3.0, 2.0 * PI - 6.0),
        ] {
            let r = Compatibility::input_residual(Some(10.0), computed, given);
            assert!((r - 10.0 * want).abs() <= 1e-12, "{computed} {given}: {r}");
        }
        assert_eq!(angle_miss(PI), PI);
        assert_eq!(angle_miss(-PI), PI);
        assert!((angle_miss(5.0 * PI / 2.0) - PI / 2.0).abs() <= 1e-15);
        // The wrap's jump is a sign change that is no root: found by the
        // driver, it keeps its size (verification then drops it).
        let found = roots(
            |x| Some(Compatibility::input_residual(Some(1.0), x, 0.5)),
            &Sampling {
                lo: -PI,
                hi: PI,
                samples: 720,
                zero: 1e-10,
                periodic: true,
            },
        );
        let real: Vec<_> = found.iter().filter(|r| r.residual.abs() <= 1e-10).collect();
        assert_eq!(real.len(), 1, "{found:?}");
        assert!((real[0].x - 0.5).abs() <= 1e-12);
    }
}
