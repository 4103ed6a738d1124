//! Forward solutions of coupled mechanisms (issue 32): every real assembly,
//! each certified, by generated code (`fk_numeric`) and by the interpreter
//! (`pkm::runtime::fk_numeric::solve`), one step of a trajectory
//! (`fk_follow`), and every assembly of the 3-RPS and of Dietmaier's 6-UPS
//! by the pose equations (`pkm::runtime::ball_legs`), against PHCpack on
//! the same 3-RPR forward problem (the polynomial system of
//! `tests/phc/planar_3rpr_phc.py`) and on Dietmaier's (the pose equations
//! written out), `phc -b` as a process, the way it is used; timed only
//! where `phc` is installed: Debian package `phcpack`. The sampled κ = 1 search these replaced is
//! gone, so it is not timed here; `docs/certified.md` gives its figures.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

pkm::mechanism!(ThreeRrr, file = "examples/mechanisms/planar_3rrr.pkm");
pkm::mechanism!(ThreeRprSix, file = "examples/mechanisms/planar_3rpr_six.pkm");
pkm::mechanism!(Tripteron, file = "examples/mechanisms/tripteron.pkm");
pkm::mechanism!(Rps, file = "examples/mechanisms/rps_3.pkm");
pkm::mechanism!(UpsDietmaier, file = "tests/fixtures/ups_6_dietmaier.pkm");

/// The six-assembly 3-RPR's legs where all six are real.
const SIX: [f64; 3] = [149.8, 153.8, 120.0];

/// PHCpack's input for the six-assembly 3-RPR at `rho` (the system of
/// `tests/phc/planar_3rpr_phc.py`, written out: x, y, c, s).
fn phc_system(rho: [f64; 3]) -> String {
    let a = [(0.0, 0.0), (159.1, 0.0), (0.0, 100.0)];
    let b = [(0.0, 0.0), (170.4, 0.0), (208.4 * 0.7f64.cos(), 208.4 * 0.7f64.sin())];
    let mut out = String::from("4\nc^2 + s^2 - 1;\n");
    for i in 0..3 {
        let ((ax, ay), (bx, by)) = (a[i], b[i]);
        // (x + bx c − by s − ax)² + (y + bx s + by c − ay)² − ρ²
        out += &format!(
            "(x + {bx:e}*c - {by:e}*s - {ax:e})^2 + (y + {bx:e}*s + {by:e}*c - {ay:e})^2 - {:e};\n",
            rho[i] * rho[i]
        );
    }
    out
}

/// PHCpack's input for Dietmaier's 6-UPS: his platform in Study's
/// parameters (`tests/fixtures/dietmaier_40_phc.txt`, written by
/// `tests/phc/ball_legs_phc.py --dietmaier`; 84 paths, each pose once, the
/// 40 real roots the 40 poses). The quaternion form of
/// `pkm_runtime::ball_legs::system` takes PHCpack minutes (a Bézout count
/// of 8192 with ±q).
fn phc_dietmaier() -> String {
    std::fs::read_to_string(common::root().join("tests/fixtures/dietmaier_40_phc.txt")).unwrap()
}

/// Times `phc -0 -b` (its fixed seed) on `system` as `name`, after
/// checking once that it finds `real` real roots.
fn phc_bench(
    g: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>,
    name: &str,
    system: &str,
    real: usize,
) {
    let dir = std::env::temp_dir().join(format!("pkm-bench-phc-{}-{name}", std::process::id()).replace('/', "_"));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("in");
    std::fs::write(&input, system).unwrap();
    let output = dir.join("out");
    let run = || {
        let _ = std::fs::remove_file(&output);
        let s = std::process::Command::new("phc")
            .args(["-0", "-b"])
            .arg(&input)
            .arg(&output)
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .unwrap();
        assert!(s.success(), "phc -0 -b {} failed", input.display());
    };
    run();
    let found = std::fs::read_to_string(&output)
        .unwrap()
        .matches("real regular")
        .count();
    assert_eq!(found, real, "{name}: PHCpack's real roots");
    g.bench_function(name, |bn| bn.iter(run));
}

