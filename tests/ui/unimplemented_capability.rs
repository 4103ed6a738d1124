// `stiffness` is a capability the compiler does not implement yet: an error,
// not a silent omission of the code the file asked for.
pkm::mechanism!(M, "mechanism m {
    capabilities fk, stiffness;
    planar;
    base R1* ∥ R2 ∥ R3 ∥ R4 base;
}");

fn main() {}
