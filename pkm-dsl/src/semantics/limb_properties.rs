//! What the static stiffness model reads besides the geometry: each limb's
//! leg properties, declared per `branch` in a `limbs { … }` block
//! (`crate::syntax::limbs`), checked against the mechanism when the file is
//! analysed ([`check`], kept as expressions in [`crate::topology::analysis::Analysis::limbs`])
//! and evaluated at a parameter set ([`crate::lowering::numeric::limb_properties`]).
//!
//! A limb is a branch of the file that is one serial leg from the base to
//! the platform. Its leg is given either by its material and section,
//! Young's modulus `E`, cross-section area `A` and second moment of area
//! `I` (the stiffness model takes k_axial = E·A/L and k_bending = 3·E·I/L³
//! at the leg's current length L), or by its stiffnesses directly, `axial`
//! and `bending` (constants, whatever the leg's length); `actuator` is an
//! actuated slide's own stiffness, in series with the leg's axial one.
//!
//! Units: forces in N, lengths in the file's length unit L (the `units`
//! block is required): `E` in N/L², `A` in L², `I` in L⁴, `axial`,
//! `bending` and `actuator` in N/L.
//!
//! Values are parameter expressions. A constant value that is not a
//! positive number is a compile error at the value; a value that reads
//! parameters is checked where it is evaluated, by [`limb_properties`]
//! at the parameters given.
//!
//! ```
//! let a = pkm_dsl::analyze_source("mechanism rps {
//!     branch A { base R1 ⊥ P1* - S1 platform; }
//!     branch B { base R2 ⊥ P2* - S2 platform; }
//!     branch C { base R3 ⊥ P3* - S3 platform; }
//!     parameters { d = 40; }
//!     units { length = mm; mass = kg; }
//!     limbs { A, B { E = 2.11e5; A = pi * d^2 / 4; I = pi * d^4 / 64; }
//!             C { axial = 1.0e5; bending = 350; actuator = 2.0e5; } } }").unwrap();
//! let limbs = pkm_dsl::numeric::limb_properties(&a, &Default::default()).unwrap();
//! assert_eq!(a.names(&limbs[0].joints), ["R1", "P1", "S1"]);
//! assert_eq!(limbs[2].actuator, Some(2.0e5));
//! ```

use crate::diagnostics::{Diagnostic, Diagnostics, Span};
use crate::semantics::geometry::Geometry;
use crate::semantics::mechanism::{suggest, JointKind, Mechanism};
use crate::syntax::ast::Name;
pub use crate::syntax::limbs::{LimbDecl, LimbValue};
use std::collections::HashMap;

/// A leg's stiffness as declared: by material and section, or directly.
/// `T` is a [`LimbValue`] as written or an `f64` evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegStiffness<T> {
    /// `E`, `A`, `I`: k_axial = E·A/L, k_bending = 3·E·I/L³ at the leg's
    /// current length L.
    Section {
        /// Young's modulus (N/L²).
        e: T,
        /// Cross-section area (L²).
        a: T,
        /// Second moment of area of the section (L⁴).
        i: T,
    },
    /// `axial`, `bending`: the stiffnesses themselves, whatever the leg's length.
    Direct {
        /// Axial stiffness (N/L).
        axial: T,
        /// Bending stiffness: lateral force at the leg's end per lateral
        /// deflection there (N/L).
        bending: T,
    },
}

/// A limb's properties, checked: as expressions of the parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Limb {
    /// The branch (index into [`Mechanism::branches`]).
    pub branch: usize,
    /// The branch's joints from the base to the platform, in order.
    pub joints: Vec<usize>,
    /// The actuated joints among them, in the same order.
    pub actuated: Vec<usize>,
    /// The leg.
    pub leg: LegStiffness<LimbValue>,
    /// The actuator's stiffness (N/L), in series with the leg's axial one.
    pub actuator: Option<LimbValue>,
}

