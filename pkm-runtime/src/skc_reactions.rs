//! The reaction system of Newton–Euler over the ordered SKCs (seed 003
//! §3.1), written once over [`Scalar`]: what each link's joints must
//! supply (its bodies' inertial wrenches less gravity, less the loads on
//! it), a parallelogram's bars folded into its joint, an S–S link's idle
//! spin dropped, and each SKC's rows and right-hand sides. At `f64` it is
//! the runtime's Newton–Euler ([`crate::newton_euler`]); traced on the
//! code generator's symbols it is the generated inverse dynamics, which
//! emits only the solve of each SKC's system.
//!
//! A wrench is `d` numbers about the base origin: (fx, fy, mz) planar,
//! (f, m) spatial; a unit twist's power coefficients against it are
//! (vx, vy, ωz) or (v, ω). In the equations moments are divided by the
//! mechanism's size ([`Layout::unit`]), so that forces and moments weigh
//! alike.
//!
//! Link `l`'s balance: `Σ ±W_j = D_l`, with `W_j` joint j's reaction (what
//! its first link exerts on its second: + on the second, − on the first)
//! and `D_l = Σ (m (a_c − g), I α + ω × I ω) − loads`, about the origin.
//! A passive joint's reaction does no work along its motion: `ξ·W_j = 0`
//! per unit twist ξ (with massive parallelogram bars, `−Σ D_i·ξ'_i`).

use crate::frame::Frame;
use crate::model::{JointType, Place};
use crate::newton_euler::SkcParts;
use crate::scalar::{cross, dot, Scalar};
use crate::velocity::Screw;

/// How wrenches are written: `d` numbers, moments over the size in the
/// equations.
#[derive(Debug, Clone, Copy)]
pub struct Layout<T> {
    /// A planar mechanism balances (Fx, Fy, Mz) per link.
    pub planar: bool,
    /// The mechanism's size ([`crate::steps::Geometry::scale`]).
    pub size: T,
}

impl<T: Scalar> Layout<T> {
    /// Numbers per wrench: 3 planar, 6 spatial.
    pub fn d(&self) -> usize {
        if self.planar {
            3
        } else {
            6
        }
    }

    /// Where a wrench turns from forces to moments: (fx, fy | mz), (f | m).
    pub fn moments_from(&self) -> usize {
        if self.planar {
            2
        } else {
            3
        }
    }

    /// A wrench `(f, m)` as `d` numbers (also a twist's power coefficients
    /// as `(v, ω)`).
    pub fn numbers(&self, f: [T; 3], m: [T; 3]) -> Vec<T> {
        if self.planar {
            vec![f[0], f[1], m[2]]
        } else {
            f.iter().chain(&m).copied().collect()
        }
    }

    /// A unit twist's power coefficients against a wrench: (v, ω).
    pub fn coefficients(&self, t: &Screw<T>) -> Vec<T> {
        self.numbers(t.v, t.w)
    }

    /// What component `c` is divided by in the equations: the size for a moment.
    pub fn unit(&self, c: usize) -> T {
        if c >= self.moments_from() {
            self.size
        } else {
            T::c(1.0)
        }
    }
}

/// How a body moves at an instant, world axes: its angular velocity and
/// acceleration, and its centroid's acceleration. The runtime takes them
/// from the velocity analysis's twists, generated code from the exact time
/// derivatives of its link poses.
#[derive(Debug, Clone, Copy)]
pub struct CentroidMotion<T> {
    /// Angular velocity ω.
    pub w: [T; 3],
    /// Angular acceleration α.
    pub alpha: [T; 3],
    /// The centroid's acceleration.
    pub a_c: [T; 3],
}

