//! The page itself: its head, figures inline, numbers and signs as text.

use super::ReportError;
use crate::plots::{self, Figure, Style};
use pkm_runtime::primitives::Sign;
use pkm_runtime::velocity;
use std::path::{Path, PathBuf};

/// The page being written and the directory it and its figures go to.
pub(super) struct Page<'a> {
    /// The HTML so far.
    pub(super) html: String,
    /// The directory the page and its figures (PNG, SVG, CSV) go to.
    pub(super) dir: &'a Path,
}

impl Page<'_> {
    /// Shows a figure already written beside the page.
    pub(super) fn figure(&mut self, f: &Figure, caption: &str) {
        self.html.push_str(&figure_html(f, caption));
    }

    /// Writes sets of points in physical space (equal axis scales; `joined`:
    /// each set as a line through its points) as the figure `stem` beside the
    /// page, and shows it with `caption`.
    pub(super) fn scatter(
        &mut self,
        stem: &str,
        title: &str,
        labels: [&str; 2],
        sets: &[(String, Vec<[f64; 2]>)],
        joined: bool,
        caption: &str,
    ) -> Result<(), ReportError> {
        let style = Style {
            equal_axes: true,
            joined,
        };
        let f = plots::scatter(&self.dir.join(stem), title, labels, sets, style)?;
        self.figure(&f, caption);
        Ok(())
    }
}

impl Page<'_> {
    /// Curves over `x` (its axis `x_label`), one chart per unit: `series`
    /// are (name, unit, values). One unit: the figure `stem`; more: one
    /// `stem_UNIT` each (the unit's letters and digits), its title and
    /// caption naming the unit.
    pub(super) fn curves_per_unit(
        &mut self,
        stem: &str,
        title: &str,
        x_label: &str,
        x: &[f64],
        series: &[(String, String, Vec<f64>)],
        caption: &str,
    ) -> Result<(), ReportError> {
        let mut units: Vec<&str> = Vec::new();
        for (_, u, _) in series {
            if !units.contains(&u.as_str()) {
                units.push(u);
            }
        }
        for unit in &units {
            let of: Vec<(String, Vec<f64>)> = series
                .iter()
                .filter(|(_, u, _)| u == unit)
                .map(|(n, _, v)| (n.clone(), v.clone()))
                .collect();
            let (stem, title, caption) = if units.len() == 1 {
                (stem.to_string(), title.to_string(), caption.to_string())
            } else {
                let tag: String = unit
                    .chars()
                    .map(|c| if c.is_alphanumeric() { c } else { '_' })
                    .collect();
                (
                    format!("{stem}_{tag}"),
                    format!("{title} ({unit})"),
                    format!("{caption}: those in {unit}"),
                )
            };
            let f = plots::curves(
                &self.dir.join(&stem),
                &title,
                [x_label, &format!("value ({unit})")],
                x,
                &of,
            )?;
            self.figure(&f, &caption);
        }
        Ok(())
    }
}

impl std::fmt::Write for Page<'_> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.html.push_str(s);
        Ok(())
    }
}

/// The page's head: title and style.
pub(super) fn head(title: &str) -> String {
    let title = html_escape(title);
    format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{title}</title>\
         <style>body{{font-family:sans-serif;max-width:64em;margin:auto;padding:0 1em}}\
         pre{{background:#f6f6f6;padding:1em;overflow:auto}}table{{border-collapse:collapse;margin:0.5em 0;display:block;overflow-x:auto;max-width:100%}}\
         td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right;white-space:nowrap}}th{{background:#f0f0f0}}\
         td.l,th.l{{text-align:left;white-space:normal}}figure{{margin:1em 0}}figure img,figure svg{{max-width:100%;height:auto}}\
         figcaption{{color:#444}}</style></head><body><h1>{title}</h1>\n"
    )
}

/// Text safe inside HTML.
pub(super) fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// A figure inline (its PNG as a data URI, so the page stands alone) with
/// links to the files beside the page.
pub(super) fn figure_html(f: &Figure, caption: &str) -> String {
    use base64::Engine as _;
    let png = std::fs::read(&f.png).unwrap_or_default();
    let data = base64::engine::general_purpose::STANDARD.encode(png);
    let name = |p: &PathBuf| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    format!(
        "<figure><img alt=\"{0}\" src=\"data:image/png;base64,{data}\"><figcaption>{0} (<a href=\"{1}\">PNG</a>, \
         <a href=\"{2}\">SVG</a>, <a href=\"{3}\">CSV</a>)</figcaption></figure>\n",
        html_escape(caption),
        name(&f.png),
        name(&f.svg),
        name(&f.csv)
    )
}

/// Numbers as `(a, b, c)` with `digits` decimals.
pub(super) fn tuple_text(v: &[f64], digits: usize) -> String {
    format!(
        "({})",
        v.iter().map(|x| format!("{x:.digits$}")).collect::<Vec<_>>().join(", ")
    )
}

/// `+−+`: a branch's signs as text.
pub(super) fn sign_text(s: &[Sign]) -> String {
    if s.is_empty() {
        return "(one)".into();
    }
    s.iter().map(|x| if *x == Sign::Plus { '+' } else { '−' }).collect()
}

/// A configuration's singularity class as the page names it.
pub(super) fn class_text(s: velocity::Singularity) -> &'static str {
    match s {
        velocity::Singularity::None => "regular",
        velocity::Singularity::Input => "input singular",
        velocity::Singularity::Output => "output singular",
        velocity::Singularity::Combined => "input and output singular",
    }
}
