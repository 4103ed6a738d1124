//! The command line: `analyze`, `fk`, `ik`, `dynamics` and `export` answers (JSON by name,
//! radians or degrees), and every failure: its exit code, its message on
//! stderr, or with `--json` its `{"error": {kind, message}}` on stdout.

#[path = "../../tests/common/mod.rs"]
mod common;

use serde_json::Value;
use std::f64::consts::PI;
use std::process::{Command, Stdio};

fn pkm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pkm"))
        .args(args)
        .current_dir(common::root())
        .output()
        .unwrap()
}

fn analyze_json(file: &str) -> Value {
    let out = pkm(&["analyze", &format!("examples/mechanisms/{file}.pkm"), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// One row of the acceptance table, read back from the JSON.
fn check(file: &str, dof: u64, xi: &[u64], delta: &[i64], kappa: u64, skcs: u64) {
    let v = analyze_json(file);
    assert_eq!(v["name"], file);
    assert_eq!(v["dof"], dof, "{file}");
    assert_eq!(v["xi"], serde_json::json!(xi), "{file}");
    assert_eq!(v["delta"], serde_json::json!(delta), "{file}");
    assert_eq!(v["kappa"], kappa, "{file}");
    assert_eq!(v["skc_count"], skcs, "{file}");
    assert!(v["platform_poc"].is_string(), "{file}");
}

#[test]
fn json_for_every_example() {
    check("seed000_a", 3, &[3, 5], &[0, 0], 0, 2);
    check("seed000_b", 3, &[3, 5], &[0, 0], 0, 2);
    check("seed003_punch_original", 1, &[3, 3, 3], &[0, 1, -1], 1, 2);
    check("seed003_punch", 1, &[3, 3, 3], &[0, 0, 0], 0, 3);
    check("four_bar", 1, &[3], &[0], 0, 1);
    check("slider_crank", 1, &[3], &[0], 0, 1);
    check("five_bar", 2, &[3], &[0], 0, 1);
    check("planar_3rrr", 3, &[3, 3], &[1, -1], 1, 1);
    check("rps_3", 3, &[6, 6], &[2, -2], 2, 1);
    check("spr_3", 3, &[6, 6], &[2, -2], 2, 1);
    check("watt_six_bar", 1, &[3, 3], &[0, 0], 0, 2);
    check("seed000_a_u", 3, &[3, 5], &[0, 0], 0, 2);
    check("upu_3", 3, &[6, 6], &[2, -2], 2, 1);
    check("ups_6", 6, &[6, 6, 6, 6, 6], &[4, -1, -1, -1, -1], 4, 1);
}

#[test]
fn json_platform_poc_of_a() {
    let v = analyze_json("seed000_a");
    assert_eq!(v["platform_poc"], "[t²(∥◇xoz); r¹(∥R6)]");
    assert_eq!(v["platform_poc_ascii"], "[t^2(||<>xoz); r^1(||R6)]");
    assert_eq!(v["decoupling"]["x"], serde_json::json!(["P1", "P2"]));
}

#[test]
fn text_report() {
    let out = pkm(&["analyze", "examples/mechanisms/seed003_punch.pkm"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("SOC2 {D∥G∥H}"), "{text}");
    assert!(text.contains("κ = 0"), "{text}");
}

/// A mechanism file written for one test (the examples have no errors).
fn scratch_file(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("pkm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// An unknown joint at line 4, column 8.
const BAD_PKM: &str = "mechanism m {\n  planar;\n  base R1* ∥ R2 ∥ R3 ∥ R4 base;\n  R2 ∥ R9;\n}\n";

const FOUR_BAR: &str = "examples/mechanisms/four_bar.pkm";
const RRR: &str = "examples/mechanisms/planar_3rrr.pkm";
const SEED000_A: &str = "examples/mechanisms/seed000_a.pkm";

/// Runs `args` twice: as text, expecting exit `code`, nothing on stdout and
/// `message` on stderr; with `--json`, expecting exit `code` and one error
/// object of `kind` whose message contains `message`.
fn check_failure(args: &[&str], code: i32, kind: &str, message: &str) {
    let out = pkm(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(
        out.stdout.is_empty(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(err.contains(message), "{args:?}: `{message}` not in {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");

    let with_json: Vec<&str> = args.iter().copied().chain(["--json"]).collect();
    let out = pkm(&with_json);
    assert_eq!(out.status.code(), Some(code), "{with_json:?}");
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{with_json:?}: not JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    });
    assert_eq!(v["error"]["kind"], kind, "{with_json:?}: {v}");
    let text = v["error"]["message"].as_str().unwrap();
    assert!(
        text.contains(message.trim_start_matches("error: ")),
        "{with_json:?}: `{message}` not in {v}"
    );
}

#[test]
fn every_failure_names_its_cause() {
    let bad = scratch_file("bad.pkm", BAD_PKM);
    // The four-bar with its crank length given as a square root.
    let four_bar = std::fs::read_to_string(common::root().join(FOUR_BAR)).unwrap();
    let root = scratch_file(
        "root.pkm",
        &four_bar
            .replace("l1 = 100;", "l1 = 100; area = 10000;")
            .replace("R2 = (l1, 0)", "R2 = (sqrt(area), 0)"),
    );
    // The 3-RRR without `fk_numeric`: plain `fk` is refused.
    let rrr = plain_rrr();
    // One row per failure: arguments, exit code, error kind, what the message says.
    #[rustfmt::skip]
    let rows: &[(&[&str], i32, &str, &str)] = &[
        // The files.
        (&["analyze", "no/such/file.pkm"], 1, "io", "cannot read `no/such/file.pkm`"),
        (&["fk", "no/such/file.pkm", "--q", "1"], 1, "io", "cannot read `no/such/file.pkm`"),
        (&["analyze", &bad], 1, "parse", "error: unknown joint `R9`"),
        (&["fk", &bad, "--q", "1"], 1, "parse", "unknown joint `R9`"),
        (&["fk", &rrr, "--q", "1,2,3"], 1, "parse", "a closed-form forward plan needs κ = 0 (κ = 1)"),
        // With `fk_numeric`: the inputs checked, and no root is no assembly.
        (&["fk", RRR, "--q", "1,2"], 1, "input", "expected 3 input values (R1, R4, R7), found 2"),
        (&["fk", RRR, "--q", "9,9,9"], 1, "unreachable", "no assembly: the compatibility residual has no root over R2's range"),
        // Input values, checked before solving.
        (&["fk", FOUR_BAR, "--q", "1,2"], 1, "input", "expected 1 input value (R1), found 2"),
        (&["fk", SEED000_A, "--q", "1,2"], 1, "input", "expected 3 input values (P1, P2, P3), found 2"),
        (&["fk", FOUR_BAR, "--q", "NaN"], 1, "input", "input R1 (--q value 1) is NaN"),
        (&["fk", FOUR_BAR, "--q", "inf"], 1, "input", "input R1 (--q value 1) = inf is not finite"),
        (&["fk", SEED000_A, "--q=1,-inf,2"], 1, "input", "input P2 (--q value 2) = -inf is not finite"),
        (&["ik", RRR, "--pose", "x=1"], 1, "input", "missing output `y`; give x, y, phi"),
        (&["ik", RRR, "--pose", "x=1,y=2,w=3"], 1, "input", "unknown output `w`; the outputs are x, y, phi"),
        (&["ik", RRR, "--pose", "x=NaN,y=2,phi=0"], 1, "input", "output x is NaN"),
        (&["ik", RRR, "--pose", "x=1,y=2,phi=0,x=3"], 1, "input", "output x is given twice"),
        // Parameters.
        (&["fk", FOUR_BAR, "--q", "1", "--param", "zz=1"], 1, "input", "unknown parameter `zz`; the parameters are l1, l2, l3, l4"),
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l1=NaN"], 1, "input", "parameter l1 is NaN"),
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l1=inf"], 1, "input", "parameter l1 = inf is not finite"),
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l1=90", "--param", "l1=80"], 1, "input", "parameter l1 is given twice"),
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l2=-5"], 1, "input", "parameter l2 = -5 must be positive: the distance R2–R3 on link coupler"),
        (&["ik", FOUR_BAR, "--pose", "psi=2", "--param", "l3=0"], 1, "input", "parameter l3 = 0 puts R3 and R4 of link rocker at one point"),
        (&["fk", &root, "--q", "1", "--param", "area=-1"], 1, "input", "at the given parameters joint R2's place on link crank is not finite"),
        // No branch (the reasons are the runtime's; see no_branch_message_lists_each_reason_once).
        // l1 = 1000: |R2R4| ≥ 1000 − 300 = 700 > l2 + l3 = 450, so R3 exists on neither branch.
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l1=1000"], 1, "unreachable", "no branch reaches: "),
        // The 3-RRR's base joints are 250 from the centre and its legs reach 300 (+ 60 on the platform).
        (&["ik", RRR, "--pose", "x=1000,y=0,phi=0"], 1, "unreachable", "no branch reaches: "),
        // A's platform point o keeps y = −a = −300 (its POC has no y translation): y = −250 over-determines it.
        (&["ik", SEED000_A, "--pose=x=37.79,y=-250,z=-38.92,alpha=0.7097"], 1, "inconsistent", "no branch reaches: the given values are inconsistent: y = -250 cannot be reached with the others, the nearest reachable value is -300 "),
        // The report's failures (its own messages).
        (&["report", FOUR_BAR, "--out", "target/cli-report", "--ranges=0:1,0:1"], 1, "report", "expected 1 ranges"),
        // The command line itself (clap): exit code 2.
        (&["fk", FOUR_BAR, "--q", "1", "--param", "l1=abc"], 2, "usage", "`abc` is not a number"),
        (&["fk", FOUR_BAR], 2, "usage", "--q <Q>"),
    ];
    for (args, code, kind, message) in rows {
        check_failure(args, *code, kind, message);
    }
}

/// The refusal of a forward solution with κ ≠ 0 names the coupled SKC,
/// its SOCs' Δ (the 3-RRR's, +1 and −1 by paper_topology's rules) and the
/// virtual variables a forward solution would need, as the compile error does.
#[test]
fn coupled_forward_refusal_names_the_skc() {
    let out = pkm(&["fk", &plain_rrr(), "--q", "1,2,3"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for part in [
        "SKC1 = SOC1 {R1∥R2∥R3∥R6∥R5∥R4} + SOC2 {R9∥R8∥R7}",
        "has Δ = (+1, −1), so κ1 = ½Σ|Δ| = 1",
        "needs 1 virtual variable solved by iteration",
    ] {
        assert!(err.contains(part), "`{part}` not in {err}");
    }
}

/// The 3-RRR as a file that does not ask for `fk_numeric`.
fn plain_rrr() -> String {
    let text = std::fs::read_to_string(common::root().join(RRR)).unwrap();
    scratch_file(
        "rrr_plain.pkm",
        &text.replace("capabilities ik, fk_numeric;", "capabilities ik;"),
    )
}

/// `pkm fk` of a κ = 1 file that asks for `fk_numeric`: the Stephenson III
/// at crank angle 1 has two assemblies (Newton's from 10⁴ starts, see
/// tests/fk_numeric.rs), each with the virtual variable's value, and each
/// keeps the crank at 1 and the binary links' lengths (by hand: 50√2, 200).
#[test]
fn fk_numeric_lists_every_assembly() {
    let v = run_json(&["fk", "examples/mechanisms/stephenson3.pkm", "--q", "1"]);
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 2, "{v}");
    assert_eq!(v["virtual"], "R2");
    let p = |b: &serde_json::Value, n: &str| -> [f64; 2] {
        let a = b["points"][n].as_array().unwrap();
        [a[0].as_f64().unwrap(), a[1].as_f64().unwrap()]
    };
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    for b in branches {
        assert!(b["virtual"]["R2"].is_number(), "{b}");
        assert_eq!(b["joints"]["R1"].as_f64(), Some(1.0));
        assert!((d(p(b, "R4"), p(b, "R5")) - 50.0 * 2f64.sqrt()).abs() < 1e-9, "{b}");
        assert!((d(p(b, "R6"), p(b, "R7")) - 200.0).abs() < 1e-9, "{b}");
    }
}

#[test]
fn no_branch_message_lists_each_reason_once() {
    // Both branches fail at R3 for the same reason: the message says it
    // once (its wording is the runtime's SolveError's).
    let out = pkm(&["fk", FOUR_BAR, "--q", "1", "--param", "l1=1000"]);
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("error: no branch reaches: "), "{err}");
    assert_eq!(err.matches("R3").count(), 1, "{err}");
    // The 3-RRR's x = 1000 is out of reach of every leg; the branches fail at the first.
    let out = pkm(&["ik", RRR, "--pose", "x=1000,y=0,phi=0"]);
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("R2"), "{err}");
}

#[test]
fn parse_errors_in_json_carry_the_file_line_and_column() {
    let bad = scratch_file("bad_json.pkm", BAD_PKM);
    for args in [
        vec!["analyze", &bad, "--json"],
        vec!["--json", "ik", &bad, "--pose", "x=1"],
    ] {
        let out = pkm(&args);
        assert_eq!(out.status.code(), Some(1));
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        let e = &v["error"];
        assert_eq!(e["kind"], "parse");
        assert_eq!(e["message"], "unknown joint `R9`");
        assert_eq!(e["file"], bad.as_str());
        assert_eq!((e["line"].as_u64(), e["column"].as_u64()), (Some(4), Some(8)), "{v}");
        assert_eq!(e["diagnostics"][0]["label"], "not declared");
    }
    // The text form keeps the caret picture.
    let err = String::from_utf8(pkm(&["analyze", &bad]).stderr).unwrap();
    assert!(err.contains("bad_json.pkm:4:8"), "{err}");
    assert!(err.contains("       ^^ not declared"), "{err}");
}

fn run_json(args: &[&str]) -> Value {
    let with_json: Vec<&str> = args.iter().copied().chain(["--json"]).collect();
    let out = pkm(&with_json);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn dist(a: &Value, b: &Value) -> f64 {
    (0..3).map(|k| (num(&a[k]) - num(&b[k])).powi(2)).sum::<f64>().sqrt()
}

/// The keys a script can rely on, with the ok branches' groups by name.
fn check_schema(v: &Value, given: &str) {
    for key in ["name", given, "units", "branches"] {
        assert!(!v[key].is_null(), "no `{key}` in {v}");
    }
    assert_eq!(v["units"]["length"], "file unit");
    for b in v["branches"].as_array().unwrap() {
        assert!(b["signs"].is_array(), "{b}");
        if b["ok"] == true {
            for key in ["joints", "inputs", "outputs", "points"] {
                assert!(b[key].is_object(), "no `{key}` in {b}");
            }
        } else {
            assert_eq!(b["ok"], false, "{b}");
            assert!(b["reason"].is_string(), "{b}");
        }
    }
}

#[test]
fn fk_by_name() {
    let v = run_json(&["fk", "examples/mechanisms/slider_crank.pkm", "--q", "1.0"]);
    check_schema(&v, "inputs");
    assert_eq!(v["units"]["angle"], "rad");
    assert_eq!(v["inputs"]["R1"], 1.0);
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 2);
    // r cos 1 ± sqrt(l² − r² sin² 1) with r = 50, l = 180.
    let (r, l) = (50.0f64, 180.0f64);
    let root = (l * l - (r * 1f64.sin()).powi(2)).sqrt();
    for (b, want) in branches.iter().zip([r * 1f64.cos() + root, r * 1f64.cos() - root]) {
        assert_eq!(b["ok"], true);
        assert!((num(&b["joints"]["P1"]) - want).abs() < 1e-9, "{b}");
        // The declared output `s = joint P1`, and the input.
        assert!((num(&b["outputs"]["s"]) - want).abs() < 1e-9, "{b}");
        assert_eq!(b["inputs"]["R1"], 1.0);
        assert!((num(&b["points"]["R3"][0]) - want).abs() < 1e-9, "{b}");
    }
}

#[test]
fn text_answer_is_the_json_indented() {
    let args = ["fk", FOUR_BAR, "--q", "1.0"];
    let out = pkm(&args);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().count() > 10, "{text}");
    assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), run_json(&args));
}

#[test]
fn planar_outputs_reproduce_the_pose_given_to_ik() {
    // The four-bar given its rocker angle psi (a joint output).
    let v = run_json(&["ik", FOUR_BAR, "--pose", "psi=2.0"]);
    check_schema(&v, "pose");
    assert_eq!(v["pose"]["psi"], 2.0);
    let ok: Vec<&Value> = v["branches"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["ok"] == true)
        .collect();
    assert_eq!(ok.len(), 2);
    for b in ok {
        assert!((num(&b["outputs"]["psi"]) - 2.0).abs() < 1e-9, "{b}");
        // The links keep their declared lengths l1 = 100, l2 = 250, l3 = 200.
        let p = &b["points"];
        assert!((dist(&p["R1"], &p["R2"]) - 100.0).abs() < 1e-9, "{b}");
        assert!((dist(&p["R2"], &p["R3"]) - 250.0).abs() < 1e-9, "{b}");
        assert!((dist(&p["R3"], &p["R4"]) - 200.0).abs() < 1e-9, "{b}");
        // The crank angle found drives the forward solution back to psi on one of its branches.
        let q = num(&b["inputs"]["R1"]).to_string();
        let fk = run_json(&["fk", FOUR_BAR, "--q", &q]);
        let back: Vec<f64> = fk["branches"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| num(&f["outputs"]["psi"]))
            .collect();
        assert!(back.iter().any(|psi| (psi - 2.0).abs() < 1e-9), "{back:?}");
    }

    // The 3-RRR given its platform's pose (x, y, phi at o).
    let v = run_json(&["ik", RRR, "--pose", "x=10,y=20,phi=0.2"]);
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 8);
    for b in branches {
        assert_eq!(b["inputs"].as_object().unwrap().len(), 3, "{b}");
        for (name, want) in [("x", 10.0), ("y", 20.0), ("phi", 0.2)] {
            assert!((num(&b["outputs"][name]) - want).abs() < 1e-9, "{name} in {b}");
        }
        // The platform centre is where it was asked to be.
        let o = &b["points"]["o"];
        assert!(dist(o, &serde_json::json!([10.0, 20.0, 0.0])) < 1e-9, "{b}");
    }

    // The five-bar given a point alone (x, y of R3).
    let v = run_json(&["ik", "examples/mechanisms/five_bar.pkm", "--pose", "x=10,y=200"]);
    for b in v["branches"].as_array().unwrap() {
        assert_eq!(b["outputs"].as_object().unwrap().len(), 2, "{b}");
        assert!((num(&b["outputs"]["x"]) - 10.0).abs() < 1e-9 && (num(&b["outputs"]["y"]) - 200.0).abs() < 1e-9);
    }
}

#[test]
fn degrees_are_radians_times_180_over_pi() {
    let rad = run_json(&["fk", FOUR_BAR, "--q", "1"]);
    let deg = run_json(&["fk", FOUR_BAR, "--q", &(180.0 / PI).to_string(), "--degrees"]);
    assert_eq!(deg["units"]["angle"], "deg");
    for (r, d) in rad["branches"]
        .as_array()
        .unwrap()
        .iter()
        .zip(deg["branches"].as_array().unwrap())
    {
        for j in ["R1", "R2", "R3", "R4"] {
            let want = num(&r["joints"][j]) * 180.0 / PI;
            assert!((num(&d["joints"][j]) - want).abs() < 1e-9, "{j}: {d}");
        }
        assert!((num(&d["outputs"]["psi"]) - num(&r["outputs"]["psi"]) * 180.0 / PI).abs() < 1e-9);
        // Lengths stay lengths.
        assert!(dist(&d["points"]["E"], &r["points"]["E"]) < 1e-9);
    }

    // ik: an angular output given in degrees, a length output unchanged; prismatic joints stay lengths.
    let rad = run_json(&["ik", RRR, "--pose", "x=10,y=20,phi=0.2"]);
    let deg = run_json(&[
        "ik",
        RRR,
        "--pose",
        &format!("x=10,y=20,phi={}", 0.2 * 180.0 / PI),
        "--degrees",
    ]);
    for (r, d) in rad["branches"]
        .as_array()
        .unwrap()
        .iter()
        .zip(deg["branches"].as_array().unwrap())
    {
        assert!((num(&d["outputs"]["phi"]) - 0.2 * 180.0 / PI).abs() < 1e-9, "{d}");
        assert!((num(&d["outputs"]["x"]) - 10.0).abs() < 1e-9, "{d}");
        assert!((num(&d["inputs"]["R1"]) - num(&r["inputs"]["R1"]) * 180.0 / PI).abs() < 1e-9);
    }
    let s = run_json(&[
        "ik",
        "examples/mechanisms/slider_crank.pkm",
        "--pose",
        "s=200",
        "--degrees",
    ]);
    for b in s["branches"].as_array().unwrap() {
        assert!((num(&b["joints"]["P1"]) - 200.0).abs() < 1e-9, "{b}");
    }
}

#[test]
fn json_is_accepted_before_and_after_the_subcommand() {
    for args in [
        ["--json", "analyze", "examples/mechanisms/four_bar.pkm"],
        ["analyze", "examples/mechanisms/four_bar.pkm", "--json"],
    ] {
        let out = pkm(&args);
        assert!(out.status.success());
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["dof"], 1);
    }
}

#[test]
fn a_closed_stdout_is_not_a_panic() {
    // The reader is gone before pkm writes: the write fails with a broken
    // pipe, which ends pkm quietly with code 0.
    for args in [
        vec!["fk", "examples/mechanisms/watt_six_bar.pkm", "--q", "1"],
        vec!["analyze", "examples/mechanisms/seed000_a.pkm"],
        vec!["fk", FOUR_BAR, "--q", "1", "--param", "l1=1000", "--json"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_pkm"))
            .args(&args)
            .current_dir(common::root())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        // A failure keeps its code even when no one reads the error object.
        let want = if args.contains(&"l1=1000") { 1 } else { 0 };
        assert_eq!(out.status.code(), Some(want), "{args:?}: {err}");
    }
}

#[test]
fn spatial_outputs_round_trip_through_ik() {
    let q = [-106.09, 181.67, -70.29];
    let fk = run_json(&["fk", SEED000_A, "--q=-106.09,181.67,-70.29"]);
    check_schema(&fk, "inputs");
    let ok: Vec<&Value> = fk["branches"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["ok"] == true)
        .collect();
    assert!(!ok.is_empty());
    for b in ok {
        // `x, y, z, alpha = pose of platform at o about x`: x, y, z are o's position.
        let o = &b["points"]["o"];
        let xyz = serde_json::json!([b["outputs"]["x"], b["outputs"]["y"], b["outputs"]["z"]]);
        assert!(dist(o, &xyz) < 1e-9, "{b}");
        // Given those outputs, one inverse branch has the inputs fk was given.
        let pose: Vec<String> = ["x", "y", "z", "alpha"]
            .iter()
            .map(|n| format!("{n}={}", num(&b["outputs"][n])))
            .collect();
        let ik = run_json(&["ik", SEED000_A, &format!("--pose={}", pose.join(","))]);
        let back = ik["branches"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|i| i["ok"] == true)
            .any(|i| {
                ["P1", "P2", "P3"]
                    .iter()
                    .zip(q)
                    .all(|(n, v)| (num(&i["inputs"][n]) - v).abs() < 1e-6)
            });
        assert!(back, "{b}\n{ik}");
    }
}

/// A U joint's two values by name: seed000_a_u's fk and ik report `U1.a`
/// and `U1.b` (and no `U1`), every other joint as seed000_a reports it at
/// the same inputs, and the U's centre where seed000_a's R3 and R4 meet.
#[test]
fn u_joint_values_by_name() {
    let with_u = "examples/mechanisms/seed000_a_u.pkm";
    let q = "--q=-106.09,181.67,-70.29";
    let (u, a) = (run_json(&["fk", with_u, q]), run_json(&["fk", SEED000_A, q]));
    check_schema(&u, "inputs");
    let (ub, ab) = (u["branches"].as_array().unwrap(), a["branches"].as_array().unwrap());
    assert_eq!(ub.len(), ab.len());
    let mut ok = 0;
    for (bu, ba) in ub.iter().zip(ab).filter(|(b, _)| b["ok"] == true) {
        let joints = bu["joints"].as_object().unwrap();
        assert!(
            joints["U1.a"].is_number() && joints["U1.b"].is_number() && !joints.contains_key("U1"),
            "{bu}"
        );
        for (name, value) in ba["joints"].as_object().unwrap() {
            if name != "R3" && name != "R4" {
                assert!((num(value) - num(&joints[name])).abs() < 1e-9, "{name}: {bu}");
            }
        }
        for half in ["U1.a", "U1.b"] {
            assert!(dist(&bu["points"][half], &ba["points"]["R3"]) < 1e-9, "{bu}");
        }
        // Its outputs through ik: one branch gives the inputs back, with its U's values.
        let pose: Vec<String> = ["x", "y", "z", "alpha"]
            .iter()
            .map(|n| format!("{n}={}", num(&bu["outputs"][n])))
            .collect();
        let ik = run_json(&["ik", with_u, &format!("--pose={}", pose.join(","))]);
        let back = ik["branches"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|i| i["ok"] == true)
            .any(|i| {
                ["P1", "P2", "P3", "U1.a", "U1.b"]
                    .iter()
                    .all(|n| (num(&i["joints"][n]) - num(&bu["joints"][n])).abs() < 1e-6)
            });
        assert!(back, "{bu}\n{ik}");
        ok += 1;
    }
    assert!(ok > 0);
}

/// Dynamics through a U joint: seed000_a (masses, payload, gravity) with its
/// R3 [cross] ⊥ R4 written as the U joint U1, whose cross is massless by
/// itself, gives seed000_a's actuator forces on every branch.
#[test]
fn u_joint_dynamics_is_the_written_out_revolutes() {
    let text = std::fs::read_to_string(common::root().join(SEED000_A)).unwrap();
    let mut with_u = text.clone();
    for (from, to) in [
        ("c2 R3 [cross] ⊥ R4 platform;", "c2 U1 platform;"),
        ("R3 ≡ R12;", "U1.a ≡ R12;"),
        ("R4 ∥ R5 ∥ R6;", "U1.b ∥ R5 ∥ R6;"),
        ("point o on R4;", "point o on U1;"),
        (
            "R12 = (0, 0, 0) along y; R3 = (0, 0, 0) along y;",
            "R12 = (0, 0, 0) along y; U1 = (0, 0, 0) along y;",
        ),
        ("cross { R3 = (0, 0, 0) along y; R4 = (0, 0, 0) along x; }", ""),
        (
            "platform { R4 = (0, 0, 0) along x;",
            "platform { U1 = (0, 0, 0) along x;",
        ),
        ("massless cross, r5, pc;", "massless r5, pc;"),
    ] {
        assert_eq!(with_u.matches(from).count(), 1, "{from}");
        with_u = with_u.replace(from, to);
    }
    let with_u = scratch_file("seed000_a_with_u.pkm", &with_u);
    for q in ["--q=-106.09,181.67,-70.29", "--q=-200,50,120"] {
        let rates = "--rates=10,-20,30";
        let (a, u) = (
            run_json(&["dynamics", SEED000_A, q, rates]),
            run_json(&["dynamics", &with_u, q, rates]),
        );
        let (ab, ub) = (a["branches"].as_array().unwrap(), u["branches"].as_array().unwrap());
        assert_eq!(ab.len(), ub.len());
        let mut ok = 0;
        for (ba, bu) in ab.iter().zip(ub).filter(|(b, _)| b["ok"] == true) {
            for n in ["P1", "P2", "P3"] {
                let (fa, fu) = (num(&ba["actuators"][n]), num(&bu["actuators"][n]));
                assert!((fa - fu).abs() < 1e-9 * (1.0 + fa.abs()), "{n}: {fa} vs {fu}");
            }
            ok += 1;
        }
        assert!(ok > 0, "{q}");
    }
}

/// The README's JSON example is what `pkm fk` prints for its command.
#[test]
fn readme_json_example_is_the_real_output() {
    let readme = std::fs::read_to_string(common::root().join("README.md")).unwrap();
    let after = readme
        .split("`pkm fk examples/mechanisms/slider_crank.pkm --q 1`:")
        .nth(1)
        .expect("the README's JSON example");
    let block = after
        .split("```json")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .unwrap();
    let shown: Value = serde_json::from_str(block).unwrap();
    let out = pkm(&["fk", "examples/mechanisms/slider_crank.pkm", "--q", "1"]);
    assert!(out.status.success());
    assert_eq!(serde_json::from_slice::<Value>(&out.stdout).unwrap(), shown);
}

/// A file over the size limit is refused before it is read, naming the limit.
#[test]
fn a_file_over_the_size_limit_is_refused() {
    let path = std::env::temp_dir().join("pkm_cli_too_big.pkm");
    std::fs::write(&path, " ".repeat(pkm::dsl::limits::MAX_FILE_BYTES + 1)).unwrap();
    let out = pkm(&["analyze", path.to_str().unwrap()]);
    std::fs::remove_file(&path).ok();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("the limit is 262144 bytes"), "{err}");
}

/// `pkm dynamics` on seed 003's punch at φ = 0.5 rad, ω = 1 rad/s: the
/// crank torque of the branch the paper draws equals virtual work's
/// (computed here through the library, a path `pkm dynamics` does not
/// take), torques in N·mm; a reaction names the links it acts between.
#[test]
fn dynamics_of_the_punch() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let v = run_json(&["dynamics", punch, "--q=0.5", "--rates=1"]);
    assert_eq!(v["units"]["torque"], "N·mm");
    let branches = v["branches"].as_array().unwrap();
    let (text, path) = common::example_text("seed003_punch");
    let c = pkm::dsl::compile(&text).unwrap_or_else(|d| panic!("{}", d.render(&text, &path)));
    let model = pkm::dsl::numeric::model(&c.analysis, &Default::default()).unwrap();
    let loading = pkm::dsl::numeric::loading(&c.analysis, &model, &Default::default()).unwrap();
    use pkm::runtime::primitives::Sign::{Minus, Plus};
    let plan = c.forward().unwrap();
    let values = plan.solve(&model, &[0.5], &[Minus, Minus, Plus]).unwrap();
    let want = pkm::runtime::virtual_work::actuator_forces(&model, &loading, &values, &[1.0], &[0.0]).unwrap()[0];
    let paper = branches
        .iter()
        .find(|b| b["signs"] == serde_json::json!(["-", "-", "+"]))
        .expect("the paper's branch");
    assert_eq!(paper["ok"], true);
    let got = num(&paper["actuators"]["A"]);
    assert!((got - want).abs() < 1e-9 * want.abs(), "{got} against {want}");
    assert_eq!(paper["reactions"]["G.2"]["by"], "7");
    assert_eq!(paper["reactions"]["G.2"]["on"], "5");
    assert_eq!(paper["undetermined"], serde_json::json!([0, 0, 0]));
}