/// A limb's properties in numbers, at one parameter set, in the file's
/// units (forces in N, lengths in its length unit L).
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedLimb {
    /// The branch (index into [`Mechanism::branches`]).
    pub branch: usize,
    /// The branch's name.
    pub name: String,
    /// The branch's joints from the base to the platform, in order
    /// (indices of the numeric model's joints, which are the mechanism's).
    pub joints: Vec<usize>,
    /// The actuated joints among them, in the same order.
    pub actuated: Vec<usize>,
    /// The leg: `E` (N/L²), `A` (L²), `I` (L⁴), or `axial` and `bending` (N/L).
    pub leg: LegStiffness<f64>,
    /// The actuator's stiffness (N/L), in series with the leg's axial one.
    pub actuator: Option<f64>,
}

impl ResolvedLimb {
    /// The properties as the runtime's stiffness model takes them
    /// ([`pkm_runtime::stiffness::stiffness`]); springs given directly have
    /// no couple stiffness (a limb bearing a constraint couple then needs
    /// its section).
    pub fn properties(&self) -> pkm_runtime::stiffness::LimbProperties {
        use pkm_runtime::stiffness::Section;
        let section = match self.leg {
            LegStiffness::Section { e, a, i } => Section::Beam { e, area: a, inertia: i },
            LegStiffness::Direct { axial, bending } => Section::Springs {
                axial,
                bending,
                couple: None,
            },
        };
        pkm_runtime::stiffness::LimbProperties {
            section,
            actuator: self.actuator,
        }
    }
}

/// The declared limb of each limb a wrench analysis found
/// ([`pkm_runtime::wrench::WrenchAnalysis::limbs`], in its order): the one
/// with the same joints.
///
/// # Errors
/// The index of the first analysed limb no entry declares.
pub fn in_analysis_order<'a>(
    limbs: &'a [ResolvedLimb],
    analysed: &[pkm_runtime::wrench::Limb],
) -> Result<Vec<&'a ResolvedLimb>, usize> {
    analysed
        .iter()
        .enumerate()
        .map(|(k, limb)| with_joints(limbs, |l| &l.joints, &limb.joints).ok_or(k))
        .collect()
}

/// The entry of `limbs` (declared or resolved, `joints` reading an
/// entry's) whose joints are those of `path`, in any order.
pub fn with_joints<'a, L>(limbs: &'a [L], joints: impl Fn(&'a L) -> &'a [usize], path: &[usize]) -> Option<&'a L> {
    let sorted = |j: &[usize]| {
        let mut j = j.to_vec();
        j.sort_unstable();
        j
    };
    let want = sorted(path);
    limbs.iter().find(|l| sorted(joints(l)) == want)
}

/// The keys of a limb entry, with what each is (for messages).
pub(crate) const KEYS: [(&str, &str); 6] = [
    ("E", "Young's modulus"),
    ("A", "cross-section area"),
    ("I", "second moment of area"),
    ("axial", "axial stiffness"),
    ("bending", "bending stiffness"),
    ("actuator", "actuator stiffness"),
];
const SECTION: [&str; 3] = ["E", "A", "I"];
const DIRECT: [&str; 2] = ["axial", "bending"];

/// Checks the `limbs` blocks (each a list of entries with the block's span)
/// against the mechanism: the file's units (`units_declared`), each branch
/// named known, given once and a serial leg, each entry's keys known and
/// given once, either `E`, `A`, `I` or `axial`, `bending` and not both,
/// values of known parameters and, where constant, positive, `actuator`
/// only on a leg driven by one slide. Every error is collected.
pub fn check(
    blocks: &[(Vec<LimbDecl>, Span)],
    units_declared: bool,
    mech: &Mechanism,
    geometry: &Geometry,
) -> Result<Vec<Limb>, Diagnostics> {
    let mut errors = Diagnostics::default();
    needs_units(blocks, units_declared, &mut errors);
    let known = |n: &str| geometry.parameters.iter().any(|p| p.name == n);
    let mut given: HashMap<usize, Span> = HashMap::new();
    let mut out = Vec::new();
    for decl in blocks.iter().flat_map(|(e, _)| e) {
        let branches: Vec<(usize, Option<Vec<usize>>)> = decl
            .branches
            .iter()
            .filter_map(|b| {
                let i = branch(mech, b, &mut given, &mut errors)?;
                Some((i, serial_leg(mech, i, b.span, &mut errors)))
            })
            .collect();
        let items = entry_items(decl, &known, &mut errors);
        let leg = leg_stiffness(decl, &items, &mut errors);
        let actuator = items.get("actuator").cloned();
        for (i, joints) in branches {
            let Some(joints) = joints else { continue };
            let actuated: Vec<usize> = joints.iter().copied().filter(|&j| mech.joints[j].actuated).collect();
            if let Some((key, _)) = decl.items.iter().find(|(k, _)| k.text == "actuator") {
                actuator_is_a_slide(mech, i, &actuated, key.span, &mut errors);
            }
            if let Some(leg) = &leg {
                out.push(Limb {
                    branch: i,
                    joints,
                    actuated,
                    leg: leg.clone(),
                    actuator: actuator.clone(),
                });
            }
        }
    }
    out.sort_by_key(|l| l.branch);
    errors.into_result(out)
}

