// `stiffness` is a capability the compiler does not implement yet: an error,
// not a silent omission of the code the file asked for. This file has what
// it will need (units, and every branch's limb properties): only the refusal.
pkm::mechanism!(M, "mechanism m {
    capabilities ik, stiffness;
    branch A { base R1 ⊥ P1* - S1 platform; }
    branch B { base R2 ⊥ P2* - S2 platform; }
    branch C { base R3 ⊥ P3* - S3 platform; }
    units { length = mm; mass = kg; }
    limbs { A, B, C { E = 2.11e5; A = 1256.6; I = 1.256e5; } }
}");

fn main() {}
