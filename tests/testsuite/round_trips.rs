//! fk∘ik and ik∘fk round trips of the generated solvers over 10⁵ random
//! reachable configurations per mechanism.
//!
//! Each sample draws actuator inputs uniformly in the mechanism's ranges; a
//! draw fk cannot assemble is not reachable and is drawn again. Of a
//! reachable sample, one fk branch (cycling through the solved ones) gives a
//! pose; ik of that pose must return the drawn inputs on some branch
//! (ik∘fk); one ik branch (cycling again) must, through fk, give the pose
//! back on some branch (fk∘ik). Lengths are compared relative to the
//! mechanism's size, angles modulo 2π, both to 1e-9 (see `bound` for the
//! few draws next to a branch switch).

use crate::common;
use crate::mechanisms::{
    BennettDriven, BlockDriven, CouplerDriven, Cylinder, FiveBar, FiveBarPa, FiveBarSlide, FiveBarTool, FourBar,
    Inverted, Rrrp2t1r, RrrrpTool, Rssp, Rssr, Rsur, Schoenflies, SeedA, SeedAU, SeedB, Shaper, SliderCrank, Spherical,
    SphericalFive, Trammel, Translational, Watt, Yoke,
};

use common::max_error;
use pkm::dsl::screw::SplitMix;
use std::f64::consts::PI;

const SAMPLES: usize = 100_000;
const TOLERANCE: f64 = 1e-9;

/// Near a singularity two branches come together and the value is fixed
/// only to about ε/gap (a near double root): the bound is 1e-9, or 1e-14
/// over the relative gap to the nearest other solution when that is below
/// 1e-5 (the two agree at the switch).
fn bound(gap: f64) -> f64 {
    TOLERANCE.max(1e-14 / gap)
}

/// The best match among `solutions` (its error) and the gap from it to the
/// nearest other solution (whole joint vectors, relative to `scale`).
fn best_and_gap<S>(
    solutions: &[&S],
    err: impl Fn(&S) -> f64,
    q: impl Fn(&S) -> &[f64],
    revolute: &[bool],
    scale: f64,
) -> (f64, f64) {
    let (i, e) = solutions
        .iter()
        .map(|s| err(s))
        .enumerate()
        .fold((0, f64::INFINITY), |b, (i, e)| if e < b.1 { (i, e) } else { b });
    let gap = solutions
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != i)
        .map(|(_, s)| max_error(q(s), q(solutions[i]), revolute, scale))
        .fold(f64::INFINITY, f64::min);
    (e, gap)
}

/// What one mechanism's run measured.
#[derive(Debug, Default)]
#[allow(dead_code)] // Read through `Debug` in the test log.
struct Tally {
    drawn: usize,
    reachable: usize,
    /// ik solutions at output singularities, left out of fk∘ik.
    singular: usize,
    /// Checks where the nearest other branch was closer than 1e-5 (relative).
    near_switch: usize,
    worst_ik_fk: f64,
    worst_fk_ik: f64,
    /// The worst error times the gap (at most 1): next to a double root the
    /// error is about ε/gap by the problem's conditioning, so this is the
    /// part a change of formulas moves (the worst alone follows whichever
    /// draw lands nearest a switch).
    scaled_ik_fk: f64,
    scaled_fk_ik: f64,
}

