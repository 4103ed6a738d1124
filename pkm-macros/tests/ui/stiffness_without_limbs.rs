// `stiffness` is asked for without what it needs: the inverse solution
// (`ik`), the file's units and every branch's limb properties. All three
// errors are reported together, at the capability.
pkm::mechanism!(M, "mechanism m {
    capabilities stiffness;
    branch A { base R1 ⊥ P1* - S1 platform; }
    branch B { base R2 ⊥ P2* - S2 platform; }
    branch C { base R3 ⊥ P3* - S3 platform; }
}");

fn main() {}
