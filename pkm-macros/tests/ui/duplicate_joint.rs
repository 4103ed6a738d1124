// R2 is declared twice.
pkm::mechanism!(M, "mechanism m {
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R2 base;
}");

fn main() {}
