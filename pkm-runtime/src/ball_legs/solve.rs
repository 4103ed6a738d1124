//! Every assembly at given inputs: the pose equations' paths
//! ([`super::homotopy`]) ended, each real root certified by Krawczyk's
//! operator on the equations in the reals (a box proven to hold exactly
//! one root) or reported possible, then every joint solved by the inverse
//! plan at that pose on each of its branches and verified against the
//! inputs.

use super::homotopy::{self, End, Point};
use super::system::{enclosed, Locus, UNKNOWNS};
use super::BallLegs;
use crate::certify::{self, Enclosed};
use crate::interval::Interval;
use crate::model::{JointType, Model};
use crate::newton::Output;
use crate::plan::{self, Plan, Solution};
use crate::primitives::Sign;
use crate::solution::SolveError;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

/// A real root of the pose equations.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseRoot {
    /// The platform frame's pose.
    pub pose: Isometry3<f64>,
    /// The unknowns `(p / size, q)` and, where certified, the box proven
    /// to hold this root and no other.
    pub x: [f64; UNKNOWNS],
    /// The certificate; `None`: possible (Krawczyk's operator passed on
    /// no box about it: singular or too ill-conditioned to prove).
    pub cert: Option<[Interval; UNKNOWNS]>,
}

/// One assembly: a real root and an inverse branch that meets the inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// Which root of [`Assemblies::roots`].
    pub root: usize,
    /// The inverse plan's branch.
    pub signs: Vec<Sign>,
    /// Every joint and link.
    pub solution: Solution,
}

/// Every real root of the pose equations, with what the paths did.
#[derive(Debug, Clone, PartialEq)]
pub struct Roots {
    /// The real roots, certified first then possible, each once.
    pub roots: Vec<PoseRoot>,
    /// Paths (one per `±q` pair of the start's roots).
    pub paths: usize,
    /// Paths that ended at complex roots.
    pub complex: usize,
    /// Paths that went to infinity.
    pub infinite: usize,
    /// Paths that failed (a singular end, or lost).
    pub failed: usize,
    /// Paths that ended at a real root another path ended at too.
    pub coincident: usize,
}

/// One assembly generated code found (`Name::fk_numeric` of a mechanism
/// whose legs end in balls): a real root, the generated inverse solution's
/// branch `signs` (`B` ± choices) that meets the inputs there, and its
/// solution `S` (every joint's value and point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found<S, const B: usize> {
    /// Which root of [`Assemblies::roots`].
    pub root: usize,
    /// The inverse solution's branch.
    pub signs: [Sign; B],
    /// Every joint and point.
    pub solution: S,
}

/// Every assembly at some inputs (`A`: the interpreter's [`Assembly`] or
/// generated code's [`Found`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Assemblies<A = Assembly> {
    /// The pose equations' real roots and what the paths did.
    pub roots: Roots,
    /// The assemblies, by root.
    pub assemblies: Vec<A>,
    /// Roots no inverse branch verifies at (index into `roots.roots`).
    pub unmet: Vec<usize>,
}

/// Every assembly of the real roots `roots`: those `at(k, root)` gives for
/// each (the inverse solution's branches that meet the inputs there), a
/// root where it gives none in `unmet`.
pub fn assemble<A>(roots: Roots, mut at: impl FnMut(usize, &PoseRoot) -> Vec<A>) -> Assemblies<A> {
    let mut assemblies = Vec::new();
    let mut unmet = Vec::new();
    for (k, root) in roots.roots.iter().enumerate() {
        let found = at(k, root);
        if found.is_empty() {
            unmet.push(k);
        }
        assemblies.extend(found);
    }
    Assemblies {
        roots,
        assemblies,
        unmet,
    }
}

