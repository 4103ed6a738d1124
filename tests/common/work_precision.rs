//! The work-precision cases shared by `tests/testsuite/reference.rs` and
//! `benches/work_precision.rs`: four mechanisms, the inputs at which each is
//! solved (inside its workspace), the branch, and the 70-digit reference
//! solution of fk and ik there.
//!
//! The generated code is called in one small function per mechanism
//! ([`four_bar`], [`slider_crank`], [`seed000_a`], [`seed000_b`]), so that a
//! change of its API touches those four functions only.
//!
//! The four mechanisms are the including crate's `mechanisms` module's
//! (the test suite's `tests/testsuite/mechanisms.rs`, the benchmark's own).
#![allow(dead_code)]

use crate::mechanisms::{FourBar, SeedA, SeedAPrepared, SeedB, SeedBPrepared, SliderCrank};

use pkm::runtime::model::Model;
use pkm::runtime::newton::{self, NewtonOptions, NewtonSolution, Output};
use pkm::runtime::plan;
use pkm::runtime::primitives::Sign;
use pkm::runtime::reference::{self, f256, Reference};
use pkm::runtime::solution::signs_of;

/// The generated solvers of one mechanism on the reference's branch: each
/// writes the joint values (and for fk the outputs) into the buffers and
/// says whether it succeeded.
#[derive(Clone, Copy)]
pub struct Generated {
    /// `fk_branch` at the inputs.
    pub fk: fn(&[f64], &mut [f64], &mut [f64]) -> bool,
    /// `ik_branch` at the outputs, on the branch of the signs' index (as for `signs_of`).
    pub ik: fn(&[f64], usize, &mut [f64]) -> bool,
    /// The fk branch's signs (an index as for `signs_of`).
    pub fk_signs: usize,
}

// Today's API: `Name::fk_branch(&params, &q, signs)` / `Name::ik_branch`.
macro_rules! generated {
    ($ty:ident, $fk_signs:expr) => {
        Generated {
            fk: |q, values, outputs| match $ty::fk_branch(
                &Default::default(),
                q.try_into().unwrap(),
                signs_of($fk_signs),
            ) {
                Ok(s) => {
                    values.copy_from_slice(&s.q);
                    outputs.copy_from_slice(&s.outputs);
                    true
                }
                Err(_) => false,
            },
            ik: |x, signs, values| match $ty::ik_branch(&Default::default(), x.try_into().unwrap(), signs_of(signs)) {
                Ok(s) => {
                    values.copy_from_slice(&s.q);
                    true
                }
                Err(_) => false,
            },
            fk_signs: $fk_signs,
        }
    };
}

/// The same for a spatial mechanism's prepared solver (`Name::prepare`
/// once, then `fk_solution` / `ik_solution` per call).
macro_rules! prepared {
    ($ty:ident, $prepared:ident, $fk_signs:expr) => {
        Generated {
            fk: |q, values, outputs| {
                static SOLVER: std::sync::OnceLock<$prepared> = std::sync::OnceLock::new();
                let solver = SOLVER.get_or_init(|| $ty::prepare(&Default::default()));
                match solver.fk_solution(q.try_into().unwrap(), signs_of($fk_signs)) {
                    Ok(s) => {
                        values.copy_from_slice(&s.q);
                        outputs.copy_from_slice(&s.outputs);
                        true
                    }
                    Err(_) => false,
                }
            },
            ik: |x, signs, values| {
                static SOLVER: std::sync::OnceLock<$prepared> = std::sync::OnceLock::new();
                let solver = SOLVER.get_or_init(|| $ty::prepare(&Default::default()));
                match solver.ik_solution(x.try_into().unwrap(), signs_of(signs)) {
                    Ok(s) => {
                        values.copy_from_slice(&s.q);
                        true
                    }
                    Err(_) => false,
                }
            },
            fk_signs: $fk_signs,
        }
    };
}

/// four_bar: the crank-rocker's open assembly.
pub fn four_bar() -> Generated {
    generated!(FourBar, 0)
}

/// slider_crank: the slider on the crank's side.
pub fn slider_crank() -> Generated {
    generated!(SliderCrank, 0)
}

