//! `OUT/index.html`: the report of a `lobes run` (or `lobes merge`) as one static page: every case with its verdict,
//! parameters, figures and pictures, failures first. It opens from disk (no server, no network:
//! inline CSS, pictures by relative path), so a CI system can keep the output folder as an
//! artefact and a person can open it.
//!
//! A case's parameters come from its `histogram.json` (the one place they are written, and
//! last); a case without one (it could not run, or is incomplete) shows no pictures, only its
//! error. The page's `<body>`
//! carries `data-images`: `pending` until the browser's `load` event, then `loaded N` when all
//! `N` pictures decoded or `broken K of N` (what a test reads back from a headless browser).

use super::caption;
use super::compare::{BARS_PNG, EXPECTED_PNG, MARGINALS_PNG, MEASURED_PNG, RESIDUAL_COARSE_PNG, RESIDUAL_PNG};
use super::label::compact;
use super::output::{CaseMeasured, CaseSummary, HistogramFile};
use std::fmt::Write;
use std::path::Path;

/// The file name in the output folder.
pub use crate::folder_names::INDEX_HTML;

/// The pictures a case folder may hold, in the order shown, with what each shows.
const PICTURES: [(&str, &str); 7] = [
    (MEASURED_PNG, "measured counts"),
    (EXPECTED_PNG, "expected counts, same colour scale"),
    (RESIDUAL_PNG, "residual (measured − expected)/√expected"),
    (MARGINALS_PNG, "marginals against expected ± 2σ"),
    (RESIDUAL_COARSE_PNG, "residual in the blocks of the grid that caught the defect"),
    (BARS_PNG, "items against expected ± 2σ"),
    ("albedo.png", "albedo per bin"),
];

/// How a case ended, in the order the page lists them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Outcome {
    Error,
    Fail,
    Pass,
}

impl Outcome {
    fn of(c: &CaseSummary) -> Self {
        match (&c.error, c.passed) {
            (Some(_), _) => Outcome::Error,
            (None, false) => Outcome::Fail,
            (None, true) => Outcome::Pass,
        }
    }

    fn word(self) -> &'static str {
        match self {
            Outcome::Error => "ERROR",
            Outcome::Fail => "FAIL",
            Outcome::Pass => "pass",
        }
    }

    fn class(self) -> &'static str {
        match self {
            Outcome::Error => "error",
            Outcome::Fail => "fail",
            Outcome::Pass => "pass",
        }
    }
}

/// The page `OUT/index.html` of a run's `cases` (written by [`super::summary::write`]);
/// `heading` lines (adapter, significance) go under the title. Case folders are looked up under
/// `out`.
pub fn page(out: &Path, heading: &[String], cases: &[CaseSummary]) -> String {
    let mut order: Vec<&CaseSummary> = cases.iter().collect();
    order.sort_by_key(|c| Outcome::of(c));
    let count = |o: Outcome| cases.iter().filter(|c| Outcome::of(c) == o).count();
    let (errors, failed, passed) = (count(Outcome::Error), count(Outcome::Fail), count(Outcome::Pass));
    let mut h = String::new();
    let title = format!("lobes: {passed} of {} cases passed", cases.len());
    let _ = write!(h, "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n", escape(&title));
    h += "<body data-images=\"pending\">\n";
    let _ = writeln!(h, "<h1>{}</h1>", escape(&title));
    for line in heading {
        let _ = writeln!(h, "<p class=\"heading\">{}</p>", escape(line));
    }
    let _ = writeln!(h, "<p class=\"tally\"><span class=\"fail\">{failed} failed</span> · <span class=\"error\">{errors} could not run</span> · <span class=\"pass\">{passed} passed</span></p>");
    // the verdict's p (the family's) and the test that decided it first; the fine grid's
    // figures after them, named by its grid
    h += "<table class=\"cases\">\n<tr><th>case</th><th>verdict</th><th>p-value (family)</th><th>decided by</th><th>fine grid χ² / dof</th><th>fine grid p</th></tr>\n";
    for c in &order {
        let o = Outcome::of(c);
        let cells = c.measured.as_ref().map_or(["-".to_string(), "-".into(), "-".into(), "-".into()], |m| {
            let fine = m.family.first().map_or(String::new(), |f| format!(" ({})", f.test));
            [compact(family_p(m)), decided_by(m), format!("{:.1} / {}{fine}", m.chi2, m.dof), compact(m.p_value)]
        });
        let _ = writeln!(
            h,
            "<tr class=\"{}\"><td><a href=\"#{}\">{}</a></td><td class=\"verdict\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            o.class(),
            escape(&anchor(&c.case)),
            escape(&c.case),
            o.word(),
            escape(&cells[0]),
            escape(&cells[1]),
            escape(&cells[2]),
            escape(&cells[3]),
        );
    }
    h += "</table>\n";
    for c in &order {
        case_section(&mut h, out, c);
    }
    h += SCRIPT;
    h += "</body>\n</html>\n";
    h
}