/// What a body's carrier must supply: its inertial wrench less gravity
/// `g`, about the base origin, as (force, moment), for mass `mass`,
/// centroid `centroid` and inertia `inertia` (the body's frame at `pose`):
/// `f = m (a_c − g)`, `m_o = R (I α_b + ω_b × I ω_b) + c × f` (Euler's
/// equations in the body's axes, `ω_b = Rᵀω`, `α_b = Rᵀα`).
pub fn inertial_demand<T: Scalar>(
    pose: &Frame<T>,
    motion: &CentroidMotion<T>,
    mass: T,
    centroid: [T; 3],
    inertia: &[[T; 3]; 3],
    gravity: [T; 3],
) -> ([T; 3], [T; 3]) {
    let centroid = pose.apply(centroid);
    let (wb, ab) = (pose.rotate_back(motion.w), pose.rotate_back(motion.alpha));
    let times = |v: [T; 3]| -> [T; 3] {
        core::array::from_fn(|i| (0..3).map(|k| inertia[i][k] * v[k]).fold(T::c(0.0), |s, x| s + x))
    };
    let (iab, iwb) = (times(ab), times(wb));
    let gyro = cross(wb, iwb);
    let moment = pose.rotate(core::array::from_fn(|i| iab[i] + gyro[i]));
    let f: [T; 3] = core::array::from_fn(|i| mass * (motion.a_c[i] - gravity[i]));
    let about_origin = cross(centroid, f);
    (f, core::array::from_fn(|i| moment[i] + about_origin[i]))
}

/// The line about which `link` turns freely: for a link held by exactly
/// two spherical joints and by nothing else (an S–S coupler), the first
/// ball's centre and the unit direction to the second's, in the link's
/// frame (NaN where the two centres coincide); `None` for any other link.
/// `joints` gives each joint's type, links and places.
pub fn idle_spin_line<T: Scalar>(
    joints: impl IntoIterator<Item = (JointType, [usize; 2], [Place<T>; 2])>,
    link: usize,
) -> Option<([T; 3], [T; 3])> {
    let mut centres = Vec::new();
    for (kind, links, places) in joints.into_iter().filter(|j| j.1.contains(&link)) {
        if kind != JointType::S || links[0] == links[1] {
            return None;
        }
        centres.push(places[usize::from(links[1] == link)].at());
    }
    let [a, b] = centres[..] else { return None };
    let d: [T; 3] = core::array::from_fn(|i| b[i] - a[i]);
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    Some((a, d.map(|x| x / n)))
}

/// An inertia without its moment about the unit `axis`: `I − (âᵀIâ) ââᵀ`
/// (for an inertia symmetric about the axis, the moment about every normal
/// to it, the axial one zero). An S–S link's idle spin does no work: its
/// bodies' inertias are taken without it.
pub fn without_axial<T: Scalar>(inertia: &[[T; 3]; 3], axis: &[T; 3]) -> [[T; 3]; 3] {
    let ia: [T; 3] = core::array::from_fn(|i| dot(inertia[i], *axis));
    let along = dot(*axis, ia);
    core::array::from_fn(|i| core::array::from_fn(|j| inertia[i][j] - axis[i] * axis[j] * along))
}

/// What a body moves with, for the demand.
#[derive(Debug, Clone, Copy)]
pub enum Carried<T> {
    /// A link.
    Link(usize),
    /// A bar of the parallelogram `joint`, hinged on its arm-carrying link
    /// `carrier`; `xi` is its unit twist relative to that link (the turn
    /// about its hinge axis through the hinge, world).
    Bar {
        /// The parallelogram joint.
        joint: usize,
        /// The arm-carrying link.
        carrier: usize,
        /// The bar's unit twist relative to the carrier.
        xi: Screw<T>,
    },
}

/// A body with mass, where it is and how it moves.
#[derive(Debug, Clone, Copy)]
pub struct MovingBody<T> {
    /// What it moves with.
    pub on: Carried<T>,
    /// Its frame in the world.
    pub pose: Frame<T>,
    /// Its motion.
    pub motion: CentroidMotion<T>,
    /// Its mass.
    pub mass: T,
    /// Its centroid, its frame.
    pub centroid: [T; 3],
    /// Its inertia about the centroid, its axes.
    pub inertia: [[T; 3]; 3],
}

