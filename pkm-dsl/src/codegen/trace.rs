//! The symbolic scalar the code generator runs the solver steps with.
//!
//! `pkm_runtime::steps` are generic over `Scalar`; run with [`Sym`], every
//! operation is recorded in a [`Graph`] instead of done. Constants fold as
//! they are recorded (exact zeros and ones disappear, so a rotation about a
//! coordinate axis keeps its four moving entries), equal nodes are shared
//! (one node per distinct expression), and each node knows whether it
//! depends on the solver's given values or on the parameters alone: the
//! latter are computed once, when the solver is prepared. The emitter
//! ([`crate::codegen::emit`]) writes the recorded graph out as straight-line Rust.

use pkm_runtime::primitives::{Error as GeomError, Sign};
use pkm_runtime::scalar::Scalar;
use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A recorded value: an index into the current [`Graph`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Sym(pub u32);

/// A root choice in generated code: fixed, or the caller's `signs[k]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Choice {
    /// A kernel with one root.
    One,
    /// Branch variable k with this sign.
    Fixed(usize, Sign),
    /// `signs[k]` at run time.
    Given(usize),
}

/// One recorded operation.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant (its bits).
    Const(u64),
    /// The parameter of this name.
    Param(String),
    /// Given value number k.
    Given(usize),
    /// The rate of given value number k (the derivative's direction).
    Rate(usize),
    /// The second derivative of given value number k in time.
    Accel(usize),
    /// A parameter expression the steps cannot trace (a power, a tangent):
    /// Rust source in `params`.
    Raw(String),
    /// `a + b`.
    Add(Sym, Sym),
    /// `a − b`.
    Sub(Sym, Sym),
    /// `a · b`.
    Mul(Sym, Sym),
    /// `a / b`.
    Div(Sym, Sym),
    /// `−a`.
    Neg(Sym),
    /// `√a`.
    Sqrt(Sym),
    /// `sin a`.
    Sin(Sym),
    /// `cos a`.
    Cos(Sym),
    /// `|a|`.
    Abs(Sym),
    /// `atan2(a, b)`.
    Atan2(Sym, Sym),
    /// `if a < b { c } else { d }`.
    /// `then` where `a < b`, else `otherwise`; the flag: a continuous
    /// selection ([`Scalar::if_less_continuous`]).
    IfLess(Sym, Sym, Sym, Sym, bool),
    /// The largest finite magnitude among the values, at least 1
    /// (`consistency::extent`): what verification scales residuals by.
    Extent(Vec<Sym>),
    /// A kernel's condition: fails the step (its site) unless `a < b`.
    Guard(Sym, Sym, Failure, [usize; 2]),
    /// `signs[k]`'s pick of two values, at run time.
    Pick(usize, Sym, Sym),
    /// A value the sign choice `k` chose (`Plus` or `Minus`): the value
    /// itself, marked as depending on that choice.
    Chosen(usize, Sign, Sym),
}

