//! `pkm report` on every example with no options, and its errors.
//!
//! Each example's page is written; every CSV beside it reads back with the
//! `csv` crate with as many fields per row as its header; the figures are not
//! degenerate (the mechanism's drawing and the workspace span both plotted
//! axes); planar mechanisms get figures in their plane only. Numbers are
//! checked against hand derivations, and bad options are errors that name
//! the file and print `error:` once.

#[path = "../../tests/common/mod.rs"]
mod common;

use common::example_text as example;
use pkm_cli::report::{write_report, ReportOptions};
use std::path::{Path, PathBuf};

fn out_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pkm-report-test-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Every CSV in `dir`: its header and rows, each row as long as the header.
fn read_csvs(dir: &Path) -> Vec<(String, Vec<String>, Vec<Vec<String>>)> {
    let mut all = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "csv") {
            let mut r = csv::Reader::from_path(&path).unwrap();
            let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
            let rows: Vec<Vec<String>> = r
                .records()
                .map(|rec| {
                    let rec = rec.unwrap_or_else(|e| panic!("{path:?}: {e}"));
                    rec.iter().map(String::from).collect()
                })
                .collect();
            for row in &rows {
                assert_eq!(row.len(), header.len(), "{path:?}: a row's fields against its header");
            }
            assert!(!rows.is_empty(), "{path:?} has no rows");
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            all.push((name, header, rows));
        }
    }
    all
}

/// The extent of a numeric column.
fn extent(rows: &[Vec<String>], column: usize) -> f64 {
    let v: Vec<f64> = rows.iter().filter_map(|r| r[column].parse().ok()).collect();
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    hi - lo
}

