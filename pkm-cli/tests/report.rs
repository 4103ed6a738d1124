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

/// The page's text without its inline images (base64 would match any word).
fn page_text(html: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(at) = rest.find("base64,") {
        out.push_str(&rest[..at]);
        rest = &rest[at..];
        rest = &rest[rest.find('"').unwrap_or(rest.len())..];
    }
    out.push_str(rest);
    out
}

/// The length unit a file's labels must show: its `units` block's, else "file unit".
fn unit_of(text: &str) -> &'static str {
    if text.contains("length = m;") {
        "m"
    } else if text.contains("length = mm;") {
        "mm"
    } else {
        "file unit"
    }
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
        // No number that is not one is printed, on the page or in a CSV.
        let words = page_text(&html);
        for bad in ["NaN", "inf,", " inf ", "None"] {
            assert!(!words.contains(bad), "{name}: the page prints {bad}");
        }
        let csvs = read_csvs(&out);
        for (stem, _, rows) in &csvs {
            assert!(
                rows.iter().flatten().all(|f| !f.contains("NaN") && !f.contains("inf")),
                "{name}: {stem}.csv holds a value that is not a number"
            );
        }
        let csv = |stem: &str| csvs.iter().find(|(n, _, _)| n == stem);
        // The link–joint graph is drawn for every file.
        assert!(csv("topology").is_some(), "{name}");
        let planar = text.contains("planar;");
        let unit = unit_of(&text);
        let length = |axis: &str| format!("{axis} ({unit})");
        // Every file with geometry and an inverse or forward plan is drawn
        // and moved: only the two whose κ = 1 files declare no outputs are topology only.
        let topology_only = ["seed003_punch_original", "stephenson3"].contains(&name.as_str());
        assert_eq!(csv("mechanism").is_none(), topology_only, "{name}: the drawing");
        if let Some((_, header, rows)) = csv("mechanism") {
            assert_eq!(header[3..], [length("x"), length("y"), length("z")], "{name}");
            assert!(
                extent(rows, 3) > 1.0 || extent(rows, 4) > 1.0,
                "{name}: the drawing spans the plane"
            );
            assert!(html.contains("<svg"), "{name}: the animation is in the page");
            assert!(out.join("animation.svg").exists(), "{name}");
            // With no forward plan the motion is driven by poses: the actuators' values along it.
            let inputs_driven = html.contains("<h2>Velocity and acceleration");
            let pose_driven = html.contains("<h2>Motion</h2>");
            assert!(inputs_driven != pose_driven, "{name}: one motion");
            if pose_driven {
                assert!(
                    csvs.iter().any(|(n, _, _)| n.starts_with("motion_inputs")),
                    "{name}: the actuators along the motion"
                );
                assert!(
                    html.contains("<h2>Singularities of the inverse solution</h2>"),
                    "{name}"
                );
            }
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
            if planar && inputs_driven {
                let (_, header, rows) = csv("workspace_xOy").unwrap_or_else(|| panic!("{name}: workspace in xOy"));
                assert_eq!(header[1..], [length("x"), length("y")]);
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
            }
            if planar {
                for flat in ["workspace_yOz", "workspace_xOz", "workspace_3d"] {
                    assert!(csv(flat).is_none(), "{name}: no {flat} for a planar mechanism");
                }
            }
        }
        // Every length label is in the file's unit.
        for (stem, header, _) in &csvs {
            for h in header {
                for other in ["(mm)", "(m)", "(file unit)", "(mm/s)", "(N·mm)"] {
                    if h.contains(other) {
                        assert!(
                            h.contains(&format!("({unit}")) || h.contains(&format!("·{unit})")),
                            "{name}: {stem}: {h}"
                        );
                    }
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
    assert!(html.contains("a curve, length 2.0000e2 file unit"));
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
    // The f33 condition by name (tests/testsuite/singularities.rs places it).
    assert!(html.contains("the path of R6 (D) moved by R4 (C1, o) touches the sphere about Pa (B3)"));
    // The velocity CSV holds the whole 0–5 s trajectory: 501 rows and a header.
    let csv = std::fs::read_to_string(out.join("velocity.csv")).unwrap();
    assert_eq!(csv.lines().count(), 502);
    // Seed 000's actuators slide: their forces in N, on a chart of their own.
    assert!(out.join("driving_forces.csv").exists() && !out.join("driving_torques.csv").exists());
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

#[test]
fn curved_workspace_reports_its_grid_image() {
    // The spherical five-bar's pointing point P stays on the sphere of
    // radius 100 about the centre: two inputs, a curved surface. Its area
    // is the input grid's image, and two full crank turns reach places
    // twice: the image (1.8e5) exceeds the whole sphere's 4π·100² = 1.26e5,
    // which the page says can happen; no flat area, no volume.
    let options = ReportOptions {
        nodes: Some(60),
        ..Default::default()
    };
    let (html, out) = page("spherical_five_bar", options);
    let text = page_text(&html);
    assert!(text.contains("The set is a curved surface"), "{text}");
    assert!(text.contains("counts each time, so the surface's own area is at most this"));
    assert!(!text.contains("flat (") && !text.contains("a solid, volume"));
    let area: f64 = text
        .split("the input grid's image has area ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|a| a.parse().ok())
        .unwrap();
    let sphere = 4.0 * std::f64::consts::PI * 100.0f64.powi(2);
    assert!(area > sphere && area < 2.0 * sphere, "{area}");
    assert!(text.contains("The curved workspace projected on its best-fitting plane"));
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn four_inputs_sweep_three_and_hold_the_fourth() {
    // The two-limb Schönflies robot (P1, R1, R4, R5): its workspace sweeps
    // P1, R1 and R4 and holds R5 at the study's start, 2.2 rad. Its
    // revolutes all turn about z, so o's height is P1's alone (the
    // decoupling table: z ← P1): a prism whose z runs over P1's range,
    // −100 .. 200, and whose volume is at most that height times the
    // xOy projection's bounding box.
    let options = ReportOptions {
        nodes: Some(20),
        ..Default::default()
    };
    let (html, out) = page("schoenflies_2limb", options);
    let text = page_text(&html);
    assert!(text.contains("R5 held at 2.2000 rad (the sample's)"), "{text}");
    let volume: f64 = text
        .split("The set is a solid, volume ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap();
    let csvs = read_csvs(&out);
    let rows = |stem: &str| &csvs.iter().find(|(n, ..)| n == stem).unwrap().2;
    let z: Vec<f64> = rows("workspace_xOz").iter().map(|r| r[2].parse().unwrap()).collect();
    let (lo, hi) = z
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(
        (lo + 100.0).abs() < 1e-9 && (hi - 200.0).abs() < 1e-9,
        "z over [{lo}, {hi}]"
    );
    let xy = rows("workspace_xOy");
    let box_area = extent(xy, 1) * extent(xy, 2);
    assert!(
        volume > 0.0 && volume <= 300.0 * box_area,
        "{volume} against {}",
        300.0 * box_area
    );
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
    // The command line's checks on the values given, with its words: a
    // link length taken through zero (a1 = 120 by the file) is refused.
    check(
        "five_bar",
        ReportOptions {
            params: vec![("a1".into(), -5.0)],
            ..o()
        },
        "parameter a1 = -5 must be positive: the distance R1–R2 on link left",
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
        "study { pose (1, 2); }",
        "`pose` needs 0 values, one per declared output",
    );
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

/// `pkm stiffness --json` (the command line's own path: `plan::run_all`,
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
        // Crossed where J is ill-conditioned, as pkm stiffness measures it.
        let conditioning = branch["conditioning"].as_f64().unwrap();
        assert_eq!(
            along_z[node][3] == "true",
            conditioning < 1e-2,
            "node {node}: σ {conditioning}"
        );
        conditioning < 1e-2
    };
    for node in [20 * 41 + 20, 0, 33 * 41 + 7] {
        assert!(!check(node), "node {node}: well conditioned at ZA = 75");
    }
    assert!(html.contains("The colour scales are logarithmic"));
    let _ = std::fs::remove_dir_all(out);
}

/// Issue 29, item 5: the 3-RPS's map at its default held height (where J
/// is best conditioned level) spans 4.5 decades of the stiffness along z:
/// its colours are on a log scale, and the corner (0.3, −0.3) where it is
/// least is crossed as ill-conditioned, as `pkm stiffness` measures J's
/// conditioning there (below 1e-2); the held pose is not.
#[test]
fn stiffness_map_marks_ill_conditioned_nodes() {
    let (html, out) = page("rps_3", ReportOptions::default());
    let words = page_text(&html);
    let at = words.find("ZA (mm) = ").unwrap() + "ZA (mm) = ".len();
    let za: f64 = words[at..]
        .split(|c: char| c != '.' && !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let (_, header, rows) = read_csvs(&out)
        .into_iter()
        .find(|(n, _, _)| n == "stiffness_z")
        .unwrap();
    assert_eq!(header[3], "ill-conditioned");
    let values: Vec<f64> = rows.iter().filter_map(|r| r[2].parse().ok()).collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
    assert!(hi / lo > 1e4, "{lo} .. {hi}: over four decades");
    for (node, crossed) in [(20 * 41 + 20, false), (40 * 41, true)] {
        let (alpha, beta) = (&rows[node][0], &rows[node][1]);
        let branch = shortest_legs_branch(
            "examples/mechanisms/rps_3.pkm",
            &format!("ZA={za},alpha={alpha},beta={beta}"),
        );
        let conditioning = branch["conditioning"].as_f64().unwrap();
        assert_eq!(conditioning < 1e-2, crossed, "node {node}: σ {conditioning}");
        assert_eq!(rows[node][3] == "true", crossed, "node {node}");
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

/// The text of an example with `from` replaced by `to` (each must occur).
fn edited(name: &str, edits: &[(&str, &str)]) -> (String, String) {
    let (mut text, path) = example(name);
    for (from, to) in edits {
        assert!(text.contains(from), "{name}: no `{from}`");
        text = text.replacen(from, to, 1);
    }
    (text, path)
}

/// Issue 29, item 5: a file in metres is labelled in metres everywhere
/// (page and CSV headers), never mm. The punch with its lengths, masses'
/// centroids and inertias in m (kg·m² = 10⁶ kg·mm²): its drawing's joint
/// positions are the millimetre file's divided by 1000, its crank torque
/// (N·m) the millimetre file's (N·mm) divided by 1000.
#[test]
fn a_file_in_metres_is_labelled_in_metres() {
    let (text, path) = example("seed003_punch");
    let metres = text
        .replace("units { length = mm; mass = kg; }", "units { length = m; mass = kg; }")
        .replace(
            "parameters { m = 235; n = 205; l1 = 40; l2 = 117; l8 = 80; l4 = 170; l5 = 108.96; l7 = 108.96; }",
            "parameters { m = 0.235; n = 0.205; l1 = 0.040; l2 = 0.117; l8 = 0.080; l4 = 0.170; l5 = 0.10896; l7 = 0.10896; }",
        )
        .replace("inertia = 0.631 - 0.00118 * (l1 / 2)^2;", "inertia = 0.631e-6 - 0.00118 * (l1 / 2)^2;")
        .replace("inertia = 12.534;", "inertia = 12.534e-6;")
        .replace("inertia = 9.63;", "inertia = 9.63e-6;")
        .replace("inertia = 2.75;", "inertia = 2.75e-6;")
        .replace("inertia = 11 - 0.00277 * (l7 / 2)^2;", "inertia = 11e-6 - 0.00277 * (l7 / 2)^2;");
    // Gravity is in m/s² in either file: it stays.
    assert_eq!(metres.matches("e-6").count(), 5);
    let nodes = ReportOptions {
        nodes: Some(73),
        ..Default::default()
    };
    let (out_m, out_mm) = (out_dir("metres"), out_dir("millimetres"));
    let page = write_report(&metres, &path, &nodes, &out_m).unwrap();
    write_report(&text, &path, &nodes, &out_mm).unwrap();
    let words = page_text(&std::fs::read_to_string(page).unwrap());
    for mm in [" mm", "(mm", "·mm", "mm)", "mm/", "mm²", "mm³"] {
        assert!(!words.contains(mm), "the page in metres says `{mm}`");
    }
    assert!(words.contains("Lengths in m and angles in radians"));
    assert!(words.contains("torques in N·m"));
    for (stem, header, _) in read_csvs(&out_m) {
        assert!(header.iter().all(|h| !h.contains("mm")), "{stem}: {header:?}");
    }
    let column = |dir: &Path, stem: &str, k: usize| -> Vec<f64> {
        let (_, _, rows) = read_csvs(dir).into_iter().find(|(n, _, _)| n == stem).unwrap();
        // An empty field is a value that is not finite (a gap in the curve).
        rows.iter()
            .map(|r| {
                if r[k].is_empty() {
                    f64::NAN
                } else {
                    r[k].parse().unwrap()
                }
            })
            .collect()
    };
    for k in [3, 4] {
        for (a, b) in column(&out_m, "mechanism", k)
            .iter()
            .zip(column(&out_mm, "mechanism", k))
        {
            assert!(
                (a.is_nan() && b.is_nan()) || (a * 1000.0 - b).abs() <= 1e-9 * b.abs().max(1.0),
                "{a} m against {b} mm"
            );
        }
    }
    let (m, mm) = (
        column(&out_m, "driving_torques", 1),
        column(&out_mm, "driving_torques", 1),
    );
    // Both files' dimensions are the same decimals in another unit, rounded
    // differently: the torques agree to 1e-6 (of the largest) where the
    // force equations are well conditioned, and both leave the same steps out.
    let largest = mm.iter().filter(|b| b.is_finite()).fold(0.0f64, |a, b| a.max(b.abs()));
    assert_eq!(m.len(), mm.len());
    for (a, b) in m.iter().zip(&mm) {
        assert!(
            (a.is_nan() && b.is_nan()) || (a * 1000.0 - b).abs() <= 1e-6 * largest,
            "{a} N·m against {b} N·mm"
        );
    }
    // A name on the command line that is not the file's unit is an error.
    let e = write_report(
        &metres,
        &path,
        &ReportOptions {
            unit: Some("mm".into()),
            ..Default::default()
        },
        &out_dir("metres-mm"),
    )
    .unwrap_err();
    assert!(e.to_string().contains("declares its lengths in m"), "{e}");
    let _ = std::fs::remove_dir_all(out_m);
    let _ = std::fs::remove_dir_all(out_mm);
}

/// Issue 29, item 5: a coordinate of −1e308 made plotters' tick routine
/// spin forever; every extent is checked before it reaches plotters, so
/// the report is an error naming the figure, well within a minute.
#[test]
fn an_overflowing_extent_is_an_error_not_a_hang() {
    let (big, path) = edited("scotch_yoke", &[("R1 = (0, 0);", "R1 = (-1e308, 0);")]);
    let cases = [
        (big, ReportOptions::default()),
        (
            example("scotch_yoke").0,
            ReportOptions {
                params: vec![("r".into(), 1e308)],
                ..Default::default()
            },
        ),
    ];
    for (k, (text, options)) in cases.into_iter().enumerate() {
        let (send, receive) = std::sync::mpsc::channel();
        let (path, out) = (path.clone(), out_dir(&format!("overflow-{k}")));
        std::thread::spawn(move || {
            let _ = send.send(write_report(&text, &path, &options, &out).map(|_| ()));
        });
        let result = receive
            .recv_timeout(std::time::Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("case {k}: no answer within 60 s"));
        let e = result.unwrap_err().to_string();
        assert!(
            e.contains("cannot be drawn") && e.contains("out of range"),
            "case {k}: {e}"
        );
    }
}

/// `pkm` with `args`, its standard output as JSON.
fn pkm_json(args: &[&str]) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pkm"))
        .args(args)
        .arg("--json")
        .current_dir(common::root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Issue 29, item 5: the punch's sweep of F against A parked F at x = 0
/// for 161 of 721 nodes (the fixed branch index, whose root is F at H past
/// the change points). With l5 = l7 the two roots of F are x = 0 and
/// x = 2·G_x (the isosceles triangle H–G–F): followed by continuity, F is
/// 2·G_x at every node, G from `pkm fk` at that input; and the page says
/// where the assembly passes from branch 3 to branch 7, around φ* =
/// 2.6968631790545614 rad, where F passes through H (G_x = 0).
#[test]
fn the_punch_sweep_follows_f_through_h() {
    let (html, out) = page("seed003_punch", ReportOptions::default());
    let (_, header, rows) = read_csvs(&out)
        .into_iter()
        .find(|(n, _, _)| n == "displacement")
        .unwrap();
    assert_eq!(header, ["A (rad)", "x", "y"]);
    assert_eq!(rows.len(), 721, "every node reached");
    let parked = rows
        .iter()
        .filter(|r| r[1].parse::<f64>().unwrap().abs() < 1e-9)
        .count();
    assert!(parked <= 1, "{parked} nodes at x = 0");
    // fk's G at every 20th node (its four solvable branches share G).
    for r in rows.iter().step_by(20) {
        let a: f64 = r[0].parse().unwrap();
        let fk = pkm_json(&["fk", "examples/mechanisms/seed003_punch.pkm", &format!("--q={a}")]);
        // Branches 3 and 7 (− − ±): C below B, G by the − root; F's is the third sign.
        let gx = fk["branches"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["ok"] == true && b["signs"][0] == "-" && b["signs"][1] == "-")
            .map(|b| b["points"]["G"][0].as_f64().unwrap())
            .unwrap();
        let x: f64 = r[1].parse().unwrap();
        assert!((x - 2.0 * gx).abs() < 1e-9, "A = {a}: F at {x}, 2·G_x = {}", 2.0 * gx);
    }
    let phi = 2.6968631790545614;
    let at = html
        .find("from branch 3 (−−+) to branch 7 (−−−) between A = 2.")
        .expect("the pass at φ*");
    let between: Vec<f64> = html[at..]
        .split("A = ")
        .skip(1)
        .take(2)
        .map(|s| s.split(' ').next().unwrap().parse().unwrap())
        .collect();
    assert!(between[0] < phi && phi < between[1], "{between:?}");
    // The trajectory names the same passes.
    assert!(html.contains("The assembly passes from branch 3 (−−+) to branch 7 (−−−) at t = "));
    let _ = std::fs::remove_dir_all(out);
}

/// Issue 29, item 5: the 3-RPS's legs are drawn as members, from each base
/// revolute to its ball, as long as `pkm ik` makes the leg (seed 004's
/// home: √(20² + 75²) = 77.62 mm), and joints drawn at one place share one
/// label (P1 and S1 at the ball).
#[test]
fn legs_are_drawn_as_members_with_one_label_per_place() {
    let (text, _) = example("rps_3");
    let a = pkm_dsl::compile(&text).unwrap().analysis;
    let values = pkm_dsl::params::overrides(&a, &[]).unwrap();
    let model = pkm_dsl::numeric::model(&a, &values).unwrap();
    let plan = pkm_dsl::planner::inverse_plan(&a).unwrap();
    // Every branch: each member as long as its slide's value; on the one
    // with the shortest legs (the seed's assembly) each is the home leg.
    let choices = plan.choices();
    let mut shortest: Option<(f64, pkm_cli::drawing::Scene)> = None;
    for b in 0..1usize << choices {
        let signs: Vec<_> = (0..choices)
            .map(|k| {
                if b >> k & 1 == 1 {
                    pkm_runtime::primitives::Sign::Minus
                } else {
                    pkm_runtime::primitives::Sign::Plus
                }
            })
            .collect();
        let Ok(v) = plan.solve(&model, &[75.0, 0.0, 0.0], &signs) else {
            continue;
        };
        let poses = pkm_runtime::newton::link_poses(&model, &v).unwrap();
        let scene = pkm_cli::drawing::scene(&model, &poses, (0, [0.0; 3]));
        let members: Vec<f64> = scene
            .segments
            .iter()
            .filter(|s| s.link.is_some())
            .map(|s| {
                let (a, b) = s.ends;
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .collect();
        assert_eq!(members.len(), 3);
        let (offsets, _) = model.value_offsets();
        let mut slides: Vec<f64> = model
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.kind == pkm_runtime::model::JointType::P)
            .map(|(k, _)| v[offsets[k]].abs())
            .collect();
        let mut sorted = members.clone();
        sorted.sort_by(f64::total_cmp);
        slides.sort_by(f64::total_cmp);
        for (m, s) in sorted.iter().zip(&slides) {
            assert!((m - s).abs() < 1e-9, "branch {b}: member {m} against slide {s}");
        }
        let total: f64 = members.iter().sum();
        if shortest.as_ref().is_none_or(|(t, _)| total < *t) {
            shortest = Some((total, scene));
        }
    }
    let (total, scene) = shortest.unwrap();
    let leg = (20f64.powi(2) + 75f64.powi(2)).sqrt();
    assert!((total - 3.0 * leg).abs() < 1e-9, "{total} against 3 × {leg}");
    let out = out_dir("members");
    std::fs::create_dir_all(&out).unwrap();
    pkm_cli::drawing::draw(
        &out.join("rps"),
        "rps",
        &scene,
        pkm_cli::drawing::View::Axonometric,
        "mm",
        "o",
    )
    .unwrap();
    let svg = std::fs::read_to_string(out.join("rps.svg")).unwrap();
    for label in ["P1, S1", "P2, S2", "P3, S3"] {
        assert!(svg.contains(label), "{label}");
    }
    let _ = std::fs::remove_dir_all(out);
}

/// Issue 29, item 5: seed000_a's P1 and P2 slide on one base line; their
/// guides, clipped to the plot, lie on one line in the drawing (clamped,
/// they turned at the plot's edge and crossed).
#[test]
fn guides_leaving_the_plot_are_clipped_in_their_direction() {
    let (_, out) = page(
        "seed000_a",
        ReportOptions {
            nodes: Some(6),
            ..Default::default()
        },
    );
    let svg = std::fs::read_to_string(out.join("mechanism.svg")).unwrap();
    // The grey guides: polylines stroked rgb(150, 150, 150), two points each.
    let mut guides: Vec<[(f64, f64); 2]> = Vec::new();
    for line in svg.split("<polyline").skip(1) {
        if !line.contains("#969696") {
            continue;
        }
        let points = line.split("points=\"").nth(1).unwrap().split('"').next().unwrap();
        let p: Vec<(f64, f64)> = points
            .split_whitespace()
            .map(|xy| {
                let (x, y) = xy.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        if p.len() == 2 {
            guides.push([p[0], p[1]]);
        }
    }
    // Two of them (P1's and P2's) are collinear: each end of one on the other's line.
    let on_line = |g: [(f64, f64); 2], p: (f64, f64)| {
        let (d, e) = ((g[1].0 - g[0].0, g[1].1 - g[0].1), (p.0 - g[0].0, p.1 - g[0].1));
        (d.0 * e.1 - d.1 * e.0).abs() / (d.0.hypot(d.1)) < 1.5
    };
    let pairs = (0..guides.len())
        .flat_map(|i| (i + 1..guides.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| on_line(guides[i], guides[j][0]) && on_line(guides[i], guides[j][1]))
        .count();
    assert!(pairs >= 1, "no two guides on one line: {guides:?}");
    let _ = std::fs::remove_dir_all(out);
}

/// Issue 29, items 2 and 5: seed 004's 3-RPS, 3-SPR and 6-UPS, and the
/// agile eye, have an inverse plan and no forward one: their pages draw
/// them, sweep the workspace through the inverse solution, map the inverse
/// singularities and move them. Every branch `pkm ik` lists at the sample
/// pose is in the page's table in its order, each ok or with its reason;
/// the actuators' rates along the motion (J_i times the outputs' rates)
/// are the differences of their values to the step's second order.
#[test]
fn inverse_only_mechanisms_get_kinematics() {
    for name in ["rps_3", "spr_3", "ups_6", "agile_eye"] {
        let (html, out) = page(
            name,
            ReportOptions {
                nodes: Some(12),
                ..Default::default()
            },
        );
        for section in [
            "<h2>The mechanism at the sample pose</h2>",
            "<h2>Singularities of the inverse solution</h2>",
            "<h2>Motion</h2>",
        ] {
            assert!(html.contains(section), "{name}: {section}");
        }
        assert!(!html.contains("no inverse plan"), "{name}");
        assert!(
            out.join("mechanism.svg").exists() && out.join("animation.svg").exists(),
            "{name}"
        );
        // The sample pose, as the page gives it, through `pkm ik`.
        let words = page_text(&html);
        let at = words.find("The sample pose: ").unwrap() + "The sample pose: ".len();
        let pose: Vec<String> = words[at..]
            .split(" (")
            .next()
            .unwrap()
            .split(", ")
            .map(|kv| {
                let (k, v) = kv.split_once(" = ").unwrap();
                format!("{k}={}", v.split(' ').next().unwrap())
            })
            .collect();
        let file = format!("examples/mechanisms/{name}.pkm");
        let ik = pkm_json(&["ik", &file, "--pose", &pose.join(",")]);
        let branches = ik["branches"].as_array().unwrap();
        let table = &words[words.find("<code>pkm ik</code> lists them").unwrap()..];
        let table = &table[..table.find("</table>").unwrap()];
        let rows: Vec<&str> = table.split("<tr><td>").skip(1).collect();
        assert_eq!(rows.len(), branches.len(), "{name}: every branch");
        for (k, (row, b)) in rows.iter().zip(branches).enumerate() {
            let signs: String = b["signs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| if s == "+" { '+' } else { '−' })
                .collect();
            assert!(row.starts_with(&k.to_string()), "{name}: row {k}: {row}");
            assert!(row.contains(&format!("<td>{signs}</td>")), "{name}: row {k}: {row}");
            assert_eq!(b["ok"] == true, !row.contains("no solution"), "{name}: row {k}: {row}");
        }
        // Rates against differences of the values (central, interior steps).
        let csvs = read_csvs(&out);
        let values: Vec<_> = csvs.iter().filter(|(n, _, _)| n.starts_with("motion_inputs")).collect();
        let rates: Vec<_> = csvs.iter().filter(|(n, _, _)| n.starts_with("motion_rates")).collect();
        if name == "agile_eye" {
            // Its outputs (a point fixed at the centre and one turn) do not fix every motion.
            assert!(rates.is_empty() && html.contains("No actuator rates"));
            continue;
        }
        assert_eq!(values.len(), rates.len(), "{name}");
        for ((_, vh, v), (_, rh, r)) in values.iter().zip(&rates) {
            assert_eq!(vh.len(), rh.len());
            let t: Vec<f64> = v.iter().map(|row| row[0].parse().unwrap()).collect();
            for c in 1..vh.len() {
                let x: Vec<f64> = v.iter().map(|row| row[c].parse().unwrap()).collect();
                let xd: Vec<f64> = r.iter().map(|row| row[c].parse().unwrap()).collect();
                let scale = xd.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                for i in 1..t.len() - 1 {
                    let fd = (x[i + 1] - x[i - 1]) / (t[i + 1] - t[i - 1]);
                    assert!(
                        (fd - xd[i]).abs() < 2e-3 * scale,
                        "{name} {}: t = {}: {fd} against {}",
                        vh[c],
                        t[i],
                        xd[i]
                    );
                }
            }
        }
        let _ = std::fs::remove_dir_all(out);
    }
}

/// Issue 29, item 4: files with spherical joints get a whole page; with
/// masses on the RSSR's links the force system is singular at every step
/// (the coupler spins about its own axis), which the page says instead of
/// drawing empty charts or printing NaN.
#[test]
fn spherical_joints_get_a_whole_page() {
    for name in ["rssr", "rsur", "rssp"] {
        let (html, out) = page(name, ReportOptions::default());
        for section in [
            "The mechanism at the sample input",
            "Workspace of",
            "Velocity and acceleration",
        ] {
            assert!(html.contains(section), "{name}: {section}");
        }
        assert!(!page_text(&html).contains("NaN"), "{name}");
        let _ = std::fs::remove_dir_all(out);
    }
    let masses = common::example_with(
        "rssr",
        "units { length = mm; mass = kg; }
         masses {
             crank { mass = 0.1; centroid = (a / 2, 0, 0); inertia = (20, 20, 20); }
             coupler { mass = 0.3; centroid = (l / 2, 0, 0); inertia = (50, 600, 600); }
             rocker { mass = 0.2; centroid = (0, b / 2, 0); inertia = (240, 20, 240); }
         }
         gravity (0, 0, -9.80665);",
    )
    .replace("capabilities fk, ik;", "capabilities fk, ik, dynamics;");
    let out = out_dir("rssr-masses");
    let page = write_report(&masses, "rssr_masses.pkm", &ReportOptions::default(), &out).unwrap();
    let words = page_text(&std::fs::read_to_string(page).unwrap());
    assert!(words.contains("<h2>Driving forces and joint reactions</h2>"));
    assert!(!words.contains("NaN"));
    // Whatever Newton–Euler gives here, no chart is drawn empty.
    for (stem, _, rows) in read_csvs(&out) {
        if stem.starts_with("reaction_") || stem.starts_with("driving_") {
            assert!(
                rows.iter().any(|r| r[1..].iter().any(|f| !f.is_empty())),
                "{stem} is empty"
            );
        }
    }
    let _ = std::fs::remove_dir_all(out);
}

/// Issue 32, item 4: a κ = 1 file that asks for `fk_numeric` may give its
/// sample as an input (`study { start (…) }`): the six-assembly 3-RPR's
/// start, the legs (149.8, 153.8, 120) mm where all six of its assemblies
/// are real (by bisection, `fk_numeric::planar_3rpr_six_real_assemblies`),
/// puts its sample pose on one of them (the pose the page gives is one of
/// `pkm fk`'s six there, the branch shown takes the start's legs) and its
/// map of assembly modes through the region of six, with the third leg
/// held at 120 mm and the node nearest the start counting six. A file
/// without a forward solution still refuses `--start`.
#[test]
fn a_coupled_file_sampled_at_its_start() {
    let (html, out) = page(
        "planar_3rpr_six",
        ReportOptions {
            nodes: Some(8),
            ..Default::default()
        },
    );
    let words = page_text(&html);
    assert!(
        words
            .contains("(the forward solution at the start (149.8000, 153.8000, 120.0000): assembly 1 of 6, certified)"),
        "{words}"
    );
    let at = words.find("The sample pose: ").unwrap() + "The sample pose: ".len();
    let pose: Vec<f64> = words[at..]
        .split(" (")
        .next()
        .unwrap()
        .split(", ")
        .map(|kv| {
            kv.split_once(" = ")
                .unwrap()
                .1
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    let fk = pkm_json(&[
        "fk",
        "examples/mechanisms/planar_3rpr_six.pkm",
        "--q",
        "149.8,153.8,120",
    ]);
    let assemblies = fk["branches"].as_array().unwrap();
    assert_eq!(assemblies.iter().filter(|b| b["ok"] == true).count(), 6, "{fk}");
    let near = assemblies.iter().any(|b| {
        ["x", "y", "phi"]
            .iter()
            .zip(&pose)
            .all(|(n, v)| b["outputs"][n].as_f64().is_some_and(|o| (o - v).abs() <= 1e-4))
    });
    assert!(near, "{pose:?} is none of {fk}");
    // The branch shown has the start's legs.
    let table = &words[words.find("<code>pkm ik</code> lists them").unwrap()..];
    let shown = table.split("<tr><td>").nth(1).unwrap();
    assert!(
        shown.starts_with("0 (followed)</td><td>+++</td><td>149.800000</td><td>153.800000</td><td>120.000000</td>"),
        "{shown}"
    );
    let csvs = read_csvs(&out);
    let (_, header, rows) = csvs.iter().find(|(n, _, _)| n == "assembly_modes").unwrap();
    assert_eq!(header[..3], ["P1 (mm)", "P2 (mm)", "real assemblies"]);
    assert!(html.contains("P3 = 120.0000 mm held"));
    let node = |r: &Vec<String>| -> (f64, f64) { (r[0].parse().unwrap(), r[1].parse().unwrap()) };
    let nearest = rows
        .iter()
        .min_by(|a, b| {
            let d = |r: &Vec<String>| {
                let (p, q) = node(r);
                (p - 149.8).hypot(q - 153.8)
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    assert_eq!(nearest[2], "6", "{nearest:?}");
    let counts: std::collections::BTreeSet<&str> = rows.iter().map(|r| r[2].as_str()).collect();
    assert!(
        counts.contains("2") && counts.contains("4") && counts.contains("6"),
        "{counts:?}"
    );
    let _ = std::fs::remove_dir_all(out);
    // The 3-RPS has no forward solution to start from.
    let (text, path) = example("rps_3");
    let e = write_report(
        &text,
        &path,
        &ReportOptions {
            start: Some(vec![300.0, 300.0, 300.0]),
            ..Default::default()
        },
        &out_dir("rps_3-start"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("--ranges, --start, --amplitude and --speed sample its inputs"),
        "{e}"
    );
}

/// Issue 32, item 4: a file without a forward plan may give its sample
/// pose (`study { pose (…); }`, one value per declared output): the 6-UPS
/// at (10, −5, 250) mm turned by (0.05, −0.03, 0.1) rad. Its drawing has,
/// by hand, each ball's centre at p + R·bᵢ (R = R_z·R_y·R_x, bᵢ on the
/// platform's circle of 100 mm) and each U's centre on the base's circle
/// of 200 mm. `pose` with the wrong count, with `start`, or in a file that
/// has a forward plan is an error at its place or said so.
#[test]
fn a_study_pose_is_the_sample() {
    let (html, out) = page(
        "ups_6",
        ReportOptions {
            nodes: Some(8),
            ..Default::default()
        },
    );
    let words = page_text(&html);
    assert!(
        words.contains("The sample pose: x = 10.0000 mm, y = -5.0000 mm, z = 250.0000 mm")
            && words.contains("(the study's `pose`)"),
        "{words}"
    );
    let csvs = read_csvs(&out);
    let (_, header, rows) = csvs.iter().find(|(n, _, _)| n == "mechanism").unwrap();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let at = |label: &str| -> [f64; 3] {
        let row = rows
            .iter()
            .find(|r| r.iter().any(|c| c == label))
            .unwrap_or_else(|| panic!("{label}: {rows:?}"));
        [col("x (mm)"), col("y (mm)"), col("z (mm)")].map(|c| row[c].parse().unwrap())
    };
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    let (p, [rx, ry, rz]) = ([10.0, -5.0, 250.0], [0.05f64, -0.03, 0.1]);
    let turn = |v: [f64; 3]| -> [f64; 3] {
        let x = [
            v[0],
            v[1] * rx.cos() - v[2] * rx.sin(),
            v[1] * rx.sin() + v[2] * rx.cos(),
        ];
        let y = [
            x[0] * ry.cos() + x[2] * ry.sin(),
            x[1],
            -x[0] * ry.sin() + x[2] * ry.cos(),
        ];
        [
            y[0] * rz.cos() - y[1] * rz.sin(),
            y[0] * rz.sin() + y[1] * rz.cos(),
            y[2],
        ]
    };
    for (k, (ball, base)) in [
        (40.0f64, 20.0f64),
        (80.0, 100.0),
        (160.0, 140.0),
        (200.0, 220.0),
        (280.0, 260.0),
        (320.0, 340.0),
    ]
    .into_iter()
    .enumerate()
    {
        let (b, a) = (ball.to_radians(), base.to_radians());
        let r = turn([100.0 * b.cos(), 100.0 * b.sin(), 0.0]);
        let want = [p[0] + r[0], p[1] + r[1], p[2] + r[2]];
        let s = at(&format!("S{}", k + 1));
        assert!(dist(s, want) <= 1e-9, "ball {}: {s:?} against {want:?}", k + 1);
        let u = at(&format!("U{}.a", k + 1));
        assert!(
            dist(u, [200.0 * a.cos(), 200.0 * a.sin(), 0.0]) <= 1e-9,
            "U {}: {u:?}",
            k + 1
        );
    }
    let _ = std::fs::remove_dir_all(out);
    let fails = |name: &str, edits: &[(&str, &str)]| -> String {
        let (text, path) = edited(name, edits);
        write_report(
            &text,
            &path,
            &ReportOptions::default(),
            &out_dir(&format!("{name}-pose")),
        )
        .unwrap_err()
        .to_string()
    };
    let study = "study { pose (10, -5, 250, 0.05, -0.03, 0.1); }";
    let e = fails("ups_6", &[(study, "study { pose (10, -5, 250); }")]);
    assert!(
        e.contains("`pose` needs 6 values, one per declared output") && e.contains("ups_6.pkm:"),
        "{e}"
    );
    let e = fails(
        "ups_6",
        &[(
            study,
            "study { start (250, 250, 250, 250, 250, 250); pose (10, -5, 250, 0.05, -0.03, 0.1); }",
        )],
    );
    assert!(
        e.contains("the sample is an input (`start`) or a pose (`pose`), not both"),
        "{e}"
    );
    let outputs = "outputs { x, y = point R3 of right_distal; }";
    let e = fails(
        "five_bar",
        &[(
            outputs,
            "outputs { x, y = point R3 of right_distal; } study { pose (0, 200); }",
        )],
    );
    assert!(
        e.contains("the study's `pose` samples a file without a forward plan"),
        "{e}"
    );
}
