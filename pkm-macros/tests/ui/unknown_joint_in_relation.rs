// A relation names a joint that is not declared.
pkm::mechanism!(M, "mechanism m {
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R4 base;
    R2 ∥ R22;
}");

fn main() {}
