//! The planner, text in and plan out: small mechanisms declared inline,
//! each with its forward and inverse plans as [`Plan::display`] writes them
//! (rust-analyzer's `check(input, expect![[…]])`; `UPDATE_EXPECT=1`
//! rewrites the expectations, which are then read against the joints:
//! every expectation below was). A plan's line is its step kind, the joint
//! it solves, the link it places from which, what it meets, and its ±
//! choice.
//!
//! [`Plan::display`]: pkm_runtime::plan::Plan::display

use expect_test::{expect, Expect};

/// The forward and inverse plans of `source`, or why there is none.
fn check(source: &str, want: Expect) {
    let c = crate::compile(source).unwrap_or_else(|d| panic!("{}", d.render(source, "test.pkm")));
    let model = c.model().unwrap();
    let mut out = String::new();
    for (direction, plan) in [("forward", c.forward()), ("inverse", c.inverse())] {
        match plan {
            Ok(plan) => out += &plan.display(model).to_string(),
            Err(d) => out += &format!("no {direction} plan: {}\n", d.0[0].message),
        }
    }
    want.assert_eq(&out);
}

/// A crank-rocker: forward, the crank given, the coupler's far end on the
/// circle about the rocker's pivot (± the two assemblies), the coupler
/// turned onto it; inverse from the rocker angle, the same dyad mirrored.
#[test]
fn four_bar_by_its_crank_and_by_its_rocker() {
    check(
        "mechanism four_bar { planar; base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
           geometry { base { R1 = (0, 0); R4 = (300, 0); } crank { R1 = (0, 0); R2 = (100, 0); }
                      coupler { R2 = (0, 0); R3 = (250, 0); } rocker { R3 = (200, 0); R4 = (0, 0); } }
           outputs { psi = joint R4; } }",
        expect![[r#"
            forward plan: given R1; 1 ± choice, 2 branches
              0 Transfer     R1 places crank from base: given 0
              1 Locus        R2 places coupler from crank: R3 on the cylinder about R4 of base, carried to rocker, ± choice 0
              2 Aim          R4 places rocker from base: R3 onto R3 of coupler
              check R3, by the miss of step 2
            inverse plan: given R4; 1 ± choice, 2 branches
              0 Transfer     R4 places rocker from base: given 0
              1 Locus        R1 places crank from base: R2 on the cylinder about R3 of rocker, carried to coupler, ± choice 0
              2 Aim          R2 places coupler from crank: R3 onto R3 of rocker
              check R3, by the miss of step 2, its turns skipped where only the results are solved
        "#]],
    );
}

/// An RPR dyad (inverted slider-crank): forward, the block turns about
/// the crank pin until its guide (P1's line) passes the rocker's pivot R3,
/// two roots (the guide's two senses), and the slide carries the rocker's
/// R3 onto the pivot; inverse, from the rocker's angle, the block's pin
/// slides along the guide to the crank's circle.
#[test]
fn inverted_slider_crank_turns_its_guide_through_the_pin() {
    check(
        "mechanism isc { planar; base R1* [crank] ∥ R2 [block] ⊥ P1 [rocker] ⊥ R3 base;
           geometry { base { R1 = (0, 0); R3 = (120, 0); } crank { R1 = (0, 0); R2 = (50, 0); }
                      block { R2 = (0, 0); P1 = (0, 0); }
                      rocker { P1 = through (0, 0) along x; R3 = (0, 0); } }
           outputs { psi = joint R3; } }",
        expect![[r#"
            forward plan: given R1; 1 ± choice, 2 branches
              0 Transfer     R1 places crank from base: given 0
              1 Guide        R2 places block from crank: the line of P1 through R3 of base, ± choice 0
              2 Aim          P1 places rocker from block: R3 onto R3 of base
              check R3, by the miss of step 2
            inverse plan: given R3; 1 ± choice, 2 branches
              0 Transfer     R3 places rocker from base: given 0
              1 Locus        P1 places block from rocker: R2 on the cylinder about R1 of base, carried to crank, ± choice 0
              2 Aim          R1 places crank from base: R2 onto R2 of block
              check R2, by the miss of step 2
        "#]],
    );
}

/// A slider-crank driven at its slider: the crank's pin on the circle
/// about the rod's far end (two assemblies), the rod turned onto it.
#[test]
fn slider_crank_driven_at_the_slider() {
    check(
        "mechanism sc { planar; base R1 [crank] ∥ R2 [rod] ∥ R3 [slider] ⊥ P1* base;
           geometry { base { R1 = (0, 0); P1 = through (0, 0) along x; } crank { R1 = (0, 0); R2 = (50, 0); }
                      rod { R2 = (0, 0); R3 = (200, 0); } slider { R3 = (0, 0); P1 = (0, 0); } }
           outputs { theta = joint R1; } }",
        expect![[r#"
            forward plan: given P1; 1 ± choice, 2 branches
              0 Transfer     P1 places slider from base: given 0
              1 Locus        R1 places crank from base: R2 on the cylinder about R3 of slider, carried to rod, ± choice 0
              2 Aim          R2 places rod from crank: R3 onto R3 of slider
              check R3, by the miss of step 2, its turns skipped where only the results are solved
            inverse plan: given R1; 1 ± choice, 2 branches
              0 Transfer     R1 places crank from base: given 0
              1 Locus        P1 places slider from base: R3 on the cylinder about R2 of crank, carried to rod, ± choice 0
              2 Aim          R2 places rod from crank: R3 onto R3 of slider
              check R3, by the miss of step 2, its turns skipped where only the results are solved
        "#]],
    );
}

/// A spatial RSSR: the rocker's ball on the sphere about the crank's
/// (the coupler's length), two roots; the coupler's spin about its own
/// line is idle.
#[test]
fn rssr_meets_a_sphere() {
    check(
        "mechanism rssr { base R1* [crank] - S1 [coupler] - S2 [rocker] - R2 base;
           geometry { base { R1 = (0, 0, 0) along z; R2 = (100, 40, 60) along x; }
                      crank { R1 = (0, 0, 0) along z; S1 = (40, 0, 0); }
                      coupler { S1 = (0, 0, 0); S2 = (160, 0, 0); }
                      rocker { R2 = (0, 0, 0) along x; S2 = (0, 120, 0); } }
           outputs { psi = joint R2; } }",
        expect![[r#"
            forward plan: given R1; 1 ± choice, 2 branches
              0 Transfer     R1 places crank from base: given 0
              1 Locus        R2 places rocker from base: S2 on the sphere about S1 of crank of radius S1–S2 on coupler, ± choice 0
              2 Rod          S1 places coupler from crank: S2 at S2 of rocker, its spin by convention
              check S2
            inverse plan: given R2; 1 ± choice, 2 branches
              0 Transfer     R2 places rocker from base: given 0
              1 Locus        R1 places crank from base: S1 on the sphere about S2 of rocker of radius S2–S1 on coupler, ± choice 0
              2 Rod          S1 places coupler from crank: S2 at S2 of rocker, its spin by convention
              check S2
        "#]],
    );
}

/// A planar 3-RRR driven at its three base joints is coupled (κ = 1): the
/// planner refuses a closed-form forward plan by κ; its inverse, from the
/// platform's pose, places the platform and then solves three dyads, one
/// ± choice each.
#[test]
fn planar_3rrr_has_an_inverse_plan_only() {
    check(
        "mechanism p3rrr { planar;
           branch A { base R1* [a1] ∥ R2 [a2] ∥ R3 platform; }
           branch B { base R4* [b1] ∥ R5 [b2] ∥ R6 platform; }
           branch C { base R7* [c1] ∥ R8 [c2] ∥ R9 platform; }
           geometry { base { R1 = (0, 0); R4 = (400, 0); R7 = (200, 346); }
                      a1 { R1 = (0, 0); R2 = (150, 0); } a2 { R2 = (0, 0); R3 = (150, 0); }
                      b1 { R4 = (0, 0); R5 = (150, 0); } b2 { R5 = (0, 0); R6 = (150, 0); }
                      c1 { R7 = (0, 0); R8 = (150, 0); } c2 { R8 = (0, 0); R9 = (150, 0); }
                      platform { R3 = (0, 0); R6 = (80, 0); R9 = (40, 69); point O = (40, 23); } }
           outputs { x, y, phi = pose of platform at O; } }",
        expect![[r#"
            no forward plan: a closed-form forward plan needs κ = 0 (κ = 1)
            inverse plan: given x, y of platform at O and its angle about z; 3 ± choices, 8 branches
              0 Place        places platform: O at given 0, turned about z
              1 Locus        R1 places a1 from base: R2 on the cylinder about R3 of platform, carried to a2, ± choice 0
              2 Aim          R3 places a2 from platform: R2 onto R2 of a1
              3 Locus        R4 places b1 from base: R5 on the cylinder about R6 of platform, carried to b2, ± choice 1
              4 Aim          R6 places b2 from platform: R5 onto R5 of b1
              5 Locus        R7 places c1 from base: R8 on the cylinder about R9 of platform, carried to c2, ± choice 2
              6 Aim          R9 places c2 from platform: R8 onto R8 of c1
              check R2, by the miss of step 2, its turns skipped where only the results are solved
              check R5, by the miss of step 4, its turns skipped where only the results are solved
              check R8, by the miss of step 6, its turns skipped where only the results are solved
        "#]],
    );
}

/// A spherical five-bar given its passive angles R2 and R4: every axis
/// passes through the centre, so R2's point keeps its distance from R3's
/// (the centre) at every turn of R1, and the sphere about that centre is
/// no equation for R1 (it was the plan's first step, which then refused
/// every input at run time as degenerate). The planner refuses at compile
/// time instead; forward, the cone step as before. The pointing point
/// given instead, the inverse plan pins the distal link there.
#[test]
fn a_sphere_about_the_turning_axis_is_no_locus() {
    let five_bar = |outputs: &str| {
        format!(
            "mechanism sfb {{ base R1* [left] - R2 [ld] - R3 [rd] - R4 [right] - R5* base;
               R1 ∧ R2 ∧ R3 ∧ R4 ∧ R5;
               geometry {{ base {{ R1 = (-50, 0, 86.6025403784) along (-0.5, 0, 0.8660254038);
                                  R5 = (50, 0, 86.6025403784) along (0.5, 0, 0.8660254038); }}
                          left {{ R1 = (0, 0, 100) along z; R2 = (70.7106781187, 0, 70.7106781187) along (1, 0, 1); }}
                          ld {{ R2 = (0, 0, 100) along z; R3 = (0, 0, 0) along (0.8660254038, 0, 0.5);
                                point P = (86.6025403784, 0, 50); }}
                          rd {{ R4 = (0, 0, 100) along z; R3 = (0, 0, 0) along (0.8660254038, 0, 0.5); }}
                          right {{ R5 = (0, 0, 100) along z; R4 = (70.7106781187, 0, 70.7106781187) along (1, 0, 1); }} }}
               outputs {{ {outputs} }} }}"
        )
    };
    check(
        &five_bar("b2 = joint R2; b4 = joint R4;"),
        expect![[r#"
            forward plan: given R1, R5; 1 ± choice, 2 branches
              0 Transfer     R1 places left from base: given 0
              1 Transfer     R5 places right from base: given 1
              2 Cone         R2 places ld from left: the axis of R3 at its angle from the axis of R4 of right, ± choice 0
              3 Aim          R3 places rd from ld: R4 onto R4 of right
              check R4
            no inverse plan: no closed-form inverse plan: links left, ld, rd, right are not reached by the step catalogue (aim, align, parallelogram plane, circle or line against sphere, plane, cylinder or pin, guide through a point, point beyond a given joint, slide onto a line, axes through one centre, a link between known spherical centres, a plane through a point, two turns about meeting axes)
        "#]],
    );
    check(
        &five_bar("x, y, z = point P of ld;"),
        expect![[r#"
            forward plan: given R1, R5; 1 ± choice, 2 branches
              0 Transfer     R1 places left from base: given 0
              1 Transfer     R5 places right from base: given 1
              2 Cone         R2 places ld from left: the axis of R3 at its angle from the axis of R4 of right, ± choice 0
              3 Aim          R3 places rd from ld: R4 onto R4 of right
              check R4
            inverse plan: given x, y, z of ld at P; 2 ± choices, 4 branches
              0 Place        places ld: P at given 0, pinned, turned by a later step
              1 Locus        R1 places left from base: R2 on the sphere about ld's pin P, carried to ld, ± choice 0
              2 Aim          R2 places ld from left: P onto P of ld
              3 Locus        R3 places rd from ld: R4 on the plane through R4 known from base through R5, R4 normal to the axis of R5 known from base through R5, ± choice 1
              4 Aim          R5 places right from base: R4 onto R4 of rd
              check R4
              check the point step 0 pinned
        "#]],
    );
}
