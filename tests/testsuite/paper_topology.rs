//! Issue 2 acceptance: the topology of every example mechanism against the
//! numbers the seed papers print (seed 000 §1.2–1.4, seed 003 §1) and hand
//! counts for the textbook mechanisms (four-bar, slider-crank, 5R five-bar,
//! 3-RRR, 3-RPS, 3-SPR, whose ξ, Δ and κ follow from Σf and the loop type).

use crate::common;
use crate::mechanisms::{PunchOriginal, SeedA};

use pkm::dsl::{analyze_source, Analysis};

fn analysis(file: &str) -> Analysis {
    let (text, path) = common::example_text(file);
    analyze_source(&text).unwrap_or_else(|e| panic!("{}", e.render(&text, &path)))
}

/// One row of the acceptance table.
fn check(file: &str, dof: usize, xi: &[usize], delta: &[i32], kappa: usize, skcs: usize) {
    let a = analysis(file);
    let t = &a.topology;
    assert_eq!(
        (t.dof, t.xi(), t.delta(), t.kappa, t.skcs.len()),
        (dof, xi.to_vec(), delta.to_vec(), kappa, skcs),
        "{file}: (F, ξ, Δ, κ, SKCs)"
    );
    // The independent computation agrees (the analysis refuses to finish otherwise).
    assert_eq!(t.xi_by_poc_formula, t.xi(), "{file}: POC formula vs loop-closure rank");
    // F = Σf − Σξ, and the Δ of a fully actuated mechanism sum to zero.
    assert_eq!(t.dof, t.total_f - xi.iter().sum::<usize>());
    assert_eq!(delta.iter().sum::<i32>(), 0);
}

#[test]
fn seed000_mechanisms_a_and_b() {
    // Seed 000 §1.2–1.3: ξ_L1 = 3 (five-bar), ξ_L2 = 5, F = 11 − 3 − 5 = 3, Δ = (5−2−3, 6−1−5).
    check("seed000_a", 3, &[3, 5], &[0, 0], 0, 2);
    check("seed000_b", 3, &[3, 5], &[0, 0], 0, 2);
}

#[test]
fn seed003_punching_eight_bar() {
    // Seed 003 §1.1: loops 4−1−3 = 0, 4−0−3 = +1, 2−0−3 = −1; SKC₂¹(1, −1), κ = 1.
    check("seed003_punch_original", 1, &[3, 3, 3], &[0, 1, -1], 1, 2);
    // Seed 003 §1.2: after merging D and E, three loops of Δ = 0 and three SKCs.
    check("seed003_punch", 1, &[3, 3, 3], &[0, 0, 0], 0, 3);
}

#[test]
fn textbook_planar_mechanisms() {
    // One planar loop: ξ = 3; Σf = 4 (or 5) with 1 (or 2) inputs gives Δ = 0.
    check("four_bar", 1, &[3], &[0], 0, 1);
    check("slider_crank", 1, &[3], &[0], 0, 1);
    check("five_bar", 2, &[3], &[0], 0, 1);
    // 3-RRR: SOC₁ two legs (6 − 2 − 3 = +1), SOC₂ the third (3 − 1 − 3 = −1).
    check("planar_3rrr", 3, &[3, 3], &[1, -1], 1, 1);
}

#[test]
fn spatial_three_leg_mechanisms() {
    // Σf = 15, two spatial loops of ξ = 6: Δ = (10 − 2 − 6, 5 − 1 − 6) = (+2, −2).
    check("rps_3", 3, &[6, 6], &[2, -2], 2, 1);
    check("spr_3", 3, &[6, 6], &[2, -2], 2, 1);
}