/// An external load on a link, world: a force through a point and a moment.
#[derive(Debug, Clone, Copy)]
pub struct Load<T> {
    /// The link.
    pub link: usize,
    /// Where the force acts, world.
    pub at: [T; 3],
    /// The force.
    pub force: [T; 3],
    /// The moment.
    pub moment: [T; 3],
}

/// What the joints must supply: per link, a wrench of `d` numbers about
/// the origin, and per joint the work of its parallelogram's bars along
/// their turn with its first link held (zero for any other joint).
#[derive(Debug, Clone)]
pub struct Demands<T> {
    /// Per link.
    pub demand: Vec<Vec<T>>,
    /// Per joint.
    pub bar_work: Vec<T>,
}

/// Each link's demand: its bodies' inertial wrenches less gravity
/// ([`inertial_demand`]), an S–S link's bodies without their moment about
/// its line ([`without_axial`]; `lines` per link, [`idle_spin_line`]),
/// each parallelogram bar's passed to its joint's first link with its
/// power along its turn relative to that link ([`bar_power`]), less the
/// loads. `twists` are every joint's unit twists' power coefficients
/// ([`Layout::coefficients`]) and `first` each joint's first link.
#[allow(clippy::too_many_arguments)]
pub fn demands<T: Scalar>(
    layout: &Layout<T>,
    n_links: usize,
    first: &[usize],
    lines: &[Option<([T; 3], [T; 3])>],
    twists: &[Vec<Vec<T>>],
    bodies: &[MovingBody<T>],
    loads: &[Load<T>],
    gravity: [T; 3],
) -> Demands<T> {
    let mut demand = vec![vec![T::c(0.0); layout.d()]; n_links];
    let mut bar_work = vec![T::c(0.0); first.len()];
    for b in bodies {
        let inertia = match b.on {
            Carried::Link(l) => match lines[l] {
                Some((_, axis)) => without_axial(&b.inertia, &axis),
                None => b.inertia,
            },
            Carried::Bar { .. } => b.inertia,
        };
        let (f, m) = inertial_demand(&b.pose, &b.motion, b.mass, b.centroid, &inertia, gravity);
        let wrench = layout.numbers(f, m);
        let link = match b.on {
            Carried::Link(l) => l,
            Carried::Bar { joint, carrier, xi } => {
                let power = bar_power(layout, first[joint], carrier, &xi, &twists[joint][0], &wrench);
                bar_work[joint] = bar_work[joint] + power;
                first[joint]
            }
        };
        for (x, y) in demand[link].iter_mut().zip(wrench) {
            *x = *x + y;
        }
    }
    for l in loads {
        let about = cross(l.at, l.force);
        let wrench = layout.numbers(l.force, core::array::from_fn(|i| l.moment[i] + about[i]));
        for (x, y) in demand[l.link].iter_mut().zip(wrench) {
            *x = *x - y;
        }
    }
    Demands { demand, bar_work }
}

/// A parallelogram bar's power along its motion relative to its joint's
/// first link `first`, per unit rate of the parallelogram, against its
/// demand `wrench`.
///
/// The bars are not links. Bar i takes `H_i` from the arm-carrying link at
/// its hinge and `K_i` from the other link at its far hinge, with
/// `H_i + K_i = D_i`; each hinge is a frictionless revolute, so `H_i`
/// does no work along the bar's turn relative to the arm-carrying link and
/// `K_i` none along its turn relative to the other link. The joint's
/// reaction `W` is what the parallelogram exerts on its second link (`−K`
/// or `−H` summed over the bars, whichever side that link is): the first
/// link receives `−W − Σ D_i`, and the virtual power with the first link
/// held gives the joint's row `W·ξ = −Σ D_i·ξ'_i`, with `ξ` the second
/// link's unit twist relative to the first (`joint_twist`, as power
/// coefficients) and `ξ'_i` bar i's (`ξ_b`, the turn about its hinge, with
/// the arm on the first link; `ξ + ξ_b` with the arm on the second).
pub fn bar_power<T: Scalar>(
    layout: &Layout<T>,
    first: usize,
    carrier: usize,
    xi: &Screw<T>,
    joint_twist: &[T],
    wrench: &[T],
) -> T {
    let own = layout.coefficients(xi);
    let relative: Vec<T> = if carrier == first {
        own
    } else {
        own.iter().zip(joint_twist).map(|(x, y)| *x + *y).collect()
    };
    relative.iter().zip(wrench).fold(T::c(0.0), |acc, (x, y)| acc + *x * *y)
}

