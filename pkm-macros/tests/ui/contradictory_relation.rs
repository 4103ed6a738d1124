// R1 ∥ R2 ∥ R3 along the chain, then R3 is declared perpendicular to R1.
pkm::mechanism!(M, "mechanism m {
    base R1* ∥ R2 ∥ R3 - R4 base;
    R1 ⊥ R3;
}");

fn main() {}
