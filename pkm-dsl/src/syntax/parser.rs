//! The pest parser: text to [`MechanismAst`]. Grammar errors become
//! [`Diagnostic`]s with spans; nothing here panics on user input.

use super::ast::*;
use super::expr::Expr;
use crate::diagnostics::{Diagnostic, Span};
use crate::limits::{MAX_EXPR_OPERATIONS, MAX_FILE_BYTES, MAX_NESTING, MAX_PARAMETERS, MAX_PLACEMENTS};
use pest::iterators::Pair;
use pest::Parser;

/// pest's parser for `grammar.pest`: `Rule` and `impl Parser<Rule>`, as
/// `#[derive(pest_derive::Parser)]` would write them, generated once and
/// committed in `grammar.rs` (`tests::generated_parser_is_current` keeps
/// it equal to the grammar), so that the macro's users compile no parser
/// generator.
struct DslParser;

/// The generated items, apart: generated code is not held to this crate's
/// lints (`#[derive]` output never is).
#[allow(dead_code, clippy::all)]
mod grammar {
    use super::DslParser;
    include!("grammar.rs");
}
pub(super) use grammar::Rule;

/// Parses one mechanism description.
///
/// ```
/// let ast = pkm_dsl::parse("mechanism four_bar { planar; base R1* - R2 - R3 - R4 base; }").unwrap();
/// assert_eq!(ast.name.text, "four_bar");
/// assert_eq!(ast.chains[0].joints.len(), 4);
/// ```
pub fn parse(source: &str) -> Result<MechanismAst, Diagnostic> {
    // Cheap limits first: the generated parser recurses once per nesting level.
    check_size_and_nesting(source)?;
    let mut pairs = DslParser::parse(Rule::file, source).map_err(|e| grammar_error(source, e))?;
    check_counts(pairs.clone())?;
    let file = pairs.next().expect("the file rule always yields one pair");
    let mechanism = file.into_inner().next().expect("a file holds one mechanism");
    Ok(build(mechanism))
}

/// Checks the text's size and the nesting of its brackets and exponents with
/// one pass over the raw text, before the recursive parser sees it.
fn check_size_and_nesting(source: &str) -> Result<(), Diagnostic> {
    if source.len() > MAX_FILE_BYTES {
        let at = (0..=MAX_FILE_BYTES)
            .rev()
            .find(|&i| source.is_char_boundary(i))
            .unwrap_or(0);
        return Err(Diagnostic::new(
            Span::new(at, next_char_end(source, at)),
            format!(
                "the text is {} bytes long; the limit is {MAX_FILE_BYTES} bytes",
                source.len()
            ),
        )
        .label("the limit is reached here"));
    }
    let bytes = source.as_bytes();
    // Pending exponents of each open parenthesis level (level 0 is outside any).
    let mut pending: Vec<usize> = vec![0];
    let mut nesting = 0usize;
    // Whether the last token ends an operand, so that a `-` after it is binary.
    let mut after_operand = false;
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        i += 1;
        match c {
            b'/' if bytes.get(i) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'/' if bytes.get(i) == Some(&b'*') => {
                i = source[i + 1..].find("*/").map_or(bytes.len(), |k| i + 1 + k + 2);
                continue;
            }
            b'"' => {
                while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
                    i += 1;
                }
                i += 1;
                after_operand = false;
                continue;
            }
            b' ' | b'\t' | b'\r' | b'\n' => continue,
            b'0'..=b'9' => {
                // A number as the grammar's `real` reads it, so that the `-` of
                // `1e-5` is not taken for a binary minus.
                let digits = |i: &mut usize| {
                    while *i < bytes.len() && bytes[*i].is_ascii_digit() {
                        *i += 1;
                    }
                };
                digits(&mut i);
                if bytes.get(i) == Some(&b'.') {
                    i += 1;
                    digits(&mut i);
                }
                if matches!(bytes.get(i), Some(b'e' | b'E')) {
                    let mut j = i + 1;
                    if matches!(bytes.get(j), Some(b'+' | b'-')) {
                        j += 1;
                    }
                    if bytes.get(j).is_some_and(u8::is_ascii_digit) {
                        i = j;
                        digits(&mut i);
                    }
                }
                after_operand = true;
                continue;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                after_operand = true;
                continue;
            }
            b'(' => {
                pending.push(0);
                nesting += 1;
            }
            b')' => {
                if pending.len() > 1 {
                    nesting -= 1 + pending.pop().unwrap_or(0);
                }
                after_operand = true;
                continue;
            }
            b'^' => {
                if let Some(top) = pending.last_mut() {
                    *top += 1;
                }
                nesting += 1;
            }
            // A binary operator or a separator ends the exponent chain of its level.
            b'+' | b'*' | b'/' | b',' | b';' | b'{' | b'}' => end_chain(&mut pending, &mut nesting),
            b'-' if after_operand => end_chain(&mut pending, &mut nesting),
            _ => {}
        }
        after_operand = false;
        if nesting > MAX_NESTING {
            return Err(Diagnostic::new(
                Span::new(start, start + 1),
                format!("expression nested more than {MAX_NESTING} deep (parentheses and exponents `^` together)"),
            )
            .label(format!("nesting level {} here", MAX_NESTING + 1))
            .note("name a part of the expression as a parameter"));
        }
    }
    Ok(())
}