/// How a joint joining `links` acts on link `l`: +1 on its second link
/// (the reaction is what the first exerts on it), −1 on its first, `None`
/// on any other.
pub fn acting_on(links: [usize; 2], l: usize) -> Option<f64> {
    if links[1] == l {
        Some(1.0)
    } else if links[0] == l {
        Some(-1.0)
    } else {
        None
    }
}

/// Per joint, its SKC and the column where its reaction starts in that
/// SKC's unknowns (`d` per joint); `None` if a joint is in no SKC.
pub fn places(skcs: &[SkcParts], n_joints: usize, d: usize) -> Option<Vec<(usize, usize)>> {
    let mut place = vec![(usize::MAX, 0); n_joints];
    for (k, skc) in skcs.iter().enumerate() {
        for (i, &j) in skc.joints.iter().enumerate() {
            place[j] = (k, i * d);
        }
    }
    place.iter().all(|p| p.0 != usize::MAX).then_some(place)
}

/// One row of an SKC's system for a unit twist of a passive joint: the
/// reaction does no work along it (`ξ·W = 0`, or a parallelogram's
/// `−Σ D_i·ξ'_i` with massive bars).
#[derive(Debug, Clone)]
pub struct PassiveRow<T> {
    /// The joint's position in the SKC.
    pub at: usize,
    /// The joint.
    pub joint: usize,
    /// The twist's power coefficients against the joint's reaction, moments
    /// over the size, and the row over the size for a turn (lever arms
    /// against forces) or as it is for a slide (a unit direction; a
    /// parallelogram's, per radian of its arm, is left in lengths).
    pub coefficients: Vec<T>,
    /// Its right-hand side.
    pub rhs: T,
}

/// One SKC's reaction system `a x = b`, `x` its joints' reactions (`d`
/// numbers each, in [`SkcParts::joints`] order, moments over the size):
/// its links' balances, then its passive rows.
#[derive(Debug, Clone)]
pub struct SkcSystem<T> {
    /// Its rows: `d` per link, then one per passive row.
    pub rows: usize,
    /// Its unknowns: `d` per joint.
    pub unknowns: usize,
    /// The entries of `a` (row, column, value): ±1 where a joint acts on
    /// a link, the passive rows' coefficients.
    pub entries: Vec<(usize, usize, T)>,
    /// `b` without the reactions of later SKCs' joints.
    pub rhs: Vec<T>,
    /// `b[row] −= sign · x_joint[c]` for those reactions (solved over the
    /// size like `x`): (row, joint, c, sign).
    pub known: Vec<(usize, usize, usize, f64)>,
    /// Per actuator twist, its coefficients against the unknowns (moments
    /// over the size): `ξ·W` is the actuator's force.
    pub actuated: Vec<Vec<(usize, T)>>,
    /// Its passive rows, in row order after the links'.
    pub passive: Vec<PassiveRow<T>>,
}

