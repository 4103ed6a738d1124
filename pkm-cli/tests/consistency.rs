//! The held-out poses of the root package's `tests/testsuite/consistency.rs`, through
//! the command line: no wrong answer marked ok by `pkm ik` either. Its
//! independent check is the same: the Newton reference's model must close
//! at the printed joint values and reproduce the given pose to 1e-9 of the
//! mechanism's extent.

#[path = "../../tests/common/mod.rs"]
mod common;

pkm::mechanism!(SeedA, file = "../examples/mechanisms/seed000_a.pkm");

/// The same held-out poses through the command line (the plan interpreter):
/// `pkm ik --json` exits 0 only with branches that close and reproduce the
/// pose (checked by the Newton reference's model from the printed joint
/// values), and 1 with the contradicted output named when none does.
#[test]
fn held_out_poses_through_the_cli() {
    let file = "examples/mechanisms/seed000_a.pkm";
    let (_, model) = common::example("seed000_a");
    let p = SeedAParams::default();
    let mut rng = pkm::dsl::screw::SplitMix::new(21);
    let (mut ok, mut refused, mut poses) = (0, 0, 0);
    while poses < 40 {
        let q = [(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)]
            .map(|(lo, hi)| lo + (hi - lo) * (rng.symmetric() + 1.0) / 2.0);
        let Some(s) = SeedA::fk(&p, &q).into_iter().find_map(|b| b.result.ok()) else {
            continue;
        };
        poses += 1;
        let extent = pkm::runtime::consistency::extent(&s.points);
        let (given, d) = common::pushed_off(&mut rng, &s.outputs, extent);
        let pose = format!(
            "x={:e},y={:e},z={:e},alpha={:e}",
            given[0], given[1], given[2], given[3]
        );
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pkm"))
            .args(["ik", file, "--json", "--pose", &pose])
            .current_dir(common::root())
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        match out.status.code() {
            Some(0) => {
                for b in v["branches"].as_array().unwrap().iter().filter(|b| b["ok"] == true) {
                    let q: Vec<f64> = model
                        .joints
                        .iter()
                        .map(|j| b["joints"][&j.name].as_f64().unwrap())
                        .collect();
                    let e = common::inconsistency(&model, &q, "o", [1.0, 0.0, 0.0], &given, extent);
                    assert!(
                        e <= 1e-9,
                        "pose {pose} ({d:e} off): an ok branch is inconsistent by {e:e}"
                    );
                    ok += 1;
                }
            }
            Some(1) => {
                let message = v["error"]["message"].as_str().unwrap();
                assert!(message.starts_with("no branch reaches: "), "{message}");
                refused += 1;
            }
            other => panic!("exit {other:?}: {v}"),
        }
    }
    assert!(ok > 0 && refused > 0, "{ok} ok, {refused} refused");
}
