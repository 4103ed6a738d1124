fn main() {
    for path in std::env::args().skip(1) {
        let src = std::fs::read_to_string(&path).unwrap();
        match pkm_dsl::analyze_source(&src) {
            Ok(a) => println!("{}", a.report()),
            Err(e) => println!("{}", e.render(&src, &path)),
        }
    }
}
