//! `pkm report` end to end on seed 000's mechanism A with a small sweep:
//! the page and every figure (PNG, SVG, CSV) are written, the page stands
//! alone (figures inline) and carries each section; mechanism B's volumes
//! sit beside A's, and the determinant factors are named.

#[test]
fn report_on_mechanism_a() {
    let path = format!("{}/examples/mechanisms/seed000_a.pkm", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let out = std::env::temp_dir().join(format!("pkm-report-test-{}", std::process::id()));
    let options = pkm::report::ReportOptions {
        ranges: vec![(-250.0, 0.0), (0.0, 250.0), (-300.0, 300.0)],
        nodes: 12,
        branch: 1,
        point: Some("G".into()),
        start: Some(vec![-131.07, 181.55, -57.74]),
        amplitude: Some(vec![20.0, -10.0, 20.0]),
        sections: vec![(1, -85.0)],
        compare: vec![format!("{}/examples/mechanisms/seed000_b.pkm", env!("CARGO_MANIFEST_DIR")).into()],
        ..Default::default()
    };
    let page = pkm::report::write_report(&text, &options, &out).unwrap();
    let html = std::fs::read_to_string(&page).unwrap();
    for section in [
        "Topology",
        "Position solutions",
        "Workspace of G",
        "Singularities",
        "Velocity and acceleration",
        "Determinant factors on branch 1",
        "Workspace volumes of G, every branch",
        "Which factor comes near 0",
    ] {
        assert!(html.contains(section), "missing {section}");
    }
    assert!(html.contains("data:image/png;base64,"));
    assert!(html.contains("ξ_L1 = 3"), "the topology report is on the page");
    // A's four branches and B's eight in one table.
    assert_eq!(html.matches("<tr><td>seed000_a</td>").count(), 4);
    assert_eq!(html.matches("<tr><td>seed000_b</td>").count(), 8);
    // The f33 condition by name (tests/singularities.rs places it).
    assert!(html.contains("the path of R6 (D) moved by R4 (C1, o) touches the sphere about Pa (B3)"));
    for stem in [
        "workspace_xOy",
        "workspace_yOz",
        "workspace_xOz",
        "section_y_-85",
        "singularity_loci",
        "singularity_factors",
        "velocity",
        "acceleration",
    ] {
        for ext in ["png", "svg", "csv"] {
            let f = out.join(format!("{stem}.{ext}"));
            assert!(std::fs::metadata(&f).map(|m| m.len() > 0).unwrap_or(false), "{f:?}");
        }
    }
    // The velocity CSV holds the whole 0–5 s trajectory: 501 rows and a header.
    let csv = std::fs::read_to_string(out.join("velocity.csv")).unwrap();
    assert_eq!(csv.lines().count(), 502);
    assert!(csv.starts_with("t (s),x,y,z,magnitude"));
    let _ = std::fs::remove_dir_all(&out);
}
