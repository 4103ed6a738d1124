// The same diagnostic for a design read from a file.
// trybuild compiles from target/tests/trybuild/pkm-macros: the path climbs back.
pkm::mechanism!(M, file = "../../../../pkm-macros/tests/ui/coupled_punch.pkm");

fn main() {}