#[test]
fn dynamics_failures_name_their_cause() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    check_failure(
        &["dynamics", FOUR_BAR, "--q=0.5"],
        1,
        "input",
        "dynamics needs the file's units and masses",
    );
    check_failure(
        &["dynamics", punch, "--q=0.5", "--rates=1,2"],
        1,
        "input",
        "--rates: expected 1 input value (A), found 2",
    );
    check_failure(&["dynamics", punch, "--q=NaN"], 1, "input", "A (--q value 1) is NaN");
}

/// `pkm export --mjcf` on seed 003's punch: Table 1's masses and inertias
/// in SI (kg·mm² to kg·m² is 1e-6), the crank's pivot A at (m, n) =
/// (235, 205) mm in metres, the crank angle `ref` the --q given, a motor
/// on A, gravity as the file's. MuJoCo itself reads the files in
/// tests/mujoco/test_mujoco.py.
#[test]
fn export_of_the_punch() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let v = run_json(&["export", punch, "--mjcf", "--q=0.5"]);
    let xml = v["mjcf"].as_str().unwrap();
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    // The attribute `key` of the first element opening with `start`.
    let attribute = |start: &str, key: &str| {
        let at = xml.find(start).unwrap_or_else(|| panic!("{start} not in {xml}"));
        attribute_of(&xml[at..], key)
    };
    assert_eq!(v["metres_per_unit"], 0.001);
    let body1 = attribute("<body name=\"1\"", "pos");
    assert!(
        near(body1[0], 0.235) && near(body1[1], 0.205) && body1[2] == 0.0,
        "{body1:?}"
    );
    assert!(near(attribute("<joint name=\"A\"", "ref")[0], 0.5));
    // Link 2: 0.01703 kg, 12.534 kg·mm² about z (its moments about x and y set equal).
    let at2 = xml.find("<body name=\"2\"").unwrap();
    let inertial = &xml[at2 + xml[at2..].find("<inertial").unwrap()..];
    let (mass, inertia) = (attribute_of(inertial, "mass"), attribute_of(inertial, "fullinertia"));
    assert!(near(mass[0], 0.01703), "{mass:?}");
    assert!(
        near(inertia[2], 12.534e-6) && near(inertia[0], 12.534e-6),
        "{inertia:?}"
    );
    assert_eq!(attribute("<option", "gravity"), vec![0.0, -9.80665, 0.0]);
    assert!(xml.contains("<motor name=\"A\" joint=\"A\""), "{xml}");
    // Three loops, each closed where a revolute is cut.
    assert_eq!(xml.matches("<connect ").count(), 3, "{xml}");
    assert_eq!(v["cut"].as_array().unwrap().len(), 3);
    assert_eq!(v["actuators"]["A"]["unit"], "N·m");
    assert!(near(v["actuators"]["A"]["to_pkm"].as_f64().unwrap(), 1000.0));
    // The slides' qpos is in metres: P2's scale is 0.001 per mm.
    assert!(near(v["joints"]["P2"]["scale"].as_f64().unwrap(), 0.001));
    // Written to a file: the same text.
    let out = scratch_file("punch.xml", "");
    let written = run_json(&["export", punch, "--mjcf", "--q=0.5", "-o", &out]);
    assert_eq!(written["file"], out.as_str());
    assert_eq!(std::fs::read_to_string(&out).unwrap(), xml);
}

