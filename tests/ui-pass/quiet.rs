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
    // trybuild compiles this from target/tests/trybuild/pkm, so the path
    // (relative to that Cargo.toml) climbs back to the repository.
    file = "../../../../examples/mechanisms/seed000_a.pkm"
);

fn main() {
    assert_eq!(FourBar::DOF + MechanismA::DOF, 4);
}