#[test]
fn spherical_mechanisms() {
    // Spherical four-bar: four revolutes through one centre, a spherical
    // loop of ξ = dim r³ = 3; F = 4 − 3 = 1, Δ = 4 − 1 − 3 = 0, κ = 0.
    check("spherical_four_bar", 1, &[3], &[0], 0, 1);
    // Agile eye (3-RRR spherical): Σf = 9, v = 9 − 8 + 1 = 2. SOC₁ two limbs,
    // ξ = dim(M_A ∪ M_B) = dim r³ = 3, Δ = 6 − 2 − 3 = +1; SOC₂ the third,
    // ξ = dim((M_A ∩ M_B) ∪ M_C) = dim r³ = 3, Δ = 3 − 1 − 3 = −1;
    // F = 9 − 6 = 3, one SKC with κ = ½(1 + 1) = 1 (the 3-RRR's planar twin
    // has the same numbers, with t²r¹ for r³).
    check("agile_eye", 3, &[3, 3], &[1, -1], 1, 1);
    // Each limb R∧R∧R: [t⁰; r³] at the centre; M_Pa = ∩ M_bi = [t⁰; r³].
    let a = analysis("agile_eye");
    assert_eq!(a.platform_poc(), "[t⁰; r³]");
    for b in &a.topology.branch_poc {
        assert_eq!(b.unicode(), "[t⁰; r³]");
    }
    // Written out, the SOCs show the relation.
    assert_eq!(a.topology.socs[1].notation.matches('∧').count(), 2);
}

#[test]
fn poc_sets_of_seed000() {
    let a = analysis("seed000_a");
    // Seed 000 §1.1.2: M_Pa1 = M1 ∩ M3 = [t²(∥◇xoz); r¹(∥R6)].
    assert_eq!(a.platform_poc(), "[t²(∥◇xoz); r¹(∥R6)]");
    // Eq. (3): branch I ends in t²(⊥R12) = t²(∥◇xoz) (R12 ∥ y) and r² over R12 (∥ R3) and R4.
    assert_eq!(a.topology.branch_poc[0].unicode(), "[t²(∥◇xoz); r²(∥◇(R3,R4))]");
    // M3 = [t³; r¹(∥R6)]. The paper prints M3's result as `t³ r²(…)` once but uses
    // [t³; r¹(∥R6)] everywhere after (the typo the issue names); arithmetic gives r¹.
    assert_eq!(a.topology.branch_poc[1].unicode(), "[t³; r¹(∥R6)]");

    let b = analysis("seed000_b");
    assert_eq!(b.platform_poc(), "[t²(∥◇xoz); r¹(∥R6)]");
    // Eq. (4): M2 = [t³; r²(∥◇(R12, R5))]; M4 = [t²; r¹(∥R6)] with t² in xoz.
    assert_eq!(b.topology.branch_poc[0].kind(), "3T2R");
    assert_eq!(b.topology.branch_poc[1].unicode(), "[t²(∥◇xoz); r¹(∥R6)]");
}

#[test]
fn topological_expressions_of_seed000() {
    // Seed 000 eqs. (9) and (10), field by field.
    assert_eq!(
        analysis("seed000_a").topology.expression,
        "²ᵀ¹ᴿPM⁰[3, 2(5, 6)] = ²ᵀ²ᴿSKC₁⁰[0; 3] + ³ᵀ¹ᴿSKC₂⁰[0; 5] = 3−J_in + BKC₁⁰(0; 3) + BKC₂⁰(0; 5)"
    );
    assert_eq!(
        analysis("seed000_b").topology.expression,
        "²ᵀ¹ᴿPM⁰[3, 2(5, 6)] = ³ᵀ²ᴿSKC₁⁰[0; 3] + ²ᵀ¹ᴿSKC₂⁰[0; 5] = 3−J_in + BKC₁⁰(0; 3) + BKC₂⁰(0; 5)"
    );
}

fn decoupling(a: &Analysis) -> Vec<(String, Vec<String>)> {
    a.topology
        .decoupling
        .iter()
        .map(|d| (d.output.clone(), a.names(&d.inputs)))
        .collect()
}

fn outputs(rows: &[(&str, &[&str])]) -> Vec<(String, Vec<String>)> {
    rows.iter()
        .map(|(o, i)| (o.to_string(), i.iter().map(|s| s.to_string()).collect()))
        .collect()
}