/// The first `key="…"` in `text`, as numbers.
fn attribute_of(text: &str, key: &str) -> Vec<f64> {
    let from = text.find(&format!(" {key}=\"")).unwrap() + key.len() + 3;
    let value = &text[from..from + text[from..].find('"').unwrap()];
    value.split(' ').map(|x| x.parse::<f64>().unwrap()).collect()
}

#[test]
fn export_failures_name_their_cause() {
    check_failure(
        &["export", FOUR_BAR, "--mjcf"],
        1,
        "input",
        "export needs the file's units and masses",
    );
    // A moving link with neither a mass nor `massless`: named.
    let no_rocker = common::example_with(
        "four_bar",
        "units { length = mm; mass = kg; } masses { crank { mass = 1; centroid = (0, 0); } coupler { mass = 1; centroid = (0, 0); } }",
    );
    let path = scratch_file("four_bar_no_rocker.pkm", &no_rocker);
    let out = pkm(&["export", &path, "--mjcf"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("rocker has none"), "{err}");
    // Nothing but massless links: nothing MuJoCo can move.
    let massless = common::example_with(
        "four_bar",
        "units { length = mm; mass = kg; } masses { massless crank, coupler, rocker; }",
    );
    let path = scratch_file("four_bar_massless.pkm", &massless);
    check_failure(
        &["export", &path, "--mjcf"],
        1,
        "input",
        "every moving link is massless",
    );
    check_failure(
        &[
            "export",
            "examples/mechanisms/seed003_punch.pkm",
            "--mjcf",
            "--timestep=0",
        ],
        1,
        "input",
        "--timestep = 0 is not a positive time",
    );
    check_failure(
        &["export", "examples/mechanisms/seed003_punch.pkm", "--mjcf", "--q=1,2"],
        1,
        "input",
        "--q: expected 1 input value (A), found 2",
    );
}

/// `pkm dynamics --states`: each line answers as `--q/--rates/--accels`
/// would, with every joint's motion (the input's own as given); a line
/// without an answer holds its error.
#[test]
fn dynamics_at_many_states() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let states = scratch_file("punch.states", "# q, rate, accel\n0.5, 1, 2\n\n1.0, -2, 0.5\nNaN\n");
    let v = run_json(&["dynamics", punch, "--states", &states]);
    let all = v["states"].as_array().unwrap();
    assert_eq!(all.len(), 3);
    for (state, args) in all.iter().zip([
        ["--q=0.5", "--rates=1", "--accels=2"],
        ["--q=1.0", "--rates=-2", "--accels=0.5"],
    ]) {
        let one = run_json(&[&["dynamics", punch][..], &args[..]].concat());
        assert_eq!(state["branches"], one["branches"]);
    }
    let motion = &all[0]["branches"][0]["motion"];
    assert_eq!(motion["values"]["A"], 0.5);
    assert_eq!(motion["rates"]["A"], 1.0);
    assert_eq!(motion["accelerations"]["A"], 2.0);
    assert!(all[2]["error"].as_str().unwrap().contains("is NaN"), "{}", all[2]);
}

