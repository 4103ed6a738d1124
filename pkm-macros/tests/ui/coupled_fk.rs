// The planar 3-RRR has κ = 1: no closed-form forward solution.
pkm::mechanism!(M, "mechanism planar_3rrr {
    capabilities fk, ik;
    planar;
    branch A { base R1* ∥ R2 ∥ R3 platform; }
    branch B { base R4* ∥ R5 ∥ R6 platform; }
    branch C { base R7* ∥ R8 ∥ R9 platform; }
}");

fn main() {}
