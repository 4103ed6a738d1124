// Every error is reported, not only the first.
pkm::mechanism!(M, "mechanism m {
    capabilities fkk;
    planar;
    base R1* ∥ Q2 ∥ R3 ∥ R4 base;
    R1 ∥ R99;
}");

fn main() {}