macro_rules! round_trips {
    ($ty:ident, $ranges:expr, $scale:expr, $singular:expr) => {{
        let params = Default::default();
        let scale: f64 = $scale;
        let ranges: [(f64, f64); $ty::INPUTS.len()] = $ranges;
        let inputs: [usize; $ty::INPUTS.len()] =
            std::array::from_fn(|i| $ty::JOINTS.iter().position(|j| *j == $ty::INPUTS[i]).unwrap());
        let input_angles = inputs.map(|j| $ty::REVOLUTE[j]);
        let singular: fn(&[f64]) -> bool = $singular;
        let mut rng = SplitMix::new(0x5eed);
        let mut t = Tally::default();
        while t.reachable < SAMPLES {
            t.drawn += 1;
            assert!(
                t.drawn < 50 * SAMPLES,
                "{}: too few reachable draws: {t:?}",
                stringify!($ty)
            );
            let q = ranges.map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
            let fk = $ty::fk(&params, &q);
            let solved: Vec<_> = fk.iter().filter_map(|b| b.result.as_ref().ok()).collect();
            if solved.is_empty() {
                continue;
            }
            t.reachable += 1;
            let pose = solved[t.reachable % solved.len()].outputs;

            let ik = $ty::ik(&params, &pose);
            let back: Vec<_> = ik.iter().filter_map(|b| b.result.as_ref().ok()).collect();
            let (e, gap) = best_and_gap(
                &back,
                |s| max_error(&inputs.map(|j| s.q[j]), &q, &input_angles, scale),
                |s| &s.q[..],
                &$ty::REVOLUTE,
                scale,
            );
            assert!(
                e <= bound(gap),
                "{}: ik∘fk at q = {q:?}: error {e:e}, gap {gap:e}",
                stringify!($ty)
            );
            t.near_switch += usize::from(gap < 1e-5);
            t.scaled_ik_fk = t.scaled_ik_fk.max(e * gap.min(1.0));
            t.worst_ik_fk = t.worst_ik_fk.max(e);

            let usable: Vec<_> = back.iter().filter(|s| !singular(&inputs.map(|j| s.q[j]))).collect();
            t.singular += back.len() - usable.len();
            // Cycled in the order of their inputs, not of the branches: the
            // draws do not change with the order a plan lists branches in.
            let mut ordered: Vec<[f64; $ty::INPUTS.len()]> = usable.iter().map(|s| inputs.map(|j| s.q[j])).collect();
            ordered.sort_by(|a, b| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| x.total_cmp(y))
                    .find(|o| o.is_ne())
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            let qi = ordered[t.reachable % ordered.len()];
            let again = $ty::fk(&params, &qi);
            let again: Vec<_> = again.iter().filter_map(|b| b.result.as_ref().ok()).collect();
            let (e, gap) = best_and_gap(
                &again,
                |s| max_error(&s.outputs, &pose, &$ty::OUTPUT_ANGLES, scale),
                |s| &s.q[..],
                &$ty::REVOLUTE,
                scale,
            );
            assert!(
                e <= bound(gap),
                "{}: fk∘ik at pose {pose:?} (inputs {qi:?}): error {e:e}, gap {gap:e}",
                stringify!($ty)
            );
            t.near_switch += usize::from(gap < 1e-5);
            t.scaled_fk_ik = t.scaled_fk_ik.max(e * gap.min(1.0));
            t.worst_fk_ik = t.worst_fk_ik.max(e);
        }
        eprintln!("{}: {t:?}", stringify!($ty));
        t
    }};
}

/// No output singularity among the ik solutions.
fn never(_: &[f64]) -> bool {
    false
}

/// Seed 000 §2.3: both five-bar sliders at one place (x1 = x2) is an output
/// singularity, where the five-bar's two circles coincide; ik lists such
/// solutions (they satisfy the loop) but fk cannot return from them.
fn sliders_together(q: &[f64]) -> bool {
    (q[0] - q[1]).abs() < 1e-6 * 300.0
}

#[test]
fn four_bar() {
    round_trips!(FourBar, [(-PI, PI)], 300.0, never);
}

#[test]
fn slider_crank() {
    round_trips!(SliderCrank, [(-PI, PI)], 300.0, never);
}

#[test]
fn inverted_slider_crank() {
    round_trips!(Inverted, [(-PI, PI)], 300.0, never);
}

#[test]
fn crank_shaper() {
    round_trips!(Shaper, [(-PI, PI)], 300.0, never);
}

/// The stroke from short of the shortest cylinder (|R2R3| = 310.5 − 150,
/// s = −39.5) to past the longest (s = 260.5): the draws out of reach are
/// skipped.
#[test]
fn cylinder_rocker() {
    round_trips!(Cylinder, [(-60.0, 300.0)], 300.0, never);
}

/// The yoke's slide s = r·cos θ: ik's two roots ±acos(s/r) meet at the
/// stroke's ends (the bound's gap takes those draws).
#[test]
fn scotch_yoke() {
    round_trips!(Yoke, [(-PI, PI)], 120.0, never);
}

/// The coupler joint's angle over a whole turn: the rocker reaches every
/// |R1R3| from 150 to 350 (two assemblies each).
#[test]
fn four_bar_coupler_driven() {
    round_trips!(CouplerDriven, [(-PI, PI)], 300.0, never);
}

/// The spherical four-bar's crank turns fully (α1 + α4 ≤ α2 + α3).
#[test]
fn spherical_four_bar() {
    round_trips!(Spherical, [(-PI, PI)], 100.0, never);
}

