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

/// Mobility from special geometry: the Bennett linkage
/// (`tests/fixtures/bennett.pkm`: four revolutes on skew axes, lengths a,
/// b, a, b, twists α, β, α, β) is F = 0 at generic instances of its
/// (undeclared) axis relations, and by Bennett's theorem moves with one
/// DOF exactly where a / sin α = b / sin β. `pkm analyze` finds the loops'
/// rank 3 (not 4) at an assembly of the declared dimensions and follows
/// the motion; with b off the condition (180 for 175.5) there is no
/// assembly to move, and nothing is said.
#[test]
fn special_geometry_of_the_bennett_linkage() {
    let file = "tests/fixtures/bennett.pkm";
    let out = pkm(&["analyze", file]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("F = Σf − Σξ_L = 4 − 4 = 0"), "{text}");
    assert!(
        text.contains("the loops' rank is 3, where generic instances of the declared axis relations give 4"),
        "{text}"
    );
    assert!(text.contains("moves with 1 DOF, not F = 0"), "{text}");
    let v: Value = serde_json::from_slice(&pkm(&["analyze", file, "--json"]).stdout).unwrap();
    let s = &v["special_geometry"];
    assert_eq!(
        (s["generic_dof"].as_u64(), s["declared_dof"].as_u64()),
        (Some(0), Some(1)),
        "{s}"
    );
    assert_eq!(
        (s["loop_rank"].as_u64(), s["finite"].as_bool()),
        (Some(3), Some(true)),
        "{s}"
    );
    let text = std::fs::read_to_string(common::root().join(file)).unwrap();
    let off = text.replace("b = a * sin(beta) / sin(alpha);", "b = 180;");
    assert_ne!(off, text);
    let path = scratch_file("not_bennett.pkm", &off);
    let out = pkm(&["analyze", &path]);
    assert!(out.status.success());
    assert!(!String::from_utf8(out.stdout).unwrap().contains("special geometry"));
    let v: Value = serde_json::from_slice(&pkm(&["analyze", &path, "--json"]).stdout).unwrap();
    assert!(v.get("special_geometry").is_none(), "{v}");
}