fn coupled(c: &mut Criterion) {
    let mut g = c.benchmark_group("coupled");
    g.sample_size(20);
    let three_rrr = ThreeRrr::prepare_fk_numeric(&Default::default());
    let q = {
        let ik = ThreeRrr::ik(&Default::default(), &[10.0, -5.0, 0.2]);
        let b = ik.iter().find_map(|b| b.result.as_ref().ok()).unwrap();
        [b.q[0], b.q[3], b.q[6]]
    };
    g.bench_function("planar_3rrr/generated", |bn| {
        bn.iter(|| three_rrr.fk_numeric(black_box(&q)))
    });
    let six = ThreeRprSix::prepare_fk_numeric(&Default::default());
    g.bench_function("planar_3rpr_six/generated", |bn| {
        bn.iter(|| six.fk_numeric(black_box(&SIX)))
    });
    let (a, model) = common::example("planar_3rpr_six");
    let vp = pkm::dsl::planner_numeric::forward_numeric_plan(&a).unwrap();
    g.bench_function("planar_3rpr_six/interpreter", |bn| {
        bn.iter(|| pkm::runtime::fk_numeric::solve(&model, &vp, black_box(&SIX)).unwrap())
    });
    let tripteron = Tripteron::prepare_fk_numeric(&Default::default());
    let qt = [20.0, -30.0, 40.0];
    g.bench_function("tripteron/generated", |bn| {
        bn.iter(|| tripteron.fk_numeric(black_box(&qt)))
    });
    // One trajectory step of the 3-RPS (κ = 2), tracked and certified.
    let (text, path) = common::example_text("rps_3");
    let c3 = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let m3 = c3.model().unwrap().clone();
    let inverse = c3.inverse().unwrap().clone();
    let start = pkm::runtime::fk_follow::at_pose(&m3, &inverse, &[300.0, 0.0, 0.0], 0).unwrap();
    let next = pkm::runtime::fk_follow::at_pose(&m3, &inverse, &[300.5, 0.0025, -0.0025], 0).unwrap();
    let q3: Vec<f64> = m3.inputs().iter().map(|&j| next.solution.values[j]).collect();
    let angles = [false, true, true];
    g.bench_function("rps_3/follow_step", |bn| {
        bn.iter(|| pkm::runtime::fk_follow::by_pose(&m3, &inverse, &angles, black_box(&q3), &start).unwrap())
    });
    // Every assembly by the pose equations: the 3-RPS (κ = 2) and
    // Dietmaier's 6-UPS (κ = 4, 40 real), each root certified; the
    // shapes' starts found before timing (once per process).
    let balls = |stem: &str| {
        let b = common::ball_legged(stem);
        let _ = pkm::runtime::ball_legs::homotopy::start(&b.legs.shape);
        (b.model, b.inverse, b.outputs, b.legs)
    };
    let (mr, ir, or, lr) = balls("rps_3");
    let qr: Vec<f64> = {
        let s = pkm::runtime::fk_follow::at_pose(&mr, &ir, &[90.0, 0.1, -0.2], 0).unwrap();
        mr.inputs().iter().map(|&j| s.solution.values[j]).collect()
    };
    g.bench_function("rps_3/every_assembly", |bn| {
        bn.iter(|| lr.solve(&mr, &ir, &or, black_box(&qr)).unwrap())
    });
    let (md, id, od, ld) = balls("tests/fixtures/ups_6_dietmaier.pkm");
    let qd = [100.0, 64.5275, 108.6284, 150.3439, 128.1933, 77.1071];
    g.bench_function("ups_6_dietmaier/every_assembly", |bn| {
        bn.iter(|| ld.solve(&md, &id, &od, black_box(&qd)).unwrap())
    });
    // The same by generated code: the runtime's roots, each root's joints
    // by the generated inverse solution.
    let rps = Rps::prepare_fk_numeric(&Default::default());
    let qr3: [f64; 3] = qr.clone().try_into().unwrap();
    g.bench_function("rps_3/every_assembly_generated", |bn| {
        bn.iter(|| rps.fk_numeric(black_box(&qr3)).unwrap())
    });
    let dietmaier = UpsDietmaier::prepare_fk_numeric(&Default::default());
    g.bench_function("ups_6_dietmaier/every_assembly_generated", |bn| {
        bn.iter(|| dietmaier.fk_numeric(black_box(&qd)).unwrap())
    });
    let loci = ld.loci(&md, &qd).unwrap();
    g.bench_function("ups_6_dietmaier/roots_certified", |bn| {
        bn.iter(|| pkm::runtime::ball_legs::solve::roots(black_box(&loci), ld.scale))
    });
    // PHCpack on the same problems, where installed.
    if std::process::Command::new("phc").arg("--version").output().is_ok() {
        phc_bench(&mut g, "planar_3rpr_six/phcpack", &phc_system(SIX), 6);
        phc_bench(&mut g, "ups_6_dietmaier/phcpack", &phc_dietmaier(), 40);
    } else {
        eprintln!("coupled: `phc` not installed (Debian package phcpack): PHCpack not timed");
    }
    g.finish();
}

criterion_group!(benches, coupled);
criterion_main!(benches);
