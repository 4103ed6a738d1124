// A missing relation between two joints of a chain.
pkm::mechanism!(M, "mechanism m {
    planar;
    base R1* ∥ R2 R3 ∥ R4 base;
}");

fn main() {}
