//! Snapshots of the code `pkm::mechanism!` generates, pretty-printed with
//! prettyplease (parsing it with syn also proves it is valid Rust). Each
//! snapshot was read line by line against the example's analysis.

mod common;

fn expansion(file: &str, type_name: &str) -> String {
    let (text, _) = common::example_text(file);
    expansion_of(&text, type_name)
}

fn expansion_of(text: &str, type_name: &str) -> String {
    let input: proc_macro2::TokenStream = format!("pub {type_name}, {text:?}").parse().unwrap();
    let tokens = pkm::dsl::expand(input).unwrap();
    prettyplease::unparse(&syn::parse_file(&tokens.to_string()).unwrap())
}

/// One snapshot per example file, named after it.
macro_rules! snapshots {
    ($($file:ident => $ty:literal),* $(,)?) => {$(
        #[test]
        fn $file() {
            let file = stringify!($file);
            insta::assert_snapshot!(expansion(file, $ty));
        }
    )*};
}

snapshots! {
    four_bar => "FourBar",
    slider_crank => "SliderCrank",
    inverted_slider_crank => "Inverted",
    crank_shaper => "Shaper",
    cylinder_rocker => "Cylinder",
    scotch_yoke => "Yoke",
    four_bar_coupler_driven => "CouplerDriven",
    planar_3rpr => "ThreeRpr",
    spherical_four_bar => "Spherical",
    agile_eye => "AgileEye",
    five_bar => "FiveBar",
    watt_six_bar => "Watt",
    planar_3rrr => "ThreeRrr",
    seed003_punch => "Punch",
    seed003_punch_original => "PunchOriginal",
    stephenson3 => "Stephenson3",
    seed000_a => "SeedA",
    seed000_a_u => "SeedAU",
    seed000_b => "SeedB",
    five_bar_pa => "FiveBarPa",
    rps_3 => "Rps",
    spr_3 => "Spr",
    rssr => "Rssr",
    rssp => "Rssp",
    rsur => "Rsur",
    upu_3 => "Upu",
    ups_6 => "Ups",
    rps_3_tilt => "RpsTilt",
    prs_3 => "Prs",
}

#[test]
fn pay_for_what_you_use() {
    // `ik` only (3-RRR, κ = 1): an inverse solver and no forward one.
    let ik_only = expansion("planar_3rrr", "ThreeRrr");
    assert!(
        ik_only.contains("pub fn ik(") && !ik_only.contains("pub fn fk("),
        "{ik_only}"
    );
    // `fk` only (seed 003's punch): a forward solver and no inverse one.
    let fk_only = expansion("seed003_punch", "Punch");
    assert!(
        fk_only.contains("pub fn fk(") && !fk_only.contains("pub fn ik("),
        "{fk_only}"
    );
    // Velocity capabilities only where asked for (seed 000 A asks).
    let four_bar = expansion("four_bar", "FourBar");
    assert!(!four_bar.contains("fn jacobian(") && !four_bar.contains("fn model("));
    let a = expansion("seed000_a", "SeedA");
    assert!(a.contains("pub fn jacobian(") && a.contains("pub fn velocity(") && a.contains("pub fn acceleration("));
    // Analysis only (a 3-RPS's topology: `ik` without geometry generates nothing yet): no function at all.
    let analysis = expansion_of(
        "mechanism rps { capabilities ik;
             branch A { base R1 ⊥ P1* - S1 platform; }
             branch B { base R2 ⊥ P2* - S2 platform; }
             branch C { base R3 ⊥ P3* - S3 platform; }
             z ⊥ R1; z ⊥ R2; z ⊥ R3; }",
        "Rps",
    );
    assert!(!analysis.contains("fn "), "{analysis}");
}