#[test]
fn every_example_with_no_options() {
    let dir = common::root().join("examples/mechanisms");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "pkm").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    names.sort();
    assert!(names.len() >= 12);
    for name in &names {
        let (text, path) = example(name);
        let out = out_dir(name);
        let page =
            write_report(&text, &path, &ReportOptions::default(), &out).unwrap_or_else(|e| panic!("{name}: {e}"));
        let html = std::fs::read_to_string(page).unwrap();
        assert!(html.contains("<h2>Topology</h2>"), "{name}");
        let csvs = read_csvs(&out);
        let csv = |stem: &str| csvs.iter().find(|(n, _, _)| n == stem);
        // The link–joint graph is drawn for every file.
        assert!(csv("topology").is_some(), "{name}");
        let planar = text.contains("planar;");
        if let Some((_, header, rows)) = csv("mechanism") {
            assert_eq!(header[3..], ["x (mm)", "y (mm)", "z (mm)"], "{name}");
            assert!(
                extent(rows, 3) > 1.0 && extent(rows, 4) > 1.0,
                "{name}: the drawing spans x and y"
            );
            assert!(html.contains("<svg"), "{name}: the animation is in the page");
            assert!(out.join("animation.svg").exists(), "{name}");
            // The 3-RRR, 3-RPR and 3-UPU have no forward plan: their motion is driven by poses, with no rates.
            let inputs_driven = !["planar_3rrr", "planar_3rpr", "upu_3"].contains(&name.as_str());
            for stem in ["velocity", "acceleration"].into_iter().filter(|_| inputs_driven) {
                let (_, header, rows) = csv(stem).unwrap_or_else(|| panic!("{name}: {stem}"));
                assert_eq!(header[0], "t (s)");
                assert_eq!(
                    header.len(),
                    if planar { 4 } else { 5 },
                    "{name}: planar motion has no z column"
                );
                assert!(rows.len() > 2, "{name}: {stem}");
            }
            if planar {
                let (_, header, rows) = csv("workspace_xOy").unwrap_or_else(|| panic!("{name}: workspace in xOy"));
                assert_eq!(header[1..], ["x (mm)", "y (mm)"]);
                match csv("displacement") {
                    // One input: a path, and its coordinates against the input.
                    Some((_, header, rows)) => {
                        assert_eq!(header[1..], ["x", "y"], "{name}");
                        assert!(extent(rows, 0) > 1.0, "{name}");
                        assert!(extent(rows, 1).max(extent(rows, 2)) > 1.0, "{name}: the point moves");
                    }
                    None => {
                        assert!(
                            extent(rows, 1) > 1.0 && extent(rows, 2) > 1.0,
                            "{name}: the workspace spans its plane"
                        )
                    }
                }
                for flat in ["workspace_yOz", "workspace_xOz", "workspace_3d"] {
                    assert!(csv(flat).is_none(), "{name}: no {flat} for a planar mechanism");
                }
            }
        }
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The page of `name` with `options`.
fn page(name: &str, options: ReportOptions) -> (String, PathBuf) {
    let (text, path) = example(name);
    let out = out_dir(&format!("{name}-{}", options.nodes.unwrap_or(0)));
    let page = write_report(&text, &path, &options, &out).unwrap_or_else(|e| panic!("{name}: {e}"));
    (std::fs::read_to_string(page).unwrap(), out)
}

#[test]
fn slider_crank_stroke() {
    // An in-line slider-crank (r = 50, e = 0) strokes 2r = 100 mm; over a full
    // crank turn the slider goes there and back: a path 4r = 200 mm long.
    let (html, out) = page("slider_crank", ReportOptions::default());
    assert!(html.contains("a curve, length 2.0000e2 mm"));
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn mechanism_a_from_its_study_block() {
    // Seed 000 §2.2: G over P1 ∈ [−250, 0], P2 ∈ [0, 250], P3 ∈ [−300, 300],
    // branch 1 (the study block); mechanism B's branches tabled beside A's.
    let options = ReportOptions {
        nodes: Some(12),
        compare: vec![common::example_path("seed000_b")],
        ..Default::default()
    };
    let (html, out) = page("seed000_a", options);
    for section in [
        "What was sampled",
        "The mechanism at the sample input",
        "Position solutions",
        "Workspace of G",
        "a solid, volume",
        "Singularities",
        "Velocity and acceleration",
        "Determinant factors on branch 1",
        "Workspaces of G, every branch",
        "Which factor comes near 0",
        "<td class=l>-250.0000 .. 0.0000 mm</td><td class=l>study block</td>",
    ] {
        assert!(html.contains(section), "missing {section}");
    }
    // A's eight branches (four platforms, each with the R5–parallelogram
    // leg in either posture: the same workspace) and B's eight in one table.
    assert_eq!(html.matches("<tr><td class=l>seed000_a</td>").count(), 8);
    assert_eq!(html.matches("<tr><td class=l>seed000_b</td>").count(), 8);
    // The output columns are named, with units; the class is named.
    assert!(html.contains("<th>alpha (rad)</th>") && html.contains("<th>x (mm)</th>"));
    assert!(!html.contains("None"));
    // The f33 condition by name (tests/singularities.rs places it).
    assert!(html.contains("the path of R6 (D) moved by R4 (C1, o) touches the sphere about Pa (B3)"));
    // The velocity CSV holds the whole 0–5 s trajectory: 501 rows and a header.
    let csv = std::fs::read_to_string(out.join("velocity.csv")).unwrap();
    assert_eq!(csv.lines().count(), 502);
    for stem in [
        "workspace_3d",
        "workspace_xOy",
        "workspace_yOz",
        "workspace_xOz",
        "section_y_-85",
    ] {
        assert!(out.join(format!("{stem}.svg")).exists(), "{stem}");
    }
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn flat_workspace_reports_an_area() {
    // A's point o lies on R4, in the five-bar's plane y = −a: its workspace is
    // flat, so the page gives an area and no volume.
    let options = ReportOptions {
        nodes: Some(12),
        point: Some("o".into()),
        ..Default::default()
    };
    let (html, out) = page("seed000_a", options);
    assert!(html.contains("flat (in the plane xOz), no volume; area ≈ "));
    assert!(!html.contains("a solid, volume"));
    assert!(out.join("workspace_xOz.csv").exists());
    assert!(!out.join("workspace_yOz.csv").exists());
    let _ = std::fs::remove_dir_all(out);
}

/// `write_report` on `name` with `options` fails with a message holding `expect`.
fn check(name: &str, options: ReportOptions, expect: &str) {
    let (text, path) = example(name);
    let out = out_dir("errors");
    let error = write_report(&text, &path, &options, &out).unwrap_err();
    let e = error.to_string();
    assert!(e.contains(expect), "{name}: {e}");
    assert!(e.starts_with("error: ") && !e.contains("error: error"), "{e}");
    // The one-line form, for callers that print their own prefix.
    assert!(!error.message().starts_with("error:") && !error.message().contains('\n'));
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn options_out_of_range() {
    let o = ReportOptions::default;
    check(
        "five_bar",
        ReportOptions { nodes: Some(0), ..o() },
        "--nodes 0: grid nodes per input must be 2 to 1000",
    );
    check(
        "seed000_a",
        ReportOptions {
            nodes: Some(1000),
            ..o()
        },
        "at most 100 per input here",
    );
    check("four_bar", ReportOptions { branch: Some(7), ..o() }, "--branch 7: ");
    check(
        "four_bar",
        ReportOptions {
            duration: Some(-1.0),
            ..o()
        },
        "--duration -1: the trajectory's duration must be above 0",
    );
    check(
        "five_bar",
        ReportOptions {
            ranges: vec![(0.0, 1.0)],
            ..o()
        },
        "--ranges: expected 2 ranges, one per actuated joint of ",
    );
    check(
        "five_bar",
        ReportOptions {
            ranges: vec![(1.0, 1.0), (0.0, 1.0)],
            ..o()
        },
        "empty or inverted",
    );
    check(
        "five_bar",
        ReportOptions {
            start: Some(vec![0.0]),
            ..o()
        },
        "--start has 1 values",
    );
    check(
        "five_bar",
        ReportOptions {
            point: Some("Q".into()),
            ..o()
        },
        "no point `Q` in ",
    );
    check(
        "five_bar",
        ReportOptions {
            params: vec![("q".into(), 1.0)],
            ..o()
        },
        "--param q: no such parameter",
    );
    check(
        "five_bar",
        ReportOptions {
            params: vec![("d".into(), f64::NAN)],
            ..o()
        },
        "--param d=NaN: not a finite number",
    );
    // Which of two values was meant is not known: neither is used.
    check(
        "five_bar",
        ReportOptions {
            params: vec![("d".into(), 90.0), ("d".into(), 80.0)],
            ..o()
        },
        "--param d: parameter d is given twice",
    );
    // A 3-RPS's topology alone.
    let topology_only = "mechanism rps { capabilities ik;\n\
         branch A { base R1 ⊥ P1* - S1 platform; }\n\
         branch B { base R2 ⊥ P2* - S2 platform; }\n\
         branch C { base R3 ⊥ P3* - S3 platform; }\n\
         z ⊥ R1; z ⊥ R2; z ⊥ R3; }";
    let out = out_dir("errors");
    let e = write_report(
        topology_only,
        "rps.pkm",
        &ReportOptions { nodes: Some(10), ..o() },
        &out,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("has no geometry") && e.starts_with("error: "), "{e}");
    let _ = std::fs::remove_dir_all(out);
    // A --compare file's own errors: its path, line and column, on one line.
    let broken = std::env::temp_dir().join(format!("pkm-report-test-{}-broken.pkm", std::process::id()));
    std::fs::write(&broken, "mechanism b { planar;\n base R1* ∥ R2 R3 base; }").unwrap();
    check(
        "five_bar",
        ReportOptions {
            nodes: Some(4),
            compare: vec![broken.clone()],
            ..o()
        },
        "broken.pkm:2:",
    );
    let _ = std::fs::remove_file(broken);
    // Errors name the file's path.
    check(
        "four_bar",
        ReportOptions { branch: Some(7), ..o() },
        "four_bar.pkm has 2 branches",
    );
}

/// A study block's error: at its line and column, under the file's path.
fn check_study(study: &str, expect: &str) {
    let text = format!(
        "mechanism m {{ planar; base R1* [crank] ∥ R2 [rod] ∥ R3 [slider] ⊥ P1 base; x ∥ P1;\n\
         parameters {{ r = 50; l = 180; }}\n\
         geometry {{ base {{ R1 = (0, 0); P1 = through (0, 0) along x; }} crank {{ R1 = (0, 0); R2 = (r, 0); }}\n\
         rod {{ R2 = (0, 0); R3 = (l, 0); }} slider {{ R3 = (0, 0); P1 = (0, 0); }} }}\n\
         {study}\n}}"
    );
    let error = write_report(&text, "crank.pkm", &ReportOptions::default(), &out_dir("study")).unwrap_err();
    assert!(matches!(error, pkm_cli::report::ReportError::Source { .. }));
    assert!(expect.starts_with(&error.message()[..10]), "{}", error.message());
    let e = error.to_string();
    assert!(e.contains(expect), "{e}");
    assert!(e.contains("crank.pkm:5:"), "{e}");
    assert_eq!(e.matches("error:").count(), 1, "{e}");
}

#[test]
fn study_errors() {
    check_study("study { ranges { R2 = 0 .. 1; } }", "`R2` is not an actuated joint");
    check_study(
        "study { ranges { R1 = 1 .. -1; } }",
        "the range of `R1` is 1 .. -1: empty or inverted",
    );
    check_study("study { nodes 1; }", "grid nodes per input must be 2 to 1000");
    check_study("study { start (1, 2); }", "`start` needs 1 values");
    check_study(
        "study { trajectory sine amplitude (1) duration -2; }",
        "the duration is -2 s",
    );
    check_study("study { point E; point F; }", "`point` is given twice");
    check_study("study { ranges { R1 = -q .. 1; } }", "unknown parameter `q`");
    check_study("study { sections { w = 1; } }", "a section's axis is x, y or z");
    check_study("study { } study { }", "a mechanism has one `study` block");
}

#[test]
fn study_overridden_by_the_command_line() {
    // The four-bar's study names E; the command line's R3 wins.
    let options = ReportOptions {
        nodes: Some(90),
        point: Some("R3".into()),
        ..Default::default()
    };
    let (html, out) = page("four_bar", options);
    assert!(html.contains("<td class=l>point followed</td><td class=l>R3</td><td class=l>command line</td>"));
    assert!(html.contains("<td class=l>grid nodes per input</td><td class=l>90</td><td class=l>command line</td>"));
    // The crank turns fully at 1 rad/s by default, for 2π s.
    assert!(html.contains("constant speed: q = start + (1.0000)·t"));
    assert!(html.contains("<td class=l>6.2832 s</td><td class=l>default</td>"));
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn five_bar_area() {
    // R3 of the 5R five-bar (base joints (±50, 0), a = 120, b = 160) reaches
    // the intersection of two annuli 40..280 about the base joints: the lens
    // 2R²·acos(d/2R) − (d/2)·√(4R² − d²) of R = 280, d = 100, less two discs
    // of radius 40 inside it: 180 554 mm². The occupied-cell estimate at the
    // default 200 nodes per input is within 2 %.
    let (r, d, hole): (f64, f64, f64) = (280.0, 100.0, 40.0);
    let lens = 2.0 * r * r * (d / (2.0 * r)).acos() - d / 2.0 * (4.0 * r * r - d * d).sqrt();
    let expected = lens - 2.0 * std::f64::consts::PI * hole * hole;
    let (html, out) = page("five_bar", ReportOptions::default());
    let at = html.find("area ≈ ").unwrap() + "area ≈ ".len();
    let area: f64 = html[at..].split(' ').next().unwrap().parse().unwrap();
    assert!((area - expected).abs() < 0.02 * expected, "{area} against {expected}");
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn five_bar_cranks_turning_together() {
    // Both cranks at 1 rad/s from the same angle keep R2R4 parallel to the
    // base: the distal triangle translates on a circle of radius a = 120 mm,
    // so R3 moves at a·ω = 120 mm/s throughout, and accelerates at a·ω² = 120 mm/s².
    let options = ReportOptions {
        nodes: Some(20),
        ..Default::default()
    };
    let (_, out) = page("five_bar", options);
    for (stem, expected) in [("velocity", 120.0), ("acceleration", 120.0)] {
        let mut r = csv::Reader::from_path(out.join(format!("{stem}.csv"))).unwrap();
        let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
        assert_eq!(header, ["t (s)", "x", "y", "magnitude"]);
        let mut rows = 0;
        for rec in r.records() {
            let magnitude: f64 = rec.unwrap()[3].parse().unwrap();
            assert!((magnitude - expected).abs() < 1e-6, "{stem}: {magnitude}");
            rows += 1;
        }
        assert_eq!(rows, 501, "the whole 2π s turn");
    }
    let _ = std::fs::remove_dir_all(out);
}

/// `pkm stiffness --json` (the command line's own path: `spatial::run_all`,
/// every branch) at `pose`: the branch with the shortest legs among those
/// with a stiffness, as tests/frame/pkm_against_frame.py draws it.
fn shortest_legs_branch(file: &str, pose: &str) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pkm"))
        .args(["--json", "stiffness", file, "--pose", pose])
        .current_dir(common::root())
        .output()
        .unwrap();
    assert!(out.status.success(), "{pose}: {}", String::from_utf8_lossy(&out.stdout));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let legs = |b: &serde_json::Value| -> f64 {
        b["limbs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["length"].as_f64().unwrap())
            .sum()
    };
    v["branches"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["ok"] == true)
        .min_by(|a, b| legs(a).total_cmp(&legs(b)))
        .unwrap()
        .clone()
}

/// The static stiffness map of seed 004's 3-RPS held at its home height
/// (Z_A = 75 mm): both maps written (PNG, SVG, 41 × 41 CSV rows) and, at
/// grid nodes, equal to what `pkm stiffness` gives there on the branch with
/// the shortest legs: the directional stiffness along z as it reports it
/// and as 1/(K⁻¹)_zz of its K, and the least eigenvalue of K's
/// translational block (this test's own eigen-solve of the CLI's K).
#[test]
fn stiffness_map_of_the_3rps_matches_pkm_stiffness() {
    let options = ReportOptions {
        hold: vec![("ZA".into(), 75.0)],
        ..Default::default()
    };
    let (html, out) = page("rps_3", options);
    assert!(html.contains("<h2>Static stiffness</h2>"));
    assert!(html.contains("ZA (mm) = 75.0000"), "the held height is the one given");
    for stem in ["stiffness_z", "stiffness_least", "stiffness_pose"] {
        for ext in ["png", "svg"] {
            let f = out.join(format!("{stem}.{ext}"));
            assert!(std::fs::metadata(&f).is_ok_and(|m| m.len() > 1000), "{f:?}");
        }
    }
    let csvs = read_csvs(&out);
    let rows = |stem: &str| csvs.iter().find(|(n, _, _)| n == stem).unwrap().2.clone();
    let (along_z, least) = (rows("stiffness_z"), rows("stiffness_least"));
    assert_eq!((along_z.len(), least.len()), (41 * 41, 41 * 41));
    // The centre, a corner, and a node off both axes.
    let check = |node: usize| {
        let (alpha, beta) = (&along_z[node][0], &along_z[node][1]);
        assert_eq!((alpha, beta), (&least[node][0], &least[node][1]));
        let branch = shortest_legs_branch(
            "examples/mechanisms/rps_3.pkm",
            &format!("ZA=75,alpha={alpha},beta={beta}"),
        );
        let k: Vec<f64> = branch["K"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|r| r.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
            .collect();
        let k = pkm_runtime::nalgebra::Matrix6::from_row_slice(&k);
        let compliance = k.try_inverse().unwrap();
        let translational = k.fixed_view::<3, 3>(0, 0).into_owned();
        let expect_least = translational.symmetric_eigenvalues().min();
        let expect_z = branch["directional"]["z"].as_f64().unwrap();
        let got_z: f64 = along_z[node][2].parse().unwrap();
        let got_least: f64 = least[node][2].parse().unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        assert!(close(got_z, expect_z), "node {node}: k_z {got_z} against {expect_z}");
        assert!(close(got_z, 1.0 / compliance[(2, 2)]), "node {node}: k_z {got_z}");
        assert!(
            close(got_least, expect_least),
            "node {node}: least {got_least} against {expect_least}"
        );
    };
    for node in [20 * 41 + 20, 0, 33 * 41 + 7] {
        check(node);
    }
    let _ = std::fs::remove_dir_all(out);
}

/// Files without `limbs` get no stiffness section, and `--hold` on them,
/// or naming no output, is an error.
#[test]
fn no_stiffness_map_without_limbs() {
    for name in ["four_bar", "rps_3_tilt", "planar_3rpr"] {
        let (html, out) = page(name, ReportOptions::default());
        assert!(!html.contains("Static stiffness"), "{name}");
        assert!(!out.join("stiffness_z.csv").exists(), "{name}");
        let _ = std::fs::remove_dir_all(out);
    }
    let hold = |name: &str| ReportOptions {
        hold: vec![(name.into(), 1.0)],
        ..Default::default()
    };
    check("rps_3_tilt", hold("ZA"), "declares no `units` and `limbs`");
    check(
        "rps_3",
        hold("height"),
        "--hold height: no such output (the outputs: ZA, alpha, beta)",
    );
}