/// `mobility by geometry;` accepts the Bennett linkage's mobility
/// (`tests/fixtures/bennett_driven.pkm`, R1 driven): the topology is
/// counted at its declared dimensions, ξ_L1 = 3 and F = 1 (generic: 0), and
/// `pkm fk` solves it. At R1 = 0.3: R3 = π − 0.3 and R4 = R2 + π (Bennett:
/// opposite joints turn alike; the frames' normals give the offsets; the
/// full relation is checked in the testsuite, `fk_agreement::bennett_linkage`).
#[test]
fn mobility_by_geometry_of_the_bennett_linkage() {
    let file = "tests/fixtures/bennett_driven.pkm";
    let out = pkm(&["analyze", file]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("Σf = 4, I = 1, ξ_L1 = 3, Δ1 = 0"), "{text}");
    assert!(text.contains("F = Σf − Σξ_L = 4 − 3 = 1"), "{text}");
    assert!(
        text.contains("mobility by geometry: counted at configurations of the declared dimensions\n  (generic instances of the declared relations give F = 0)"),
        "{text}"
    );
    let v: Value = serde_json::from_slice(&pkm(&["analyze", file, "--json"]).stdout).unwrap();
    assert_eq!(
        (v["dof"].as_u64(), v["generic_dof"].as_u64()),
        (Some(1), Some(0)),
        "{v}"
    );
    let out = pkm(&["fk", file, "--q", "0.3", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let ok: Vec<&Value> = v["branches"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["ok"] == true)
        .collect();
    assert_eq!(ok.len(), 1, "{v}");
    let q: Vec<f64> = ok[0]["joints"]
        .as_object()
        .unwrap()
        .values()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let pi = std::f64::consts::PI;
    assert!((q[2] - (pi - 0.3)).abs() < 1e-12, "{q:?}");
    assert!((q[3] - (q[1] + pi)).abs() < 1e-12, "{q:?}");
    // Without the statement, the refusal (0 DOF, 1 actuated joint) names it.
    let text = std::fs::read_to_string(common::root().join(file)).unwrap();
    let without = text.replace("    mobility by geometry;\n", "");
    assert_ne!(without, text);
    let out = pkm(&["analyze", &scratch_file("bennett_undeclared.pkm", &without)]);
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("the mechanism has 0 DOF but 1 actuated joint"), "{err}");
    assert!(
        err.contains("the declared dimensions move with 1 DOF (the loops' rank 3 at an assembly, where generic instances of the declared relations give 4)"),
        "{err}"
    );
    assert!(err.contains("declare `mobility by geometry;`"), "{err}");
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
/// tests/testsuite/fk_numeric.rs), each with the virtual variable's value, and each
/// keeps the crank at 1 and the binary links' lengths (by hand: 50√2, 200),
/// each root certified (`docs/certified.md`).
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
        // Each root proven: its certificate, an interval of R2 about the
        // residual's rounding over its slope wide (1.7e-13 here), holds
        // the value reported.
        assert_eq!(b["certificate"]["status"], "certified", "{b}");
        let (v, cert) = (b["virtual"]["R2"].as_f64().unwrap(), &b["certificate"]["R2"]);
        let (lo, hi) = (cert[0].as_f64().unwrap(), cert[1].as_f64().unwrap());
        assert!(lo <= v && v <= hi && hi - lo <= 1e-11, "{b}");
        assert_eq!(b["tangent"], false, "{b}");
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

/// The keys a script can rely on, with the ok branches' groups by name;
/// lengths in `unit`, the file's `units` block's (else "file unit"); every
/// branch of the plan numbered in order.
fn check_schema(v: &Value, given: &str, unit: &str) {
    for key in ["name", given, "units", "branches"] {
        assert!(!v[key].is_null(), "no `{key}` in {v}");
    }
    assert_eq!(v["units"]["length"], unit);
    for (k, b) in v["branches"].as_array().unwrap().iter().enumerate() {
        assert!(b["signs"].is_array(), "{b}");
        assert_eq!(b["branch"], k, "{b}");
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
    check_schema(&v, "inputs", "file unit");
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

/// The slider-crank's slide at crank angle t: r cos t ± sqrt(l² − r² sin² t)
/// (r = 50, l = 180), branch `+` then `-`.
fn slider_by_hand(t: f64) -> [f64; 2] {
    let (r, l) = (50.0f64, 180.0f64);
    let root = (l * l - (r * t.sin()).powi(2)).sqrt();
    [r * t.cos() + root, r * t.cos() - root]
}

/// Without `--json`, `pkm fk` prints a table for people: a title with the
/// inputs, the names over their units, one row per branch (number, signs,
/// ok), every 1-DOF joint's value and every output; the slide by hand to the
/// seven digits shown.
#[test]
fn fk_prints_a_table_for_people() {
    let out = pkm(&["fk", "examples/mechanisms/slider_crank.pkm", "--q", "1"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0], "slider_crank: forward position at R1 = 1; 2 branches, 2 ok",
        "{text}"
    );
    let names: Vec<&str> = lines[2].split_whitespace().collect();
    assert_eq!(names, ["branch", "signs", "ok", "R1", "R2", "R3", "P1", "s"], "{text}");
    // The file has no `units` block: its lengths are in "file unit".
    assert_eq!(lines[3].matches("rad").count(), 3, "{text}");
    assert_eq!(lines[3].matches("file unit").count(), 2, "{text}");
    for (k, want) in slider_by_hand(1.0).into_iter().enumerate() {
        let row: Vec<&str> = lines[4 + k].split_whitespace().collect();
        assert_eq!(row[..3], [k.to_string().as_str(), ["+", "-"][k], "ok"], "{text}");
        let p1: f64 = row[6].parse().unwrap();
        assert!((p1 - want).abs() <= 5e-7 * want.abs(), "{p1} against {want}");
    }
    assert_eq!(lines.len(), 6, "{text}");
}

#[test]
fn planar_outputs_reproduce_the_pose_given_to_ik() {
    // The four-bar given its rocker angle psi (a joint output).
    let v = run_json(&["ik", FOUR_BAR, "--pose", "psi=2.0"]);
    check_schema(&v, "pose", "file unit");
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
    // seed000_a.pkm: `units { length = mm; … }`.
    check_schema(&fk, "inputs", "mm");
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
    check_schema(&u, "inputs", "file unit");
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

/// The README's JSON example is what `pkm fk --json` prints for its command.
#[test]
fn readme_json_example_is_the_real_output() {
    let readme = std::fs::read_to_string(common::root().join("README.md")).unwrap();
    let after = readme
        .split("`pkm fk examples/mechanisms/slider_crank.pkm --q 1`\n(with `--json`, indented here):")
        .nth(1)
        .expect("the README's JSON example");
    let block = after
        .split("```json")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .unwrap();
    let shown: Value = serde_json::from_str(block).unwrap();
    let out = pkm(&["fk", "examples/mechanisms/slider_crank.pkm", "--q", "1", "--json"]);
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

/// Issue 29, item 6: `pkm export` ignored the study's `branch` (seed 000
/// A came out on branch 0, the punch on branch 1). The default is the
/// study's branch in `pkm fk`'s numbering, the reference configuration fk's
/// solution there; `--branch` overrides it.
#[test]
fn export_takes_the_studys_branch() {
    // The examples' studies say `branch 1;` (seed 000 A) and `branch 3;` (the punch).
    for (file, study) in [(SEED000_A, 1), ("examples/mechanisms/seed003_punch.pkm", 3)] {
        assert!(
            std::fs::read_to_string(common::root().join(file))
                .unwrap()
                .contains(&format!("branch {study};")),
            "{file}"
        );
        let v = run_json(&["export", file, "--mjcf"]);
        assert_eq!(v["branch"], study, "{file}");
        assert_eq!(v["branch_from"], "the study's `branch`", "{file}");
        let q: Vec<String> = v["input_order"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| num(&v["inputs"][n.as_str().unwrap()]).to_string())
            .collect();
        let fk = run_json(&["fk", file, &format!("--q={}", q.join(","))]);
        let branch = &fk["branches"][study];
        assert_eq!(v["signs"], branch["signs"], "{file}");
        // Every revolute's and slide's reference is fk's value on that branch.
        for (name, j) in v["joints"].as_object().unwrap() {
            let pkm_name = j["pkm"].as_str().unwrap();
            if name == pkm_name {
                let theirs = num(&branch["joints"][pkm_name]);
                assert!(
                    (num(&j["reference"]) - theirs).abs() < 1e-9,
                    "{file} {name}: {j} {theirs}"
                );
            }
        }
        let xml = v["mjcf"].as_str().unwrap();
        assert!(xml.contains(&format!("branch {study} (")), "{file}");
    }
    let v = run_json(&["export", SEED000_A, "--mjcf", "--branch=0"]);
    assert_eq!(
        (v["branch"].as_u64(), v["branch_from"].as_str()),
        (Some(0), Some("--branch"))
    );
    check_failure(
        &["export", SEED000_A, "--mjcf", "--branch=99"],
        1,
        "input",
        "branch 99 (--branch): the mechanism has",
    );
}

/// Issue 29, item 4: `pkm export --mjcf` on the RSSR and the RSUR with
/// masses panicked (index out of bounds: one value per joint assumed).
/// A spherical joint of the tree is a ball, whose reference is pkm's
/// rotation vector; the U's cross, without mass, has no body: its two
/// hinges are the coupler's. MuJoCo reads both in tests/mujoco/test_mujoco.py.
#[test]
fn export_of_spherical_joints() {
    let v = run_json(&["export", "tests/fixtures/rssr_masses.pkm", "--mjcf", "--q=0.5"]);
    assert_eq!(v["joints"]["S1"]["type"], "ball");
    assert_eq!(v["joints"]["S1"]["reference"].as_array().map(Vec::len), Some(3));
    assert_eq!(v["cut"], serde_json::json!(["S2"]));
    let xml = v["mjcf"].as_str().unwrap();
    assert!(xml.contains("<joint name=\"S1\" type=\"ball\""), "{xml}");
    assert_eq!(xml.matches("<connect ").count(), 1, "{xml}");
    // The coupler's mass is symmetric about its S–S line: its idle spin
    // takes no force, and pkm holds it (MuJoCo's statics agree:
    // tests/mujoco/test_mujoco.py).
    assert_eq!(v["holding"]["ok"], true, "{v}");
    let v = run_json(&["export", "tests/fixtures/rsur_masses.pkm", "--mjcf", "--q=0.5"]);
    assert_eq!(v["merged"]["U1.cross"], "coupler");
    for half in ["U1.a", "U1.b"] {
        assert_eq!(v["joints"][half]["body"], "coupler", "{half}");
    }
    assert!(!v["mjcf"].as_str().unwrap().contains("U1.cross"));
    assert_eq!(v["holding"]["ok"], true);
}

/// A massless link whose joints can go to the next body has no body of its
/// own (seed 000 A's cross, r5 and pc: no stand-in mass, and the loops cut
/// between links with mass); one that would end the tree at a cut joint is
/// refused, as MuJoCo's constraint on it would carry no force.
#[test]
fn export_of_massless_links() {
    let v = run_json(&["export", SEED000_A, "--mjcf"]);
    assert_eq!(v["stand_in"]["bodies"], serde_json::json!([]));
    for link in ["cross", "r5", "pc"] {
        assert!(v["merged"][link].is_string(), "{link}: {}", v["merged"]);
    }
    let leaf = common::example_with(
        "four_bar",
        "units { length = mm; mass = kg; } masses { crank { mass = 0.1; centroid = (50, 0); } massless coupler, rocker; }",
    );
    let path = scratch_file("four_bar_light_dyad.pkm", &leaf);
    check_failure(
        &["export", &path, "--mjcf"],
        1,
        "input",
        "export cannot close a loop through rocker",
    );
    // The coupler alone without mass is a chain of two hinges in the rocker's body.
    let middle = common::example_with(
        "four_bar",
        "units { length = mm; mass = kg; } masses { crank { mass = 0.1; centroid = (50, 0); } rocker { mass = 0.1; centroid = (100, 0); } massless coupler; }",
    );
    let path = scratch_file("four_bar_light_coupler.pkm", &middle);
    let v = run_json(&["export", &path, "--mjcf"]);
    assert_eq!(v["merged"]["coupler"], "rocker");
    assert_eq!(v["cut"], serde_json::json!(["R4"]));
}

/// The moving links of a mechanism file: its `geometry` block's entries
/// but the base.
fn moving_links(text: &str) -> Vec<String> {
    let from = text.find("geometry").unwrap();
    let open = from + text[from..].find('{').unwrap() + 1;
    let (mut depth, mut start, mut names) = (1, open, Vec::new());
    for (i, c) in text[open..].char_indices() {
        let at = open + i;
        match c {
            '{' => {
                if depth == 1 {
                    let name = text[start..at].split_whitespace().last().unwrap();
                    names.push(name.to_string());
                }
                depth += 1;
            }
            '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
                if depth == 1 {
                    start = at + 1;
                }
            }
            _ => {}
        }
    }
    names.retain(|n| n != "base");
    names
}

/// An example with this test's masses: 0.1 kg on each moving link, 20 mm
/// along its frame's x, radius of gyration 40 mm (its own `units` and
/// `masses` left out).
fn with_test_masses(stem: &str) -> String {
    let (text, _) = common::example_text(stem);
    let planar = text.contains("planar;");
    let masses: Vec<String> = moving_links(&text)
        .iter()
        .map(|l| {
            if planar {
                format!("{l} {{ mass = 0.1; centroid = (20, 0); inertia = 160; }}")
            } else {
                format!("{l} {{ mass = 0.1; centroid = (20, 0, 0); inertia = (160, 208, 256); }}")
            }
        })
        .collect();
    common::example_with(
        stem,
        &format!("units {{ length = mm; mass = kg; }} masses {{ {} }}", masses.join(" ")),
    )
}

/// Issue 29, item 6: every example's export opens in MuJoCo. Every example
/// exports (with this test's masses where it has none), the twelve with no
/// closed-form forward plan or no assembly at zeros included, the agile eye
/// by ik at a pose of its declared outputs. Never a panic.
#[test]
fn export_of_every_example_answers() {
    let dir = common::root().join("examples/mechanisms");
    let mut files: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    let mut refused = Vec::new();
    for file in files {
        let stem = file.file_stem().unwrap().to_str().unwrap().to_string();
        let mut path = file.to_str().unwrap().to_string();
        let export = |path: &str| {
            let out = pkm(&["export", path, "--mjcf", "--json"]);
            let v: Value = serde_json::from_slice(&out.stdout)
                .unwrap_or_else(|e| panic!("{path}: not JSON ({e}): {}", String::from_utf8_lossy(&out.stderr)));
            (out.status.code(), v)
        };
        let (mut code, mut v) = export(&path);
        let message = v["error"]["message"].as_str().unwrap_or_default().to_string();
        let diagnostics = v["error"]["diagnostics"].to_string();
        if message.contains("needs the file's units and masses")
            || diagnostics.contains("needs every moving link's mass")
        {
            path = scratch_file(&format!("{stem}_masses.pkm"), &with_test_masses(&stem));
            (code, v) = export(&path);
        }
        match code {
            Some(0) => assert!(v["mjcf"].as_str().unwrap().starts_with("<mujoco"), "{stem}"),
            Some(1) => refused.push((stem, v["error"]["message"].as_str().unwrap_or_default().to_string())),
            code => panic!("{stem}: exit {code:?}: {v}"),
        }
    }
    // The agile eye, refused while its file declared no outputs, is
    // assembled by ik at a pose since it declares them (x, y, z, phi).
    assert!(refused.is_empty(), "{refused:?}");
}

/// Issue 29, item 6: the 6-UPS (κ = 4, only an inverse plan) was refused
/// ("a closed-form forward plan needs κ = 0"). It is assembled by its
/// inverse plan: at the outputs' home its platform lies in the base plane,
/// an output singularity on every branch, so its height goes to where the
/// forward velocity map is best conditioned, level and centred. Each leg
/// joins a base U at 200 mm and a platform S at 100 mm, 20° apart about z:
/// at height z its slide is √(200² + 100² − 2·200·100·cos 20° + z²), by
/// hand. `--pose` sets the pose, numbered as `pkm ik`'s branches; `--q`
/// cannot be solved without a forward solution, said so.
#[test]
fn export_by_the_inverse_plan() {
    // Without the example's study pose: the home and its scan.
    let study = "    study { pose (10, -5, 250, 0.05, -0.03, 0.1); }\n";
    let text = with_test_masses("ups_6");
    assert!(text.contains(study));
    let path = scratch_file("ups_6_home.pkm", &text.replace(study, ""));
    let v = run_json(&["export", &path, "--mjcf"]);
    assert_eq!(v["solver"], "ik");
    assert_eq!(
        (v["branch"].as_u64(), v["branch_from"].as_str()),
        (Some(0), Some("the best conditioned at the pose"))
    );
    assert!(
        v["pose_from"].as_str().unwrap().contains("no branch is regular"),
        "{}",
        v["pose_from"]
    );
    let z = num(&v["pose"]["z"]);
    assert!(z > 0.0 && z < 600.0, "{z}");
    for o in ["x", "y", "rx", "ry", "rz"] {
        assert_eq!(num(&v["pose"][o]), 0.0, "{o}");
    }
    let leg = (200f64.powi(2) + 100f64.powi(2) - 2.0 * 200.0 * 100.0 * 20f64.to_radians().cos() + z * z).sqrt();
    for k in 1..=6 {
        let p = num(&v["inputs"][format!("P{k}")]);
        assert!((p - leg).abs() < 1e-9 * leg, "P{k} = {p}, by hand {leg}");
    }
    assert_eq!(v["holding"]["ok"], true, "{}", v["holding"]);
    // At a pose given, on an ik branch: ik's values there.
    let pose = "--pose=x=5,y=-3,z=150,rx=0.1,ry=-0.05,rz=0.2";
    let v = run_json(&["export", &path, "--mjcf", pose, "--branch=5"]);
    assert_eq!(
        (v["branch"].as_u64(), v["pose_from"].as_str()),
        (Some(5), Some("--pose"))
    );
    let ik = run_json(&["ik", &path, pose]);
    let branch = &ik["branches"][5];
    assert_eq!(v["signs"], branch["signs"]);
    for (name, j) in v["joints"].as_object().unwrap() {
        if j["type"] != "ball" {
            let theirs = num(&branch["joints"][j["pkm"].as_str().unwrap()]);
            assert!((num(&j["reference"]) - theirs).abs() < 1e-9, "{name}: {j} {theirs}");
        }
    }
    check_failure(
        &["export", &path, "--mjcf", "--q=200,200,200,200,200,200"],
        1,
        "input",
        "--q: ups_6 has no forward solution to take inputs (κ = 4): give its outputs with --pose",
    );
    check_failure(
        &["export", &path, "--mjcf", "--branch=64"],
        1,
        "input",
        "branch 64 (--branch): the inverse plan has 64 branches, 0 to 63",
    );
}

/// Issue 29, item 6: a κ = 1 mechanism with `fk_numeric` (the original
/// punch: four assemblies at A = 0, three of them on branch 3) is
/// assembled by its numeric forward solution, numbered as `pkm fk` lists
/// it: `--branch` the plan branch, `--assembly` the row among that
/// branch's; by default the first that assembles.
#[test]
fn export_by_the_virtual_variable() {
    let path = scratch_file("punch_original_masses.pkm", &with_test_masses("seed003_punch_original"));
    let fk = run_json(&["fk", &path, "--q=0"]);
    let rows: Vec<&Value> = fk["branches"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["ok"] == true)
        .collect();
    let v = run_json(&["export", &path, "--mjcf"]);
    assert_eq!(v["solver"], "fk_numeric");
    assert_eq!(
        (v["branch"].clone(), v["assembly"].as_u64()),
        (rows[0]["branch"].clone(), Some(0))
    );
    for (k, row) in rows.iter().filter(|r| r["branch"] == 3).enumerate() {
        let v = run_json(&["export", &path, "--mjcf", "--branch=3", &format!("--assembly={k}")]);
        assert_eq!(
            (v["branch"].as_u64(), v["assembly"].as_u64()),
            (Some(3), Some(k as u64))
        );
        assert_eq!(v["virtual"]["D"], row["virtual"]["D"]);
        for (name, j) in v["joints"].as_object().unwrap() {
            let theirs = num(&row["joints"][j["pkm"].as_str().unwrap()]);
            assert!((num(&j["reference"]) - theirs).abs() < 1e-9, "{name}: {j} {theirs}");
        }
    }
    check_failure(
        &["export", &path, "--mjcf", "--branch=3", "--assembly=3"],
        1,
        "unreachable",
        "branch 3 (--branch) has 3 assemblies at the inputs (0) from zeros, no assembly 3 (--assembly)",
    );
    check_failure(
        &[
            "export",
            "examples/mechanisms/seed003_punch.pkm",
            "--mjcf",
            "--assembly=1",
        ],
        1,
        "input",
        "--assembly picks one of a branch's assemblies of `fk_numeric`",
    );
}

/// A U joint's massless cross that every spanning tree would leave hanging
/// at a cut (the 3-UPU's platform U's, two of three) was refused; the U is
/// now cut whole: a `connect` at its centre and a spatial tendon of fixed
/// length between its two axes, the cross without a body. MuJoCo holds it
/// in tests/mujoco/test_mujoco.py.
#[test]
fn export_cuts_a_u_joint_whole() {
    let path = scratch_file("upu_3_masses.pkm", &with_test_masses("upu_3"));
    let v = run_json(&["export", &path, "--mjcf"]);
    let crosses = v["cut_crosses"].as_array().unwrap();
    assert_eq!(crosses.len(), 2, "{crosses:?}");
    let xml = v["mjcf"].as_str().unwrap();
    for c in crosses {
        let name = c["cross"].as_str().unwrap();
        assert!(!xml.contains(&format!("<body name=\"{name}\"")), "{name}");
        assert!(xml.contains(&format!("<spatial name=\"{name}.angle\"")), "{name}");
        assert!(
            xml.contains(&format!("<tendon name=\"{name}.angle\" tendon1=\"{name}.angle\"")),
            "{name}"
        );
        assert!(xml.contains(&format!("<connect name=\"{name}\"")), "{name}");
    }
    assert_eq!(v["cut"], serde_json::json!([]));
    assert_eq!(v["holding"]["ok"], true);
}

/// `--rates` and `--accels` put the reference in motion: the keyframe's
/// qvel holds every joint's rate (the crank's as given) and its ctrl the
/// forces of that motion, `pkm dynamics`'s on the same branch.
#[test]
fn export_in_motion() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let state = ["--q=0.5", "--rates=2", "--accels=-3"];
    let v = run_json(&[&["export", punch, "--mjcf"][..], &state[..]].concat());
    assert_eq!(v["motion"]["at_rest"], false);
    assert_eq!(v["joints"]["A"]["rate"], 2.0);
    let dynamics = run_json(&[&["dynamics", punch][..], &state[..]].concat());
    let branch = dynamics["branches"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["signs"] == v["signs"])
        .unwrap();
    let (ours, theirs) = (num(&v["holding"]["as_declared"]["A"]), num(&branch["actuators"]["A"]));
    assert!((ours - theirs).abs() < 1e-12 * theirs.abs(), "{ours} {theirs}");
    let xml = v["mjcf"].as_str().unwrap();
    let key = &xml[xml.find("<key ").unwrap()..];
    let qvel = attribute_of(key, "qvel");
    let a = v["joints"]["A"]["scale"].as_f64().unwrap() * 2.0;
    assert!(qvel.contains(&a), "{qvel:?}");
    assert!(!run_json(&["export", punch, "--mjcf"])["mjcf"]
        .as_str()
        .unwrap()
        .contains("qvel"));
}

/// Seed 000 A with a U joint had no study start and no branch assembles at
/// zeros (both sliders of the five-bar at one point); its study now starts
/// where seed000_a's does, on the paper's branch, and the export is
/// seed000_a's configuration: every joint the two files share at one value.
#[test]
fn export_of_seed000_a_with_a_u_joint() {
    let path = scratch_file("seed000_a_u_masses.pkm", &with_test_masses("seed000_a_u"));
    let v = run_json(&["export", &path, "--mjcf"]);
    assert_eq!(
        (v["inputs_from"].as_str(), v["branch"].as_u64()),
        (Some("the study's start"), Some(1))
    );
    let a = run_json(&["export", SEED000_A, "--mjcf"]);
    assert_eq!(v["inputs"], a["inputs"]);
    let mut shared = Vec::new();
    for (name, j) in v["joints"].as_object().unwrap() {
        if let Some(theirs) = a["joints"].get(name) {
            assert!(
                (num(&j["reference"]) - num(&theirs["reference"])).abs() < 1e-9,
                "{name}"
            );
            shared.push(name.as_str());
        }
    }
    // The others are cut in one file or the other, or are the U's halves.
    assert_eq!(shared, ["P1", "P2", "P3", "Pa", "Pa.tip", "R11", "R5"]);
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
    let first_ok = all[0]["branches"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["ok"] == true)
        .unwrap();
    let motion = &first_ok["motion"];
    assert_eq!(all[0]["line"], 2);
    assert_eq!(motion["values"]["A"], 0.5);
    assert_eq!(motion["rates"]["A"], 1.0);
    assert_eq!(motion["accelerations"]["A"], 2.0);
    assert!(all[2]["error"].as_str().unwrap().contains("is NaN"), "{}", all[2]);
}

/// Every branch of `pkm fk` and `pkm dynamics` at one input, side by side:
/// the same count, order and signs; where fk has no position, dynamics
/// gives fk's reason. `args`: the file and `--q`, then dynamics' own.
fn branches_as_fk(args: &[&str]) -> (Vec<Value>, Vec<Value>) {
    let fk = run_json(&[&["fk"][..], &args[..2]].concat());
    let dynamics = run_json(&[&["dynamics"][..], args].concat());
    let (f, d) = (
        fk["branches"].as_array().unwrap().clone(),
        dynamics["branches"].as_array().unwrap().clone(),
    );
    assert_eq!(f.len(), d.len(), "{args:?}");
    for (a, b) in f.iter().zip(&d) {
        assert_eq!(a["signs"], b["signs"], "{args:?}");
        if a["ok"] == false {
            assert_eq!(b["ok"], false, "{args:?}: {b}");
            assert_eq!(a["reason"], b["reason"], "{args:?}");
        }
        assert!(b["ok"] == true || b["reason"].is_string(), "{b}");
    }
    (f, d)
}

/// Issue 29, item 1: `pkm dynamics seed003_punch.pkm --q=2.6968633537
/// --rates=1` (1e-5° past the change point where F passes through H) gave
/// branch − − − ok with a crank torque of 2670.10 N·mm, exactly −8.914887
/// (a 60-digit Newton–Euler: tests/fixtures/seed003_change_points.csv).
/// Now the two branches where F's roots nearly meet say why they have no
/// answer, and the two others answer.
#[test]
fn dynamics_next_to_a_change_point_is_refused_saying_why() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let (_, d) = branches_as_fk(&[punch, "--q=2.6968633537", "--rates=1"]);
    let by_signs = |s: &str| {
        d.iter()
            .find(|b| {
                b["signs"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_str().unwrap())
                    .collect::<String>()
                    == s
            })
            .unwrap()
    };
    for signs in ["--+", "---"] {
        let b = by_signs(signs);
        assert_eq!(b["ok"], false, "{b}");
        let why = b["reason"].as_str().unwrap();
        for part in [
            "SKC 3 (joints G.2, F, P2) is next to a change point",
            "below 6.06e-4",
            "fewer than 6 digits",
        ] {
            assert!(why.contains(part), "{why}");
        }
    }
    for signs in ["-++", "-+-"] {
        assert_eq!(by_signs(signs)["ok"], true);
    }
}

/// Issue 29, item 2: every branch of the plan, in fk's order with fk's
/// signs, ok or with its reason: 1e-6° from the change point (where fk
/// has the paper's branch with `tangent` and its twin as a double root),
/// and at q = 1e308.
#[test]
fn dynamics_lists_every_branch_as_fk_does() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    let beside = format!("--q={}", 2.6968631790545614f64 + 1e-6f64.to_radians());
    for args in [
        vec![punch, beside.as_str()],
        vec![punch, beside.as_str(), "--rates=1"],
        vec![punch, "--q=1e308"],
    ] {
        let (f, d) = branches_as_fk(&args);
        assert_eq!(d.len(), 8, "{args:?}");
        let ok = |l: &[Value]| l.iter().filter(|b| b["ok"] == true).count();
        assert!(ok(&d) >= 1 && ok(&d) <= ok(&f), "{args:?}");
    }
}

/// Issue 29, item 2: `--states` exits non-zero when no state has an
/// answer, after listing each one's error; and when a line is not a state.
#[test]
fn dynamics_states_fail_when_none_answers() {
    let punch = "examples/mechanisms/seed003_punch.pkm";
    // The crank's pivot 2 m up: the loop D–G–H closes nowhere.
    let states = scratch_file("unreachable.states", "0.5, 1\n1.5\n");
    for json in [true, false] {
        let mut args = vec!["dynamics", punch, "--param", "n=2000", "--states", &states];
        if json {
            args.push("--json");
        }
        let out = pkm(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        let all = v["states"].as_array().unwrap();
        assert_eq!(all.len(), 2);
        assert!(
            all.iter().all(|s| s["error"].as_str().unwrap().contains("no branch")),
            "{v}"
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("none of the 2 states has an answer"), "{err}");
    }
    let states = scratch_file("malformed.states", "0.5, 1\n1, 2, 3, 4\n");
    let out = pkm(&["dynamics", punch, "--states", &states, "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["states"][0]["branches"].is_array(), "{v}");
    assert!(
        v["states"][1]["error"]
            .as_str()
            .unwrap()
            .contains(":2: expected 1, 2 or 3 numbers"),
        "{v}"
    );
}

/// Issue 29, item 4: `pkm dynamics rssr.pkm --q=0.5` (with masses on its
/// three links) failed "expected 8 joint values, got 4" (rsur: 7, 5)
/// although `pkm fk` solves both branches: every branch fk solves now has
/// its dynamics, a spherical joint's reaction a force without a moment,
/// its value, rate and acceleration three numbers each.
#[test]
fn dynamics_with_spherical_joints() {
    for (file, branches) in [("examples/mechanisms/rssr.pkm", 2), ("examples/mechanisms/rsur.pkm", 4)] {
        let (_, d) = branches_as_fk(&[file, "--q=0.5", "--rates=1", "--accels=2"]);
        assert_eq!(d.len(), branches, "{file}");
        for b in &d {
            assert_eq!(b["ok"], true, "{file}: {b}");
            let s1 = &b["reactions"]["S1"];
            let force = (0..3).map(|k| num(&s1["force"][k]).abs()).fold(0.0, f64::max);
            let moment = (0..3).map(|k| num(&s1["moment"][k]).abs()).fold(0.0, f64::max);
            assert!(force > 0.0 && moment < 1e-9 * force * 200.0, "{file}: {s1}");
            for part in ["values", "rates", "accelerations"] {
                assert_eq!(b["motion"][part]["S1"].as_array().map(Vec::len), Some(3), "{file}: {b}");
            }
        }
    }
}

const RPS_3: &str = "examples/mechanisms/rps_3.pkm";

/// `pkm stiffness` on seed 004's 3-RPS at home (Z_A = 75 mm, level), in
/// both of its assemblies: the drawn one, each leg reaching in by h = 20 mm
/// (RB − RA) to its ball, and the platform turned half a turn about z, each
/// leg reaching across by h = 180 mm (RB + RA). A leg is √(h² + 75²) long,
/// its R axis tangent, so at the platform centre K_zz = 3·k_a·(75/L)²,
/// K_xx = K_yy = (3/2)·(k_a·(h/L)² + k_c) with k_a = E·A/L, k_c = 3·E·I/L³
/// (seed 004 eqs. 13–17), by hand.
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
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs();
    let mut seen = [0; 2];
    for b in v["branches"].as_array().unwrap() {
        let lengths: Vec<f64> = b["limbs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| num(&l["length"]))
            .collect();
        let Some(which) = [20.0f64, 180.0]
            .iter()
            .position(|&h| lengths.iter().all(|&x| near(x, h.hypot(75.0))))
        else {
            panic!("legs {lengths:?} are neither assembly's: {b}");
        };
        seen[which] += 1;
        let h: f64 = [20.0, 180.0][which];
        let l = h.hypot(75.0);
        let (ka, kc) = (e * a / l, 3.0 * e * i / l.powi(3));
        let kzz = 3.0 * ka * (75.0 / l).powi(2);
        let kxx = 1.5 * (ka * (h / l).powi(2) + kc);
        let k = |r: usize, c: usize| num(&b["K"][r][c]);
        assert!(
            near(k(2, 2), kzz) && near(k(0, 0), kxx) && near(k(1, 1), kxx),
            "h = {h}: {}",
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
        // A vertical load sinks the level platform by F/K_zz alone; the
        // wrench's large moments turn the platform by up to 1e-3 rad,
        // which carries K's rounding into δz at about cond(K)·ε: 1e-10.
        let dz = num(&b["deflection"]["translation"][2]);
        assert!((dz - 20.0 / kzz).abs() <= 1e-10 * dz.abs(), "{}", b["deflection"]);
    }
    assert_eq!(seen, [8, 8], "{v}");
}

/// Issue 29, item 3: `pkm stiffness` listed the 3-RPS's 16 branches at a
/// pose as 16 answers for 2 distinct platform configurations. Each
/// configuration is now said to be one assembly, its stiffness computed
/// once, every branch still listed by number. Checked against `pkm ik` at
/// the same pose: within a configuration every joint point is the same and
/// the joint values differ as the stiffness says (R + π with its slide
/// negated), across the two the balls are elsewhere.
#[test]
fn stiffness_says_which_branches_are_one_assembly() {
    let pose = "ZA=75,alpha=0.2,beta=-0.1";
    let v = run_json(&["stiffness", RPS_3, "--pose", pose]);
    let ik = run_json(&["ik", RPS_3, "--pose", pose]);
    let (branches, solutions) = (v["branches"].as_array().unwrap(), ik["branches"].as_array().unwrap());
    assert_eq!(branches.len(), 16);
    let even: Vec<usize> = (0..16).step_by(2).collect();
    let odd: Vec<usize> = (1..16).step_by(2).collect();
    let groups: Vec<Vec<usize>> = v["configurations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| serde_json::from_value(c["branches"].clone()).unwrap())
        .collect();
    assert_eq!(groups, [even.clone(), odd.clone()], "{}", v["configurations"]);
    let point = |b: usize, joint: &str| ik["branches"][b]["points"][joint].clone();
    let value = |b: usize, joint: &str| num(&solutions[b]["joints"][joint]);
    let scale = 100.0;
    for group in [&even, &odd] {
        let first = group[0];
        for &b in group {
            assert_eq!(branches[b]["branch"], b);
            assert_eq!(branches[b]["configuration"], first);
            // Computed once: the first branch's K, every digit.
            assert_eq!(branches[b]["K"], branches[first]["K"], "branch {b}");
            for joint in ["R1", "P1", "S1", "R2", "P2", "S2", "R3", "P3", "S3", "o"] {
                assert!(
                    dist(&point(b, joint), &point(first, joint)) <= 1e-9 * scale,
                    "{joint} of {b}"
                );
            }
            // What the stiffness says differs, from the joint values of ik.
            let said: Vec<String> =
                serde_json::from_value(v["configurations"][first % 2]["differences"][b.to_string()].clone())
                    .unwrap_or_default();
            for leg in ["1", "2", "3"] {
                let turned =
                    ((value(b, &format!("R{leg}")) - value(first, &format!("R{leg}"))).abs() - PI).abs() < 1e-9;
                let negated = (value(b, &format!("P{leg}")) + value(first, &format!("P{leg}"))).abs() < 1e-9;
                assert_eq!(turned, negated, "leg {leg} of branch {b}");
                assert_eq!(said.contains(&format!("R{leg} + π")), turned, "{said:?}");
                assert_eq!(said.contains(&format!("P{leg} negated")), negated, "{said:?}");
            }
        }
    }
    for joint in ["S1", "S2", "S3"] {
        assert!(dist(&point(0, joint), &point(1, joint)) > 1.0, "{joint}");
    }
    // The table says so in words, with the criterion and its tolerance.
    let out = pkm(&["stiffness", RPS_3, "--pose", pose]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("Configuration 0: branches 0, 2, 4, 6, 8, 10, 12, 14 are one assembly: the same platform pose, and every joint at the same place with its axis on the same line, within 1e-7 mm"),
        "{text}"
    );
    assert!(text.contains("  2: R1 + π, P1 negated, S1 turned by π\n"), "{text}");
    assert!(text.contains("Its stiffness is computed once, on branch 1."), "{text}");
}

/// Issue 29, item 8: `pkm stiffness` printed 5 187 lines of JSON for one
/// pose. Without `--json` it prints a table: every branch by number with
/// its directional stiffnesses, then each configuration's K once; the
/// 3-RPS at home, its legs √(20² + 75²) on the drawn branch 1, K_zz and
/// K_xx by hand (as above) to the seven digits shown.
#[test]
fn stiffness_prints_a_table_for_people() {
    let out = pkm(&["stiffness", RPS_3, "--pose", "ZA=75,alpha=0,beta=0"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() < 80, "{} lines:\n{text}", lines.len());
    assert!(lines[0].contains("16 branches, 16 ok, 2 configurations"), "{text}");
    for b in 0..16 {
        let row = format!("{b:>6}  ");
        assert!(lines.iter().any(|l| l.starts_with(&row)), "branch {b}: {text}");
    }
    let (e, a, i) = (2.11e5, std::f64::consts::PI * 400.0, 1.256e5);
    let l = 20.0f64.hypot(75.0);
    let (ka, kc) = (e * a / l, 3.0 * e * i / l.powi(3));
    let (kzz, kxx) = (3.0 * ka * (75.0 / l).powi(2), 1.5 * (ka * (20.0 / l).powi(2) + kc));
    let at = lines.iter().position(|l| l.starts_with("Configuration 1:")).unwrap();
    let k_line = at
        + lines[at..]
            .iter()
            .position(|l| l.starts_with("K about o [N/mm, N, N·mm/rad"))
            .unwrap();
    let k: Vec<Vec<f64>> = lines[k_line + 1..k_line + 7]
        .iter()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    for (got, want) in [(k[2][2], kzz), (k[0][0], kxx), (k[1][1], kxx)] {
        assert!((got - want).abs() <= 5e-7 * want, "{got} against {want}");
    }
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

/// The number of the branch with `signs` as the README defines it: bit k
/// set when choice k is `-`.
fn number_of(signs: &Value) -> usize {
    signs
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(k, s)| usize::from(s == "-") << k)
        .sum()
}

/// Issue 29, item 2: every command lists every branch of the plan, in
/// order, numbered as `pkm fk` and `pkm ik` number them, each ok or with
/// its reason. `pkm stiffness` on the 3-PRS dropped the eight branches
/// whose inverse position fails (it listed 8 of 16): they are listed as
/// `pkm ik` lists them at the same pose. `pkm fk` of a κ = 1 file listed
/// only the assemblies found: the plan branches without one are listed too.
#[test]
fn every_branch_is_listed_by_number() {
    let (prs, pose) = ("examples/mechanisms/prs_3.pkm", "z=150,rx=0.3,ry=0.2");
    let stiffness = run_json(&["stiffness", prs, "--pose", pose]);
    let ik = run_json(&["ik", prs, "--pose", pose]);
    let (s, i) = (
        stiffness["branches"].as_array().unwrap(),
        ik["branches"].as_array().unwrap(),
    );
    assert_eq!((s.len(), i.len()), (16, 16));
    for (k, (sb, ib)) in s.iter().zip(i).enumerate() {
        assert_eq!((&sb["branch"], &ib["branch"]), (&Value::from(k), &Value::from(k)));
        assert_eq!(number_of(&sb["signs"]), k);
        assert_eq!(sb["signs"], ib["signs"]);
        assert_eq!(sb["ok"], ib["ok"], "branch {k}");
        if ib["ok"] == false {
            assert_eq!(sb["reason"], ib["reason"], "branch {k}");
        }
    }
    assert_eq!(s.iter().filter(|b| b["ok"] == false).count(), 8);
    // In the table: every number, the failed ones `no` with their reasons under it.
    let text = String::from_utf8(pkm(&["stiffness", prs, "--pose", pose]).stdout).unwrap();
    for b in i.iter().filter(|b| b["ok"] == false) {
        let line = format!(
            "branch {} ({}): {}",
            b["branch"],
            b["signs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap())
                .collect::<String>(),
            b["reason"].as_str().unwrap()
        );
        assert!(text.contains(&line), "`{line}` not in {text}");
    }

    // Seed 003's original punch (κ = 1) at A = 0.5: two ± choices, four
    // plan branches; every one listed in order, several assemblies on one.
    let v = run_json(&["fk", "examples/mechanisms/seed003_punch_original.pkm", "--q=0.5"]);
    let numbers: Vec<usize> = v["branches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| {
            assert_eq!(b["branch"], number_of(&b["signs"]), "{b}");
            assert!(b["ok"] == true || b["reason"].is_string(), "{b}");
            assert_eq!(b["ok"] == true, b["virtual"]["D"].is_number(), "{b}");
            number_of(&b["signs"])
        })
        .collect();
    let mut distinct = numbers.clone();
    distinct.dedup();
    assert_eq!(distinct, [0, 1, 2, 3], "{numbers:?}");
}

/// Issue 29, item 8: `pkm analyze` passed files the macro refuses (a
/// `dynamics` without units or masses, a `stiffness` without limbs, `fk`
/// on κ ≠ 0). It now reports what `pkm::mechanism!` reports: for every
/// compile-fail case of pkm-macros/tests/ui with its mechanism inline, the errors
/// trybuild recorded from the compiler (pkm-macros/tests/ui/*.stderr), each message
/// at the same line and column, exit code 1.
#[test]
fn analyze_refuses_what_the_macro_refuses() {
    let ui = common::root().join("pkm-macros/tests/ui");
    let mut cases = 0;
    let mut names: Vec<_> = std::fs::read_dir(&ui).unwrap().map(|e| e.unwrap().path()).collect();
    names.sort();
    for rs in names.iter().filter(|p| p.extension().is_some_and(|e| e == "rs")) {
        let source = std::fs::read_to_string(rs).unwrap();
        // `pkm::mechanism!(M, "…");`: the mechanism is the string literal.
        let Some(open) = source.find(", \"mechanism ") else {
            continue;
        };
        let literal = &source[open + 3..];
        let text = &literal[..literal.find("\");").unwrap()];
        let text = text.replace("\\\"", "\"").replace("\\\\", "\\");
        let stem = rs.file_stem().unwrap().to_str().unwrap();
        let file = scratch_file(&format!("ui_{stem}.pkm"), &text);
        // Each `error: …` line with the `<inline>:line:column` under it.
        let errors = |text: &str, place: &str| -> Vec<(String, String)> {
            let lines: Vec<&str> = text.lines().collect();
            lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.starts_with("error: "))
                .map(|(k, l)| {
                    let next = lines.get(k + 1).copied().unwrap_or("");
                    let at = next.split(place).nth(1).map_or(String::new(), |p| p.trim().to_string());
                    (l.to_string(), at)
                })
                .collect()
        };
        let recorded = std::fs::read_to_string(rs.with_extension("stderr")).unwrap();
        let want = errors(&recorded, "<inline>:");
        let out = pkm(&["analyze", &file]);
        let got = errors(&String::from_utf8_lossy(&out.stderr), &format!("{file}:"));
        assert_eq!(out.status.code(), Some(1), "{stem}");
        assert_eq!(got, want, "{stem}");
        cases += 1;
    }
    // Among them the three the issue names.
    assert!(cases >= 20, "{cases}");
    for stem in ["dynamics_without_masses", "stiffness_without_limbs", "coupled_fk"] {
        assert!(names.iter().any(|p| p.ends_with(format!("{stem}.rs"))), "{stem}");
    }
    // With --json: the first error's line and column, every diagnostic.
    let rrr = std::fs::read_to_string(common::root().join(RRR)).unwrap();
    let rrr_fk = scratch_file(
        "rrr_fk.pkm",
        &rrr.replace("capabilities ik, fk_numeric;", "capabilities fk, ik;"),
    );
    let v: Value = serde_json::from_slice(&pkm(&["analyze", &rrr_fk, "--json"]).stdout).unwrap();
    assert_eq!(v["error"]["kind"], "parse");
    assert!(v["error"]["message"]
        .as_str()
        .unwrap()
        .starts_with("`fk` needs a closed-form forward position solution"));
    assert!(
        v["error"]["line"].is_number() && v["error"]["column"].is_number(),
        "{v}"
    );
}

/// The README's error example is what `pkm` prints for its command.
#[test]
fn readme_error_example_is_the_real_output() {
    let readme = std::fs::read_to_string(common::root().join("README.md")).unwrap();
    let at = readme.find("    $ pkm fk ").expect("the README's error example");
    let mut lines = readme[at..].lines();
    let command = lines.next().unwrap().trim().trim_start_matches("$ pkm ");
    let shown: Value = serde_json::from_str(lines.next().unwrap().trim()).unwrap();
    let out = pkm(&command.split_whitespace().collect::<Vec<_>>());
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(serde_json::from_slice::<Value>(&out.stdout).unwrap(), shown);
}

/// Reads CSV text into its header and rows.
fn read_csv(text: &[u8]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_reader(text);
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// `pkm fk --csv`: one input a row, every branch of every row, the header
/// naming each column with its unit; a row that is not a number lists
/// every branch with why; the slide by hand to every digit (1e-12).
#[test]
fn fk_reads_and_writes_csv() {
    let inputs = scratch_file("crank.csv", "R1\n1\n# a comment\n2\nabc\n\n100\n");
    let out = pkm(&["fk", "examples/mechanisms/slider_crank.pkm", "--csv", &inputs]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, rows) = read_csv(&out.stdout);
    assert_eq!(
        header,
        [
            "row",
            "branch",
            "signs",
            "ok",
            "reason",
            "R1 [rad]",
            "R2 [rad]",
            "R3 [rad]",
            "P1 [file unit]",
            "s [file unit]",
            "tangent"
        ]
    );
    assert_eq!(rows.len(), 8);
    for (k, row) in rows.iter().enumerate() {
        let (input, branch) = (k / 2, k % 2);
        assert_eq!(
            row[..3],
            [input.to_string(), branch.to_string(), ["+", "-"][branch].to_string()]
        );
        if input == 2 {
            assert_eq!(
                row[3..5],
                ["false".to_string(), "R1 = `abc` is not a number".to_string()]
            );
            assert!(row[5..].iter().all(String::is_empty), "{row:?}");
            continue;
        }
        let t = [1.0, 2.0, 0.0, 100.0][input];
        assert_eq!(row[3], "true", "{row:?}");
        let p1: f64 = row[8].parse().unwrap();
        let want = slider_by_hand(t)[branch];
        assert!(
            (p1 - want).abs() <= 1e-12 * want.abs(),
            "row {input}: {p1} against {want}"
        );
        assert_eq!(row[5].parse::<f64>().unwrap(), t);
    }
    // --out writes the same to a file; --degrees takes degrees, named in the header.
    let written = scratch_file("crank_out.csv", "");
    let degrees = scratch_file("crank_deg.csv", "R1 [deg]\n90\n");
    let out = pkm(&[
        "fk",
        "examples/mechanisms/slider_crank.pkm",
        "--csv",
        &degrees,
        "--degrees",
        "--out",
        &written,
    ]);
    assert!(out.status.success() && out.stdout.is_empty());
    let (header, rows) = read_csv(std::fs::read_to_string(&written).unwrap().as_bytes());
    assert_eq!(header[5], "R1 [deg]");
    let p1: f64 = rows[0][8].parse().unwrap();
    assert!((p1 - slider_by_hand(PI / 2.0)[0]).abs() <= 1e-12 * p1, "{p1}");
}

/// `--csv -` streams: each row's branches come out before the next row is
/// read, so a program can hold pkm open and ask one pose at a time (and a
/// million rows take the memory of one).
#[test]
fn csv_streams_one_row_at_a_time() {
    use std::io::{BufRead, BufReader, Write};
    let mut child = Command::new(env!("CARGO_BIN_EXE_pkm"))
        .args(["fk", "examples/mechanisms/slider_crank.pkm", "--csv", "-"])
        .current_dir(common::root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let (lines_tx, lines) = std::sync::mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            if lines_tx.send(line.unwrap()).is_err() {
                break;
            }
        }
    });
    let next = || {
        lines
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("a row before the next input")
    };
    writeln!(stdin, "R1\n1").unwrap();
    stdin.flush().unwrap();
    assert!(next().starts_with("row,branch,signs,ok,reason,"));
    for t in [1.0, 2.0, 3.0] {
        if t > 1.0 {
            writeln!(stdin, "{t}").unwrap();
            stdin.flush().unwrap();
        }
        for branch in 0..2 {
            let line = next();
            let cells: Vec<&str> = line.split(',').collect();
            let p1: f64 = cells[8].parse().unwrap();
            let want = slider_by_hand(t)[branch];
            assert!((p1 - want).abs() <= 1e-12 * want.abs(), "{line}");
        }
    }
    drop(stdin);
    assert!(child.wait().unwrap().success());
    reader.join().unwrap();
}

/// `pkm ik --csv` and `pkm stiffness --csv`: the 3-RRR's outputs reproduce
/// the poses given; the 3-RPS at home has K_zz and K_xx by hand in its
/// drawn configuration (branch 1 and the seven others it is).
#[test]
fn ik_and_stiffness_read_and_write_csv() {
    let poses = scratch_file("rrr.csv", "phi [deg],x,y\n10,10,20\n-5,0,30\n");
    let out = pkm(&["ik", RRR, "--csv", &poses, "--degrees"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, rows) = read_csv(&out.stdout);
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 16);
    for row in rows.iter().filter(|r| r[3] == "true") {
        let given = [[10.0, 10.0, 20.0], [-5.0, 0.0, 30.0]][row[0].parse::<usize>().unwrap()];
        for (name, want) in ["phi [deg]", "x [file unit]", "y [file unit]"].iter().zip(given) {
            let got: f64 = row[column(name)].parse().unwrap();
            assert!((got - want).abs() < 1e-9, "{name}: {row:?}");
        }
    }

    let poses = scratch_file("rps.csv", "ZA [mm],alpha,beta\n75,0,0\n0,0,0\n");
    let out = pkm(&["stiffness", RPS_3, "--csv", &poses]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, rows) = read_csv(&out.stdout);
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (e, a, i) = (2.11e5, std::f64::consts::PI * 400.0, 1.256e5);
    let l = 20.0f64.hypot(75.0);
    let (ka, kc) = (e * a / l, 3.0 * e * i / l.powi(3));
    let (kzz, kxx) = (3.0 * ka * (75.0 / l).powi(2), 1.5 * (ka * (20.0 / l).powi(2) + kc));
    assert_eq!(rows.len(), 32);
    let drawn: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[0] == "0" && r[column("configuration")] == "1")
        .collect();
    assert_eq!(drawn.len(), 8);
    for row in drawn {
        for (name, want) in [("K_zz [N/mm]", kzz), ("K_xx [N/mm]", kxx), ("K_yy [N/mm]", kxx)] {
            let got: f64 = row[column(name)].parse().unwrap();
            assert!((got - want).abs() <= 1e-12 * want, "{name}: {got} against {want}");
        }
    }
    // The platform in the base plane: every branch listed, none ok, each with why.
    for row in rows.iter().filter(|r| r[0] == "1") {
        assert_eq!(row[3], "false");
        assert!(row[4].contains("actuation singularity"), "{row:?}");
    }
}

/// What `--csv` refuses, naming the cause; a file where no row solves
/// is written out, then exits 1.
#[test]
fn csv_failures_name_their_cause() {
    let crank = "examples/mechanisms/slider_crank.pkm";
    #[rustfmt::skip]
    let rows: &[(&str, &str, &str)] = &[
        ("R2\n1\n", "input", "column `R2` is not a value this command takes; the header must name R1 [rad]"),
        ("R1 [deg]\n1\n", "input", "column `R1 [deg]` is in deg; R1 is taken in rad"),
        ("R1,R1\n1,2\n", "input", "column R1 is named twice"),
        ("R1\n", "input", "has a header and no input row"),
        ("R1\n1\n1,2\n", "input", "found record with 2 fields"),
    ];
    for (k, (text, kind, message)) in rows.iter().enumerate() {
        let file = scratch_file(&format!("bad{k}.csv"), text);
        let out = pkm(&["fk", crank, "--csv", &file]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{text}: {err}");
        assert!(err.contains(message), "{text}: `{message}` not in {err}");
        let out = pkm(&[
            "fk",
            crank,
            "--csv",
            &file,
            "--out",
            &scratch_file("ignored.csv", ""),
            "--json",
        ]);
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["error"]["kind"], *kind, "{v}");
    }
    check_failure(
        &["fk", crank, "--csv", "no/such.csv"],
        1,
        "io",
        "cannot read `no/such.csv`",
    );
    // A line over the limit is refused, not read into memory.
    let long = scratch_file("long.csv", &format!("R1\n{}\n", "1".repeat((1 << 20) + 1)));
    check_failure(
        &["fk", crank, "--csv", &long],
        1,
        "io",
        "a line is longer than 1048576 bytes",
    );
    // l1 = 1000 closes no branch at any row: every row written, then exit 1.
    let file = scratch_file("unreachable.csv", "R1\n1\n2\n");
    let out = pkm(&["fk", FOUR_BAR, "--csv", &file, "--param", "l1=1000"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(read_csv(&out.stdout).1.len(), 4);
    assert!(String::from_utf8_lossy(&out.stderr).contains("no branch solves at any of the 2 input rows"));
    // --q and --csv are one or the other.
    let out = pkm(&["fk", crank, "--q=1", "--csv", &file]);
    assert_eq!(out.status.code(), Some(2));
}

/// `pkm dynamics` for people and for many states (issue 29, item 8): a
/// table by default (every branch by fk's number, the actuators with their
/// units, each answered branch's reactions under it), and `--csv` one state
/// a row. The slider-crank fixture at rest without gravity, pushed along
/// its slide by fx: by virtual work the crank holds τ = −fx·ds/dθ, s = r
/// cos θ ± √(l² − r² sin² θ), on each branch; a row with rates is the one
/// state `--json` gives.
#[test]
fn dynamics_table_and_csv() {
    let crank = "tests/fixtures/slider_crank_dynamics.pkm";
    let params = ["--param", "gy=0", "--param", "fx=25"];
    let out = pkm(&[&["dynamics", crank, "--q=0.7"][..], &params].concat());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("branch  signs  ok") && text.contains("N·mm"), "{text}");
    assert!(text.contains("branch 0 (+):") && text.contains("Fx"), "{text}");

    let states = scratch_file(
        "crank_states.csv",
        "R1 [rad], R1 rate [rad/s], R1 accel [rad/s²]\n0.7, 0, 0\n2.0, 0, 0\n1.1, 3, -2\nx, 0, 0\n",
    );
    let out = pkm(&[&["dynamics", crank, "--csv", &states][..], &params].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, rows) = read_csv(&out.stdout);
    assert_eq!(header[..6], ["row", "branch", "signs", "ok", "reason", "R1 [N·mm]"]);
    assert!(header.contains(&"R3.Fx [N]".to_string()) && header.contains(&"R1.Mz [N·mm]".to_string()));
    assert_eq!(rows.len(), 8);
    let (r, l, fx) = (50.0f64, 180.0f64, 25.0);
    for theta in [0.7f64, 2.0] {
        let root = (l * l - (r * theta.sin()).powi(2)).sqrt();
        let mut want: Vec<f64> = [1.0, -1.0]
            .iter()
            .map(|side| -fx * (-r * theta.sin() - side * r * r * theta.sin() * theta.cos() / root))
            .collect();
        let row = if theta == 0.7 { "0" } else { "1" };
        let mut got: Vec<f64> = rows
            .iter()
            .filter(|x| x[0] == row && x[3] == "true")
            .map(|x| x[5].parse().unwrap())
            .collect();
        for v in [&mut want, &mut got] {
            v.sort_by(f64::total_cmp);
        }
        assert_eq!(got.len(), 2, "{rows:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-9 * w.abs(), "θ = {theta}: {g} against {w}");
        }
    }
    let one = run_json(&[&["dynamics", crank, "--q=1.1", "--rates=3", "--accels=-2"][..], &params].concat());
    for (b, row) in one["branches"]
        .as_array()
        .unwrap()
        .iter()
        .zip(rows.iter().filter(|x| x[0] == "2"))
    {
        assert_eq!(b["branch"].as_u64().unwrap().to_string(), row[1]);
        // serde_json reads a float to within an ulp, not always to it.
        let (a, c) = (num(&b["actuators"]["R1"]), row[5].parse::<f64>().unwrap());
        assert!((a - c).abs() <= 2.0 * f64::EPSILON * c.abs(), "{a} against {c}");
    }
    for row in rows.iter().filter(|x| x[0] == "3") {
        assert_eq!(row[3..5], ["false".to_string(), "R1 = `x` is not a number".to_string()]);
    }
}

/// Issue 29, items 3 and 7, the issue's commands: `pkm fk four_bar.pkm
/// --q=1e11` lists both assemblies (R4 = 1.74949…, −2.42859…, by hand at
/// the input reduced in 400 digits: tests/testsuite/limits.rs), neither tangent nor
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

/// `pkm fk --csv TRAJECTORY --follow-from POSE`: the 3-RPS (κ = 2) along a
/// path of poses, its slides computed by `pkm ik` on the start's branch:
/// every row is tracked (proven the same assembly mode) and puts the
/// platform back at the path's pose; the 6-UPS's row is reached but said
/// possible (or not reached, with why); a start pose naming an unknown
/// output is refused with why.
#[test]
fn fk_follows_a_trajectory() {
    let mut poses = String::from("ZA,alpha,beta\n");
    let path: Vec<[f64; 3]> = (0..=10)
        .map(|k| {
            let t = f64::from(k) / 10.0;
            [300.0 + 20.0 * t, 0.1 * t, -0.1 * t]
        })
        .collect();
    for p in &path {
        poses += &format!("{},{},{}\n", p[0], p[1], p[2]);
    }
    let poses = scratch_file("follow_poses.csv", &poses);
    let ik = pkm(&["ik", "examples/mechanisms/rps_3.pkm", "--csv", &poses]);
    assert!(ik.status.success());
    let mut slides = String::from("P1,P2,P3\n");
    let mut r = csv::Reader::from_reader(&ik.stdout[..]);
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| header.iter().position(|h| h.split(' ').next() == Some(name)).unwrap();
    for rec in r.records() {
        let rec = rec.unwrap();
        if &rec[col("branch")] == "0" {
            slides += &format!("{},{},{}\n", &rec[col("P1")], &rec[col("P2")], &rec[col("P3")]);
        }
    }
    let slides = scratch_file("follow_slides.csv", &slides);
    let follow = |file: &str, csv: &str, from: &str, more: &[&str]| {
        let args: Vec<&str> = ["fk", file, "--csv", csv, "--follow-from", from]
            .into_iter()
            .chain(more.iter().copied())
            .collect();
        pkm(&args)
    };
    let out = follow(
        "examples/mechanisms/rps_3.pkm",
        &slides,
        "ZA=300,alpha=0,beta=0",
        &["--branch", "0"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (header, rows) = read_csv(&out.stdout);
    let want = "row branch signs ok reason follow ZA_[mm] alpha_[rad] beta_[rad]";
    assert_eq!(header.join(" ").replace(" [", "_["), want);
    assert_eq!(rows.len(), path.len());
    for (rec, want) in rows.iter().zip(&path) {
        assert_eq!((rec[3].as_str(), rec[5].as_str()), ("true", "tracked"), "{rec:?}");
        for i in 0..3 {
            let got: f64 = rec[6 + i].parse().unwrap();
            assert!(
                (got - want[i]).abs() <= 1e-9 * want[i].abs().max(1.0),
                "{rec:?} vs {want:?}"
            );
        }
    }
    // The 6-UPS: not proven by the step's certificate, resolved by every
    // assembly of the pose equations (8 real there), the nearest to the
    // start: the platform still about 250 mm up and nearly level.
    let legs = scratch_file("follow_legs.csv", "P1,P2,P3,P4,P5,P6\n275,276,277,275,276,277\n");
    let out = follow(
        "examples/mechanisms/ups_6.pkm",
        &legs,
        "x=0,y=0,z=250,rx=0,ry=0,rz=0",
        &[],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut r = csv::Reader::from_reader(&out.stdout[..]);
    let row = r.records().next().unwrap().unwrap();
    assert_eq!(&row[3], "true", "{row:?}");
    assert!(row[5].starts_with("resolved: "), "{row:?}");
    let z: f64 = row[8].parse().unwrap();
    let tilt = (1..=3)
        .map(|k| row[8 + k].parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!((z - 250.0).abs() < 10.0 && tilt < 0.05, "{row:?}");
    // A start pose naming an output the file does not declare.
    let out = follow("examples/mechanisms/rps_3.pkm", &slides, "ZA=300,gamma=0,beta=0", &[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("unknown output `gamma`"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Issue 32: the study's `pose` is where `pkm export` assembles a file
/// without a forward plan when `--pose` is not given: the 6-UPS at
/// (10, −5, 250) mm turned by (0.05, −0.03, 0.1) rad, on the
/// best-conditioned branch there, and its actuators hold it; `--pose`
/// still wins.
#[test]
fn export_at_the_study_pose() {
    let path = scratch_file("ups_6_masses.pkm", &with_test_masses("ups_6"));
    let v = run_json(&["export", &path, "--mjcf"]);
    assert_eq!(v["pose_from"], "the study's `pose`");
    assert_eq!(v["branch_from"], "the best conditioned at the pose");
    for (axis, want) in [
        ("x", 10.0),
        ("y", -5.0),
        ("z", 250.0),
        ("rx", 0.05),
        ("ry", -0.03),
        ("rz", 0.1),
    ] {
        assert_eq!(v["pose"][axis].as_f64(), Some(want), "{axis}");
    }
    assert_eq!(v["holding"]["ok"], true, "{}", v["holding"]);
    let v = run_json(&["export", &path, "--mjcf", "--pose", "x=0,y=0,z=260,rx=0,ry=0,rz=0"]);
    assert_eq!(v["pose_from"], "--pose");
    assert_eq!(v["pose"]["z"].as_f64(), Some(260.0));
}
