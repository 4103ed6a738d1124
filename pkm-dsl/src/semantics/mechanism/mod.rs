//! The semantic model: the mechanism as a graph of links and joints with its
//! axis relations, built from the syntax tree with every check that needs no
//! geometry. All errors are collected, not just the first.

use crate::diagnostics::Span;
use crate::syntax::ast::RelationKind;

mod builder;
mod relations;
mod statements;
#[cfg(test)]
mod tests;

pub use crate::limits::MAX_JOINTS;
pub use builder::{build, suggest};
pub use relations::{concurrent_groups, DirectionClasses};

/// The joint types of the POC literature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Revolute, f = 1.
    R,
    /// Prismatic, f = 1.
    P,
    /// Helical, f = 1.
    H,
    /// Cylindrical, f = 2.
    C,
    /// Universal (two perpendicular intersecting axes), f = 2.
    U,
    /// Spherical, f = 3.
    S,
    /// Parallelogram of four R joints, counted as one joint with one
    /// translational DOF; its internal loop is not counted in v or Σξ.
    Pa,
}

impl JointKind {
    /// The type named by the prefix of a joint's name (`R11` → R, `Pa` → Pa).
    pub fn from_name_prefix(name: &str) -> Option<JointKind> {
        if name.starts_with("Pa") {
            return Some(JointKind::Pa);
        }
        Self::from_symbol(name.get(..1)?)
    }

    /// The type written out in full (`R`, `P`, `H`, `C`, `U`, `S`, `Pa`).
    pub fn from_symbol(s: &str) -> Option<JointKind> {
        Some(match s {
            "R" => JointKind::R,
            "P" => JointKind::P,
            "H" => JointKind::H,
            "C" => JointKind::C,
            "U" => JointKind::U,
            "S" => JointKind::S,
            "Pa" => JointKind::Pa,
            _ => return None,
        })
    }

    /// The joint's degree of freedom f.
    pub fn dof(self) -> usize {
        match self {
            JointKind::R | JointKind::P | JointKind::H | JointKind::Pa => 1,
            JointKind::C | JointKind::U => 2,
            JointKind::S => 3,
        }
    }

    /// The type's symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            JointKind::R => "R",
            JointKind::P => "P",
            JointKind::H => "H",
            JointKind::C => "C",
            JointKind::U => "U",
            JointKind::S => "S",
            JointKind::Pa => "Pa",
        }
    }

    /// Whether the joint has an axis direction that relations can refer to.
    pub fn has_direction(self) -> bool {
        self != JointKind::S
    }

    /// Whether the joint has a fixed axis line (so it can be coaxial with another).
    pub fn has_axis_line(self) -> bool {
        matches!(self, JointKind::R | JointKind::H | JointKind::C | JointKind::U)
    }

    /// Whether the joint rotates about its axis (its axis names a rotation).
    pub fn is_rotational(self) -> bool {
        matches!(self, JointKind::R | JointKind::H | JointKind::C | JointKind::U)
    }
}

/// What a user can ask the compiler to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Capability {
    /// Topology analysis only (always on).
    Analysis,
    /// Closed-form forward position solution.
    Fk,
    /// Closed-form inverse position solution.
    Ik,
    /// Forward position solution of a κ = 1 mechanism by one virtual
    /// variable and the roots of its compatibility residual.
    FkNumeric,
    /// Output and input Jacobians.
    Jacobian,
    /// Velocities of points and links.
    Velocity,
    /// Accelerations of points and links.
    Acceleration,
    /// Workspace sweeps.
    Workspace,
    /// Inverse dynamics.
    Dynamics,
    /// Static stiffness.
    Stiffness,
}

impl Capability {
    /// Every capability with its DSL name.
    pub const ALL: [(Capability, &'static str); 10] = [
        (Capability::Analysis, "analysis"),
        (Capability::Fk, "fk"),
        (Capability::Ik, "ik"),
        (Capability::Jacobian, "jacobian"),
        (Capability::Velocity, "velocity"),
        (Capability::Acceleration, "acceleration"),
        (Capability::Workspace, "workspace"),
        (Capability::Dynamics, "dynamics"),
        (Capability::FkNumeric, "fk_numeric"),
        (Capability::Stiffness, "stiffness"),
    ];

    /// The DSL name.
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(c, _)| *c == self).map_or("?", |(_, n)| n)
    }

    /// Every capability's name, listed with commas.
    pub fn names() -> String {
        let names: Vec<&str> = Self::ALL.iter().map(|(_, n)| *n).collect();
        names.join(", ")
    }
}

/// A rigid body of the mechanism. Link 0 is the base (frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Its name (`base`, `platform`, a label, or `J1/J2` for an anonymous link between two joints).
    pub name: String,
    /// Its description from a `link` statement.
    pub description: Option<String>,
    /// Where it is first named, if it is named.
    pub span: Option<Span>,
}

/// A kinematic joint between two links.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointKind,
    /// The two links it connects; the joint's motion is that of `links[1]` relative
    /// to `links[0]`. A joint on the base has the base first.
    pub links: [usize; 2],
    /// Whether it is actuated.
    pub actuated: bool,
    /// Where it is declared.
    pub span: Span,
    /// The branch (limb) it belongs to.
    pub branch: Option<usize>,
}

