// `fkk` is not a capability.
pkm::mechanism!(M, "mechanism m {
    capabilities fkk;
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R4 base;
}");

fn main() {}