/// One case: its name and verdict, parameters, figures, error and pictures.
fn case_section(h: &mut String, out: &Path, c: &CaseSummary) {
    let o = Outcome::of(c);
    let _ = writeln!(h, "<section class=\"case {}\" id=\"{}\">", o.class(), escape(&anchor(&c.case)));
    let _ = writeln!(h, "<h2>{} <span class=\"verdict\">{}</span></h2>", escape(&c.case), o.word());
    let folder = c.output.clone().unwrap_or_else(|| out.join(&c.case));
    // a folder without its histogram.json (written last) is incomplete: its pictures may be
    // half-written or left by an earlier run, so none is shown
    let complete = HistogramFile::read(&folder.join("histogram.json")).ok();
    if let Some(doc) = &complete {
        let _ = writeln!(h, "<p class=\"params\">{}</p>", escape(&caption::parameters(&doc.description)));
    }
    if let Some(e) = c.error.as_ref().or(c.failure.as_ref()) {
        let _ = writeln!(h, "<pre class=\"message\">{}</pre>", escape(e));
    }
    let mut figures = vec![("samples", c.samples.to_string())];
    if let Some(m) = &c.measured {
        figures.push(("p-value (family)", compact(family_p(m))));
        figures.push(("decided by", decided_by(m)));
        let fine = m.family.first().map_or("fine grid".to_string(), |f| format!("fine grid {}", f.test));
        figures.push(("χ² / dof", format!("{:.1} / {} ({fine}, p = {})", m.chi2, m.dof, compact(m.p_value))));
        figures.push(match m.gpu_seconds {
            Some(g) => ("GPU time", format!("{g:.3} s")),
            None => ("wall time", format!("{:.3} s", m.wall_seconds)),
        });
        if let Some(a) = m.max_angle_rad {
            figures.push(("max angle error", format!("{a:.2e} rad")));
        }
        if let Some(a) = &m.albedo {
            let verdict = if a.passed { "pass" } else { "FAIL" };
            let name = if a.transmitted.is_some() { "reflected albedo" } else { "albedo" };
            figures.push((name, format!("{:.5} against {:.5} ({:+.1e}), p = {}: {verdict}", a.albedo, a.reference, a.relative_error, compact(a.p_value))));
            if let Some(t) = &a.transmitted {
                figures.push(("transmitted albedo", format!("{:.5} against {:.5} ({:+.1e}), p = {}", t.albedo, t.reference, t.relative_error, compact(t.p_value))));
            }
        }
    }
    if let Some(checks) = c.failed_checks.as_ref().filter(|f| !f.is_empty()) {
        figures.push(("failed checks", checks.join(", ")));
    }
    h.push_str("<dl class=\"figures\">");
    for (name, value) in figures {
        let _ = write!(h, "<dt>{}</dt><dd>{}</dd>", escape(name), escape(&value));
    }
    h.push_str("</dl>\n<div class=\"pictures\">\n");
    let href = folder.strip_prefix(out).map_or_else(|_| segment(&c.case), |rel| rel.iter().map(|s| segment(&s.to_string_lossy())).collect::<Vec<_>>().join("/"));
    if complete.is_none() {
        h.push_str("<p class=\"message\">No pictures: the case's outputs are incomplete.</p>\n");
    }
    for (file, what) in PICTURES.iter().filter(|(file, _)| complete.is_some() && folder.join(file).is_file()) {
        let src = format!("{href}/{file}");
        let wide = if [MARGINALS_PNG, BARS_PNG].contains(file) { " class=\"wide\"" } else { "" };
        let _ = writeln!(h, "<figure{wide}><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{1}</figcaption></figure>", escape(&src), escape(what));
    }
    h.push_str("</div>\n</section>\n");
}