fn end_chain(pending: &mut [usize], nesting: &mut usize) {
    if let Some(top) = pending.last_mut() {
        *nesting -= *top;
        *top = 0;
    }
}

/// Checks the limits that need the parse tree: operations per expression,
/// parameters and placements per file. One pass over the flat token list; nothing recurses.
fn check_counts(pairs: pest::iterators::Pairs<Rule>) -> Result<(), Diagnostic> {
    // The top-level expression being counted: its span and its operations so far.
    let mut current: Option<(Span, usize)> = None;
    let mut parameters = 0usize;
    let mut placements = 0usize;
    for p in pairs.flatten() {
        let span = span_of(&p);
        let operation = match p.as_rule() {
            Rule::expr => {
                if current.is_none_or(|(s, _)| span.start >= s.end) {
                    current = Some((span, 0));
                }
                false
            }
            Rule::add_op | Rule::mul_op | Rule::neg_op | Rule::call => true,
            Rule::power => p.clone().into_inner().nth(1).is_some(),
            Rule::placement => {
                placements += 1;
                if placements > MAX_PLACEMENTS {
                    return Err(
                        Diagnostic::new(span, format!("more than {MAX_PLACEMENTS} placements in `geometry`"))
                            .label(format!("placement number {} here", MAX_PLACEMENTS + 1)),
                    );
                }
                false
            }
            Rule::parameter => {
                parameters += 1;
                if parameters > MAX_PARAMETERS {
                    return Err(Diagnostic::new(span, format!("more than {MAX_PARAMETERS} parameters"))
                        .label(format!("parameter number {} here", MAX_PARAMETERS + 1)));
                }
                false
            }
            _ => false,
        };
        if let (true, Some((expr_span, count))) = (operation, current.as_mut()) {
            *count += 1;
            if *count > MAX_EXPR_OPERATIONS {
                return Err(Diagnostic::new(
                    *expr_span,
                    format!("expression with more than {MAX_EXPR_OPERATIONS} operations"),
                )
                .label("too long")
                .also(span, format!("operation number {} is", MAX_EXPR_OPERATIONS + 1))
                .note("split it into several parameters"));
            }
        }
    }
    Ok(())
}