/// seed000_a: the paper's assembly (the five-bar above the sliders).
pub fn seed000_a() -> Generated {
    prepared!(SeedA, SeedAPrepared, 0b01)
}

/// seed000_b: the paper's assembly.
pub fn seed000_b() -> Generated {
    prepared!(SeedB, SeedBPrepared, 0b011)
}

/// The plan interpreter of one direction.
pub struct Interpreter(pub plan::Plan);

impl Interpreter {
    /// The joint values on the branch `signs`, or `None` if it fails.
    pub fn run(&self, model: &Model, given: &[f64], signs: &[Sign]) -> Option<Vec<f64>> {
        plan::run(model, &self.0, given, signs).ok().map(|s| s.values)
    }
}

/// One solution point: the inputs, the outputs there (the fk reference's,
/// rounded to `f64`: the ik problem's given values), and the references.
pub struct Point {
    /// The fk inputs.
    pub inputs: Vec<f64>,
    /// The ik given outputs.
    pub outputs: Vec<f64>,
    /// Newton's fk start: the generated solution at inputs 0.05 away.
    pub fk_guess: Vec<f64>,
    /// The ik branch whose solution is the fk solution (an index as for `signs_of`).
    pub ik_signs: usize,
    /// Newton's ik start: the generated solution at outputs 0.05 away.
    pub ik_guess: Vec<f64>,
    /// The fk reference.
    pub fk: Reference,
    /// The fk reference's outputs.
    pub fk_outputs: Vec<f256>,
    /// The ik reference.
    pub ik: Reference,
}

/// One mechanism's case.
pub struct Case {
    /// The example's file stem.
    pub name: &'static str,
    /// Its model at the nominal parameters.
    pub model: Model,
    /// Its outputs, as Newton's ik takes them.
    pub outputs: Vec<Output>,
    /// `model_scale`.
    pub scale: f64,
    /// Which joint values are angles.
    pub value_angles: Vec<bool>,
    /// Which outputs are angles.
    pub output_angles: Vec<bool>,
    /// The generated solvers.
    pub generated: Generated,
    /// The interpreter, fk and ik.
    pub interpreter: [Interpreter; 2],
    /// The number of branch signs of fk and of ik.
    pub branches: [usize; 2],
    /// The solution points.
    pub points: Vec<Point>,
}

/// Newton's options at `tolerance`.
pub fn newton_options(tolerance: f64) -> NewtonOptions {
    NewtonOptions {
        tolerance,
        max_iterations: 100,
    }
}

/// The branch signs of an index, as many as the plan has branches.
pub fn signs(index: usize, branches: usize) -> Vec<Sign> {
    (0..branches)
        .map(|k| if index >> k & 1 == 1 { Sign::Minus } else { Sign::Plus })
        .collect()
}

/// The inputs of each mechanism's points: around a nominal configuration,
/// all inside the workspace (every one assembles on the branch).
fn inputs_of(name: &str) -> Vec<Vec<f64>> {
    match name {
        // Crank angles round the full turn (l1 + l4 < l2 + l3: a crank-rocker).
        "four_bar" => [0.1, 0.7, 1.5, 2.2, 3.0, 4.0, 5.0, 5.9]
            .iter()
            .map(|&t| vec![t])
            .collect(),
        "slider_crank" => [0.1, 0.7, 1.5, 2.2, 3.0, 4.0, 5.0, 5.9]
            .iter()
            .map(|&t| vec![t])
            .collect(),
        // Seed 000 Table 1's inputs (mm) and seven nearby.
        _ => {
            let nominal = [-106.09, 181.67, -70.29];
            let offsets = [
                [0.0, 0.0, 0.0],
                [20.0, 0.0, 0.0],
                [0.0, -20.0, 0.0],
                [0.0, 0.0, 30.0],
                [-15.0, 10.0, -25.0],
                [10.0, 15.0, 40.0],
                [-25.0, -10.0, 10.0],
                [5.0, 25.0, -40.0],
            ];
            offsets
                .iter()
                .map(|d| nominal.iter().zip(d).map(|(a, b)| a + b).collect())
                .collect()
        }
    }
}

