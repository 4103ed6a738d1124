//! Seed 000 §3.1: mechanism A driven by y1 = 20 sin πt, y2 = −10 sin πt,
//! y3 = 20 sin πt (mm) added to ρ = (−131.07, 181.55, −57.74), 0 ≤ t ≤ 5 s,
//! along the branch that continues from the start (`fk_follow`). Output
//! velocities and accelerations from the differentiated loop equations
//! agree with central differences of the followed positions to 1e-6 of
//! their size, and the path has no jump.

use crate::common;
use crate::mechanisms::SeedA;

use pkm::runtime::{kinematics, velocity};
use std::f64::consts::PI;

const START: [f64; 3] = [-131.07, 181.55, -57.74];
const AMPLITUDE: [f64; 3] = [20.0, -10.0, 20.0];

fn rho(t: f64) -> [f64; 3] {
    std::array::from_fn(|i| START[i] + AMPLITUDE[i] * (PI * t).sin())
}

fn rho_dot(t: f64) -> [f64; 3] {
    AMPLITUDE.map(|a| a * PI * (PI * t).cos())
}

fn rho_ddot(t: f64) -> [f64; 3] {
    AMPLITUDE.map(|a| -a * PI * PI * (PI * t).sin())
}

#[test]
fn section_3_1_trajectory() {
    let (_, model) = common::example("seed000_a");
    let p = Default::default();

    // The paper's assembly: the five-bar above the sliders (z > 0), first α root.
    let start = SeedA::fk(&p, &rho(0.0));
    let first = start
        .iter()
        .filter_map(|b| b.result.as_ref().ok())
        .find(|s| s.outputs[2] > 0.0)
        .copied()
        .unwrap();
    let (steps, dt) = (2000, 5.0 / 2000.0);
    let mut path = vec![first];
    for k in 1..=steps {
        let t = k as f64 * dt;
        let before = (k >= 2).then(|| path[k - 2]);
        let next = SeedA::fk_follow(&p, &rho(t), &path[k - 1], before.as_ref()).unwrap();
        path.push(next);
    }

    // Central differences of the followed outputs (second order; dt small).
    let (mut worst_v, mut worst_a) = (0.0f64, 0.0f64);
    for k in 2..steps - 1 {
        let t = k as f64 * dt;
        // The generated capabilities (`velocity`, `acceleration`).
        let acc = SeedA::acceleration(&p, &path[k].q, &rho_dot(t), &rho_ddot(t)).unwrap();
        let v = SeedA::output_rates(&p, &path[k].q, &acc.velocities).unwrap();
        let poses = kinematics::link_poses(&model, &path[k].q).unwrap();
        // Five-point central differences (error O(dt⁴)).
        let o = |d: isize| path[(k as isize + d) as usize].outputs;
        let fd_v: Vec<f64> = (0..4)
            .map(|i| (8.0 * (o(1)[i] - o(-1)[i]) - (o(2)[i] - o(-2)[i])) / (12.0 * dt))
            .collect();
        let speed = v.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let e = v.iter().zip(&fd_v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / speed;
        worst_v = worst_v.max(e);
        // Accelerations of the output point and of α.
        let platform = 5;
        let at = poses[platform].translation.vector;
        let acc_point = velocity::point_acceleration(&acc.velocities.twists[platform], &acc.twists[platform], &at);
        let alpha_dd = acc.twists[platform].w.x;
        let fd_a: Vec<f64> = (0..4)
            .map(|i| (-o(2)[i] + 16.0 * o(1)[i] - 30.0 * o(0)[i] + 16.0 * o(-1)[i] - o(-2)[i]) / (12.0 * dt * dt))
            .collect();
        let mine = [acc_point.x, acc_point.y, acc_point.z, alpha_dd];
        let size = mine.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let e = mine.iter().zip(&fd_a).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / size;
        worst_a = worst_a.max(e);
        // No jump: each step moves no more than its velocity allows.
        let step = (0..4).map(|i| (o(1)[i] - o(0)[i]).abs()).fold(0.0, f64::max);
        assert!(step < 2.0 * speed * dt, "jump at t = {t}");
    }
    eprintln!("§3.1: worst velocity error {worst_v:e}, acceleration {worst_a:e} (relative)");
    assert!(worst_v < 1e-6, "{worst_v:e}");
    assert!(worst_a < 1e-6, "{worst_a:e}");
}