/// Limb properties are in the file's units: a `limbs` block needs a `units` block.
fn needs_units(blocks: &[(Vec<LimbDecl>, Span)], units_declared: bool, errors: &mut Diagnostics) {
    if let (false, Some((_, span))) = (units_declared, blocks.first()) {
        // At the keyword `limbs`, not the whole block.
        let keyword = Span::new(span.start, span.start + "limbs".len());
        errors.push(
            Diagnostic::new(keyword, "limbs need the file's units")
                .label("in which units?")
                .note("declare them once: `units { length = mm; mass = kg; }`; then E is in N/mm², A in mm², I in mm⁴ and stiffnesses in N/mm"),
        );
    }
}

/// The branch `b` names, recorded as given (an unknown branch and a second
/// entry for one branch are errors).
fn branch(mech: &Mechanism, b: &Name, given: &mut HashMap<usize, Span>, errors: &mut Diagnostics) -> Option<usize> {
    let Some(i) = mech.branches.iter().position(|x| x.name == b.text) else {
        let mut e = Diagnostic::new(b.span, format!("unknown branch `{}`", b.text)).label("no such branch");
        e = match suggest(&b.text, mech.branches.iter().map(|x| x.name.as_str())) {
            Some(s) => e.note(format!("did you mean `{s}`?")),
            None if mech.branches.is_empty() => {
                e.note("limbs are the file's branches: write each leg as `branch NAME { … }`")
            }
            None => e,
        };
        errors.push(e);
        return None;
    };
    errors
        .given_once(given, i, b.span, || format!("branch `{}`", b.text))
        .then_some(i)
}

/// Branch `i`'s joints from the base to the platform, if they are one
/// serial chain between them (a loop or a side chain is an error at `at`).
fn serial_leg(mech: &Mechanism, i: usize, at: Span, errors: &mut Diagnostics) -> Option<Vec<usize>> {
    let mut left = mech.branches[i].joints.clone();
    let mut link = 0;
    let mut path = Vec::with_capacity(left.len());
    let serial = loop {
        if Some(link) == mech.platform {
            break left.is_empty();
        }
        let mut next = left.iter().filter(|&&j| mech.joints[j].links.contains(&link));
        let (Some(&j), None) = (next.next(), next.next()) else {
            break false;
        };
        left.retain(|&k| k != j);
        path.push(j);
        link = mech.joints[j].other(link);
    };
    if serial {
        return Some(path);
    }
    errors.push(
        Diagnostic::new(
            at,
            format!(
                "branch `{}` is not one serial leg from the base to the platform",
                mech.branches[i].name
            ),
        )
        .label("a closed loop or a side chain")
        .note("the stiffness model takes each limb as one leg between its base joint and its platform joint"),
    );
    None
}