impl Joint {
    /// The link at the other end from `link`.
    pub fn other(&self, link: usize) -> usize {
        if self.links[0] == link {
            self.links[1]
        } else {
            self.links[0]
        }
    }
}

/// A universal (U) joint as the semantic model holds it: two revolutes whose
/// axes meet at right angles at the U's centre, `NAME.a` from the U's first
/// link to an internal cross link `NAME.cross` and `NAME.b` from the cross
/// to the U's second link. The cross is massless and carries nothing else,
/// so topology (f = 1 + 1, one link and one joint more: the same loops),
/// plans, the Newton reference, velocities and generated code all treat the
/// U as the two revolutes it is, under the names the user writes for its
/// axes. The topology's generic instances put both axes through one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Universal {
    /// Its name as written (`U1`).
    pub name: String,
    /// The revolutes `NAME.a` (on the first link) and `NAME.b` (on the second).
    pub halves: [usize; 2],
    /// The internal cross link.
    pub cross: usize,
    /// Where it is declared.
    pub span: Span,
}

/// A branch (limb) from the base to the platform; it may contain loops (a hybrid branch).
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Its name.
    pub name: String,
    /// Its joints.
    pub joints: Vec<usize>,
    /// Where its name is written.
    pub span: Span,
}

/// A direction that relations can refer to: a joint's axis, a frame axis, or
/// the second axis of a U joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DirectionItem {
    /// The axis (or sliding direction) of a joint.
    Joint(usize),
    /// Frame axis 0 = x, 1 = y, 2 = z.
    Frame(usize),
    /// The second axis of a U joint.
    USecond(usize),
    /// The normal of the k-th plane `◇(A,B)` written in a relation.
    PlaneNormal(usize),
}

/// One declared (or implied) relation between two directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relation {
    /// Which relation.
    pub kind: RelationKind,
    /// Left side.
    pub a: DirectionItem,
    /// Right side.
    pub b: DirectionItem,
    /// Where it is written, if it is written (implied relations have none).
    pub span: Option<Span>,
}

/// A mechanism ready for analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Mechanism {
    /// Its name.
    pub name: String,
    /// Its title.
    pub title: Option<String>,
    /// Declared `planar;`.
    pub planar: bool,
    /// Where `mobility by geometry;` is declared: the topology is then
    /// counted at configurations of the declared geometry, not at generic
    /// instances of its relations (`lowering::mobility::accept`).
    pub mobility_by_geometry: Option<Span>,
    /// Links; 0 is the base.
    pub links: Vec<Link>,
    /// Joints in declaration order, compound hinges expanded.
    pub joints: Vec<Joint>,
    /// Branches.
    pub branches: Vec<Branch>,
    /// The moving platform, if there is one.
    pub platform: Option<usize>,
    /// The joint on whose axis the platform's base point o lies, if chosen by the user.
    pub base_point: Option<usize>,
    /// The parts of the platform's pose the file declares as outputs
    /// (`pose (z, rx, ry) of platform`): the motions the user takes as
    /// independent, the others of the platform's being parasitic.
    pub platform_outputs: Vec<String>,
    /// Without a platform, the link the first pose or point output is
    /// on, with the joint it is taken at where that is one of the link's
    /// joints (a point): the topology gives its POC set as the platform's.
    pub output_link: Option<(usize, Option<usize>)>,
    /// Requested capabilities with where they are written.
    pub capabilities: Vec<(Capability, Span)>,
    /// Every relation, declared and implied.
    pub relations: Vec<Relation>,
    /// Whether frame axis x, y, z was tied to the mechanism by a relation.
    pub frame_declared: [bool; 3],
    /// How many planes `◇(A,B)` relations wrote (each has a normal direction item).
    pub planes: usize,
    /// The U joints, each two revolutes of `joints` and a cross link of `links`.
    pub universals: Vec<Universal>,
}

impl Mechanism {
    /// Where the mechanism's first joint is declared (a place for whole-mechanism errors).
    pub fn name_span(&self) -> Span {
        self.joints.first().map_or_else(Span::default, |j| j.span)
    }

    /// Σf over all joints.
    pub fn total_dof(&self) -> usize {
        self.joints.iter().map(|j| j.kind.dof()).sum()
    }

    /// Number of actuated joints.
    pub fn actuator_count(&self) -> usize {
        self.joints.iter().filter(|j| j.actuated).count()
    }

    /// Whether the capability was requested.
    pub fn wants(&self, c: Capability) -> bool {
        self.capabilities.iter().any(|(k, _)| *k == c)
    }

    /// The joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The U joint called `name`.
    pub fn universal(&self, name: &str) -> Option<&Universal> {
        self.universals.iter().find(|u| u.name == name)
    }

    /// The joint called `name` that touches `link`: the joint itself, or
    /// the half of a U joint of that name on that side.
    pub fn joint_on(&self, name: &str, link: usize) -> Option<usize> {
        self.joint_index(name)
            .or_else(|| {
                self.universal(name)?
                    .halves
                    .into_iter()
                    .find(|&h| self.joints[h].links.contains(&link))
            })
            .filter(|&j| self.joints[j].links.contains(&link))
    }

    /// The joints incident to each link.
    pub fn incidence(&self) -> Vec<Vec<usize>> {
        let mut inc = vec![Vec::new(); self.links.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            inc[joint.links[0]].push(j);
            inc[joint.links[1]].push(j);
        }
        inc
    }
}
