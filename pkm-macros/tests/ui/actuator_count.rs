// A five-bar has two DOF but only one joint is actuated.
pkm::mechanism!(M, "mechanism five_bar {
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R4 ∥ R5 base;
}");

fn main() {}