/// An entry's `key = value;` items by key: each key known and given once,
/// each value of known parameters and, if constant, a positive number.
fn entry_items<'a>(
    decl: &'a LimbDecl,
    known: &dyn Fn(&str) -> bool,
    errors: &mut Diagnostics,
) -> HashMap<&'a str, LimbValue> {
    let mut seen: HashMap<&str, Span> = HashMap::new();
    let mut items = HashMap::new();
    for (key, v) in &decl.items {
        if !errors.given_once(&mut seen, key.text.as_str(), key.span, || format!("`{}`", key.text)) {
            continue;
        }
        let Some((_, what)) = KEYS.iter().find(|(k, _)| *k == key.text) else {
            let mut e = Diagnostic::new(key.span, format!("unknown limb property `{}`", key.text))
                .label("not a limb property")
                .note("a limb has `E`, `A` and `I`, or `axial` and `bending`, and may have `actuator`");
            // `e` for `E` first: the keys are short, and close to each other.
            let same_but_case = KEYS.iter().map(|(k, _)| *k).find(|k| k.eq_ignore_ascii_case(&key.text));
            if let Some(s) = same_but_case.or_else(|| suggest(&key.text, KEYS.iter().map(|(k, _)| *k))) {
                e = e.note(format!("did you mean `{s}`?"));
            }
            errors.push(e);
            continue;
        };
        let mut found = Vec::new();
        v.expr.check(known, &mut found);
        if !found.is_empty() {
            errors.0.extend(found);
            continue;
        }
        if v.expr.is_constant() && constant_problem(&key.text, what, v, errors) {
            continue;
        }
        items.insert(key.text.as_str(), v.clone());
    }
    items
}

/// Whether a constant value is not a positive number (then reported at it).
fn constant_problem(key: &str, what: &str, v: &LimbValue, errors: &mut Diagnostics) -> bool {
    match v.expr.eval_checked(&HashMap::new()) {
        Ok(x) if x > 0.0 => false,
        Ok(x) => {
            errors.push(
                Diagnostic::new(v.span, format!("the {what} `{key}` is {x}; it must be positive"))
                    .label("not positive"),
            );
            true
        }
        Err(why) => {
            errors.push(Diagnostic::new(v.span, format!("the {what} `{key}` is not a number: {why}")).label("here"));
            true
        }
    }
}

/// The leg's stiffness of an entry: all of `E`, `A`, `I` or both of
/// `axial`, `bending`, not some of each (mixed or missing keys are errors;
/// a value already reported leaves the entry without a leg, silently).
fn leg_stiffness(
    decl: &LimbDecl,
    items: &HashMap<&str, LimbValue>,
    errors: &mut Diagnostics,
) -> Option<LegStiffness<LimbValue>> {
    let written = |keys: &[&str]| -> Vec<&Name> {
        decl.items
            .iter()
            .map(|(k, _)| k)
            .filter(|k| keys.contains(&k.text.as_str()))
            .collect()
    };
    let (section, direct) = (written(&SECTION), written(&DIRECT));
    if let (Some(s), Some(d)) = (section.first(), direct.first()) {
        // In the order written, at the later.
        let (first, later) = if s.span.start < d.span.start { (s, d) } else { (d, s) };
        errors.push(
            Diagnostic::new(
                later.span,
                format!(
                    "`{}` and `{}` in one limb: give its leg either by `E`, `A` and `I` or by `axial` and `bending`",
                    first.text, later.text
                ),
            )
            .label("mixed"),
        );
        return None;
    }
    let names: Vec<&str> = decl.branches.iter().map(|b| b.text.as_str()).collect();
    let who = match names.as_slice() {
        [one] => format!("limb `{one}` needs"),
        many => format!("limbs `{}` need", many.join("`, `")),
    };
    let at = match (decl.branches.first(), decl.branches.last()) {
        (Some(f), Some(l)) => Span::new(f.span.start, l.span.end),
        _ => decl.span,
    };
    let (keys, note) = match (section.is_empty(), direct.is_empty()) {
        (true, true) => {
            errors.push(
                Diagnostic::new(
                    at,
                    format!("{who} a leg stiffness: `E`, `A` and `I`, or `axial` and `bending`"),
                )
                .label("no leg stiffness"),
            );
            return None;
        }
        (false, _) => (
            &SECTION[..],
            "the axial stiffness is E·A/L and the bending stiffness 3·E·I/L³ at the leg's length L",
        ),
        (_, false) => (&DIRECT[..], "or give the leg's `E`, `A` and `I` instead"),
    };
    let missing: Vec<&str> = keys
        .iter()
        .copied()
        .filter(|k| !decl.items.iter().any(|(n, _)| n.text == *k))
        .collect();
    if !missing.is_empty() {
        errors.push(
            Diagnostic::new(at, format!("{who} `{}`", missing.join("` and `")))
                .label("incomplete")
                .note(note),
        );
        return None;
    }
    let get = |k: &str| items.get(k).cloned();
    match keys.len() {
        3 => Some(LegStiffness::Section {
            e: get("E")?,
            a: get("A")?,
            i: get("I")?,
        }),
        _ => Some(LegStiffness::Direct {
            axial: get("axial")?,
            bending: get("bending")?,
        }),
    }
}