fn grammar_error(source: &str, e: pest::error::Error<Rule>) -> Diagnostic {
    let span = match e.location {
        pest::error::InputLocation::Pos(p) => Span::new(p, next_char_end(source, p)),
        pest::error::InputLocation::Span((s, t)) => Span::new(s, t),
    };
    let message = match &e.variant {
        pest::error::ErrorVariant::ParsingError { positives, negatives } => {
            let mut expected: Vec<&str> = positives.iter().map(|r| rule_name(*r)).collect();
            expected.sort_unstable();
            expected.dedup();
            let found = source[span.start.min(source.len())..]
                .chars()
                .next()
                .map_or("end of text".to_string(), |c| format!("`{c}`"));
            if expected.is_empty() {
                let unexpected: Vec<&str> = negatives.iter().map(|r| rule_name(*r)).collect();
                format!("syntax error: unexpected {}", unexpected.join(", "))
            } else {
                format!("syntax error: expected {}, found {found}", join_or(&expected))
            }
        }
        pest::error::ErrorVariant::CustomError { message } => message.clone(),
    };
    Diagnostic::new(span, message).label("here")
}

fn next_char_end(source: &str, p: usize) -> usize {
    source
        .get(p..)
        .and_then(|s| s.chars().next())
        .map_or(p, |c| p + c.len_utf8())
}

fn join_or(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_string(),
        [init @ .., last] => format!("{} or {}", init.join(", "), last),
    }
}

fn rule_name(r: Rule) -> &'static str {
    match r {
        Rule::EOI => "end of text",
        Rule::file | Rule::mechanism | Rule::kw_mechanism => "`mechanism NAME { … }`",
        Rule::title_stmt | Rule::kw_title => "`title`",
        Rule::capabilities_stmt | Rule::kw_capabilities => "`capabilities`",
        Rule::planar_stmt | Rule::kw_planar => "`planar`",
        Rule::mobility_stmt | Rule::kw_mobility => "`mobility by geometry`",
        Rule::kw_by => "`by`",
        Rule::link_stmt | Rule::kw_link => "`link`",
        Rule::link_item => "a link",
        Rule::joint_stmt | Rule::kw_joint => "`joint`",
        Rule::branch_stmt | Rule::kw_branch => "`branch`",
        Rule::platform_stmt | Rule::kw_platform => "`platform`",
        Rule::point_stmt | Rule::kw_point => "`point`",
        Rule::kw_on => "`on`",
        Rule::chain => "a chain",
        Rule::connector => "a relation (`∥`, `⊥`) or `-`",
        Rule::label => "a link label `[name]`",
        Rule::joint => "a joint",
        Rule::actuated => "`*`",
        Rule::relation_stmt => "a relation statement",
        Rule::relation => "a relation",
        Rule::parallel => "`∥`",
        Rule::perpendicular => "`⊥`",
        Rule::coaxial => "`≡`",
        Rule::concurrent => "`∧`",
        Rule::direction => "a joint, a frame axis or a plane",
        Rule::plane => "a plane `◇xoz` or `◇(A,B)`",
        Rule::unrelated => "`-`",
        Rule::name => "a name",
        Rule::ident => "a name",
        Rule::axis_ref => "a joint or a U joint's axis `U1.a`",
        Rule::number => "a number",
        Rule::string => "a string",
        Rule::text => "text",
        Rule::word_end => "the end of a word",
        Rule::statement => "a statement",
        Rule::WHITESPACE | Rule::COMMENT => "white space",
        Rule::parameters_stmt | Rule::kw_parameters => "`parameters`",
        Rule::outputs_stmt | Rule::kw_outputs => "`outputs`",
        Rule::output => "an output `names = pose of LINK at POINT;`, `names = point P of LINK;` or `name = joint J;`",
        Rule::pose_output | Rule::kw_pose => "`pose of LINK at POINT`",
        Rule::pose_parts => "`(x, y, z, rx, ry, rz)`",
        Rule::joint_output => "`joint J`",
        Rule::point_output => "`point P of LINK`",
        Rule::kw_of => "`of`",
        Rule::kw_at => "`at`",
        Rule::parameter => "a parameter `name = value;`",
        Rule::geometry_stmt | Rule::kw_geometry => "`geometry`",
        Rule::link_geometry => "a link's geometry `LINK { … }`",
        Rule::placement => "a placement `JOINT = (…);`",
        Rule::line_place | Rule::kw_through => "`through`",
        Rule::point_place => "a point `(…)`",
        Rule::kw_along => "`along`",
        Rule::kw_arm => "`arm`",
        Rule::kw_about => "`about`",
        Rule::axis => "an axis (`x`, `y`, `z` or `(…)`)",
        Rule::tuple => "a tuple `(…)`",
        Rule::expr | Rule::term | Rule::factor | Rule::power | Rule::atom => "an expression",
        Rule::call => "a function call",
        Rule::add_op => "`+` or `-`",
        Rule::mul_op => "`*` or `/`",
        Rule::neg_op => "`-`",
        Rule::real => "a number",
        Rule::study_stmt
        | Rule::study_ranges
        | Rule::study_range
        | Rule::study_start
        | Rule::study_pose
        | Rule::study_trajectory
        | Rule::study_sine
        | Rule::study_constant
        | Rule::study_point
        | Rule::study_branch
        | Rule::study_sections
        | Rule::study_section
        | Rule::study_nodes
        | Rule::study_item
        | Rule::kw_study
        | Rule::kw_ranges
        | Rule::kw_start
        | Rule::kw_trajectory
        | Rule::kw_sine
        | Rule::kw_amplitude
        | Rule::kw_constant
        | Rule::kw_speed
        | Rule::kw_duration
        | Rule::kw_sections
        | Rule::kw_nodes => super::study::rule_name(r),
        Rule::units_stmt
        | Rule::unit_item
        | Rule::masses_stmt
        | Rule::massless_item
        | Rule::link_mass
        | Rule::bar_mass
        | Rule::mass_item
        | Rule::gravity_stmt
        | Rule::loads_stmt
        | Rule::load
        | Rule::load_part
        | Rule::value
        | Rule::kw_units
        | Rule::kw_masses
        | Rule::kw_massless
        | Rule::kw_bar
        | Rule::kw_gravity
        | Rule::kw_loads
        | Rule::kw_force
        | Rule::kw_moment => super::masses::rule_name(r),
        Rule::limbs_stmt | Rule::limb_entry | Rule::limb_item | Rule::kw_limbs => super::limbs::rule_name(r),
    }
}

