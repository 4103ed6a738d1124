//! Every mechanism the suite's tests call generated code of, declared once
//! (`pkm::mechanism!` expands to a few thousand lines each: declared in
//! every module that uses it, the suite compiled each of them up to seven
//! times). Each is declared from its file as it stands, so its
//! capabilities are the file's own; the test modules import the types they
//! use (`use crate::mechanisms::{SeedA, SeedAParams}`). A mechanism given
//! only inline, next to the test that explains it, stays there
//! (`consistency::FoldingFourBar`).

// Planar one-loop examples.
pkm::mechanism!(pub FourBar, file = "examples/mechanisms/four_bar.pkm");
pkm::mechanism!(pub SliderCrank, file = "examples/mechanisms/slider_crank.pkm");
pkm::mechanism!(pub Inverted, file = "examples/mechanisms/inverted_slider_crank.pkm");
pkm::mechanism!(pub Shaper, file = "examples/mechanisms/crank_shaper.pkm");
pkm::mechanism!(pub Cylinder, file = "examples/mechanisms/cylinder_rocker.pkm");
pkm::mechanism!(pub Yoke, file = "examples/mechanisms/scotch_yoke.pkm");
pkm::mechanism!(pub CouplerDriven, file = "examples/mechanisms/four_bar_coupler_driven.pkm");
pkm::mechanism!(pub Spherical, file = "examples/mechanisms/spherical_four_bar.pkm");
pkm::mechanism!(pub FiveBar, file = "examples/mechanisms/five_bar.pkm");
pkm::mechanism!(pub Watt, file = "examples/mechanisms/watt_six_bar.pkm");

// Planar two-DOF loops whose tool point is on a link, off its joints (the
// inverse turns that link about the point: `steps::locus::pin`).
pkm::mechanism!(pub FiveBarTool, file = "examples/mechanisms/five_bar_tool.pkm");
pkm::mechanism!(pub FiveBarSlide, file = "examples/mechanisms/five_bar_slide.pkm");
pkm::mechanism!(pub RrrrpTool, file = "examples/mechanisms/rrrrp_tool.pkm");
// Driven at a joint between two moving links, solved by sliding the two as
// one body onto a guide (`steps::beyond`).
pkm::mechanism!(pub Trammel, file = "examples/mechanisms/trammel.pkm");
// Driven at a joint between two moving links, solved by turning the two as
// one body until a line carried across the given joint passes a known point
// (`steps::guide`).
pkm::mechanism!(pub BlockDriven, file = "examples/mechanisms/inverted_slider_crank_block_driven.pkm");

// Planar parallel mechanisms and the κ = 1 examples (`fk_numeric`).
pkm::mechanism!(pub ThreeRrr, file = "examples/mechanisms/planar_3rrr.pkm");
pkm::mechanism!(pub ThreeRpr, file = "examples/mechanisms/planar_3rpr.pkm");
pkm::mechanism!(pub ThreeRprSix, file = "examples/mechanisms/planar_3rpr_six.pkm");
pkm::mechanism!(pub Stephenson3, file = "examples/mechanisms/stephenson3.pkm");
pkm::mechanism!(pub Tripteron, file = "examples/mechanisms/tripteron.pkm");

// Seed 000 (2T1R mechanisms A and B) and the five-bar 2T1R.
pkm::mechanism!(
    /// Seed 000's mechanism A, declared over several lines as a user may:
    /// clippy (`cargo clippy --all-targets` in CI) then sees its expansion
    /// at the name's line, not across the invocation's.
    pub SeedA,
    file = "examples/mechanisms/seed000_a.pkm"
);
pkm::mechanism!(pub SeedAU, file = "examples/mechanisms/seed000_a_u.pkm");
pkm::mechanism!(pub SeedB, file = "examples/mechanisms/seed000_b.pkm");
pkm::mechanism!(pub FiveBarPa, file = "examples/mechanisms/five_bar_pa.pkm");

// Seed 003: the punching eight-bar as declared for pkm and as in the paper.
pkm::mechanism!(pub Punch, file = "examples/mechanisms/seed003_punch.pkm");
pkm::mechanism!(pub PunchOriginal, file = "examples/mechanisms/seed003_punch_original.pkm");

// Spatial four-bars.
pkm::mechanism!(pub Rssr, file = "examples/mechanisms/rssr.pkm");
pkm::mechanism!(pub Rssp, file = "examples/mechanisms/rssp.pkm");
pkm::mechanism!(pub Rsur, file = "examples/mechanisms/rsur.pkm");

// Spatial parallel mechanisms: seed 004's 3-RPS and 3-SPR, and the others.
pkm::mechanism!(pub Rps, file = "examples/mechanisms/rps_3.pkm");
pkm::mechanism!(pub Spr, file = "examples/mechanisms/spr_3.pkm");
pkm::mechanism!(pub RpsTilt, file = "examples/mechanisms/rps_3_tilt.pkm");
pkm::mechanism!(pub Prs, file = "examples/mechanisms/prs_3.pkm");
pkm::mechanism!(pub Ups, file = "examples/mechanisms/ups_6.pkm");
pkm::mechanism!(pub Upu, file = "examples/mechanisms/upu_3.pkm");
pkm::mechanism!(pub Delta, file = "examples/mechanisms/delta_3ruu.pkm");
pkm::mechanism!(pub Orthoglide, file = "examples/mechanisms/orthoglide.pkm");

// Fixtures (tests/fixtures/: each file says what it adds to its example).
// A four-bar whose plan pins a point (the fixture says how).
pkm::mechanism!(pub FourBarOver, file = "tests/fixtures/four_bar_over.pkm");
pkm::mechanism!(pub SliderCrankDynamics, file = "tests/fixtures/slider_crank_dynamics.pkm");
pkm::mechanism!(pub FiveBarPaDynamics, file = "tests/fixtures/five_bar_pa_dynamics.pkm");
pkm::mechanism!(pub AgileEye, file = "tests/fixtures/agile_eye_ik.pkm");
pkm::mechanism!(pub ThreeRrrSix, file = "tests/fixtures/planar_3rrr_six.pkm");
pkm::mechanism!(pub RpsParameters, file = "tests/fixtures/rps_3_limb_parameters.pkm");
// Dietmaier's 6-UPS with 40 real assemblies (generated `fk_numeric`).
pkm::mechanism!(pub UpsDietmaier, file = "tests/fixtures/ups_6_dietmaier.pkm");
// Mobile by its special geometry only (`mobility by geometry`): the
// topology counted at its declared dimensions.
pkm::mechanism!(pub BennettDriven, file = "tests/fixtures/bennett_driven.pkm");
// Two links one body seen along an axis (a slide along the revolutes'
// axes): the cylinder about R4 across P3 (`steps::locus`, axial reaches).
pkm::mechanism!(pub Rrrp2t1r, file = "examples/mechanisms/rrrp_2t1r.pkm");
// A slide along the turning axis at the platform: the platform turned
// until the slide's line passes a known axis (`steps::aim_along`).
pkm::mechanism!(pub Schoenflies, file = "examples/mechanisms/schoenflies_2limb.pkm");
// The catalogue's (docs/catalogue.md) 3T: a platform that keeps its orientation.
pkm::mechanism!(pub Translational, file = "examples/mechanisms/translational_2limb.pkm");
// A spatial point output (the pointing direction on the sphere) pins its
// link: the sphere about the pin (`steps::locus::pin`).
pkm::mechanism!(pub SphericalFive, file = "examples/mechanisms/spherical_five_bar.pkm");
