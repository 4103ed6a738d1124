// A limb's leg is given by E, A and I or by axial and bending stiffness,
// not a mixture, and a constant value is positive: both errors, at the keys
// and values.
pkm::mechanism!(M, "mechanism m {
    branch A { base R1 ⊥ P1* - S1 platform; }
    branch B { base R2 ⊥ P2* - S2 platform; }
    branch C { base R3 ⊥ P3* - S3 platform; }
    units { length = mm; mass = kg; }
    limbs {
        A, B { E = 2.11e5; A = 1256.6; bending = 350; }
        C { axial = -1.0e5; bending = 350; }
    }
}");

fn main() {}