pub(crate) fn span_of(p: &Pair<Rule>) -> Span {
    Span::new(p.as_span().start(), p.as_span().end())
}

pub(crate) fn name(p: Pair<Rule>) -> Name {
    Name {
        text: p.as_str().to_string(),
        span: span_of(&p),
    }
}

fn string_text(p: Pair<Rule>) -> String {
    p.into_inner()
        .next()
        .map(|t| t.as_str().to_string())
        .unwrap_or_default()
}

fn relation_kind(p: &Pair<Rule>) -> Option<RelationKind> {
    match p.as_rule() {
        Rule::parallel => Some(RelationKind::Parallel),
        Rule::perpendicular => Some(RelationKind::Perpendicular),
        Rule::coaxial => Some(RelationKind::Coaxial),
        Rule::concurrent => Some(RelationKind::Concurrent),
        _ => None,
    }
}

fn build(mechanism: Pair<Rule>) -> MechanismAst {
    let mut inner = mechanism.into_inner();
    let _kw = inner.next();
    let mech_name = name(inner.next().expect("mechanism name"));
    let mut ast = MechanismAst {
        name: mech_name,
        title: None,
        capabilities: Vec::new(),
        planar: None,
        mobility_by_geometry: None,
        links: Vec::new(),
        joints: Vec::new(),
        chains: Vec::new(),
        branches: Vec::new(),
        platform: None,
        point: None,
        relations: Vec::new(),
        parameters: Vec::new(),
        geometry: Vec::new(),
        outputs: Vec::new(),
        studies: Vec::new(),
        units: Vec::new(),
        masses: Vec::new(),
        gravity: Vec::new(),
        loads: Vec::new(),
        limbs: Vec::new(),
    };
    for stmt in inner {
        match stmt.as_rule() {
            Rule::title_stmt => {
                let s = stmt.into_inner().nth(1).expect("title string");
                ast.title = Some(string_text(s));
            }
            Rule::capabilities_stmt => {
                ast.capabilities
                    .extend(stmt.into_inner().filter(|p| p.as_rule() == Rule::ident).map(name));
            }
            Rule::planar_stmt => ast.planar = Some(span_of(&stmt)),
            Rule::mobility_stmt => ast.mobility_by_geometry = Some(span_of(&stmt)),
            Rule::link_stmt => {
                for item in stmt.into_inner().filter(|p| p.as_rule() == Rule::link_item) {
                    let mut it = item.into_inner();
                    let n = name(it.next().expect("link name"));
                    let description = it.next().map(string_text);
                    ast.links.push(LinkDecl { name: n, description });
                }
            }
            Rule::joint_stmt => ast.joints.push(joint_decl(stmt)),
            Rule::branch_stmt => {
                let mut it = stmt.into_inner().skip(1);
                let bname = name(it.next().expect("branch name"));
                let index = ast.branches.len();
                ast.branches.push(bname);
                for c in it {
                    ast.chains.push(chain(c, Some(index)));
                }
            }
            Rule::platform_stmt => {
                ast.platform = stmt.into_inner().nth(1).map(name);
            }
            Rule::point_stmt => {
                let mut it = stmt.into_inner().filter(|p| p.as_rule() == Rule::ident);
                let point = name(it.next().expect("point name"));
                let joint = name(it.next().expect("point joint"));
                ast.point = Some((point, joint));
            }
            Rule::chain => ast.chains.push(chain(stmt, None)),
            Rule::study_stmt => ast.studies.push(super::study::build(stmt)),
            Rule::units_stmt => ast.units.push(super::masses::build_units(stmt)),
            Rule::masses_stmt => {
                let span = span_of(&stmt);
                ast.masses.push((super::masses::build_masses(stmt), span));
            }
            Rule::gravity_stmt => ast.gravity.push(super::masses::build_gravity(stmt)),
            Rule::loads_stmt => ast.loads.extend(super::masses::build_loads(stmt)),
            Rule::limbs_stmt => {
                let span = span_of(&stmt);
                ast.limbs.push((super::limbs::build_limbs(stmt), span));
            }
            Rule::outputs_stmt => ast.outputs.extend(
                stmt.into_inner()
                    .filter(|p| p.as_rule() == Rule::output)
                    .map(output_decl),
            ),
            Rule::parameters_stmt => {
                for p in stmt.into_inner().filter(|p| p.as_rule() == Rule::parameter) {
                    let mut it = p.into_inner();
                    let n = name(it.next().expect("parameter name"));
                    ast.parameters.push((n, expr(it.next().expect("parameter value"))));
                }
            }
            Rule::geometry_stmt => {
                for lg in stmt.into_inner().filter(|p| p.as_rule() == Rule::link_geometry) {
                    let mut it = lg.into_inner();
                    let link = name(it.next().expect("link name"));
                    let placements = it.map(placement).collect();
                    ast.geometry.push(LinkGeometry { link, placements });
                }
            }
            Rule::relation_stmt => ast.relations.push(relation_stmt(stmt)),
            _ => {}
        }
    }
    ast
}

