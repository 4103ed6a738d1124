//! Generated code adds no warning, even under strict lints.
#![deny(warnings, missing_docs, unused, clippy::all)]

pkm::mechanism!(pub FourBar, "mechanism four_bar {
    capabilities fk, ik;
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R4 base;
}");

pkm::mechanism!(
    /// Seed 000's mechanism A.
    pub(crate) MechanismA,
    // trybuild compiles this from target/tests/trybuild/pkm-macros, so the path
    // (relative to that Cargo.toml) climbs back to the repository.
    file = "../../../../examples/mechanisms/seed000_a.pkm"
);

// Parameters become a struct and `fk` a solver; an upper-case name must not warn.
pkm::mechanism!(pub Crank, "mechanism crank {
    capabilities fk;
    planar;
    base R1* [c] ∥ R2 [r] ∥ R3 [s] ⊥ P1 base;
    parameters { L = 50; rod = 3 * L; }
    geometry {
        base { R1 = (0, 0); P1 = through (0, 0) along x; }
        c { R1 = (0, 0); R2 = (L, 0); }
        r { R2 = (0, 0); R3 = (rod, 0); }
        s { R3 = (0, 0); P1 = (0, 0); }
    }
}");

// Static stiffness: the wrench analysis and K from the limbs' twists.
pkm::mechanism!(
    /// Seed 004's 3-SPR, with its stiffness.
    pub Spr,
    file = "../../../../examples/mechanisms/spr_3.pkm"
);

// Hygiene: constants of the caller's module named like the mechanism's
// parameters (spr_3's `RB`, `RA`; the crank's `L`) are not taken for the
// generated code's locals, nor its locals for them.
#[allow(dead_code)]
const RB: f64 = 100.0;
#[allow(dead_code)]
const RA: f64 = 80.0;
#[allow(dead_code)]
const L: f64 = 1.0;

fn main() {
    assert_eq!(FourBar::DOF + MechanismA::DOF, 4);
    assert_eq!(CrankParams::default(), CrankParams { L: 50.0, rod: 150.0 });
    assert_eq!(Crank::PARAMETERS.len(), 2);
    let branches = Crank::fk(&CrankParams::default(), &[0.5]);
    assert!(branches.iter().all(|b| b.result.is_ok()));
    let home = Spr::ik(&SprParams::default(), &[75.0, 0.0, 0.0]);
    let solved = home.iter().filter(|b| b.result.is_ok()).count();
    let stiff = home
        .iter()
        .filter(|b| Spr::stiffness(&SprParams::default(), &[75.0, 0.0, 0.0], b.signs).is_ok())
        .count();
    assert!(solved > 0 && stiff == solved);
}