/// Some of the inverse solution's ± choices and the actuated joints whose
/// values depend on those choices alone (indices into the inputs), found
/// and proven on the traced solver at compile time: two branches that
/// agree on a group's choices give its joints the same values. A group
/// without joints: choices no actuated joint depends on (every sign of
/// them is an assembly where the rest is); without choices: joints no
/// choice moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChoiceGroup {
    /// The choices (bit k of a branch's index in `signs_of` order).
    pub choices: &'static [usize],
    /// The actuated joints they move.
    pub joints: &'static [usize],
}

/// The branches (indices in `signs_of` order, ascending) whose actuated
/// joints can meet the inputs, found by probing each group's choices
/// rather than solving every branch: `probe(signs)` gives the actuated
/// joints' values on a branch (`None`: the branch failed), `meets(i, v)`
/// whether joint `i`'s value `v` meets its input. Branches run for every
/// sign of the widest group at once (the other groups' signs cycled
/// alongside); a group's signs are kept where its joints meet, and the
/// branches returned are every combination of the kept signs with every
/// sign of the free choices. A branch left out has some group's joints at
/// the values of a probe where they did not meet: it cannot meet the
/// inputs. `None` where a probe failed (a failure cannot be put down to
/// one group): the caller then solves every branch.
pub fn branches_to_solve<const B: usize, const N: usize>(
    groups: &[ChoiceGroup],
    mut probe: impl FnMut([Sign; B]) -> Option<[f64; N]>,
    meets: impl Fn(usize, f64) -> bool,
) -> Option<Vec<usize>> {
    let bits = |g: &ChoiceGroup, a: usize| -> usize {
        g.choices.iter().enumerate().fold(0, |b, (i, &k)| b | (a >> i & 1) << k)
    };
    let probed = |g: &&ChoiceGroup| !g.joints.is_empty();
    let widest = groups.iter().filter(probed).map(|g| g.choices.len()).max().unwrap_or(0);
    let mut kept: Vec<Vec<usize>> = vec![Vec::new(); groups.len()];
    for a in 0..1usize << widest {
        let index = groups
            .iter()
            .filter(probed)
            .fold(0, |b, g| b | bits(g, a % (1 << g.choices.len())));
        let values = probe(crate::solution::signs_of::<B>(index))?;
        for (g, kept) in groups.iter().zip(&mut kept) {
            if probed(&g) && a < 1 << g.choices.len() && g.joints.iter().all(|&i| meets(i, values[i])) {
                kept.push(bits(g, a));
            }
        }
    }
    // Every combination: the free choices take every sign.
    let mut out = vec![0usize];
    for (g, kept) in groups.iter().zip(kept) {
        let options: Vec<usize> = if probed(&g) {
            kept
        } else {
            (0..1usize << g.choices.len()).map(|a| bits(g, a)).collect()
        };
        out = out.iter().flat_map(|&b| options.iter().map(move |&o| b | o)).collect();
    }
    out.sort_unstable();
    Some(out)
}

/// Whether a finite end is real: its unknowns' imaginary parts below this.
pub const REAL: f64 = 1e-6;

/// The equations on some loci, as a residual to certify: enclosed over
/// boxes on intervals, evaluated at points in plain floats (the same rows,
/// [`super::system::with_slopes`] over either ring).
struct Equations<'a>(&'a [Locus<f64>]);

impl certify::Residual<UNKNOWNS> for Equations<'_> {
    fn enclose(&mut self, b: &[Interval; UNKNOWNS]) -> Option<Enclosed<UNKNOWNS>> {
        let out = enclosed(self.0, b);
        Some(Enclosed {
            f: out.f,
            j: out.j,
            decided: true,
        })
    }

    fn at(&mut self, p: &[f64; UNKNOWNS]) -> Option<([f64; UNKNOWNS], [[f64; UNKNOWNS]; UNKNOWNS])> {
        let (f, j) = super::system::at(self.0, p);
        f.iter().all(|v| v.is_finite()).then_some((f, j))
    }
}

/// The platform pose of real unknowns `x`.
fn pose_of(x: &[f64; UNKNOWNS], scale: f64) -> Isometry3<f64> {
    let q = UnitQuaternion::from_quaternion(Quaternion::new(x[3], x[4], x[5], x[6]));
    Isometry3::from_parts(Translation3::new(x[0] * scale, x[1] * scale, x[2] * scale), q)
}