/// `joint NAME = KIND(LINK, LINK, …) *;`: a joint declared on its own
/// (`*` marks it actuated; more than two links make a compound hinge).
fn joint_decl(stmt: Pair<Rule>) -> JointDecl {
    let span = span_of(&stmt);
    let mut it = stmt.into_inner().skip(1);
    let jname = name(it.next().expect("joint name"));
    let kind = name(it.next().expect("joint kind"));
    let mut links = Vec::new();
    let mut actuated = false;
    for p in it {
        match p.as_rule() {
            Rule::name => links.push(name(p)),
            Rule::actuated => actuated = true,
            _ => {}
        }
    }
    JointDecl {
        name: jname,
        kind,
        links,
        actuated,
        span,
    }
}

/// One declared output: its names and what they measure (a pose, a point or a joint).
fn output_decl(o: Pair<Rule>) -> OutputDecl {
    let span = span_of(&o);
    let mut names = Vec::new();
    let mut what = None;
    for q in o.into_inner() {
        match q.as_rule() {
            Rule::ident => names.push(name(q)),
            Rule::pose_output => {
                let inner: Vec<_> = q.into_inner().collect();
                let mut it = inner.iter().filter(|r| matches!(r.as_rule(), Rule::name | Rule::ident));
                let link = name(it.next().expect("pose link").clone());
                let at = name(it.next().expect("pose point").clone());
                let about = inner.iter().find(|r| r.as_rule() == Rule::axis).cloned().map(axis);
                let parts = inner
                    .iter()
                    .find(|r| r.as_rule() == Rule::pose_parts)
                    .map(|r| r.clone().into_inner().map(name).collect());
                what = Some(OutputWhat::Pose { link, at, about, parts });
            }
            Rule::point_output => {
                let inner: Vec<_> = q.into_inner().collect();
                let mut it = inner.iter().filter(|r| matches!(r.as_rule(), Rule::name | Rule::ident));
                let at = name(it.next().expect("point output's point").clone());
                let link = name(it.next().expect("point output's link").clone());
                what = Some(OutputWhat::Point { link, at });
            }
            Rule::joint_output => {
                let j = q
                    .into_inner()
                    .find(|r| r.as_rule() == Rule::axis_ref)
                    .expect("output joint");
                what = Some(OutputWhat::Joint(name(j)));
            }
            _ => {}
        }
    }
    OutputDecl {
        names,
        what: what.expect("output kind"),
        span,
    }
}