#[test]
fn five_bar() {
    round_trips!(FiveBar, [(-PI, PI), (-PI, PI)], 160.0, never);
}

/// The tool point E off R3: ik turns right_distal about E
/// (`steps::locus::pin`), four branches.
#[test]
fn five_bar_tool() {
    round_trips!(FiveBarTool, [(-PI, PI), (-PI, PI)], 160.0, never);
}

/// A slide and a crank drive it; the tool point is on the coupler next to the crank.
#[test]
fn five_bar_slide() {
    round_trips!(FiveBarSlide, [(-150.0, 150.0), (-PI, PI)], 150.0, never);
}

/// Crank and slide driven, the tool point on the coupler.
#[test]
fn rrrrp_tool() {
    round_trips!(RrrrpTool, [(-PI, PI), (-150.0, 250.0)], 150.0, never);
}

/// Driven at the block–bar joint: fk slides block1 and the bar as one body
/// until R2 is on block2's guide (one root); ik, given block1's slide,
/// two (the bar above or below the x axis).
#[test]
fn trammel() {
    round_trips!(Trammel, [(-PI, PI)], 200.0, never);
}

/// Driven at the crank–block joint: fk turns crank and block as one body
/// until the block's line passes the rocker's pivot (two roots).
#[test]
fn inverted_slider_crank_block_driven() {
    round_trips!(BlockDriven, [(-PI, PI)], 120.0, never);
}

#[test]
fn watt_six_bar() {
    round_trips!(Watt, [(-PI, PI)], 300.0, never);
}

#[test]
fn five_bar_with_parallelogram() {
    round_trips!(FiveBarPa, [(-PI, PI), (-PI, PI), (-300.0, 300.0)], 300.0, never);
}

#[test]
fn seed000_a() {
    // §2.2's actuator ranges.
    round_trips!(
        SeedA,
        [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        300.0,
        sliders_together
    );
}

/// Seed 000 A with its cross written as the U joint U1.
#[test]
fn seed000_a_u() {
    round_trips!(
        SeedAU,
        [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        300.0,
        sliders_together
    );
}

/// The 2T1R with an R-R-R-P branch: seed 000's five-bar, and R5 over
/// the angles where branch II reaches the platform.
#[test]
fn rrrp_2t1r() {
    round_trips!(
        Rrrp2t1r,
        [(-250.0, 0.0), (0.0, 250.0), (0.0, 1.2)],
        450.0,
        sliders_together
    );
}

/// The two-limb Schönflies robot over its study ranges.
#[test]
fn schoenflies_2limb() {
    round_trips!(
        Schoenflies,
        [(-100.0, 200.0), (-0.5, 2.0), (-1.5, 1.5), (1.6, 2.8)],
        400.0,
        never
    );
}

/// The spherical five-bar: its pointing point P given (on the sphere), both cranks over a turn.
#[test]
fn spherical_five_bar() {
    round_trips!(SphericalFive, [(-PI, PI), (-PI, PI)], 100.0, never);
}

/// The Bennett linkage (mobile by its geometry, `mobility by geometry`),
/// R1 over a turn, its output the opposite joint R4.
#[test]
fn bennett_linkage() {
    round_trips!(BennettDriven, [(-3.1, 3.1)], 100.0, never);
}

/// The two-limb 3T over its study ranges.
#[test]
fn translational_2limb() {
    round_trips!(
        Translational,
        [(-200.0, 200.0), (0.5, 2.5), (-100.0, 300.0)],
        400.0,
        never
    );
}

#[test]
fn seed000_b() {
    round_trips!(
        SeedB,
        [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        300.0,
        sliders_together
    );
}

/// The spatial RSSR: the crank turns fully. Its S joints have no one value
/// (NaN in `q`), so the comparisons see the revolutes only.
#[test]
fn rssr() {
    round_trips!(Rssr, [(-PI, PI)], 200.0, never);
}

/// The spatial crank-slider R-S-S-P: the crank turns fully.
#[test]
fn rssp() {
    round_trips!(Rssp, [(-PI, PI)], 200.0, never);
}

/// The spatial R-S-U-R: the crank turns fully; four branches each way (the
/// rocker's or crank's two, the U's two). Its S joint has no one value.
#[test]
fn rsur() {
    round_trips!(Rsur, [(-PI, PI)], 200.0, never);
}
