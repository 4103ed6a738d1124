// `dynamics` needs the forward solution and every moving link's mass: a
// four-bar asking for it with `ik` only and a mass for its crank alone gets
// both errors, the links without mass listed by name.
pkm::mechanism!(M, "mechanism m {
    capabilities ik, dynamics;
    planar;
    base R1* [crank] ∥ R2 [coupler] ∥ R3 [rocker] ∥ R4 base;
    parameters { a = 40; b = 120; c = 80; d = 100; }
    geometry {
        base    { R1 = (0, 0); R4 = (d, 0); }
        crank   { R1 = (0, 0); R2 = (a, 0); }
        coupler { R2 = (0, 0); R3 = (b, 0); }
        rocker  { R4 = (0, 0); R3 = (c, 0); }
    }
    outputs { psi = joint R4; }
    units { length = mm; mass = kg; }
    masses { crank { mass = 0.1; centroid = (a / 2, 0); inertia = 13.3; } }
}");

fn main() {}