/// `A ∥ B ⊥ ◇C …`: the directions and the relations between neighbours.
fn relation_stmt(stmt: Pair<Rule>) -> RelationStmt {
    let mut items = Vec::new();
    let mut ops = Vec::new();
    for p in stmt.into_inner() {
        match relation_kind(&p) {
            Some(k) => ops.push((k, span_of(&p))),
            None if p.as_rule() == Rule::plane => {
                let span = span_of(&p);
                let mut names = p.into_inner().map(name);
                let first = names.next().expect("a plane names something");
                items.push(match names.next() {
                    Some(second) => DirectionRef::PlaneOf(first, second, span),
                    None => DirectionRef::FramePlane(Name { text: first.text, span }),
                });
            }
            None => items.push(DirectionRef::Axis(name(p))),
        }
    }
    RelationStmt { items, ops }
}

fn placement(p: Pair<Rule>) -> Placement {
    let span = span_of(&p);
    let mut extra_point = false;
    let mut n = None;
    let mut place = None;
    for q in p.into_inner() {
        match q.as_rule() {
            Rule::kw_point => extra_point = true,
            Rule::ident => n = Some(name(q)),
            Rule::line_place => {
                let mut it = q
                    .into_inner()
                    .filter(|r| matches!(r.as_rule(), Rule::tuple | Rule::axis));
                let through = tuple(it.next().expect("line point"));
                place = Some(Place::Line(through, axis(it.next().expect("line axis"))));
            }
            Rule::point_place => {
                let mut it = q
                    .into_inner()
                    .filter(|r| matches!(r.as_rule(), Rule::tuple | Rule::axis));
                let at = tuple(it.next().expect("point"));
                let along = it.next().map(axis);
                place = Some(match (along, it.next()) {
                    (Some(d), Some(arm)) => Place::Arm(at, d, tuple(arm)),
                    (d, _) => Place::Point(at, d),
                });
            }
            _ => {}
        }
    }
    Placement {
        name: n.expect("placement name"),
        extra_point,
        place: place.expect("placement place"),
        span,
    }
}

pub(crate) fn tuple(p: Pair<Rule>) -> Tuple {
    Tuple {
        span: span_of(&p),
        items: p.into_inner().map(expr).collect(),
    }
}

fn axis(p: Pair<Rule>) -> AxisRef {
    let q = p.into_inner().next().expect("axis");
    match q.as_rule() {
        Rule::tuple => AxisRef::Vector(tuple(q)),
        _ => AxisRef::Frame(name(q)),
    }
}

