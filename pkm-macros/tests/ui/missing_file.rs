// The file does not exist.
pkm::mechanism!(M, file = "tests/ui/no_such_file.pkm");

fn main() {}