/// A guard's failure, its values recorded.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Failure {
    /// `Error::Degenerate { what }`.
    Degenerate(&'static str),
    /// `Error::Unreachable { constraint, by }`.
    Unreachable(&'static str, Sym),
    /// `unreachable_distance(d, dmax, dmin)`.
    Distance(Sym, Sym, Sym),
}

/// What the graph knows about each node.
#[derive(Debug, Clone, Default)]
pub struct Graph {
    /// The nodes in the order recorded (operands before their uses).
    pub nodes: Vec<Node>,
    /// Whether a node depends on a given value (else on parameters alone).
    pub live: Vec<bool>,
    /// The signs a node depends on: `(which, values)` bit masks.
    pub signs: Vec<(u64, u64)>,
    /// A name for the node, where the steps gave one.
    pub names: Vec<Option<String>>,
    /// Whether a node is never negative by its making (NaN aside): a root,
    /// a magnitude, a square, a non-negative constant, and sums, products,
    /// quotients and choices of those, or a chosen one.
    non_negative: Vec<bool>,
    /// The guards met since [`take_guards`], in order.
    guards: Vec<Sym>,
    index: HashMap<Node, Sym, BuildHasherDefault<FastHash>>,
}

/// A small multiplicative hash (FxHash's): the graph hashes every recorded
/// operation, and SipHash at opt-level 0 (a user's debug build runs the
/// macro unoptimised) was most of the macro's time.
#[derive(Default)]
pub struct FastHash(u64);

impl Hasher for FastHash {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
}

thread_local! {
    static GRAPH: RefCell<Graph> = RefCell::new(Graph::default());
}

/// The guards met since the last call, in the order met: every condition a
/// traced function must check.
pub fn take_guards() -> Vec<Sym> {
    with(|g| std::mem::take(&mut g.guards))
}

/// Runs `f` with a fresh graph and returns what it returned and the graph.
pub fn record<R>(f: impl FnOnce() -> R) -> (R, Graph) {
    GRAPH.with(|g| *g.borrow_mut() = Graph::default());
    let r = f();
    let g = GRAPH.with(|g| std::mem::take(&mut *g.borrow_mut()));
    (r, g)
}

impl Graph {
    /// The constant a node is, if it is one.
    pub fn constant(&self, s: Sym) -> Option<f64> {
        match self.nodes[s.0 as usize] {
            Node::Const(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }

    fn add(&mut self, n: Node) -> Sym {
        if let Some(&s) = self.index.get(&n) {
            return s;
        }
        let operands = operands(&n);
        let mut live = matches!(
            n,
            Node::Given(_) | Node::Rate(_) | Node::Accel(_) | Node::Pick(..) | Node::Guard(..)
        );
        let mut signs = (0u64, 0u64);
        for o in &operands {
            live |= self.live[o.0 as usize];
            let (w, v) = self.signs[o.0 as usize];
            signs = (signs.0 | w, signs.1 | v);
        }
        if let Node::Chosen(b, sign, _) = &n {
            let bit = 1u64 << b;
            signs.0 |= bit;
            if *sign == Sign::Minus {
                signs.1 |= bit;
            }
        }
        let nn = |a: &Sym| self.non_negative[a.0 as usize];
        let non_negative = match &n {
            Node::Const(bits) => f64::from_bits(*bits) >= 0.0,
            Node::Sqrt(_) | Node::Abs(_) | Node::Extent(_) => true,
            Node::Mul(a, b) if a == b => true,
            Node::Add(a, b) | Node::Mul(a, b) | Node::Div(a, b) => nn(a) && nn(b),
            Node::IfLess(_, _, c, d, _) | Node::Pick(_, c, d) => nn(c) && nn(d),
            Node::Chosen(_, _, a) => nn(a),
            _ => false,
        };
        let s = Sym(self.nodes.len() as u32);
        self.nodes.push(n.clone());
        self.live.push(live);
        self.non_negative.push(non_negative);
        self.signs.push(signs);
        self.names.push(None);
        self.index.insert(n, s);
        s
    }
}

/// The operands of a node.
pub fn operands(n: &Node) -> Vec<Sym> {
    match n {
        Node::Const(_) | Node::Param(_) | Node::Given(_) | Node::Rate(_) | Node::Accel(_) | Node::Raw(_) => vec![],
        Node::Extent(values) => values.clone(),
        Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) | Node::Atan2(a, b) => vec![*a, *b],
        Node::Neg(a) | Node::Sqrt(a) | Node::Sin(a) | Node::Cos(a) | Node::Abs(a) => vec![*a],
        Node::IfLess(a, b, c, d, _) => vec![*a, *b, *c, *d],
        Node::Guard(a, b, f, _) => {
            let mut v = vec![*a, *b];
            match f {
                Failure::Degenerate(_) => {}
                Failure::Unreachable(_, by) => v.push(*by),
                Failure::Distance(d, x, n) => v.extend([*d, *x, *n]),
            }
            v
        }
        Node::Pick(_, a, b) => vec![*a, *b],
        Node::Chosen(_, _, a) => vec![*a],
    }
}

fn with<R>(f: impl FnOnce(&mut Graph) -> R) -> R {
    GRAPH.with(|g| f(&mut g.borrow_mut()))
}

fn node(n: Node) -> Sym {
    with(|g| g.add(n))
}

fn konst(s: Sym) -> Option<f64> {
    with(|g| g.constant(s))
}

/// The constant `s` is, if it is one, while recording.
pub fn constant_of(s: Sym) -> Option<f64> {
    konst(s)
}

/// Whether `s` is never negative ([`Graph::non_negative`]).
fn non_negative(s: Sym) -> bool {
    with(|g| g.non_negative[s.0 as usize])
}

/// Both operands' constants at once (one access to the graph).
fn konst2(a: Sym, b: Sym) -> (Option<f64>, Option<f64>) {
    with(|g| (g.constant(a), g.constant(b)))
}

impl Sym {
    /// A parameter.
    pub fn param(name: &str) -> Sym {
        node(Node::Param(name.to_string()))
    }

    /// A parameter expression as Rust source (in `params`).
    pub fn raw(text: String) -> Sym {
        node(Node::Raw(text))
    }

    /// The rate of given value number `k`.
    pub fn rate(k: usize) -> Sym {
        node(Node::Rate(k))
    }

    /// The second derivative of given value number `k` in time.
    pub fn accel(k: usize) -> Sym {
        node(Node::Accel(k))
    }

    /// Given value number `k`.
    pub fn given(k: usize) -> Sym {
        node(Node::Given(k))
    }

    /// The largest finite magnitude of `values`, at least 1 (as
    /// `consistency::extent`), each value taken once: constants folded now,
    /// and those that depend on the parameters alone in one prepared node.
    pub fn extent(values: &[Sym]) -> Sym {
        let mut values = values.to_vec();
        values.sort();
        values.dedup();
        let constants: Vec<[f64; 1]> = values.iter().filter_map(|&v| konst(v)).map(|c| [c]).collect();
        let (live, fixed): (Vec<Sym>, Vec<Sym>) = values
            .into_iter()
            .filter(|&v| konst(v).is_none())
            .partition(|v| v.is_live());
        let mut args = Vec::new();
        let c = pkm_runtime::consistency::extent(&constants);
        if c > 1.0 {
            args.push(Sym::c(c));
        }
        if !fixed.is_empty() {
            args.push(node(Node::Extent(fixed)));
        }
        args.extend(live);
        match args.as_slice() {
            [] => Sym::c(1.0),
            [one] if konst(*one).is_some() || !one.is_live() => *one,
            _ => node(Node::Extent(args)),
        }
    }

    /// Whether this node is `−b`.
    fn negates(self, b: Sym) -> bool {
        with(|g| matches!(g.nodes[self.0 as usize], Node::Neg(a) if a == b))
    }

    /// Whether this node depends on a given value (else it is prepared once).
    pub fn is_live(self) -> bool {
        with(|g| g.live[self.0 as usize])
    }

    fn unary(self, f: fn(f64) -> f64, n: fn(Sym) -> Node) -> Sym {
        match konst(self) {
            Some(a) => Sym::c(f(a)),
            None => node(n(self)),
        }
    }
}

impl std::ops::Add for Sym {
    type Output = Sym;
    fn add(self, b: Sym) -> Sym {
        match konst2(self, b) {
            (Some(x), Some(y)) => Sym::c(x + y),
            (Some(0.0), _) => b,
            (_, Some(0.0)) => self,
            // a + (−a) = 0, exact for the finite values the solvers take
            // (a point crossed onto a coaxial joint and back).
            _ if self.negates(b) || b.negates(self) => Sym::c(0.0),
            _ => node(Node::Add(self, b)),
        }
    }
}

impl std::ops::Sub for Sym {
    type Output = Sym;
    fn sub(self, b: Sym) -> Sym {
        match konst2(self, b) {
            (Some(x), Some(y)) => Sym::c(x - y),
            (Some(0.0), _) => -b,
            (_, Some(0.0)) => self,
            // Exact for the finite values the solvers take.
            _ if self == b => Sym::c(0.0),
            // (a + b) − b = a is not exact in floating point: kept as is.
            _ => node(Node::Sub(self, b)),
        }
    }
}

impl std::ops::Mul for Sym {
    type Output = Sym;
    fn mul(self, b: Sym) -> Sym {
        match konst2(self, b) {
            (Some(x), Some(y)) => Sym::c(x * y),
            (Some(x), _) | (_, Some(x)) if x == 0.0 => Sym::c(0.0),
            (Some(1.0), _) => b,
            (_, Some(1.0)) => self,
            (Some(-1.0), _) => -b,
            (_, Some(-1.0)) => -self,
            _ => node(Node::Mul(self, b)),
        }
    }
}

/// Whether `y` is a power of two whose inverse is normal too, so that
/// `x / y` and `x · (1/y)` are the same number for every `x`.
fn exact_inverse(y: f64) -> bool {
    let mantissa = y.to_bits() & ((1u64 << 52) - 1);
    y.is_normal() && mantissa == 0 && (1.0 / y).is_normal()
}

impl std::ops::Div for Sym {
    type Output = Sym;
    fn div(self, b: Sym) -> Sym {
        match konst2(self, b) {
            (Some(x), Some(y)) => Sym::c(x / y),
            (_, Some(1.0)) => self,
            (_, Some(-1.0)) => -self,
            // Dividing by a power of two is multiplying by its inverse, exactly.
            (_, Some(y)) if exact_inverse(y) => self * Sym::c(1.0 / y),
            // 0 / x: every divisor the steps use is checked non-zero first.
            (Some(0.0), _) => Sym::c(0.0),
            _ => node(Node::Div(self, b)),
        }
    }
}

impl std::ops::Neg for Sym {
    type Output = Sym;
    fn neg(self) -> Sym {
        if let Some(x) = konst(self) {
            return Sym::c(-x);
        }
        match with(|g| match g.nodes[self.0 as usize] {
            Node::Neg(a) => Some((a, None)),
            Node::Sub(a, b) => Some((a, Some(b))),
            _ => None,
        }) {
            Some((a, None)) => a,
            Some((a, Some(b))) => b - a,
            None => node(Node::Neg(self)),
        }
    }
}

impl Scalar for Sym {
    type Choice = Choice;

    fn c(x: f64) -> Self {
        // −0 is 0 here: the steps never rely on the sign of a zero.
        node(Node::Const(if x == 0.0 { 0.0f64 } else { x }.to_bits()))
    }
    fn sqrt(self) -> Self {
        // √(x·x) = |x| exactly (short of overflow).
        if let Node::Mul(a, b) = with(|g| g.nodes[self.0 as usize].clone()) {
            if a == b {
                return a.abs();
            }
        }
        self.unary(f64::sqrt, Node::Sqrt)
    }
    fn sin(self) -> Self {
        self.unary(f64::sin, Node::Sin)
    }
    fn cos(self) -> Self {
        self.unary(f64::cos, Node::Cos)
    }
    fn abs(self) -> Self {
        // A value never negative is its own magnitude (NaN too).
        if non_negative(self) && konst(self).is_none() {
            return self;
        }
        self.unary(f64::abs, Node::Abs)
    }
    fn atan2(self, x: Self) -> Self {
        match (konst(self), konst(x)) {
            (Some(a), Some(b)) => Sym::c(pkm_runtime::scalar::angle(a, b)),
            _ => node(Node::Atan2(self, x)),
        }
    }
    fn if_less(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        select(a, b, then, otherwise, false)
    }
    fn if_less_continuous(a: Self, b: Self, then: Self, otherwise: Self) -> Self {
        select(a, b, then, otherwise, true)
    }
    fn require(
        a: Self,
        b: Self,
        failure: pkm_runtime::scalar::Failure<Self>,
        site: [usize; 2],
    ) -> Result<(), GeomError<f64>> {
        use pkm_runtime::scalar::Failure as F;
        if let (Some(x), Some(y)) = (konst(a), konst(b)) {
            // Decided by the geometry's constants: nothing to check at run time.
            if x < y {
                return Ok(());
            }
        }
        let f = match failure {
            F::Degenerate(w) => Failure::Degenerate(w),
            F::Unreachable(c, by) => Failure::Unreachable(c, by),
            F::Distance { d, dmax, dmin } => Failure::Distance(d, dmax, dmin),
        };
        let guard = node(Node::Guard(a, b, f, site));
        with(|g| g.guards.push(guard));
        Ok(())
    }
    fn pick(choice: Choice, plus: Self, minus: Self) -> Self {
        if plus == minus {
            return plus;
        }
        match choice {
            Choice::One => plus,
            Choice::Fixed(k, sign) => {
                let v = if sign == Sign::Plus { plus } else { minus };
                if konst(v).is_some() {
                    v
                } else {
                    node(Node::Chosen(k, sign, v))
                }
            }
            Choice::Given(k) => node(Node::Pick(k, plus, minus)),
        }
    }
    fn named(self, name: &dyn Fn() -> String) -> Self {
        with(|g| {
            let i = self.0 as usize;
            if g.names[i].is_none() && !matches!(g.nodes[i], Node::Const(_) | Node::Param(_) | Node::Given(_)) {
                g.names[i] = Some(name());
            }
        });
        self
    }
    fn choice(signs: &[Choice], k: Option<usize>) -> Choice {
        k.map_or(Choice::One, |k| signs[k])
    }
}

/// Which of the first `n` recorded operations `roots` depend on (live
/// ones only): what a derivative has to differentiate.
fn reachable(roots: &[Sym], n: usize) -> Vec<bool> {
    let mut seen = vec![false; n];
    let mut stack = roots.to_vec();
    while let Some(s) = stack.pop() {
        let i = s.0 as usize;
        if seen[i] || !with(|g| g.live[i]) {
            continue;
        }
        seen[i] = true;
        stack.extend(operands(&with(|g| g.nodes[i].clone())));
    }
    seen
}

/// The derivative of `roots` along the given values' rates (`rate(k)` for
/// given value k), by the chain rule through the recorded operations in
/// their order: forward-mode differentiation of the straight-line solver,
/// itself straight-line.
pub fn derivative(roots: &[Sym], rate: &dyn Fn(usize) -> Sym) -> Vec<Sym> {
    let n = with(|g| g.nodes.len());
    let seen = reachable(roots, n);
    let zero = Sym::c(0.0);
    let mut d: Vec<Sym> = vec![zero; n];
    for i in (0..n).filter(|&i| seen[i]) {
        let s = Sym(i as u32);
        let node = with(|g| g.nodes[i].clone());
        let dd = |x: &Sym| d[x.0 as usize];
        d[i] = match node {
            // Rates and accelerations are the directions, constant along them.
            Node::Const(_) | Node::Param(_) | Node::Raw(_) | Node::Rate(_) | Node::Accel(_) | Node::Guard(..) => zero,
            // A scale, not a value: the residuals it scales are not differentiated.
            Node::Extent(_) => zero,
            Node::Given(k) => rate(k),
            Node::Add(a, b) => dd(&a) + dd(&b),
            Node::Sub(a, b) => dd(&a) - dd(&b),
            Node::Mul(a, b) => dd(&a) * b + a * dd(&b),
            // (a / b)' = (a' − (a / b)·b') / b.
            Node::Div(a, b) => (dd(&a) - s * dd(&b)) / b,
            Node::Neg(a) => -dd(&a),
            Node::Sqrt(a) => dd(&a) / (Sym::c(2.0) * s),
            Node::Sin(a) => a.cos() * dd(&a),
            Node::Cos(a) => -(a.sin() * dd(&a)),
            Node::Abs(a) => Sym::if_less(a, zero, -dd(&a), dd(&a)),
            Node::Atan2(y, x) => (x * dd(&y) - y * dd(&x)) / (x * x + y * y),
            Node::IfLess(a, b, c, e, k) => select(a, b, dd(&c), dd(&e), k),
            Node::Pick(k, p, m) => Sym::pick(Choice::Given(k), dd(&p), dd(&m)),
            // The chosen value's own derivative: derivatives are written only
            // in one-branch functions, where the choice's mark plays no part.
            Node::Chosen(_, _, v) => dd(&v),
        };
    }
    roots
        .iter()
        .map(|r| if seen[r.0 as usize] { d[r.0 as usize] } else { zero })
        .collect()
}

/// The first and second time derivatives of `roots` in one pass (forward
/// mode to second order, as a Taylor expansion): along the given values'
/// rates `rate(k)` and accelerations `accel(k)`, `x' = Σ ∂x/∂q_k q̇_k` and
/// `x'' = Σ ∂²x/∂q_k∂q_l q̇_k q̇_l + Σ ∂x/∂q_k q̈_k`, what
/// `derivative(derivative(x, rate), rate) + derivative(x, accel)` gives,
/// with fewer operations: the second derivative of a product is
/// `a'' b + 2 a' b' + a b''`, and a quotient's or a root's reuses its
/// first derivative over the same divisor (two divisions where the
/// derivative of the derivative and the accelerations' took three).
pub fn second_derivatives(
    roots: &[Sym],
    rate: &dyn Fn(usize) -> Sym,
    accel: &dyn Fn(usize) -> Sym,
) -> (Vec<Sym>, Vec<Sym>) {
    let n = with(|g| g.nodes.len());
    let seen = reachable(roots, n);
    let zero = Sym::c(0.0);
    let two = Sym::c(2.0);
    let mut d: Vec<(Sym, Sym)> = vec![(zero, zero); n];
    for i in (0..n).filter(|&i| seen[i]) {
        let s = Sym(i as u32);
        let node = with(|g| g.nodes[i].clone());
        let dd = |x: &Sym| d[x.0 as usize];
        d[i] = match node {
            Node::Const(_) | Node::Param(_) | Node::Raw(_) | Node::Rate(_) | Node::Accel(_) | Node::Guard(..) => {
                (zero, zero)
            }
            Node::Extent(_) => (zero, zero),
            Node::Given(k) => (rate(k), accel(k)),
            Node::Add(a, b) => {
                let ((a1, a2), (b1, b2)) = (dd(&a), dd(&b));
                (a1 + b1, a2 + b2)
            }
            Node::Sub(a, b) => {
                let ((a1, a2), (b1, b2)) = (dd(&a), dd(&b));
                (a1 - b1, a2 - b2)
            }
            Node::Mul(a, b) => {
                let ((a1, a2), (b1, b2)) = (dd(&a), dd(&b));
                (a1 * b + a * b1, a2 * b + two * (a1 * b1) + a * b2)
            }
            // a = c b: a' = c' b + c b', a'' = c'' b + 2 c' b' + c b''.
            Node::Div(a, b) => {
                let ((a1, a2), (b1, b2)) = (dd(&a), dd(&b));
                let c1 = (a1 - s * b1) / b;
                (c1, (a2 - two * (c1 * b1) - s * b2) / b)
            }
            Node::Neg(a) => {
                let (a1, a2) = dd(&a);
                (-a1, -a2)
            }
            // a = s²: a' = 2 s s', a'' = 2 s'² + 2 s s''.
            Node::Sqrt(a) => {
                let (a1, a2) = dd(&a);
                let twice = two * s;
                let s1 = a1 / twice;
                (s1, (a2 - two * (s1 * s1)) / twice)
            }
            Node::Sin(a) => {
                let (a1, a2) = dd(&a);
                let (c, sn) = (a.cos(), s);
                (c * a1, c * a2 - sn * (a1 * a1))
            }
            Node::Cos(a) => {
                let (a1, a2) = dd(&a);
                let (c, sn) = (s, a.sin());
                (-(sn * a1), -(sn * a2) - c * (a1 * a1))
            }
            Node::Abs(a) => {
                let (a1, a2) = dd(&a);
                (Sym::if_less(a, zero, -a1, a1), Sym::if_less(a, zero, -a2, a2))
            }
            // θ' = (x y' − y x') / (x² + y²), and its derivative over the same divisor.
            Node::Atan2(y, x) => {
                let ((y1, y2), (x1, x2)) = (dd(&y), dd(&x));
                let squares = x * x + y * y;
                let t1 = (x * y1 - y * x1) / squares;
                let turn = x * y2 - y * x2;
                let grow = two * (x * x1 + y * y1);
                (t1, (turn - t1 * grow) / squares)
            }
            Node::IfLess(a, b, c, e, k) => {
                let ((c1, c2), (e1, e2)) = (dd(&c), dd(&e));
                (select(a, b, c1, e1, k), select(a, b, c2, e2, k))
            }
            Node::Pick(k, p, m) => {
                let ((p1, p2), (m1, m2)) = (dd(&p), dd(&m));
                (Sym::pick(Choice::Given(k), p1, m1), Sym::pick(Choice::Given(k), p2, m2))
            }
            Node::Chosen(_, _, v) => dd(&v),
        };
    }
    roots
        .iter()
        .map(|r| {
            if seen[r.0 as usize] {
                d[r.0 as usize]
            } else {
                (zero, zero)
            }
        })
        .unzip()
}

/// [`Scalar::if_less`] on symbols, the continuous kind flagged.
fn select(a: Sym, b: Sym, then: Sym, otherwise: Sym, continuous: bool) -> Sym {
    if then == otherwise {
        return then;
    }
    match (konst(a), konst(b)) {
        (Some(x), Some(y)) => {
            if x < y {
                then
            } else {
                otherwise
            }
        }
        // A value never negative is not below 0.
        (_, Some(y)) if y <= 0.0 && non_negative(a) => otherwise,
        _ => node(Node::IfLess(a, b, then, otherwise, continuous)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value of `s` at the given values `q`, rates `qd` and accelerations `qdd`.
    fn value(s: Sym, q: &[f64], qd: &[f64], qdd: &[f64]) -> f64 {
        let v = |x: Sym| value(x, q, qd, qdd);
        match with(|g| g.nodes[s.0 as usize].clone()) {
            Node::Const(b) => f64::from_bits(b),
            Node::Given(k) => q[k],
            Node::Rate(k) => qd[k],
            Node::Accel(k) => qdd[k],
            Node::Add(a, b) => v(a) + v(b),
            Node::Sub(a, b) => v(a) - v(b),
            Node::Mul(a, b) => v(a) * v(b),
            Node::Div(a, b) => v(a) / v(b),
            Node::Neg(a) => -v(a),
            Node::Sqrt(a) => v(a).sqrt(),
            Node::Sin(a) => v(a).sin(),
            Node::Cos(a) => v(a).cos(),
            Node::Abs(a) => v(a).abs(),
            Node::Atan2(a, b) => v(a).atan2(v(b)),
            Node::IfLess(a, b, c, e, _) => {
                if v(a) < v(b) {
                    v(c)
                } else {
                    v(e)
                }
            }
            other => panic!("not in this test: {other:?}"),
        }
    }

    /// x = √(1 + u²)·sin u / (2 + cos w) + atan2(w, u) + |u − w| along
    /// u = t², w = 3t at t = 0.7 (u' = 2t, u'' = 2, w' = 3, w'' = 0): the
    /// one pass's first and second derivatives against x(t)'s central
    /// differences, and against the derivative of the derivative plus the
    /// accelerations' derivative.
    #[test]
    fn second_derivatives_in_one_pass() {
        let t = 0.7f64;
        let x_of = |t: f64| {
            let (u, w) = (t * t, 3.0 * t);
            (1.0 + u * u).sqrt() * u.sin() / (2.0 + w.cos()) + w.atan2(u) + (u - w).abs()
        };
        let ((first, second, twice), _) = record(|| {
            let (u, w) = (Sym::given(0), Sym::given(1));
            let one = Sym::c(1.0);
            let x = (one + u * u).sqrt() * u.sin() / (Sym::c(2.0) + w.cos()) + w.atan2(u) + (u - w).abs();
            let (d1, d2) = second_derivatives(&[x], &Sym::rate, &Sym::accel);
            let dd = derivative(&derivative(&[x], &Sym::rate), &Sym::rate)[0] + derivative(&[x], &Sym::accel)[0];
            let (q, qd, qdd) = ([t * t, 3.0 * t], [2.0 * t, 3.0], [2.0, 0.0]);
            (
                value(d1[0], &q, &qd, &qdd),
                value(d2[0], &q, &qd, &qdd),
                value(dd, &q, &qd, &qdd),
            )
        });
        let h = 1e-4;
        let by_differences = (x_of(t + h) - x_of(t - h)) / (2.0 * h);
        let curvature = (x_of(t + h) - 2.0 * x_of(t) + x_of(t - h)) / (h * h);
        assert!((first - by_differences).abs() < 1e-7, "{first} {by_differences}");
        assert!((second - curvature).abs() < 1e-5, "{second} {curvature}");
        assert!(
            (second - twice).abs() < 1e-13 * twice.abs().max(1.0),
            "{second} {twice}"
        );
    }

    /// What the trace knows is never negative folds its tests against 0
    /// and its magnitudes; what it does not know stays a node.
    #[test]
    fn non_negative_values_fold_their_sign_tests() {
        let ((), _) = record(|| {
            let (x, y, a, b) = (Sym::given(0), Sym::given(1), Sym::given(2), Sym::given(3));
            let h = (x * x + y * y).sqrt();
            let zero = Sym::c(0.0);
            assert_eq!(Sym::if_less(h, zero, a, b), b);
            assert_eq!(h.abs(), h);
            let r = h / (Sym::c(2.0) + x.abs());
            assert_eq!(Sym::if_less(r, zero, a, b), b);
            // x may be negative, and h − x is a difference.
            let kind = |s: Sym| with(|g| g.nodes[s.0 as usize].clone());
            assert!(matches!(kind(Sym::if_less(x, zero, a, b)), Node::IfLess(..)));
            assert!(matches!(kind((h - x).abs()), Node::Abs(_)));
        });
    }

    /// The exact folds of sums and differences: x − x and x + (−x) are 0
    /// either way round; x + (−y) and (x + y) − y are not folded.
    #[test]
    fn opposite_terms_cancel_exactly() {
        let ((), _) = record(|| {
            let (x, y) = (Sym::given(0), Sym::given(1));
            let zero = Sym::c(0.0);
            assert_eq!(x - x, zero);
            assert_eq!(x + (-x), zero);
            assert_eq!((-x) + x, zero);
            let kind = |s: Sym| with(|g| g.nodes[s.0 as usize].clone());
            assert!(matches!(kind(x + (-y)), Node::Add(..)));
            assert!(matches!(kind((x + y) - y), Node::Sub(..)));
        });
    }
}
