// The same diagnostic for a design read from a file.
// trybuild compiles from target/tests/trybuild/pkm: the path climbs back.
pkm::mechanism!(M, file = "../../../../tests/ui/coupled_punch.pkm");

fn main() {}
