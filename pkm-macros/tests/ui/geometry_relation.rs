// R2 is declared parallel to R1, but placed along x on link a while R1 is along z.
pkm::mechanism!(M, "mechanism m {
    base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
    parameters { l = 1; }
    geometry {
        base { R1 = (0, 0, 0) along z; R4 = (l, 0, 0) along z; }
        a { R1 = (0, 0, 0) along z; R2 = (l, 0, 0) along x; }
        b { R2 = (0, 0, 0) along z; R3 = (l, 0, 0) along z; }
        c { R3 = (0, 0, 0) along z; R4 = (0, l, 0) along z; }
    }
}");

fn main() {}