#[test]
fn motion_decoupling_of_seed000() {
    // Seed 000 §1.4: A's x and z depend on P1, P2 only, its angle (about x) on all three.
    assert_eq!(
        decoupling(&analysis("seed000_a")),
        outputs(&[("x", &["P1", "P2"]), ("z", &["P1", "P2"]), ("rx", &["P1", "P2", "P3"])])
    );
    // B's x depends on P1, P2 only; z and the angle on all three.
    assert_eq!(
        decoupling(&analysis("seed000_b")),
        outputs(&[
            ("x", &["P1", "P2"]),
            ("z", &["P1", "P2", "P3"]),
            ("rx", &["P1", "P2", "P3"])
        ])
    );
}

#[test]
fn parasitic_motions_of_the_3_rps() {
    // Lee & Shah (1988): a 3-RPS platform has three
    // independent motions, z and the tilts rx, ry; x, y and rz follow them
    // (parasitic). The file declares `pose (z, rx, ry)`, and the POC set
    // has dim 3: the other three are printed as parasitic, not as outputs.
    let a = analysis("rps_3");
    assert_eq!(a.topology.platform_poc.as_ref().map(|p| p.dim), Some(3));
    let d = &a.topology.decoupling;
    let independent: Vec<&str> = d.iter().filter(|d| !d.parasitic).map(|d| d.output.as_str()).collect();
    let parasitic: Vec<&str> = d.iter().filter(|d| d.parasitic).map(|d| d.output.as_str()).collect();
    assert_eq!((independent, parasitic), (vec!["z", "rx", "ry"], vec!["x", "y", "rz"]));
    assert!(a
        .report()
        .contains("parasitic motions (the POC set has dim 3: they follow z, rx, ry"));
    // Seed 000's A: as many outputs move as its POC set has dimensions, none parasitic.
    assert!(analysis("seed000_a").topology.decoupling.iter().all(|d| !d.parasitic));
}

#[test]
fn identical_branches_read_the_same() {
    // The three R-P-S limbs of a 3-RPS are one limb turned 120°. Each
    // alone moves its S centre in the plane normal to its R (the leg's
    // plane): [t²(⊥R); r³], dim 5 (Σf of R, P, S). At o on S1 the other
    // two limbs' rotations about their own centres add a derived
    // translation at o, [t³; r³] with the same dim 5; the printout gives
    // both, so that the three limbs read the same at their own centres.
    let a = analysis("rps_3");
    let t = &a.topology;
    let at_o: Vec<String> = t.branch_poc.iter().map(|p| p.unicode()).collect();
    assert_eq!(at_o, ["[t²(⊥R1); r³]", "[t³; r³]", "[t³; r³]"]);
    let own: Vec<Option<(String, String)>> = t
        .branch_own_poc
        .iter()
        .map(|o| {
            o.as_ref()
                .map(|(j, p)| (a.mechanism.joints[*j].name.clone(), p.unicode()))
        })
        .collect();
    assert_eq!(
        own,
        [
            None,
            Some(("S2".to_string(), "[t²(⊥R2); r³]".to_string())),
            Some(("S3".to_string(), "[t²(⊥R3); r³]".to_string()))
        ]
    );
    assert!(t.branch_poc.iter().all(|p| p.dim == 5));
    assert!(a.report().contains("[t²(⊥R2); r³] at its own S2"));
    // Seed 000's branch II stays at o as the paper prints it (§1.2): at its
    // own R6 it is the same set, so nothing more is printed.
    assert_eq!(analysis("seed000_a").topology.branch_own_poc, [None, None]);
}