/// Every real root of the pose equations on the loci `loci` (lengths
/// over `scale`, the platform's pose in lengths): every path of the
/// shape's start carried to them ([`homotopy::ends`]); each end with
/// imaginary parts below [`REAL`] refined and certified in the reals
/// ([`certify::isolate`]) or, where no box passes, possible; `q` and `−q`
/// one pose, and a pose two paths reach counted once (`coincident`).
pub fn roots(loci: &[Locus<f64>], scale: f64) -> Roots {
    let shape: Vec<_> = loci.iter().map(|l| (l.on, l.normal.is_some())).collect();
    let start = homotopy::start(&shape);
    let ends = homotopy::ends(&start, loci);
    let mut out = Roots {
        roots: Vec::new(),
        paths: ends.len(),
        complex: 0,
        infinite: 0,
        failed: 0,
        coincident: 0,
    };
    let mut real: Vec<Point> = Vec::new();
    for end in ends {
        match end {
            End::Finite(x) if x.iter().all(|c| c.im.abs() <= REAL * (1.0 + c.re.abs())) => real.push(x),
            End::Finite(_) => out.complex += 1,
            End::Infinite => out.infinite += 1,
            End::Failed => out.failed += 1,
        }
    }
    for x in real {
        let x: [f64; UNKNOWNS] = homotopy::canonical(x).map(|c| c.re);
        let (mut x, cert) = match certify::isolate_with(x, &mut Equations(loci)) {
            Some(r) => (r.x, Some(r.cert)),
            None => (x, None),
        };
        // q and −q: one pose, the one whose largest component is positive.
        if x[3..]
            .iter()
            .copied()
            .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m })
            < 0.0
        {
            for v in &mut x[3..] {
                *v = -*v;
            }
        }
        let pose = pose_of(&x, scale);
        let near = |r: &PoseRoot| {
            (r.pose.translation.vector - pose.translation.vector).norm() <= 1e-9 * scale
                && r.pose.rotation.angle_to(&pose.rotation) <= 1e-9
        };
        if out.roots.iter().any(near) {
            out.coincident += 1;
            continue;
        }
        out.roots.push(PoseRoot { pose, x, cert });
    }
    out.roots.sort_by_key(|r| r.cert.is_none());
    out
}

/// Whether a solution meets the inputs, read off a model once: its
/// actuated joints, each with the size its angle is an arc of (`None`: a
/// slide), and the verification's zero ([`crate::fk_numeric::zero_of`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Meets {
    joints: Vec<(usize, Option<f64>)>,
    zero: f64,
}

impl Meets {
    /// The check of `model`'s actuated joints.
    pub fn of(model: &Model) -> Meets {
        let scale = crate::kinematics::model_scale(model);
        Meets {
            joints: model
                .inputs()
                .into_iter()
                .map(|j| (j, (model.joints[j].kind != JointType::P).then_some(scale)))
                .collect(),
            zero: crate::fk_numeric::zero_of(model),
        }
    }

    /// Whether the value `value` of the `i`-th actuated joint meets its
    /// input `q` (as [`Meets::at`] checks each).
    pub fn input(&self, i: usize, value: f64, q: f64) -> bool {
        self.joints
            .get(i)
            .is_some_and(|&(_, arc)| crate::fk_numeric::Compatibility::input_residual(arc, value, q).abs() <= self.zero)
    }

    /// Whether joint values `values` (one per joint) meet the `inputs`
    /// (the actuated joints in declaration order): each within the zero,
    /// an angle as an arc of the size.
    pub fn at(&self, inputs: &[f64], values: &[f64]) -> bool {
        self.joints.len() == inputs.len()
            && self
                .joints
                .iter()
                .zip(inputs)
                .enumerate()
                .all(|(i, (&(j, _), &q))| self.input(i, values[j], q))
    }
}

