//! The syntax tree of a mechanism description, as written (before any
//! semantic check). Every name keeps its span for diagnostics.

use super::expr::Expr;
use crate::diagnostics::Span;

/// A name with its place in the text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Name {
    /// The name as written.
    pub text: String,
    /// Where it is written.
    pub span: Span,
}

/// A relation between two axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RelationKind {
    /// `∥` or `||`: parallel axes (or directions).
    Parallel,
    /// `⊥` or `_|_`: perpendicular axes.
    Perpendicular,
    /// `≡` or `==`: the same axis line (coaxial joints, a compound hinge).
    Coaxial,
    /// `∧` or `/\`: axes that meet at one point (every axis of one
    /// statement, and of statements sharing an axis, at the same point).
    Concurrent,
}

impl RelationKind {
    /// The Unicode symbol of the relation.
    pub fn symbol(self) -> &'static str {
        match self {
            RelationKind::Parallel => "∥",
            RelationKind::Perpendicular => "⊥",
            RelationKind::Coaxial => "≡",
            RelationKind::Concurrent => "∧",
        }
    }
}

/// A whole mechanism description.
#[derive(Debug, Clone, PartialEq)]
pub struct MechanismAst {
    /// `mechanism NAME { … }`.
    pub name: Name,
    /// `title "…";`.
    pub title: Option<String>,
    /// `capabilities fk, ik;` (all such statements, in order).
    pub capabilities: Vec<Name>,
    /// `planar;`, if present.
    pub planar: Option<Span>,
    /// `mobility by geometry;`, if present.
    pub mobility_by_geometry: Option<Span>,
    /// `link 1 "AB", 2 "BCD";`.
    pub links: Vec<LinkDecl>,
    /// `joint A = R(base, 1)*;`.
    pub joints: Vec<JointDecl>,
    /// Chains, at top level or inside branches.
    pub chains: Vec<Chain>,
    /// `branch NAME { … }` names; chains refer to them by index.
    pub branches: Vec<Name>,
    /// `platform = LINK;`.
    pub platform: Option<Name>,
    /// `point o on R4;`: the platform's base point lies on this joint's axis.
    pub point: Option<(Name, Name)>,
    /// `x ∥ P1 ∥ P2; R4 ⊥ R3; R3 ≡ R12;`.
    pub relations: Vec<RelationStmt>,
    /// `parameters { a = 300; … }`, in order.
    pub parameters: Vec<(Name, Expr)>,
    /// `geometry { LINK { … } … }`.
    pub geometry: Vec<LinkGeometry>,
    /// `outputs { … }`.
    pub outputs: Vec<OutputDecl>,
    /// `study { … }` blocks: what `pkm report` samples (one allowed; a second is reported there).
    pub studies: Vec<super::study::Study>,
    /// `units { … }` blocks (one allowed; a second is reported).
    pub units: Vec<super::masses::UnitsDecl>,
    /// `masses { … }` blocks: their entries and the block's span.
    pub masses: Vec<(Vec<super::masses::MassDecl>, Span)>,
    /// `gravity (…);` statements (one allowed).
    pub gravity: Vec<super::masses::Value>,
    /// The loads of `loads { … }` blocks.
    pub loads: Vec<super::masses::LoadDecl>,
    /// `limbs { … }` blocks: their entries and the block's span.
    pub limbs: Vec<(Vec<super::limbs::LimbDecl>, Span)>,
}

/// `x, y, phi = pose of platform at o;` or `psi = joint R4;`.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputDecl {
    /// The names the user gives the output values.
    pub names: Vec<Name>,
    /// What they are.
    pub what: OutputWhat,
    /// The whole declaration.
    pub span: Span,
}

