// The description must be a string literal or `file = "…"`.
pkm::mechanism!(M, mechanism);

fn main() {}
