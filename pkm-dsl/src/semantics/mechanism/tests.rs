/// The messages of every error the text produces, in order.
fn check(source: &str, expected: &[&str]) {
    let messages: Vec<String> = match crate::topology::analysis::analyze_source(source) {
        Ok(_) => Vec::new(),
        Err(d) => d.0.into_iter().map(|e| e.message).collect(),
    };
    assert_eq!(messages, expected, "{source}");
}

const FOUR_BAR: &str = "base R1* ∥ R2 ∥ R3 ∥ R4 base;";

#[test]
fn only_axis_lines_meet_at_a_point() {
    let chain = "base R1* - R2 - P1 - R4 base;";
    check(
        "mechanism m { base R1* - R2 - R3 - R4 base; R1 ∧ R2 /\\ R3 ∧ R4; }",
        &[],
    );
    check(
        &format!("mechanism m {{ {chain} R1 ∧ P1; }}"),
        &["joint `P1` (P) has no axis line to meet others at a point"],
    );
    check(
        &format!("mechanism m {{ {chain} R1 ∧ x; }}"),
        &["only joint axes can meet at one point"],
    );
    check(
        &format!("mechanism m {{ {chain} R1 ∧ ◇xoy; }}"),
        &["a plane cannot meet other axes at one point"],
    );
    check(
        &format!("mechanism m {{ {chain} R1 ∥ R2; R1 ∧ R2; }}"),
        &["`R1 ∧ R2`: the other relations make these axes parallel, and parallel axes meet only as one line"],
    );
}

#[test]
fn planar_mechanisms_have_r_p_and_pa_only() {
    check(
        "mechanism m { planar; base R1* ∥ R2 - S1 - R4 base; }",
        &["joint `S1` (S) cannot move in a plane"],
    );
}

#[test]
fn coaxial_needs_an_axis_line() {
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} base P1 - R5 [k] - R6 base; R5 ≡ P1; }}"),
        &["joint `P1` (P) has no axis line to share"],
    );
}

#[test]
fn spherical_joints_have_no_axis() {
    check(
        "mechanism m { base S1* - P1 - S2 base; S1 ∥ P1; }",
        &["joint `S1` is spherical and has no axis to relate"],
    );
}

#[test]
fn branches_need_a_platform() {
    check(
        "mechanism m { planar; branch A { base R1* ∥ R2 ∥ R3 ∥ R4 base; } }",
        &["branches need a platform"],
    );
}

#[test]
fn platform_cannot_be_the_base() {
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} platform = base; }}"),
        &["the platform cannot be the base"],
    );
}

#[test]
fn base_point_must_be_on_a_platform_joint() {
    check(
        "mechanism m { planar; base R1* ∥ R2 ∥ R3 platform; base R4 ∥ R5 ∥ R6 platform; point o on R1; }",
        &["joint `R1` does not touch the platform"],
    );
    check(
        "mechanism m { planar; base R1* ∥ R2 ∥ R3 platform; base R4 ∥ R5 ∥ R6 platform; point o on R9; }",
        &["unknown joint `R9`"],
    );
}

#[test]
fn explicit_joint_declarations() {
    check("mechanism m { joint A = Q(base, 1); }", &["unknown joint type `Q`"]);
    check(
        "mechanism m { planar; joint A = R(1, 1)*; joint B = R(base, 1); joint C = R(1, base); }",
        &["joint `A` connects link `1` to itself"],
    );
    check(
        "mechanism m { joint G = P(1, 2, 3); }",
        &["a compound hinge needs an axis line; `P` has none"],
    );
}

#[test]
fn frame_axis_names_are_reserved() {
    check(
        "mechanism m { planar; base R1* [x] ∥ R2 ∥ R3 ∥ R4 base; }",
        &["`x` names a frame axis and cannot name a link"],
    );
}

#[test]
fn every_link_is_reached_from_the_base() {
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} joint A = R(7, 8); joint B = R(8, 7); }}"),
        &[
            "link `7` is not connected to the base",
            "link `8` is not connected to the base",
        ],
    );
}