#[test]
fn planar_output_link_poc() {
    // A 5R five-bar without a platform, its output the point R3 of
    // right_distal: that link's POC set at R3 is printed as the platform's
    // would be. R3 moves over the plane (t² ∥ xoy) and the link turns
    // about axes ∥ R4 (all parallel, along z); the motion has dim F = 2,
    // the rotation a function of the translation.
    let a = analysis("five_bar");
    let t = &a.topology;
    assert_eq!(
        t.platform_poc.as_ref().map(|p| (p.unicode(), p.dim)),
        Some(("[t²(∥◇xoy); r¹(∥R4)]".to_string(), 2))
    );
    assert_eq!(t.base_point.map(|j| a.mechanism.joints[j].name.as_str()), Some("R3"));
    assert!(a
        .report()
        .contains("output link right_distal  M = [t²(∥◇xoy); r¹(∥R4)]  (dim 2, o on R3)"));
    assert!(a.report().contains("only 2 of these 3 are independent"));
    // A mechanism whose outputs are joint values has no output link.
    assert!(analysis("four_bar").topology.platform_poc.is_none());
}

#[test]
fn more_actuators_than_dof_points_at_the_branches() {
    // Seed 000's A without R4 ∥ R6 (only R5 ∥ R6 kept): branch I turns
    // about the plane of R3 and R4, branch II about R6, which generically
    // lies outside that plane, so the platform keeps no rotation: F = 11 −
    // 9 = 2 (by hand: ξ_L2 = 6 once the loop's rotations are independent)
    // for three actuated slides. The refusal names the lost rotation and
    // the branches' axes that need a relation.
    let (text, path) = common::example_text("seed000_a");
    let edited = text.replace("    R4 ∥ R5 ∥ R6;", "    R5 ∥ R6;");
    assert_ne!(edited, text);
    let e = analyze_source(&edited).expect_err("F = 2 with three actuators");
    let d = &e.0[0];
    assert_eq!(
        d.message,
        "the mechanism has 2 DOF but 3 actuated joints",
        "{}",
        e.render(&edited, &path)
    );
    let notes = d.notes.join("\n");
    assert!(notes.contains("F = Σf − Σξ_L = 11 − 9 = 2"), "{notes}");
    assert!(notes.contains("M_Pa = [t²(∥◇xoz); r⁰] (dim 2, o on R4)"), "{notes}");
    assert!(
        notes.contains("each branch has at least r¹ but together they keep r⁰: I r²(∥◇(R3,R4)), II r¹(∥R6)"),
        "{notes}"
    );
}

#[test]
fn the_order_of_socs_matters() {
    // poc.md: for A, SOC₁ = P1R11R12R3R4R6·Pa·R5P3, SOC₂ = R13P2 gives Δ = (2, −2), κ = 2.
    let a = analysis("seed000_a");
    let poor = pkm::dsl::topology::evaluate_order(
        &a.mechanism,
        &[
            &["P1", "R11", "R12", "R3", "R4", "R6", "Pa", "R5", "P3"],
            &["R13", "P2"],
        ],
    )
    .unwrap();
    assert_eq!(poor, vec![(5, 2), (3, -2)]);
    // The paper's order is the one chosen: SOC₁ is the five-bar.
    assert_eq!(a.topology.socs[0].notation, "P1⊥R11∥R12∥R13⊥P2");
    assert_eq!(a.topology.socs[1].notation, "R3⊥R4∥R6⊥Pa⊥R5∥P3");
}

#[test]
fn seed000_b_second_loop_is_l2() {
    // The paper labels B's second loop ξ_L3 and writes F = Σf − Σ_{j=1}^{3} ξ_Lj; with
    // v = m − n + 1 = 11 − 10 + 1 = 2 loops it is ξ_L2, and the sum is 3 + 5 = 8.
    let b = analysis("seed000_b");
    assert_eq!(b.topology.loops, 2);
    assert_eq!(b.topology.xi(), vec![3, 5]);
    assert_eq!(b.topology.total_f - 3 - 5, 3);
}

#[test]
fn seed003_skcs_are_the_papers_loops() {
    let a = analysis("seed003_punch");
    let socs: Vec<Vec<String>> = a.topology.socs.iter().map(|s| a.names(&s.joints)).collect();
    // Loops ABCP1, DGH and GFP2; G is the compound hinge of links 4, 5, 7 (joints G and G.2).
    assert_eq!(
        socs,
        vec![vec!["A", "B", "C", "P1"], vec!["D", "G", "H"], vec!["G.2", "F", "P2"]]
    );
    let o = analysis("seed003_punch_original");
    let socs: Vec<Vec<String>> = o.topology.socs.iter().map(|s| o.names(&s.joints)).collect();
    assert_eq!(
        socs,
        vec![vec!["A", "B", "C", "P1"], vec!["D", "E", "F", "P2"], vec!["G", "H"]]
    );
}