/// The generated solution at `given` with its first entry moved by ±0.05,
/// whichever assembles first: Newton's start.
fn nearby(given: &[f64], solve: impl Fn(&[f64]) -> Option<Vec<f64>>) -> Vec<f64> {
    [-0.05, 0.05]
        .iter()
        .find_map(|d| {
            let mut near = given.to_vec();
            near[0] += d;
            solve(&near)
        })
        .expect("the branch assembles 0.05 away")
}

/// The case of the example `name` with its generated solvers, and the
/// reference at each point: f64 Newton from the generated solution, then
/// the 70-digit Newton from there.
pub fn case(name: &'static str, generated: Generated) -> Case {
    let path = format!("{}/examples/mechanisms/{name}.pkm", env!("CARGO_MANIFEST_DIR"));
    let c = pkm::dsl::compile(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = c.model().unwrap().clone();
    let outputs = c.outputs().unwrap().to_vec();
    let (f, i) = (c.forward().unwrap().clone(), c.inverse().unwrap().clone());
    let branches = [f.branches, i.branches];
    let interpreter = [Interpreter(f), Interpreter(i)];
    let scale = pkm::runtime::kinematics::model_scale(&model);
    let n_values = model.value_offsets().1;
    let n_outputs: usize = outputs.iter().map(|o| o.len(model.planar)).sum();
    let fk = |q: &[f64]| {
        let (mut values, mut out) = (vec![0.0; n_values], vec![0.0; n_outputs]);
        (generated.fk)(q, &mut values, &mut out).then_some((values, out))
    };
    let ik = |x: &[f64], signs: usize| {
        let mut values = vec![0.0; n_values];
        (generated.ik)(x, signs, &mut values).then_some(values)
    };
    let angles = reference::value_is_angle(&model);
    let tight = newton_options(1e-13);
    let points = inputs_of(name)
        .into_iter()
        .map(|inputs| {
            let (start, _) = fk(&inputs).unwrap_or_else(|| panic!("{name}: no fk at {inputs:?}"));
            let fk_newton: NewtonSolution = newton::solve_fk(&model, &inputs, &start, &tight).unwrap();
            let fk_ref = reference::fk(&model, &inputs, &fk_newton.values).unwrap();
            let fk_outputs = reference::output_values(&model, &outputs, &fk_ref.values).unwrap();
            // The ik problem: the reference's outputs rounded to f64. An
            // output that the others determine (seed000's y, always ±a) is
            // then exactly consistent with them; f64 fk's may be off by an ulp,
            // and leave the ik without an exact solution.
            let given: Vec<f64> = fk_outputs.iter().map(|&x| reference::to_f64(x)).collect();
            // The ik branch that returns to the fk solution.
            let (ik_signs, ik_start) = (0..1 << branches[1])
                .find_map(|s| {
                    let q = ik(&given, s)?;
                    (crate::common::max_error(&q, &start, &angles, scale) < 1e-8).then_some((s, q))
                })
                .unwrap_or_else(|| panic!("{name}: no ik branch at {given:?} returns to {start:?}"));
            let ik_newton = newton::solve_ik(&model, &outputs, &given, &ik_start, &tight).unwrap();
            let ik_ref = reference::ik(&model, &outputs, &given, &ik_newton.values).unwrap();
            Point {
                fk_guess: nearby(&inputs, |q| fk(q).map(|s| s.0)),
                ik_guess: nearby(&given, |x| ik(x, ik_signs)),
                ik_signs,
                inputs,
                outputs: given,
                fk: fk_ref,
                fk_outputs,
                ik: ik_ref,
            }
        })
        .collect();
    Case {
        name,
        value_angles: reference::value_is_angle(&model),
        output_angles: reference::output_is_angle(&model, &outputs),
        branches,
        model,
        outputs,
        scale,
        generated,
        interpreter,
        points,
    }
}

/// The four cases.
pub fn cases() -> Vec<Case> {
    vec![
        case("four_bar", four_bar()),
        case("slider_crank", slider_crank()),
        case("seed000_a", seed000_a()),
        case("seed000_b", seed000_b()),
    ]
}