#[test]
fn over_constrained_perpendicularity() {
    check(
        &format!("mechanism m {{ {FOUR_BAR} R1 ⊥ x; R1 ⊥ y; R1 ⊥ z; }}"),
        &["a direction is required to be perpendicular to three independent directions"],
    );
}

#[test]
fn actuators_must_match_the_dof() {
    check(
        "mechanism m { planar; base R1 ∥ R2 ∥ R3 ∥ R4 base; }",
        &["the mechanism has 1 DOF but 0 actuated joints"],
    );
    check(
        "mechanism m { planar; base R1* ∥ R2* ∥ R3 ∥ R4 base; }",
        &["the mechanism has 1 DOF but 2 actuated joints"],
    );
}

#[test]
fn actuators_that_cannot_drive_the_mechanism() {
    // F = 2 = I, but both inputs sit in the four-bar loop R1-R4 of a Watt
    // six-bar: that loop is over-driven and the other loop moves freely.
    check(
        "mechanism m { planar; base R1* ∥ R2* [c] ∥ R3 ∥ R4 base; c R5 ∥ R6 ∥ R7 ∥ R8 base; }",
        &["with its actuated joints locked the mechanism still moves (1 DOF): the actuators cannot drive it"],
    );
}

#[test]
fn planes_stand_for_their_normals() {
    // R1 ⊥ ◇xoz makes R1 ∥ y, which contradicts R1 ⊥ y.
    check(
        &format!("mechanism m {{ {FOUR_BAR} R1 ⊥ ◇xoz; R1 ⊥ y; }}"),
        &["`R1 ⊥ y` contradicts the other relations, which make them parallel"],
    );
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} P9 ∥ ◇xoy; }}"),
        &["unknown joint `P9`"],
    );
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} R3 ≡ ◇xoy; }}"),
        &["a plane cannot be coaxial with anything"],
    );
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} R3 ⊥ ◇xyz; }}"),
        &["unknown frame plane `◇xyz`"],
    );
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} R3 ∥ ◇(R1, R2); }}"),
        &["the plane ◇(R1,R2) is not defined: its axes are parallel"],
    );
    check("mechanism m { base R1* ∥ R2 ∥ R3 ∥ R4 base; x ∥ ◇(R1, y); }", &[]);
    check(
        &format!("mechanism m {{ planar; {FOUR_BAR} R1 ∥ R9; R2 ∥ R9; }}"),
        &["unknown joint `R9`"],
    );
}

#[test]
fn a_chain_visits_each_link_once() {
    check(
        "mechanism m { planar; base R1* [a] ∥ R2 [b] ∥ R3 [a] ∥ R4 base; }",
        &["link `a` appears twice in one chain"],
    );
    // Both are true: the label repeats the start, so R1 would join the base to itself.
    check(
        "mechanism m { planar; base R1* [base] ∥ R2 ∥ R3 base; }",
        &[
            "link `base` appears twice in one chain",
            "joint `R1` connects link `base` to itself",
        ],
    );
}

#[test]
fn capabilities_must_be_known() {
    check(
        &format!("mechanism m {{ capabilities fk, ik; planar; {FOUR_BAR} }}"),
        &[],
    );
    // What these need of the file is checked where code is generated
    // (codegen's `stiffness_needs_units_limbs_and_ik`).
    check(
        &format!("mechanism m {{ capabilities fk, dynamics, stiffness; planar; {FOUR_BAR} }}"),
        &[],
    );
    check(
        &format!("mechanism m {{ capabilities fk, workspace; planar; {FOUR_BAR} }}"),
        &[],
    );
    check(
        &format!("mechanism m {{ capabilities fkk; planar; {FOUR_BAR} }}"),
        &["unknown capability `fkk`"],
    );
}

#[test]
fn valid_descriptions_pass() {
    check(&format!("mechanism m {{ planar; {FOUR_BAR} }}"), &[]);
    check("mechanism m { planar; base R1* || R2 _|_ P1 - R3 base; x || P1; }", &[]);
}

