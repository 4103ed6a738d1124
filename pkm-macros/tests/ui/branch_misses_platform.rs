// Branch B returns to the base without reaching the platform.
pkm::mechanism!(M, "mechanism m {
    planar;
    branch A { base R1* ∥ R2 ∥ R3 platform; }
    branch B { base R4* ∥ R5 ∥ R6 base; }
    base R7* ∥ R8 ∥ R9 platform;
}");

fn main() {}