const RPS_3: &str = "examples/mechanisms/rps_3.pkm";

/// `pkm stiffness` on seed 004's 3-RPS at home (Z_A = 75 mm, level): the
/// legs √(20² + 75²) long, leaning in by 20/L, their R axes tangent, so at
/// the platform centre K_zz = 3·k_a·(75/L)², K_xx = K_yy = (3/2)·(k_a·(20/L)²
/// + k_c) with k_a = E·A/L, k_c = 3·E·I/L³ (seed 004 eqs. 13–17), by hand.
#[test]
fn stiffness_of_the_3rps_at_home_by_hand() {
    let v = run_json(&[
        "stiffness",
        RPS_3,
        "--pose",
        "ZA=75,alpha=0,beta=0",
        "--wrench",
        "10,-15,20,-20000,10000,15000",
    ]);
    let (e, a, i) = (2.11e5, std::f64::consts::PI * 400.0, 1.256e5);
    let l = (20.0f64 * 20.0 + 75.0 * 75.0).sqrt();
    let (ka, kc) = (e * a / l, 3.0 * e * i / l.powi(3));
    let kzz = 3.0 * ka * (75.0 / l).powi(2);
    let kxx = 1.5 * (ka * (20.0 / l).powi(2) + kc);
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs();
    let mut home = 0;
    for b in v["branches"].as_array().unwrap() {
        let lengths: Vec<f64> = b["limbs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| num(&l["length"]))
            .collect();
        // The drawn assembly (the others turn the platform half a turn).
        if !lengths.iter().all(|&x| near(x, l)) {
            continue;
        }
        home += 1;
        let k = |r: usize, c: usize| num(&b["K"][r][c]);
        assert!(
            near(k(2, 2), kzz) && near(k(0, 0), kxx) && near(k(1, 1), kxx),
            "{}",
            b["K"]
        );
        // Every row's spring is the seed's: three E·A/L, three 3·E·I/L³.
        let springs: Vec<f64> = b["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| num(&r["spring"]))
            .collect();
        assert!(
            springs[..3].iter().all(|&s| near(s, ka)) && springs[3..].iter().all(|&s| near(s, kc)),
            "{springs:?}"
        );
        // A vertical load sinks the level platform by F/K_zz alone.
        assert!(
            near(num(&b["deflection"]["translation"][2]), 20.0 / kzz),
            "{}",
            b["deflection"]
        );
    }
    assert!(home > 0, "{v}");
}

#[test]
fn stiffness_failures_name_their_cause() {
    check_failure(
        &["stiffness", FOUR_BAR, "--pose", "psi=0.5"],
        1,
        "input",
        "stiffness needs the file's units and limbs",
    );
    check_failure(
        &["stiffness", RPS_3, "--pose", "ZA=75,alpha=0,beta=0", "--wrench", "1,2"],
        1,
        "input",
        "--wrench takes 6 values (fx, fy, fz, mx, my, mz), not 2",
    );
    check_failure(
        &[
            "stiffness",
            RPS_3,
            "--pose",
            "ZA=75,alpha=0,beta=0",
            "--wrench",
            "1,2,3,4,5,NaN",
        ],
        1,
        "input",
        "wrench component 6 is NaN",
    );
    // The platform in the base plane: the legs cannot hold it up.
    check_failure(
        &["stiffness", RPS_3, "--pose", "ZA=0,alpha=0,beta=0"],
        1,
        "unreachable",
        "actuation singularity",
    );
    // A limb's E through a parameter that is not positive.
    let rps = std::fs::read_to_string(common::root().join(RPS_3)).unwrap();
    let with_e = scratch_file(
        "rps_e.pkm",
        &rps.replace(
            "parameters { RB = 100; RA = 80; }",
            "parameters { RB = 100; RA = 80; e = 2.11e5; }",
        )
        .replace("E = 2.11e5;", "E = e;"),
    );
    check_failure(
        &[
            "stiffness",
            &with_e,
            "--pose",
            "ZA=75,alpha=0,beta=0",
            "--param",
            "e=-1",
        ],
        1,
        "parse",
        "Young's modulus `E` of limb `A` is -1 at these parameters; it must be positive",
    );
}

/// `pkm stiffness` on the 6-UPS, whose file declares its legs and nothing
/// written for it: six actuation forces along the legs, no constraint, and
/// K about o = Σ kᵢ wᵢ wᵢᵀ with wᵢ = (lᵢ, (Sᵢ − o) × lᵢ), lᵢ the unit leg
/// from the base U centre to the ball, kᵢ = 1/(Lᵢ/(E·A) + 1/k_act): the
/// legs' ends placed here by hand from the pose (R = R_z·R_y·R_x).
#[test]
fn stiffness_of_the_stewart_platform_by_hand() {
    let pose = [5.0, -8.0, 180.0, 0.1, -0.05, 0.2];
    let given = format!(
        "x={},y={},z={},rx={},ry={},rz={}",
        pose[0], pose[1], pose[2], pose[3], pose[4], pose[5]
    );
    let v = run_json(&["stiffness", "examples/mechanisms/ups_6.pkm", "--pose", &given]);
    let (e, a) = (2.1e5, std::f64::consts::PI * (100.0 - 64.0));
    let rot = |axis: usize, t: f64| {
        let (c, s) = (t.cos(), t.sin());
        let mut m = [[0.0; 3]; 3];
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        m[axis][axis] = 1.0;
        m[i][i] = c;
        m[j][j] = c;
        m[i][j] = -s;
        m[j][i] = s;
        m
    };
    let mul = |p: [[f64; 3]; 3], q: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| p[i][k] * q[k][j]).sum()))
    };
    let r = mul(mul(rot(2, pose[5]), rot(1, pose[4])), rot(0, pose[3]));
    let on = |radius: f64, deg: f64| [radius * deg.to_radians().cos(), radius * deg.to_radians().sin(), 0.0];
    let bases = [20.0, 100.0, 140.0, 220.0, 260.0, 340.0].map(|d| on(200.0, d));
    let balls = [40.0, 80.0, 160.0, 200.0, 280.0, 320.0].map(|d| {
        let b = on(100.0, d);
        std::array::from_fn::<f64, 3, _>(|i| pose[i] + (0..3).map(|k| r[i][k] * b[k]).sum::<f64>())
    });
    let mut want = [[0.0f64; 6]; 6];
    for (u, s) in bases.iter().zip(&balls) {
        let d: [f64; 3] = std::array::from_fn(|i| s[i] - u[i]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let l = d.map(|x| x / len);
        let arm: [f64; 3] = std::array::from_fn(|i| s[i] - pose[i]);
        let m = [
            arm[1] * l[2] - arm[2] * l[1],
            arm[2] * l[0] - arm[0] * l[2],
            arm[0] * l[1] - arm[1] * l[0],
        ];
        let w = [l[0], l[1], l[2], m[0], m[1], m[2]];
        let k = 1.0 / (len / (e * a) + 1.0 / 2e5);
        for i in 0..6 {
            for j in 0..6 {
                want[i][j] += k * w[i] * w[j];
            }
        }
    }
    let mut drawn = 0;
    for b in v["branches"].as_array().unwrap() {
        let rows = b["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 6, "{b}");
        assert!(rows.iter().all(|r| r["kind"] == "actuation"), "{b}");
        // The branch with every slide positive: its legs reach the balls.
        let reach = b["limbs"].as_array().unwrap().iter().zip(&balls).all(|(l, s)| {
            let p = &l["joints"].as_array().unwrap().last().unwrap()["point"];
            (0..3).all(|i| (num(&p[i]) - s[i]).abs() <= 1e-9)
        });
        if !reach {
            continue;
        }
        drawn += 1;
        let scale = want.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..6 {
            for j in 0..6 {
                let got = num(&b["K"][i][j]);
                assert!(
                    (got - want[i][j]).abs() <= 1e-12 * scale,
                    "K[{i}][{j}] = {got}, by hand {}",
                    want[i][j]
                );
            }
        }
    }
    assert!(drawn > 0, "{v}");
}

/// Issue 29, items 3 and 7, the issue's commands: `pkm fk four_bar.pkm
/// --q=1e11` lists both assemblies (R4 = 1.74949…, −2.42859…, by hand at
/// the input reduced in 400 digits: tests/limits.rs), neither tangent nor
/// a double root; a slide of 1e308 is out of reach, not NaN; seed 000 A at
/// Table 1's inputs lists eight assemblies, the R5–parallelogram leg in
/// both postures.
#[test]
fn every_assembly_and_huge_values() {
    let v = run_json(&["fk", "examples/mechanisms/four_bar.pkm", "--q=1e11"]);
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 2);
    for (b, want) in branches.iter().zip([1.7494924528818856, -2.428590097057323]) {
        assert_eq!(b["ok"], true, "{b}");
        assert_eq!(b["tangent"], false, "{b}");
        assert!((b["joints"]["R4"].as_f64().unwrap() - want).abs() < 1e-12, "{b}");
    }
    let out = pkm(&["fk", "examples/mechanisms/cylinder_rocker.pkm", "--q=1e308", "--json"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        !out.status.success() && text.contains("unreachable") && text.contains("fails by 1e308"),
        "{text}"
    );
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let v = run_json(&["fk", "examples/mechanisms/seed000_a.pkm", "--q=-106.09,181.67,-70.29"]);
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 8);
    assert!(branches.iter().all(|b| b["ok"] == true), "{v}");
}
