//! Two paths that must agree: the closed-form plan (interpreter) and the
//! reference Newton solver, started near each branch, at random inputs.

use pkm::runtime::model::Model;
use pkm::runtime::newton::{self, NewtonOptions};
use pkm::runtime::plan::{self, Plan};
use std::collections::HashMap;
use std::f64::consts::PI;

fn load(file: &str) -> (Model, Plan) {
    let path = format!("{}/examples/mechanisms/{file}.pkm", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let a = pkm::dsl::analyze_source(&text).unwrap();
    (
        pkm::dsl::plan::model(&a, &HashMap::new()).unwrap(),
        pkm::dsl::plan::forward_plan(&a).unwrap(),
    )
}

/// A deterministic generator (splitmix64), uniform in [lo, hi).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// For `samples` random inputs in `ranges`: every branch the plan solves is
/// found again by Newton from a start perturbed by 1e-3 (radians or mm), and
/// every joint point agrees to 1e-9 of the mechanism's size.
fn check(file: &str, ranges: &[(f64, f64)], samples: usize) {
    let (model, plan) = load(file);
    let scale = newton::model_scale(&model);
    let mut rng = Rng(0x5eed);
    let mut solved = 0;
    for _ in 0..samples {
        let q: Vec<f64> = ranges.iter().map(|&(lo, hi)| rng.uniform(lo, hi)).collect();
        for (signs, result) in plan::run_all(&model, &plan, &q) {
            let Ok(sol) = result else { continue };
            let guess: Vec<f64> = sol.values.iter().map(|v| v + rng.uniform(-1e-3, 1e-3)).collect();
            let reference = newton::solve_fk(&model, &q, &guess, &NewtonOptions::default())
                .unwrap_or_else(|e| panic!("{file} {q:?} {signs:?}: Newton failed: {e}"));
            for j in 0..model.joints.len() {
                let a = plan::joint_point(&model, &sol.poses, j);
                let b = newton::joint_point(&model, &reference.poses, j);
                let err = (a[0] - b[0]).hypot(a[1] - b[1]);
                assert!(
                    err <= 1e-9 * scale,
                    "{file} {q:?} {signs:?} joint {}: {err}",
                    model.joints[j].name
                );
            }
            solved += 1;
        }
    }
    assert!(solved >= samples, "{file}: only {solved} solved branches");
}

#[test]
fn four_bar() {
    check("four_bar", &[(-PI, PI)], 200);
}

#[test]
fn slider_crank() {
    check("slider_crank", &[(-PI, PI)], 200);
}

#[test]
fn five_bar() {
    check("five_bar", &[(1.2, 2.8), (0.3, 1.9)], 200);
}

#[test]
fn seed003_punch() {
    check("seed003_punch", &[(-PI, PI)], 200);
}

#[test]
fn watt_six_bar() {
    check("watt_six_bar", &[(-PI, PI)], 200);
}