/// Builds an expression; `expr`, `term`, `factor`, `power` and `atom` nest as the grammar does.
pub(crate) fn expr(p: Pair<Rule>) -> Expr {
    match p.as_rule() {
        Rule::expr | Rule::term => {
            let mut it = p.into_inner();
            let mut acc = expr(it.next().expect("operand"));
            while let (Some(op), Some(rhs)) = (it.next(), it.next()) {
                let c = op.as_str().chars().next().unwrap_or('+');
                acc = Expr::Bin(c, Box::new(acc), Box::new(expr(rhs)));
            }
            acc
        }
        Rule::factor => {
            let parts: Vec<Pair<Rule>> = p.into_inner().collect();
            let negations = parts.iter().filter(|q| q.as_rule() == Rule::neg_op).count();
            let mut e = expr(parts.into_iter().last().expect("power"));
            for _ in 0..negations {
                e = Expr::Neg(Box::new(e));
            }
            e
        }
        Rule::power => {
            let mut it = p.into_inner();
            let base = expr(it.next().expect("base"));
            match it.next() {
                Some(exp) => Expr::Bin('^', Box::new(base), Box::new(expr(exp))),
                None => base,
            }
        }
        Rule::atom => expr(p.into_inner().next().expect("atom")),
        Rule::real => Expr::Num(p.as_str().parse().unwrap_or(f64::NAN)),
        Rule::ident => Expr::Var(p.as_str().to_string(), span_of(&p)),
        Rule::call => {
            let span = span_of(&p);
            let mut it = p.into_inner();
            let f = it.next().expect("function").as_str().to_string();
            Expr::Call(f, it.map(expr).collect(), span)
        }
        _ => Expr::Num(f64::NAN),
    }
}

