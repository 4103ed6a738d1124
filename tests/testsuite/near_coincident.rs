//! Seed 000 mechanism A as its two slider pivots B1 and B2 nearly coincide
//! (x2 a few ulps above x1): the five-bar's apex C1 is well conditioned,
//! x = (x1 + x2)/2 and z = l1 ± sqrt(l2² − ((x2 − x1)/2)²) (the paper's own
//! formulas, exact to an ulp here), and the closed form must keep that.

use crate::mechanisms::{SeedA, SeedAParams, SeedASolution};

fn point(s: &SeedASolution, name: &str) -> [f64; 3] {
    s.points[SeedA::POINTS.iter().position(|p| *p == name).unwrap()]
}

#[test]
fn apex_is_exact_when_the_pivots_nearly_coincide() {
    let p = SeedAParams::default();
    let (l1, l2) = (p.l1, p.l2);
    let mut rng = pkm::dsl::screw::SplitMix::new(7);
    for _ in 0..500 {
        let x1 = 250.0 * rng.symmetric();
        let mut x2 = x1;
        for ulps in 1..=10 {
            x2 = f64::next_up(x2);
            let half = (x2 - x1) / 2.0; // exact: Sterbenz
            let x = x1 + half;
            let h = (l2 * l2 - half * half).sqrt();
            let mut found = 0;
            for b in SeedA::fk(&p, &[x1, x2, x1 + 50.0]) {
                let Ok(s) = b.result else { continue };
                let c1 = point(&s, "C1");
                let z = if c1[2] > l1 { l1 + h } else { l1 - h };
                let err = (c1[0] - x).abs().max((c1[2] - z).abs());
                assert!(
                    err <= 4.0 * f64::EPSILON * 300.0,
                    "x1 = {x1}, {ulps} ulps: C1 = {c1:?}, want ({x}, {z}), error {err:e}"
                );
                found += 1;
            }
            assert!(found >= 2, "x1 = {x1}, {ulps} ulps: only {found} branches");
        }
    }
}
