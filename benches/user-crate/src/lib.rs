//! One `pkm::mechanism!` per example, each behind its feature, as a user
//! would write them (the file path is relative to this crate's Cargo.toml).

#[cfg(feature = "five_bar")]
pkm::mechanism!(pub FiveBar, file = "../../examples/mechanisms/five_bar.pkm");
#[cfg(feature = "five_bar_pa")]
pkm::mechanism!(pub FiveBarPa, file = "../../examples/mechanisms/five_bar_pa.pkm");
#[cfg(feature = "four_bar")]
pkm::mechanism!(pub FourBar, file = "../../examples/mechanisms/four_bar.pkm");
#[cfg(feature = "planar_3rrr")]
pkm::mechanism!(pub Planar3Rrr, file = "../../examples/mechanisms/planar_3rrr.pkm");
#[cfg(feature = "rps_3")]
pkm::mechanism!(pub Rps3, file = "../../examples/mechanisms/rps_3.pkm");
#[cfg(feature = "seed000_a")]
pkm::mechanism!(pub SeedA, file = "../../examples/mechanisms/seed000_a.pkm");
#[cfg(feature = "seed000_b")]
pkm::mechanism!(pub SeedB, file = "../../examples/mechanisms/seed000_b.pkm");
#[cfg(feature = "seed003_punch")]
pkm::mechanism!(pub Punch, file = "../../examples/mechanisms/seed003_punch.pkm");
#[cfg(feature = "seed003_punch_original")]
pkm::mechanism!(pub PunchOriginal, file = "../../examples/mechanisms/seed003_punch_original.pkm");
#[cfg(feature = "slider_crank")]
pkm::mechanism!(pub SliderCrank, file = "../../examples/mechanisms/slider_crank.pkm");
#[cfg(feature = "spr_3")]
pkm::mechanism!(pub Spr3, file = "../../examples/mechanisms/spr_3.pkm");
#[cfg(feature = "watt_six_bar")]
pkm::mechanism!(pub WattSixBar, file = "../../examples/mechanisms/watt_six_bar.pkm");
