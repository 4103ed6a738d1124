// `Q1` names no joint type.
pkm::mechanism!(M, "mechanism m {
    planar;
    base R1* ∥ Q1 ∥ R3 ∥ R4 base;
}");

fn main() {}
