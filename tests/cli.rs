//! `pkm analyze`: the text report, `--json`, and errors on stderr with a
//! non-zero exit.

use serde_json::Value;
use std::process::Command;

fn pkm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pkm"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
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

#[test]
fn errors_go_to_stderr_with_a_failure_code() {
    let dir = std::env::temp_dir().join(format!("pkm-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.pkm");
    std::fs::write(
        &bad,
        "mechanism m {\n  planar;\n  base R1* ∥ R2 ∥ R3 ∥ R4 base;\n  R2 ∥ R9;\n}\n",
    )
    .unwrap();
    let out = pkm(&["analyze", bad.to_str().unwrap(), "--json"]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("error: unknown joint `R9`"), "{err}");
    assert!(err.contains("bad.pkm:4:8"), "{err}");
    assert!(err.contains("       ^^ not declared"), "{err}");

    let out = pkm(&["analyze", "no/such/file.pkm"]);
    assert!(!out.status.success());
    assert!(String::from_utf8(out.stderr).unwrap().contains("cannot read"));
}

#[test]
fn fk_and_ik_json() {
    let out = pkm(&["fk", "examples/mechanisms/slider_crank.pkm", "--q", "1.0", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 2);
    // r cos 1 ± sqrt(l² − r² sin² 1) with r = 50, l = 180.
    let (r, l) = (50.0f64, 180.0f64);
    let root = (l * l - (r * 1f64.sin()).powi(2)).sqrt();
    for (b, want) in branches.iter().zip([r * 1f64.cos() + root, r * 1f64.cos() - root]) {
        assert_eq!(b["ok"], true);
        assert!((b["outputs"]["P1"].as_f64().unwrap() - want).abs() < 1e-9);
        assert_eq!(b["points"]["R3"].as_array().unwrap().len(), 3);
        assert!(b["signs"].is_array());
    }

    let out = pkm(&[
        "ik",
        "examples/mechanisms/planar_3rrr.pkm",
        "--pose",
        "x=10,y=20,phi=0.2",
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let branches = v["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 8);
    for b in branches {
        assert_eq!(b["q"].as_array().unwrap().len(), 3, "{b}");
        // The platform centre is where it was asked to be.
        let o = b["points"]["o"].as_array().unwrap();
        assert!((o[0].as_f64().unwrap() - 10.0).abs() < 1e-9 && (o[1].as_f64().unwrap() - 20.0).abs() < 1e-9);
    }

    let out = pkm(&["ik", "examples/mechanisms/planar_3rrr.pkm", "--pose", "x=1"]);
    assert!(!out.status.success());
    assert!(String::from_utf8(out.stderr).unwrap().contains("missing output `y`"));
}
