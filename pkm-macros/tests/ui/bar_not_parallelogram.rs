// A bar's mass given to a revolute: only a parallelogram's (`Pa`) swinging
// bars are bodies without a link of their own.
pkm::mechanism!(M, "mechanism m {
    branch I { base R1* [a1] ∥ R2 [b1] ∥ R3 [b2] ∥ R4 [a2] ∥ R5* base; b1 R6 [cross] ⊥ R7 platform; }
    branch II { base P3* [s3] ∥ R8 [r8] - Pa [pc] - R9 platform; }
    R6 ≡ R3; y ∥ R1; x ∥ P3; R7 ∥ R8 ∥ R9; Pa ⊥ R8;
    parameters { a = 250; d = 80; r = 150; l = 260; h = 80; p = 380; m = 300; }
    geometry {
        base  { R1 = (-d, -a, 0) along y; R5 = (d, -a, 0) along y; P3 = through (0, a, 0) along x; }
        a1    { R1 = (0, 0, 0) along y; R2 = (r, 0, 0) along y; }
        b1    { R2 = (0, 0, 0) along y; R3 = (l, 0, 0) along y; R6 = (l, 0, 0) along y; }
        b2    { R3 = (l, 0, 0) along y; R4 = (0, 0, 0) along y; }
        a2    { R4 = (r, 0, 0) along y; R5 = (0, 0, 0) along y; }
        cross { R6 = (0, 0, 0) along y; R7 = (0, 0, 0) along x; }
        platform { R7 = (0, 0, 0) along x; R9 = (0, p, 0) along x; }
        pc    { R9 = (0, 0, 0) along x; Pa = (0, 0, 0) along y; }
        r8    { R8 = (0, 0, 0) along x; Pa = (0, 0, 0) along y arm (0, 0, m); }
        s3    { P3 = (0, 0, 0); R8 = (0, 0, h) along x; }
    }
    units { length = mm; mass = kg; }
    masses { R8 bar at (0, 0, 0) { mass = 0.1; centroid = (0, 0, m / 2); } }
}");

fn main() {}