/// The p-value the verdict compares with the significance: the family's (Holm's smallest,
/// [`crate::stats::family::judge`]), or the fine grid's where the case has no family.
fn family_p(m: &CaseMeasured) -> f64 {
    m.family_p_value.unwrap_or(m.p_value)
}

/// The test of the family with the smallest Holm p-value, with its own p: the one that caught
/// the defect (or came closest to), e.g. "8 × 16: p = 5e-8 (Holm 4e-7)"; a case without a
/// family (an older summary) is decided by the fine grid.
fn decided_by(m: &CaseMeasured) -> String {
    match m.family.iter().min_by(|a, b| a.holm_p_value.total_cmp(&b.holm_p_value)) {
        Some(t) => format!("{}: p = {} (Holm {})", t.test, compact(t.p_value), compact(t.holm_p_value)),
        None => "fine grid".into(),
    }
}

/// The element id of a case's section.
fn anchor(case: &str) -> String {
    format!("case-{case}")
}

/// Text for HTML content and attribute values.
fn escape(s: &str) -> String {
    let mut e = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => e.push_str("&amp;"),
            '<' => e.push_str("&lt;"),
            '>' => e.push_str("&gt;"),
            '"' => e.push_str("&quot;"),
            '\'' => e.push_str("&#39;"),
            c => e.push(c),
        }
    }
    e
}

/// A path segment of a relative URL: bytes outside `A-Za-z0-9-_.~` percent-encoded (RFC 3986).
fn segment(s: &str) -> String {
    s.bytes()
        .map(|b| if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) { (b as char).to_string() } else { format!("%{b:02X}") })
        .collect()
}

