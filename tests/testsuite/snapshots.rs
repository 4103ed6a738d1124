//! Snapshots of what `pkm::mechanism!` generates. Three examples keep the
//! whole generated code, pretty-printed with prettyplease (parsing it with
//! syn also proves it is valid Rust): a planar four-bar, seed 003's punch
//! (planar, eight bars, `fk` only) and the spatial R-S-U-R. Every other
//! example's snapshot is its plans as text
//! ([`pkm::runtime::plan::Plan::display`]): the steps the generated code
//! traces, one line each. Each snapshot was read line by line against the
//! example's joints.

use crate::common;

fn expansion(file: &str, type_name: &str) -> String {
    let (text, _) = common::example_text(file);
    expansion_of(&text, type_name)
}

fn expansion_of(text: &str, type_name: &str) -> String {
    let input: proc_macro2::TokenStream = format!("pub {type_name}, {text:?}").parse().unwrap();
    let tokens = pkm::dsl::expand(input).unwrap();
    prettyplease::unparse(&syn::parse_file(&tokens.to_string()).unwrap())
}

/// An example's forward and inverse plans as text, or why it has none.
fn plans(file: &str) -> String {
    let (text, path) = common::example_text(file);
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let mut out = String::new();
    for (direction, plan) in [("forward", c.forward()), ("inverse", c.inverse())] {
        match plan {
            Ok(plan) => out += &plan.display(&model).to_string(),
            Err(d) => out += &format!("no {direction} plan: {}\n", d.0[0].message),
        }
    }
    out
}

/// The whole generated code of one example file, named after it.
macro_rules! code_snapshots {
    ($($file:ident => $ty:literal),* $(,)?) => {$(
        #[test]
        fn $file() {
            let file = stringify!($file);
            insta::assert_snapshot!(expansion(file, $ty));
        }
    )*};
}

/// The plans of one example file, named after it.
macro_rules! plan_snapshots {
    ($($file:ident),* $(,)?) => {$(
        #[test]
        fn $file() {
            insta::assert_snapshot!(plans(stringify!($file)));
        }
    )*};
}

code_snapshots! {
    four_bar => "FourBar",
    seed003_punch => "Punch",
    rsur => "Rsur",
}

plan_snapshots! {
    slider_crank,
    inverted_slider_crank,
    crank_shaper,
    cylinder_rocker,
    scotch_yoke,
    four_bar_coupler_driven,
    planar_3rpr,
    spherical_four_bar,
    agile_eye,
    five_bar,
    five_bar_tool,
    five_bar_slide,
    rrrrp_tool,
    trammel,
    inverted_slider_crank_block_driven,
    rrrp_2t1r,
    schoenflies_2limb,
    translational_2limb,
    spherical_five_bar,
    watt_six_bar,
    planar_3rrr,
    seed003_punch_original,
    stephenson3,
    tripteron,
    seed000_a,
    seed000_a_u,
    seed000_b,
    five_bar_pa,
    rps_3,
    spr_3,
    rssr,
    rssp,
    upu_3,
    ups_6,
    rps_3_tilt,
    prs_3,
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
