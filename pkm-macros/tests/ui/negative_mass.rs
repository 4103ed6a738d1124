// A mass that evaluates below zero at the parameters' values.
pkm::mechanism!(M, "mechanism m {
    base R1* [a] ∥ R2 [b] ∥ R3 [c] ∥ R4 base;
    parameters { l = 100; m = 0.5; }
    geometry {
        base { R1 = (0, 0, 0) along z; R4 = (3 * l, 0, 0) along z; }
        a { R1 = (0, 0, 0) along z; R2 = (l, 0, 0) along z; point M = (l / 2, 0, 0); }
        b { R2 = (0, 0, 0) along z; R3 = (2.5 * l, 0, 0) along z; }
        c { R3 = (2 * l, 0, 0) along z; R4 = (0, 0, 0) along z; }
    }
    units { length = mm; mass = kg; }
    masses { a { mass = m - 1; centroid = (l / 2, 0, 0); } }
}");

fn main() {}