/// `actuator` is a slide's stiffness in series with the leg: the branch is
/// driven by exactly one actuated joint, a P joint (else an error at `at`).
fn actuator_is_a_slide(mech: &Mechanism, i: usize, actuated: &[usize], at: Span, errors: &mut Diagnostics) {
    let name = &mech.branches[i].name;
    let problem = match actuated {
        [] => format!("branch `{name}` has no actuated joint for an `actuator` stiffness"),
        [j] if mech.joints[*j].kind == JointKind::P => return,
        [j] => format!(
            "`actuator` is an actuated slide's stiffness, but branch `{name}` is driven by the {} joint `{}`",
            mech.joints[*j].kind.symbol(),
            mech.joints[*j].name
        ),
        many => format!(
            "branch `{name}` has {} actuated joints: `actuator` is the stiffness of one slide",
            many.len()
        ),
    };
    errors.push(
        Diagnostic::new(at, problem)
            .label("no single actuated slide")
            .note("`actuator` (N/L) acts in series with the leg's axial stiffness"),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lowering::numeric::limb_properties;
    use crate::syntax::expr::Expr;
    use crate::topology::analysis::Analysis;

    /// A 3-RPS topology with units and two parameters; `limbs` is line 7.
    fn rps(limbs: &str) -> String {
        format!(
            "mechanism m {{
    branch A {{ base R1 ⊥ P1* - S1 platform; }}
    branch B {{ base R2 ⊥ P2* - S2 platform; }}
    branch C {{ base R3 ⊥ P3* - S3 platform; }}
    parameters {{ d = 40; e0 = 2.11e5; }}
    units {{ length = mm; mass = kg; }}
{limbs}
}}"
        )
    }

    /// Every error the text produces, in order: line, column and message.
    fn check(source: &str, expected: &[(usize, usize, &str)]) {
        let got: Vec<(usize, usize, String)> = match crate::topology::analysis::analyze_source(source) {
            Ok(_) => Vec::new(),
            Err(d) => d.0.into_iter().map(|e| at(source, e)).collect(),
        };
        let expected: Vec<(usize, usize, String)> = expected.iter().map(|&(l, c, m)| (l, c, m.to_string())).collect();
        assert_eq!(got, expected, "{source}");
    }

    fn at(source: &str, e: Diagnostic) -> (usize, usize, String) {
        let (l, c) = e.span.map_or((0, 0), |s| s.line_col(source));
        (l, c, e.message)
    }

    fn analysis(source: &str) -> Analysis {
        crate::topology::analysis::analyze_source(source).expect("no error")
    }

    /// The errors of [`limb_properties`] at parameter overrides, as [`check`] gives them.
    fn check_at(source: &str, overrides: &[(&str, f64)], expected: &[(usize, usize, &str)]) {
        let a = analysis(source);
        let values = overrides.iter().map(|&(n, v)| (n.to_string(), v)).collect();
        let got: Vec<(usize, usize, String)> = match limb_properties(&a, &values) {
            Ok(_) => Vec::new(),
            Err(d) => d.0.into_iter().map(|e| at(source, e)).collect(),
        };
        let expected: Vec<(usize, usize, String)> = expected.iter().map(|&(l, c, m)| (l, c, m.to_string())).collect();
        assert_eq!(got, expected, "{source} at {overrides:?}");
    }

    #[test]
    fn a_block_parses_into_entries_of_several_branches() {
        let ast = crate::parse(
            "mechanism m { limbs { A, B, C { E = 2.11e5; A = 1256.6; I = 1.256e5; }
                                   D { axial = 1.0e5; bending = 350; actuator = 2 * k; } } }",
        )
        .unwrap();
        assert_eq!(ast.limbs.len(), 1);
        let entries = &ast.limbs[0].0;
        let branches = |e: &LimbDecl| e.branches.iter().map(|b| b.text.clone()).collect::<Vec<_>>();
        let keys = |e: &LimbDecl| e.items.iter().map(|(k, _)| k.text.clone()).collect::<Vec<_>>();
        assert_eq!(branches(&entries[0]), ["A", "B", "C"]);
        assert_eq!(keys(&entries[0]), ["E", "A", "I"]);
        assert_eq!(entries[0].items[0].1.expr, Expr::Num(2.11e5));
        assert_eq!(branches(&entries[1]), ["D"]);
        assert_eq!(keys(&entries[1]), ["axial", "bending", "actuator"]);
        // `2 * k`: a product of a number and a parameter, its span the text's.
        let actuator = &entries[1].items[2].1;
        assert!(matches!(&actuator.expr, Expr::Bin('*', a, b)
            if **a == Expr::Num(2.0) && matches!(&**b, Expr::Var(k, _) if k == "k")));
        let text = "mechanism m { limbs { A, B, C { E = 2.11e5; A = 1256.6; I = 1.256e5; }
                                   D { axial = 1.0e5; bending = 350; actuator = 2 * k; } } }";
        assert_eq!(&text[actuator.span.start..actuator.span.end], "2 * k");
    }

    #[test]
    fn a_syntax_error_names_the_blocks_items() {
        let err = |text: &str| crate::parse(text).unwrap_err().message;
        assert_eq!(
            err("mechanism m { limbs { A { 3 = 1; } } }"),
            "syntax error: expected a name, found `3`"
        );
        // A branch list is names separated by commas: the entry fails at its start.
        assert_eq!(
            err("mechanism m { limbs { A + B { E = 1; } } }"),
            "syntax error: expected a limb's properties `BRANCH, … { E = …; A = …; I = …; }`, found `A`"
        );
    }

    #[test]
    fn limbs_resolve_per_branch_from_base_to_platform() {
        let a = analysis(&rps(
            "limbs { A, B { E = 2.11e5; A = pi * d^2 / 4; I = pi * d^4 / 64; } C { axial = 1.0e5; bending = 350; actuator = 2 * e0; } }",
        ));
        let limbs = limb_properties(&a, &HashMap::new()).unwrap();
        assert_eq!(limbs.len(), 3);
        for (k, (name, joints)) in [
            ("A", ["R1", "P1", "S1"]),
            ("B", ["R2", "P2", "S2"]),
            ("C", ["R3", "P3", "S3"]),
        ]
        .into_iter()
        .enumerate()
        {
            assert_eq!((limbs[k].branch, limbs[k].name.as_str()), (k, name));
            assert_eq!(a.names(&limbs[k].joints), joints);
            assert_eq!(a.names(&limbs[k].actuated), [joints[1]]);
        }
        // A solid round leg of diameter d = 40: A = π·40²/4 = 400π, I = π·40⁴/64 = 40000π.
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-15 * y;
        let LegStiffness::Section { e, a: area, i } = limbs[0].leg else {
            panic!("A is given by its section: {:?}", limbs[0].leg)
        };
        assert_eq!(e, 2.11e5);
        assert!(close(area, 400.0 * std::f64::consts::PI) && close(i, 40000.0 * std::f64::consts::PI));
        assert_eq!(limbs[1].leg, limbs[0].leg);
        assert_eq!((limbs[0].actuator, limbs[1].actuator), (None, None));
        assert_eq!(
            limbs[2].leg,
            LegStiffness::Direct {
                axial: 1.0e5,
                bending: 350.0
            }
        );
        assert_eq!(limbs[2].actuator, Some(4.22e5));
        // Through the parameters: d = 20 gives 100π and 2500π.
        let at20 = limb_properties(&a, &HashMap::from([("d".to_string(), 20.0)])).unwrap();
        let LegStiffness::Section { a: area, i, .. } = at20[0].leg else {
            panic!("A is given by its section")
        };
        assert!(close(area, 100.0 * std::f64::consts::PI) && close(i, 2500.0 * std::f64::consts::PI));
    }

    #[test]
    fn a_u_joints_halves_are_in_its_leg_in_order() {
        let a = analysis(
            "mechanism m {
                branch A { base U1 - P1* - S1 platform; }   branch B { base U2 - P2* - S2 platform; }
                branch C { base U3 - P3* - S3 platform; }   branch D { base U4 - P4* - S4 platform; }
                branch E { base U5 - P5* - S5 platform; }   branch F { base U6 - P6* - S6 platform; }
                units { length = mm; mass = kg; }
                limbs { A, B, C, D, E, F { axial = 1; bending = 2; actuator = 3; } } }",
        );
        let limbs = limb_properties(&a, &HashMap::new()).unwrap();
        assert_eq!(a.names(&limbs[0].joints), ["U1.a", "U1.b", "P1", "S1"]);
        assert_eq!(a.names(&limbs[5].joints), ["U6.a", "U6.b", "P6", "S6"]);
    }

    #[test]
    fn files_without_limbs_analyse_as_before() {
        let with = analysis(&rps("limbs { A, B, C { axial = 1; bending = 2; } }"));
        let without = analysis(&rps(""));
        assert!(without.limbs.is_empty());
        assert_eq!(with.limbs.len(), 3);
        assert_eq!(with.report(), without.report());
        assert_eq!(limb_properties(&without, &HashMap::new()), Ok(Vec::new()));
    }

    #[test]
    fn limbs_need_the_files_units() {
        let source = "mechanism m {
    branch A { base R1 ⊥ P1* - S1 platform; }
    branch B { base R2 ⊥ P2* - S2 platform; }
    branch C { base R3 ⊥ P3* - S3 platform; }
    parameters { d = 40; }
limbs { A, B, C { axial = 1; bending = 2; } }
}";
        check(source, &[(6, 1, "limbs need the file's units")]);
    }

    #[test]
    fn each_branch_known_and_given_once() {
        check(
            &rps("limbs { A, D { axial = 1; bending = 2; } A { axial = 1; bending = 2; } }"),
            &[(7, 12, "unknown branch `D`"), (7, 42, "branch `A` is given twice")],
        );
        // Without branches there are no limbs to name.
        check(
            "mechanism m { planar; base R1* ∥ R2 ∥ R3 ∥ R4 base;
units { length = mm; mass = kg; } limbs { R1 { axial = 1; bending = 2; } } }",
            &[(2, 43, "unknown branch `R1`")],
        );
    }

    #[test]
    fn each_key_known_and_given_once() {
        let source = rps("limbs { A, B, C { E = 1; E = 2; colour = 3; e = 4; A = 1; I = 1; } }");
        check(
            &source,
            &[
                (7, 26, "`E` is given twice"),
                (7, 33, "unknown limb property `colour`"),
                (7, 45, "unknown limb property `e`"),
            ],
        );
        let notes = crate::topology::analysis::analyze_source(&source).unwrap_err().0[2]
            .notes
            .clone();
        assert!(notes.contains(&"did you mean `E`?".to_string()), "{notes:?}");
    }

    #[test]
    fn a_leg_by_its_section_or_by_its_stiffnesses_not_both() {
        check(
            &rps("limbs { A, B, C { axial = 1; E = 1; A = 1; I = 1; } }"),
            &[(
                7,
                30,
                "`axial` and `E` in one limb: give its leg either by `E`, `A` and `I` or by `axial` and `bending`",
            )],
        );
        check(
            &rps("limbs { A { E = 1; A = 1; } B, C { bending = 2; } }"),
            &[(7, 9, "limb `A` needs `I`"), (7, 29, "limbs `B`, `C` need `axial`")],
        );
        check(
            &rps("limbs { A, B, C { actuator = 1; } }"),
            &[(
                7,
                9,
                "limbs `A`, `B`, `C` need a leg stiffness: `E`, `A` and `I`, or `axial` and `bending`",
            )],
        );
    }

    #[test]
    fn a_constant_value_is_a_positive_number() {
        check(
            &rps("limbs { A { E = 0; A = -3; I = 1 - 2; } B { axial = 1/0; bending = sqrt(-1); } C { axial = q; bending = -2.11e5; } }"),
            &[
                (7, 17, "the Young's modulus `E` is 0; it must be positive"),
                (7, 24, "the cross-section area `A` is -3; it must be positive"),
                (7, 32, "the second moment of area `I` is -1; it must be positive"),
                (7, 53, "the axial stiffness `axial` is not a number: division by zero"),
                (7, 68, "the bending stiffness `bending` is not a number: sqrt of a negative number"),
                (7, 92, "unknown parameter `q`"),
                (7, 105, "the bending stiffness `bending` is -211000; it must be positive"),
            ],
        );
    }

    #[test]
    fn a_value_of_the_parameters_is_checked_at_the_parameters_given() {
        // E = e0 − 3·10⁵ is −89000 at the file's e0 = 2.11·10⁵ and 10⁵ at
        // e0 = 4·10⁵; A = 1/(d − 40) divides by zero at the file's d = 40.
        let source = rps("limbs { A, B, C { E = e0 - 3e5; A = 1 / (d - 40); I = 1; } }");
        let e = "the Young's modulus `E` of limb `{}` is -89000 at these parameters; it must be positive";
        let a = "the cross-section area `A` of limb `{}` is not a number at these parameters: division by zero";
        let (ea, eb, ec) = (e.replace("{}", "A"), e.replace("{}", "B"), e.replace("{}", "C"));
        let (aa, ab, ac) = (a.replace("{}", "A"), a.replace("{}", "B"), a.replace("{}", "C"));
        check(&source, &[]);
        check_at(
            &source,
            &[],
            &[
                (7, 23, &ea),
                (7, 37, &aa),
                (7, 23, &eb),
                (7, 37, &ab),
                (7, 23, &ec),
                (7, 37, &ac),
            ],
        );
        check_at(&source, &[("e0", 4e5), ("d", 41.0)], &[]);
        let limbs = limb_properties(
            &analysis(&source),
            &HashMap::from([("e0".into(), 4e5), ("d".into(), 41.0)]),
        )
        .unwrap();
        assert_eq!(limbs[2].leg, LegStiffness::Section { e: 1e5, a: 1.0, i: 1.0 });
    }

    #[test]
    fn an_actuator_stiffness_is_a_single_actuated_slides() {
        // A planar 3-RRR: each leg driven by a revolute.
        check(
            "mechanism m { planar;
    branch A { base R1* [a1] ∥ R2 [a2] ∥ R3 platform; }
    branch B { base R4* [b1] ∥ R5 [b2] ∥ R6 platform; }
    branch C { base R7* [c1] ∥ R8 [c2] ∥ R9 platform; }
    units { length = mm; mass = kg; }
limbs { A { axial = 1; bending = 2; actuator = 3; } } }",
            &[(
                6,
                37,
                "`actuator` is an actuated slide's stiffness, but branch `A` is driven by the R joint `R1`",
            )],
        );
        // A fourth, passive UPS leg (f = 6, one loop more: the DOF stay 3).
        check(
            &rps("branch D { base U4 - P4 - S4 platform; }
limbs { D { axial = 1; bending = 2; actuator = 3; } }"),
            &[(8, 37, "branch `D` has no actuated joint for an `actuator` stiffness")],
        );
        // A planar leg driven by two slides.
        check(
            "mechanism m { planar;
    branch A { base P1* [s] ⊥ P2* [t] - R1 platform; }
    branch B { base R2 [u] ∥ R3 platform; }
    units { length = mm; mass = kg; }
limbs { A { axial = 1; bending = 2; actuator = 3; } } }",
            &[(
                5,
                37,
                "branch `A` has 2 actuated joints: `actuator` is the stiffness of one slide",
            )],
        );
    }

    #[test]
    fn a_limb_is_one_serial_leg() {
        // Branch A closes a four-bar on the base before it reaches the platform.
        check(
            "mechanism m { planar;
    branch A { base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base; b R5 platform; }
    branch B { base R6 [e] ∥ R7 platform; }
    units { length = mm; mass = kg; }
limbs { A, B { axial = 1; bending = 2; } } }",
            &[(5, 9, "branch `A` is not one serial leg from the base to the platform")],
        );
    }
}