const STYLE: &str = "
body { font: 15px/1.4 system-ui, sans-serif; margin: 24px; color: #222; }
h1 { font-size: 22px; margin: 0 0 8px; }
h2 { font-size: 18px; margin: 0 0 6px; }
p.heading { margin: 2px 0; color: #555; }
.tally { font-weight: 600; margin: 12px 0; }
.fail .verdict, span.fail { color: #b00020; }
.error .verdict, span.error { color: #8a4b00; }
.pass .verdict, span.pass { color: #1b7a2f; }
table.cases { border-collapse: collapse; margin-bottom: 24px; }
table.cases td, table.cases th { padding: 2px 12px; text-align: left; border-bottom: 1px solid #ddd; }
section.case { border-left: 6px solid #1b7a2f; padding: 8px 16px; margin: 0 0 28px; background: #fafafa; }
section.fail { border-left-color: #b00020; background: #fff5f5; }
section.error { border-left-color: #8a4b00; background: #fff8ec; }
.params { font-family: ui-monospace, monospace; margin: 4px 0; }
pre.message, p.message { white-space: pre-wrap; color: #8a4b00; }
dl.figures { display: grid; grid-template-columns: max-content auto; gap: 2px 16px; margin: 8px 0; }
dl.figures dt { color: #555; }
dl.figures dd { margin: 0; }
.pictures { display: flex; flex-wrap: wrap; gap: 12px; }
figure { margin: 0; flex: 0 1 460px; }
figure.wide { flex-basis: 944px; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; background: #fff; }
figcaption { font-size: 13px; color: #555; }
";

/// Marks the body once the page has loaded: whether every picture decoded.
const SCRIPT: &str = "<script>
addEventListener('load', () => {
  const imgs = Array.from(document.images);
  const broken = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).length;
  document.body.dataset.images = broken ? `broken ${broken} of ${imgs.length}` : `loaded ${imgs.length}`;
});
</script>
";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::chi2::FamilyTest;

    fn case(name: &str, passed: bool, error: Option<&str>) -> CaseSummary {
        CaseSummary {
            case: name.into(),
            samples: 1000,
            shards: None,
            backend: None,
            passed,
            failed_checks: None,
            failure: None,
            measured: error.is_none().then_some(CaseMeasured { gpu_seconds: None, wall_seconds: 0.5, chi2: 12.0, dof: 10, p_value: 0.28, family_p_value: None, family: Vec::new(), albedo: None, max_angle_rad: None }),
            error: error.map(String::from),
            output: None,
        }
    }

    #[test]
    fn failures_come_first_and_text_is_escaped() {
        let cases = [case("a", true, None), case("b", false, None), case("c<d", false, Some("device lost & gone")), case("e", true, None)];
        let page = page(Path::new("/nonexistent"), &["adapter: <x>".into()], &cases);
        let at = |s: &str| page.find(s).unwrap_or_else(|| panic!("{s} not in the page"));
        // sections in the order error, fail, pass, pass (scene order within each)
        let sections: Vec<usize> = ["id=\"case-c&lt;d\"", "id=\"case-b\"", "id=\"case-a\"", "id=\"case-e\""].iter().map(|s| at(s)).collect();
        assert!(sections.is_sorted(), "{sections:?}");
        assert!(page.contains("device lost &amp; gone") && page.contains("adapter: &lt;x&gt;"));
        assert!(page.contains("lobes: 2 of 4 cases passed"));
        assert!(page.contains("1 failed") && page.contains("1 could not run") && page.contains("2 passed"));
        // no network: no absolute URL anywhere
        assert!(!page.contains("http:") && !page.contains("https:") && !page.contains("//cdn"));
    }

    /// A case the fine grid passes (p 0.28) and the 8 × 16 grid catches: its row shows the
    /// family's p beside FAIL, and the test that decided it, not the fine grid's p alone.
    #[test]
    fn the_case_table_shows_the_family_p_and_the_deciding_test() {
        let test = |name: &str, rows, cols, p: f64, holm: f64| FamilyTest {
            test: name.into(),
            rows,
            cols,
            statistic: 1.0,
            dof: 1,
            p_value: p,
            holm_p_value: holm,
            rejected: holm < 0.01,
        };
        let mut caught = case("caught-coarse", false, None);
        let m = caught.measured.as_mut().unwrap();
        m.family = vec![test("64 × 128", 64, 128, 0.28, 1.0), test("8 × 16", 8, 16, 5e-8, 4e-7), test("φ", 1, 128, 0.02, 0.1)];
        m.family_p_value = Some(4e-7);
        let page = page(Path::new("/nonexistent"), &[], &[caught]);
        let row = page.lines().find(|l| l.starts_with("<tr class=\"fail\">")).expect("the case's row");
        let cells: Vec<&str> = row.split("<td").skip(1).map(|c| c.split_once('>').unwrap().1.trim_end_matches("</td></tr>").trim_end_matches("</td>")).collect();
        assert_eq!(cells[1..], ["FAIL", "4e-7", "8 × 16: p = 5e-8 (Holm 4e-7)", "12.0 / 10 (64 × 128)", "0.28"], "{row}");
        assert!(page.contains("<th>p-value (family)</th><th>decided by</th>"));
        // the case's figures say the same
        assert!(page.contains("<dt>p-value (family)</dt><dd>4e-7</dd><dt>decided by</dt><dd>8 × 16: p = 5e-8 (Holm 4e-7)</dd>"), "{page}");
    }

    #[test]
    fn picture_paths_are_relative_and_encoded() {
        assert_eq!(segment("ggx-vndf_2.5"), "ggx-vndf_2.5");
        assert_eq!(segment("é x"), "%C3%A9%20x");
        assert_eq!(escape("a\"b'c"), "a&quot;b&#39;c");
    }
}