// The generated type carries the same numbers.

#[test]
fn generated_consts() {
    assert_eq!((SeedA::DOF, SeedA::KAPPA, SeedA::SKC_COUNT), (3, 0, 2));
    assert_eq!((SeedA::XI, SeedA::DELTA), (&[3usize, 5][..], &[0i32, 0][..]));
    assert_eq!(SeedA::REPORT.decoupling[0], ("x", &["P1", "P2"][..]));
    assert_eq!(SeedA::REPORT.to_string(), analysis("seed000_a").report());
    // κ = 1 with only `ik` requested compiles.
    assert_eq!((PunchOriginal::KAPPA, PunchOriginal::DELTA), (1, &[0, 1, -1][..]));
    assert_eq!(PunchOriginal::REPORT.skcs[1].socs, &[1, 2]);
    assert_eq!(PunchOriginal::PLATFORM_POC, None);
}

/// The counts of a mechanism with U joints as the POC literature writes
/// them (each U one joint of f = 2): n links, m joints, v = m − n + 1 loops,
/// Σf; and the platform's POC set.
fn check_universal(file: &str, n: usize, m: usize, v: usize, total_f: usize, platform: &str) {
    let a = analysis(file);
    let (mech, t) = (&a.mechanism, &a.topology);
    let u = mech.universals.len();
    assert_eq!(
        (mech.links.len() - u, mech.joints.len() - u, t.loops, t.total_f),
        (n, m, v, total_f),
        "{file}: (n, m, v, Σf)"
    );
    assert_eq!(a.platform_poc(), platform, "{file}");
}

#[test]
fn translational_3_upu() {
    // Per leg U-P-U: f = 2 + 1 + 2 = 5, Σf = 15; n = 2 + 3·2 = 8 links,
    // m = 9 joints, v = 9 − 8 + 1 = 2. A leg turns its end about U.a and
    // U.b only (the platform U's axes are parallel to the base U's), so
    // M_b = [t³; r²(∥◇(U.a, U.b))], a different plane per leg. SOC₁ (legs
    // A, B): ξ_L1 = dim(M_A ∪ M_B) = dim [t³; r³] = 6, Δ₁ = 10 − 2 − 6 = +2;
    // SOC₂ (leg C): M_A ∩ M_B = [t³; r¹] (two planes meet in a line), its
    // union with M_C is [t³; r³], ξ_L2 = 6, Δ₂ = 5 − 1 − 6 = −2. F = 15 − 12 = 3,
    // one SKC of κ = 2; the platform: three planes share no direction, [t³; r⁰].
    check("upu_3", 3, &[6, 6], &[2, -2], 2, 1);
    check_universal("upu_3", 8, 9, 2, 15, "[t³; r⁰]");
    let a = analysis("upu_3");
    assert_eq!(a.topology.branch_poc[0].unicode(), "[t³; r²(∥◇(U12.a,U12.b))]");
}

#[test]
fn stewart_6_ups() {
    // Per leg U-P-S: f = 2 + 1 + 3 = 6, M_b = [t³; r³]; Σf = 36; n = 2 + 6·2 = 14,
    // m = 18, v = 5. SOC₁ (two legs): ξ = 6, Δ₁ = 12 − 2 − 6 = +4; each further
    // leg: ξ = 6, Δ = 6 − 1 − 6 = −1. F = 36 − 5·6 = 6, one SKC of κ = 4, [t³; r³].
    check("ups_6", 6, &[6, 6, 6, 6, 6], &[4, -1, -1, -1, -1], 4, 1);
    check_universal("ups_6", 14, 18, 5, 36, "[t³; r³]");
}