/// What every SKC's system is assembled from.
#[derive(Debug, Clone, Copy)]
pub struct Assembly<'a, T> {
    /// How wrenches are written.
    pub layout: &'a Layout<T>,
    /// Per joint, its links.
    pub links: &'a [[usize; 2]],
    /// Per joint, its type.
    pub kinds: &'a [JointType],
    /// Per joint, whether it is actuated.
    pub actuated: &'a [bool],
    /// Per joint, its unit twists' power coefficients.
    pub twists: &'a [Vec<Vec<T>>],
    /// What the joints must supply ([`demands`]).
    pub demands: &'a Demands<T>,
    /// Per joint, its SKC and column ([`places`]).
    pub place: &'a [(usize, usize)],
}

impl<T: Scalar> Assembly<'_, T> {
    /// SKC `k`'s reaction system: its links' balances (the reactions of its
    /// own joints unknown, of later SKCs' known), then a row per unit twist
    /// of each passive joint, and the actuators' coefficients.
    pub fn system(&self, k: usize, skc: &SkcParts) -> SkcSystem<T> {
        let w = self.layout;
        let d = w.d();
        let (mut entries, mut rhs, mut known) = (Vec::new(), Vec::new(), Vec::new());
        for (r, &l) in skc.links.iter().enumerate() {
            for (c, need) in self.demands.demand[l].iter().enumerate() {
                rhs.push(*need / w.unit(c));
            }
            for (j, &(owner, at)) in self.place.iter().enumerate() {
                let Some(sign) = acting_on(self.links[j], l) else {
                    continue;
                };
                for c in 0..d {
                    if owner == k {
                        entries.push((r * d + c, at + c, T::c(sign)));
                    } else if owner > k {
                        known.push((r * d + c, j, c, sign));
                    }
                }
            }
        }
        let mut row = skc.links.len() * d;
        let (mut actuated, mut passive) = (Vec::new(), Vec::new());
        for (i, &j) in skc.joints.iter().enumerate() {
            let turns = matches!(self.kinds[j], JointType::R | JointType::S);
            for xi in &self.twists[j] {
                let coefficients = xi.iter().enumerate().map(|(c, v)| (i * d + c, *v * w.unit(c)));
                if self.actuated[j] {
                    actuated.push(coefficients.collect());
                } else {
                    // A turn's row has lever arms (lengths) against forces, a
                    // slide's unit direction: both in units of the size.
                    let scale = if turns { T::c(1.0) / w.size } else { T::c(1.0) };
                    let scaled: Vec<T> = coefficients.map(|(_, s)| s * scale).collect();
                    for (c, s) in scaled.iter().enumerate() {
                        entries.push((row, i * d + c, *s));
                    }
                    // ξ·W = 0, or a parallelogram's −Σ D_i·ξ'_i with massive bars.
                    let right = -self.demands.bar_work[j] * scale;
                    rhs.push(right);
                    passive.push(PassiveRow {
                        at: i,
                        joint: j,
                        coefficients: scaled,
                        rhs: right,
                    });
                    row += 1;
                }
            }
        }
        SkcSystem {
            rows: row,
            unknowns: skc.joints.len() * d,
            entries,
            rhs,
            known,
            actuated,
            passive,
        }
    }

    /// Link `l`'s balance: its demand's components over their units, and
    /// the joints acting on it with their signs.
    pub fn balance(&self, l: usize) -> (Vec<T>, Vec<(usize, f64)>) {
        let w = self.layout;
        let need = (0..w.d()).map(|c| self.demands.demand[l][c] / w.unit(c)).collect();
        let on = (0..self.links.len())
            .filter_map(|j| acting_on(self.links[j], l).map(|s| (j, s)))
            .collect();
        (need, on)
    }

    /// The spanning tree of SKC `skc`'s links that reduces its system to
    /// its cut joints' reactions ([`crate::force_system::tree`]), for
    /// `passive` passive rows; `None` where it does not reduce.
    pub fn tree(&self, skc: &SkcParts, passive: usize) -> Option<crate::force_system::Tree> {
        let node = |l: usize| skc.links.iter().position(|&x| x == l).unwrap_or(skc.links.len());
        let ends: Vec<[usize; 2]> = skc.joints.iter().map(|&j| self.links[j].map(node)).collect();
        crate::force_system::tree(&ends, skc.links.len(), self.layout.d(), passive)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planar pendulum: link 1 hinged to the base at the origin by joint
    /// 0 (R about z), its centroid at (L, 0) of its frame, mass m, moment
    /// I_c about the centroid, at angle θ, rate ω, acceleration α, gravity
    /// (0, −g), a load F = (1, −3) at the centroid and a moment M = 0.4.
    struct Pendulum {
        m: f64,
        l: f64,
        i_c: f64,
        theta: f64,
        w: f64,
        alpha: f64,
        g: f64,
    }

    const P: Pendulum = Pendulum {
        m: 2.0,
        l: 0.5,
        i_c: 0.1,
        theta: 0.3,
        w: 1.5,
        alpha: -0.7,
        g: 9.81,
    };
    const F: [f64; 3] = [1.0, -3.0, 0.0];
    const M: f64 = 0.4;
    const SIZE: f64 = 0.5;

    fn layout() -> Layout<f64> {
        Layout {
            planar: true,
            size: SIZE,
        }
    }

    /// Its demand by [`demands`], and the twists of its joint (the unit
    /// turn about z through the origin: ω = ẑ, v = 0, coefficients (0, 0, 1)).
    fn pendulum() -> (Demands<f64>, Vec<Vec<Vec<f64>>>) {
        let (c, s) = (P.theta.cos(), P.theta.sin());
        let pose = Frame {
            t: [0.0; 3],
            ..Frame::about_z(c, s)
        };
        // The centroid on its circle: a = L α (−s, c) − L ω² (c, s).
        let a_c = [
            -P.l * P.alpha * s - P.l * P.w * P.w * c,
            P.l * P.alpha * c - P.l * P.w * P.w * s,
            0.0,
        ];
        let body = MovingBody {
            on: Carried::Link(1),
            pose,
            motion: CentroidMotion {
                w: [0.0, 0.0, P.w],
                alpha: [0.0, 0.0, P.alpha],
                a_c,
            },
            mass: P.m,
            centroid: [P.l, 0.0, 0.0],
            inertia: [[0.0; 3], [0.0; 3], [0.0, 0.0, P.i_c]],
        };
        let load = Load {
            link: 1,
            at: [P.l * c, P.l * s, 0.0],
            force: F,
            moment: [0.0, 0.0, M],
        };
        let twists = vec![vec![vec![0.0, 0.0, 1.0]]];
        let d = demands(
            &layout(),
            2,
            &[0],
            &[None, None],
            &twists,
            &[body],
            &[load],
            [0.0, -P.g, 0.0],
        );
        (d, twists)
    }

    /// By hand: f = m (a_c − g) = m (−Lα s − Lω² c, Lα c − Lω² s + g);
    /// about the origin `m_o = I_c α + (c × f)_z = (I_c + m L²) α + m g L cos θ`
    /// (the ω² terms are along c and have no moment); less the load:
    /// `F` and `M + (c × F)_z = M + L (c F_y − s F_x)`.
    #[test]
    fn a_pendulums_demand_by_hand() {
        let (d, _) = pendulum();
        let (c, s) = (P.theta.cos(), P.theta.sin());
        let fx = P.m * (-P.l * P.alpha * s - P.l * P.w * P.w * c) - F[0];
        let fy = P.m * (P.l * P.alpha * c - P.l * P.w * P.w * s + P.g) - F[1];
        let mz = (P.i_c + P.m * P.l * P.l) * P.alpha + P.m * P.g * P.l * c - (M + P.l * (c * F[1] - s * F[0]));
        for (got, want) in d.demand[1].iter().zip([fx, fy, mz]) {
            assert!((got - want).abs() < 1e-13, "{got} against {want}");
        }
        assert_eq!(d.demand[0], [0.0; 3]);
        assert_eq!(d.bar_work, [0.0]);
    }

    /// The pendulum's SKC (link 1, joint 0): link 1's rows say `W = D_1`
    /// (+1 on the joint's second link), the moment over the size; actuated,
    /// its twist's coefficients (0, 0, size) give the torque `W_z`; passive,
    /// one more row `W_z / size · size / size = 0`: (0, 0, 1) = 0.
    #[test]
    fn a_pendulums_system_by_hand() {
        let (d, twists) = pendulum();
        let skc = SkcParts {
            links: vec![1],
            joints: vec![0],
            undetermined: 0,
        };
        let place = places(std::slice::from_ref(&skc), 1, 3).expect("joint 0 in SKC 0");
        assert_eq!(place, [(0, 0)]);
        let system = |actuated: bool| {
            Assembly {
                layout: &layout(),
                links: &[[0, 1]],
                kinds: &[JointType::R],
                actuated: &[actuated],
                twists: &twists,
                demands: &d,
                place: &place,
            }
            .system(0, &skc)
        };
        let motor = system(true);
        assert_eq!((motor.rows, motor.unknowns), (3, 3));
        assert_eq!(motor.entries, [(0, 0, 1.0), (1, 1, 1.0), (2, 2, 1.0)]);
        let demand = &d.demand[1];
        assert_eq!(motor.rhs, [demand[0], demand[1], demand[2] / SIZE]);
        assert_eq!(motor.actuated, [vec![(0, 0.0), (1, 0.0), (2, SIZE)]]);
        assert!(motor.passive.is_empty() && motor.known.is_empty());
        let hinge = system(false);
        assert_eq!(hinge.rows, 4);
        assert_eq!(&hinge.entries[3..], [(3, 0, 0.0), (3, 1, 0.0), (3, 2, 1.0)]);
        assert_eq!(hinge.rhs[3], 0.0);
        assert_eq!((hinge.passive[0].at, hinge.passive[0].joint), (0, 0));
        assert!(hinge.actuated.is_empty());
    }

    /// An S–S coupler (link 2 between balls at (1, 0, 0) and (1, 0, 2) of
    /// its frame) turns about the line from the first to the second, ẑ;
    /// a link with another joint does not.
    #[test]
    fn the_idle_spin_line_and_its_drop() {
        let ball = |at: [f64; 3]| Place::Point { at };
        let joints = [
            (JointType::S, [1, 2], [ball([0.0; 3]), ball([1.0, 0.0, 0.0])]),
            (JointType::S, [2, 3], [ball([1.0, 0.0, 2.0]), ball([0.0; 3])]),
            (JointType::R, [0, 1], [ball([0.0; 3]), ball([0.0; 3])]),
        ];
        assert_eq!(idle_spin_line(joints, 2), Some(([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])));
        assert_eq!(idle_spin_line(joints, 1), None);
        // I − (âᵀIâ) ââᵀ: about z, diag(1, 1, 2) loses its 2; about x, its first 1.
        let i = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]];
        assert_eq!(without_axial(&i, &[0.0, 0.0, 1.0])[2], [0.0, 0.0, 0.0]);
        assert_eq!(without_axial(&i, &[1.0, 0.0, 0.0])[0], [0.0, 0.0, 0.0]);
    }

    /// A bar on the joint's first link moving with ξ = (ω ẑ about the
    /// origin): its power against a wrench (fx, fy, mz) is mz alone; on the
    /// second link the joint's own twist is added.
    #[test]
    fn a_bars_power() {
        let xi = Screw {
            w: [0.0, 0.0, 1.0],
            v: [0.0; 3],
        };
        let wrench = [2.0, 3.0, 5.0];
        assert_eq!(bar_power(&layout(), 0, 0, &xi, &[7.0, 0.0, 0.0], &wrench), 5.0);
        assert_eq!(bar_power(&layout(), 0, 1, &xi, &[7.0, 0.0, 0.0], &wrench), 19.0);
    }
}