/// What an output measures.
#[derive(Debug, Clone, PartialEq)]
pub enum OutputWhat {
    /// The pose of a link at one of its points: (x, y, angle) in a planar mechanism.
    Pose {
        /// The link.
        link: Name,
        /// A named point of the link, or a joint on it.
        at: Name,
        /// In a spatial mechanism, the axis the link turns about (its one
        /// orientation output); without it the link keeps the base's orientation.
        about: Option<AxisRef>,
        /// In a spatial mechanism, which of x, y, z, rx, ry, rz are given
        /// (`pose (z, rx, ry) of …`); the rest are the mechanism's.
        parts: Option<Vec<Name>>,
    },
    /// A point of a link alone, its orientation not given: (x, y) in a
    /// planar mechanism, (x, y, z) otherwise.
    Point {
        /// The link.
        link: Name,
        /// A named point of the link, or a joint on it.
        at: Name,
    },
    /// A joint's value.
    Joint(Name),
}

/// The placements on one link, in its own frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkGeometry {
    /// The link.
    pub link: Name,
    /// Its joints and named points.
    pub placements: Vec<Placement>,
}

/// `R2 = (l1, 0) along z;`, `P1 = through (0, -a, 0) along x;` or `point D = (…);`.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The joint (or, with `point`, the new point) placed.
    pub name: Name,
    /// Written with `point`: a named point of the link, not a joint.
    pub extra_point: bool,
    /// Where.
    pub place: Place,
    /// The whole placement.
    pub span: Span,
}

/// A point (with an optional axis) or a line.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// A point, and the joint's axis through it if given.
    Point(Tuple, Option<AxisRef>),
    /// A line `through POINT along AXIS` (the guide of a P joint).
    Line(Tuple, AxisRef),
    /// A parallelogram's hinge with its arm: `(…) along AXIS arm (…)`.
    Arm(Tuple, AxisRef, Tuple),
}

/// `(e1, e2[, e3])`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tuple {
    /// The coordinates.
    pub items: Vec<Expr>,
    /// Where it is written.
    pub span: Span,
}

/// An axis direction: a frame axis of the link (`x`, `y`, `z`) or a vector.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisRef {
    /// `x`, `y` or `z` of the link's frame.
    Frame(Name),
    /// A vector.
    Vector(Tuple),
}

/// `link NAME "description"`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinkDecl {
    /// The link's name.
    pub name: Name,
    /// Its description, if given.
    pub description: Option<String>,
}

/// `joint NAME = KIND(link, link, …)*;`. More than two links make a compound
/// hinge: k links on one axis, k − 1 joints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JointDecl {
    /// The joint's name.
    pub name: Name,
    /// The joint type as written (`R`, `P`, `Pa`, …).
    pub kind: Name,
    /// The links it connects.
    pub links: Vec<Name>,
    /// Marked `*`: an actuated joint.
    pub actuated: bool,
    /// The whole statement.
    pub span: Span,
}

/// A joint inside a chain; its type is the prefix of its name (`R11`, `Pa`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChainJoint {
    /// The joint's name.
    pub name: Name,
    /// Marked `*`.
    pub actuated: bool,
}

/// What stands between two consecutive joints of a chain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Connector {
    /// `[name]`: the name of the link between the two joints.
    pub label: Option<Name>,
    /// `∥` or `⊥` between the two axes; `None` for `-`.
    pub relation: Option<(RelationKind, Span)>,
}

/// A single open chain from link `start` to link `end`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Chain {
    /// The branch that contains the chain, as an index into `branches`.
    pub branch: Option<usize>,
    /// First link.
    pub start: Name,
    /// Joints in order from `start`.
    pub joints: Vec<ChainJoint>,
    /// `connectors[i]` joins `joints[i]` and `joints[i + 1]`.
    pub connectors: Vec<Connector>,
    /// Last link.
    pub end: Name,
    /// The whole chain.
    pub span: Span,
}

/// What a relation statement relates.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DirectionRef {
    /// A joint's axis or a frame axis (`x`, `y`, `z`).
    Axis(Name),
    /// A frame plane, `◇xoz` (`<>xoz`).
    FramePlane(Name),
    /// The plane of two axes, `◇(R12,R4)`; the span covers the whole reference.
    PlaneOf(Name, Name, Span),
}

/// `a ∥ b ⊥ c;`: relations between consecutive directions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RelationStmt {
    /// The joints, frame axes or planes related.
    pub items: Vec<DirectionRef>,
    /// `ops[i]` relates `items[i]` and `items[i + 1]`.
    pub ops: Vec<(RelationKind, Span)>,
}