/// A 6-UPS leg set, with `extra` written after the first leg.
fn ups(first_leg: &str, extra: &str) -> String {
    let legs: String = (2..=6)
        .map(|i| format!("branch L{i} {{ base U{i} - P{i}* - S{i} platform; }} "))
        .collect();
    format!("mechanism m {{ branch L1 {{ {first_leg} }} {legs} {extra} }}")
}

#[test]
fn u_joints_name_their_two_axes() {
    check(&ups("base U1 - P1* - S1 platform;", "U1.a ⊥ x; U1.b ∥ P2;"), &[]);
    check(
        &ups("base U1 - P1* - S1 platform;", "U1 ∥ x;"),
        &["U joint `U1` has two axes"],
    );
    check(
        &ups("base U1 - P1* - S1 platform;", "U1.c ∥ x;"),
        &["unknown joint `U1.c`"],
    );
    // The implied U1.a ⊥ U1.b, contradicted.
    check(
        &ups("base U1 - P1* - S1 platform;", "U1.a ∥ y; U1.b ∥ y;"),
        &["this relation makes `U1.a` parallel to `U1.b`, which must be perpendicular (implied by the frame, a U joint or `planar`)"],
    );
}

#[test]
fn u_joints_are_passive_and_spatial() {
    check(
        &ups("base U1* - P1* - S1 platform;", ""),
        &["U joint `U1` cannot be an input"],
    );
    check(
        "mechanism m { planar; base R1* ∥ R2 - U1 - R3 base; }",
        &["joint `U1` (U) cannot move in a plane"],
    );
    check(
        &ups("base U1 - P1* - S1 platform;", "joint U1 = U(base, platform);"),
        // Declared joints come first: the chain's U1 is the second, and left out.
        &[
            "joint `U1` is declared twice",
            "branch `L1` never reaches the platform `platform`",
        ],
    );
}

#[test]
fn a_chain_relates_the_u_axis_on_the_shared_link() {
    // base R1 [k] ∥ U1 [l] ⊥ P1: R1 and U1.a sit on k, U1.b and P1 on l.
    let ast = crate::parse("mechanism m { base R1* [k] ∥ U1 [l] ⊥ P1 [n] - S1 base; }").unwrap();
    let m = super::build(&ast).unwrap();
    let j = |n: &str| super::DirectionItem::Joint(m.joint_index(n).unwrap());
    let has = |kind, a, b| m.relations.iter().any(|r| r.kind == kind && r.a == a && r.b == b);
    use crate::syntax::ast::RelationKind::{Parallel, Perpendicular};
    assert!(has(Parallel, j("R1"), j("U1.a")));
    assert!(has(Perpendicular, j("U1.b"), j("P1")));
    assert!(has(Perpendicular, j("U1.a"), j("U1.b")));
    let u = m.universal("U1").unwrap();
    let names = |l: usize| m.links[l].name.as_str();
    assert_eq!(
        u.halves.map(|h| m.joints[h].links.map(names)),
        [["k", "U1.cross"], ["U1.cross", "l"]]
    );
    assert_eq!(
        m.joint_on("U1", m.links.iter().position(|x| x.name == "l").unwrap()),
        m.joint_index("U1.b")
    );
}

#[test]
fn parallel_sliders_in_series_leave_the_crank_locked() {
    // R1 ⊥ P1 ∥ P2 − R2: the links beside P1 ∥ P2 only translate along x
    // relative to each other, so both turn by the same angle about two
    // distinct axes, which closes the loop only at zero turn. The one
    // DOF (Σf 4 − ξ 3) is P1 and P2 sliding against each other; R1 never moves.
    check(
        "mechanism m { planar; base R1* _|_ P1 || P2 - R2 base; x || P1; }",
        &["with its actuated joints locked the mechanism still moves (1 DOF): the actuators cannot drive it"],
    );
}