impl BallLegs {
    /// The declared `outputs`' values (what the inverse plan is given)
    /// with the platform at `pose`.
    pub fn given_values(&self, model: &Model, outputs: &[Output], pose: &Isometry3<f64>) -> Vec<f64> {
        let mut poses = vec![Isometry3::identity(); model.links.len()];
        poses[self.platform] = *pose;
        outputs
            .iter()
            .flat_map(|o| plan::output_values(&poses, &[], model.planar, o))
            .collect()
    }

    /// Every assembly of `model` at `inputs` (the actuated joints in
    /// declaration order): the pose equations' real roots ([`roots`]),
    /// each solved by `inverse` (given the declared `outputs`, read off
    /// the root's platform pose) on every branch whose actuated joints
    /// meet the inputs (to [`crate::fk_numeric::zero_of`]).
    ///
    /// # Errors
    /// Inputs of the wrong count or not finite, or loci that cannot be
    /// formed (a leg's passive axes apart at these inputs).
    pub fn solve(
        &self,
        model: &Model,
        inverse: &Plan,
        outputs: &[Output],
        inputs: &[f64],
    ) -> Result<Assemblies, SolveError> {
        crate::fk_numeric::check_inputs(inputs, model.inputs().len())?;
        let loci = self
            .loci(model, inputs)
            .map_err(|why| SolveError::BadInput { what: why.into() })?;
        let roots = roots(&loci, self.scale);
        let prepared = plan::Prepared::new(model, inverse);
        let meets = Meets::of(model);
        Ok(assemble(roots, |k, root| {
            let given = self.given_values(model, outputs, &root.pose);
            crate::solution::every_branch(inverse.branches, |s| prepared.run(&given, s))
                .into_iter()
                .filter_map(|(signs, r)| {
                    let solution = r.ok()?;
                    meets.at(inputs, &solution.values).then_some(Assembly {
                        root: k,
                        signs,
                        solution,
                    })
                })
                .collect()
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Groups probed instead of every branch give the same branches as
    /// every branch solved and checked: joints that depend on their own
    /// group's choices alone (joint 0 on choice 0; joint 1 on choices 1
    /// and 3, meeting on two of their four signs; joint 2 on none), choice
    /// 2 free. Every subset of the meeting signs tried.
    #[test]
    fn probed_groups_give_every_branch_that_meets() {
        const GROUPS: &[ChoiceGroup] = &[
            ChoiceGroup {
                choices: &[0],
                joints: &[0],
            },
            ChoiceGroup {
                choices: &[1, 3],
                joints: &[1],
            },
            ChoiceGroup {
                choices: &[2],
                joints: &[],
            },
            ChoiceGroup {
                choices: &[],
                joints: &[2],
            },
        ];
        let minus = |s: &[Sign; 4], k: usize| f64::from(u8::from(s[k] == Sign::Minus));
        // Joint values that name their group's signs.
        let values = |s: [Sign; 4]| [minus(&s, 0), 10.0 + minus(&s, 1) + 2.0 * minus(&s, 3), 7.0];
        for wanted in 0..1u32 << 7 {
            // Which values of each joint meet: joint 0's two, joint 1's four, joint 2's one.
            let meets = |i: usize, v: f64| {
                let bit = match i {
                    0 => v as u32,
                    1 => 2 + (v - 10.0) as u32,
                    _ => 6,
                };
                wanted >> bit & 1 == 1
            };
            let got = branches_to_solve::<4, 3>(GROUPS, |s| Some(values(s)), meets).unwrap();
            let every: Vec<usize> = (0..16)
                .filter(|&b| {
                    let v = values(crate::solution::signs_of::<4>(b));
                    (0..3).all(|i| meets(i, v[i]))
                })
                .collect();
            assert_eq!(got, every, "meeting values {wanted:07b}");
        }
        // A probe that fails: every branch is to be solved.
        assert_eq!(branches_to_solve::<4, 3>(GROUPS, |_| None, |_, _| true), None);
    }
}