fn chain(p: Pair<Rule>, branch: Option<usize>) -> Chain {
    let span = span_of(&p);
    let mut names = Vec::new();
    let mut joints = Vec::new();
    let mut connectors = Vec::new();
    for q in p.into_inner() {
        match q.as_rule() {
            Rule::name => names.push(name(q)),
            Rule::joint => {
                let mut it = q.into_inner();
                let n = name(it.next().expect("joint name"));
                joints.push(ChainJoint {
                    name: n,
                    actuated: it.next().is_some(),
                });
            }
            Rule::connector => {
                let mut label = None;
                let mut relation = None;
                for c in q.into_inner() {
                    match c.as_rule() {
                        Rule::label => label = c.into_inner().next().map(name),
                        _ => relation = relation_kind(&c).map(|k| (k, span_of(&c))),
                    }
                }
                connectors.push(Connector { label, relation });
            }
            _ => {}
        }
    }
    let mut names = names.into_iter();
    let start = names.next().expect("chain start");
    let end = names.next().expect("chain end");
    Chain {
        branch,
        start,
        joints,
        connectors,
        end,
        span,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parser pest's generator writes for `grammar.pest` (as
    /// `pest_derive` would, without its `include_str!` of the grammar),
    /// formatted; `grammar.rs` must be exactly this. After a change to the
    /// grammar, `PKM_WRITE_GRAMMAR=1 cargo test -p pkm-dsl --lib
    /// generated_parser_is_current` writes it.
    #[test]
    fn generated_parser_is_current() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/syntax");
        let grammar = std::fs::read_to_string(dir.join("grammar.pest")).unwrap();
        let input = quote::quote! {
            #[grammar_inline = #grammar]
            struct DslParser;
        };
        let tokens = pest_generator::derive_parser(input, false);
        let file: syn::File = syn::parse2(tokens).unwrap();
        let generated = format!(
            "// Generated by pest_generator from grammar.pest: do not edit; see\n\
             // parser.rs, `tests::generated_parser_is_current`.\n\n{}",
            prettyplease::unparse(&file)
        );
        let path = dir.join("grammar.rs");
        if std::env::var_os("PKM_WRITE_GRAMMAR").is_some() {
            std::fs::write(&path, &generated).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == generated,
            "src/syntax/grammar.rs is not the parser of grammar.pest: run \
             `PKM_WRITE_GRAMMAR=1 cargo test -p pkm-dsl --lib generated_parser_is_current`"
        );
    }

    fn check_err(source: &str, expected: &str) {
        let d = parse(source).unwrap_err();
        assert_eq!(d.render(source, "m.pkm"), expected);
    }

    #[test]
    fn ascii_and_unicode_symbols_parse_alike() {
        let relations = |m: &MechanismAst| -> Vec<Option<RelationKind>> {
            m.chains[0].connectors.iter().map(|c| c.relation.map(|r| r.0)).collect()
        };
        let u = parse("mechanism m { base P1* ⊥ R11 ∥ R12 - R13 base; x ∥ P1; R3 ≡ R12; }").unwrap();
        let a = parse("mechanism m { base P1* _|_ R11 || R12 - R13 base; x || P1; R3 == R12; }").unwrap();
        assert_eq!(
            relations(&u),
            vec![Some(RelationKind::Perpendicular), Some(RelationKind::Parallel), None]
        );
        assert_eq!(relations(&u), relations(&a));
        assert_eq!(u.relations[1].ops[0].0, RelationKind::Coaxial);
        assert_eq!(a.relations[1].ops[0].0, RelationKind::Coaxial);
    }

    #[test]
    fn planes_in_relations() {
        let u = parse("mechanism m { Pa ⊥ ◇xoz; P1 ∥ ◇(R11, R4); }").unwrap();
        let a = parse("mechanism m { Pa _|_ <>xoz; P1 || <>(R11,R4); }").unwrap();
        for m in [&u, &a] {
            assert!(matches!(&m.relations[0].items[1], DirectionRef::FramePlane(n) if n.text == "xoz"));
            assert!(
                matches!(&m.relations[1].items[1], DirectionRef::PlaneOf(p, q, _) if p.text == "R11" && q.text == "R4")
            );
        }
    }

    #[test]
    fn labels_name_the_links_between_joints() {
        let m =
            parse("mechanism m { base P1 ⊥ R11 [c1] ∥ R12 [c2] ∥ R13 ⊥ P2 base; c2 - R3 ⊥ R4 - platform; }").unwrap();
        assert_eq!(m.chains[0].connectors[1].label.as_ref().unwrap().text, "c1");
        assert_eq!(m.chains[1].start.text, "c2");
        assert_eq!(m.chains[1].end.text, "platform");
    }

    #[test]
    fn statements_of_every_kind() {
        let m = parse(
            r#"mechanism punch {
                title "a punch";
                capabilities: fk, ik;
                planar;
                link 1 "AB", 2;
                joint A = R(base, 1)*;
                joint G = R(4, 5, 7);
                branch I { base R1 - R2 platform; }
                platform = 7;
                point o on A;
            }"#,
        )
        .unwrap();
        assert_eq!(m.title.as_deref(), Some("a punch"));
        assert_eq!(m.capabilities.len(), 2);
        assert!(m.planar.is_some());
        assert_eq!(m.links[0].description.as_deref(), Some("AB"));
        assert!(m.joints[0].actuated);
        assert_eq!(m.joints[1].links.len(), 3);
        assert_eq!(m.chains[0].branch, Some(0));
        assert_eq!(m.platform.as_ref().unwrap().text, "7");
        assert_eq!(m.point.as_ref().unwrap().1.text, "A");
    }

    #[test]
    fn missing_connector_is_a_syntax_error() {
        check_err(
            "mechanism m { base R1 R2 base; }",
            "error: syntax error: expected a relation (`∥`, `⊥`) or `-`, found `R`\n --> m.pkm:1:23\n  |\n1 | mechanism m { base R1 R2 base; }\n  |                       ^ here\n",
        );
    }

    #[test]
    fn unterminated_mechanism() {
        let d = parse("mechanism m { base R1 - R2 base;").unwrap_err();
        assert_eq!(d.span.unwrap().line_col("mechanism m { base R1 - R2 base;"), (1, 33));
    }
}
