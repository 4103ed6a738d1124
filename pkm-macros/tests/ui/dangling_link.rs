// `platfrom` is a typo: the link hangs on one joint.
pkm::mechanism!(M, "mechanism m {
    planar;
    branch A { base R1* ∥ R2 ∥ R3 platform; }
    branch B { base R4* ∥ R5 ∥ R6 platform; }
    base R7 ∥ R8 ∥ R9 platfrom;
}");

fn main() {}
