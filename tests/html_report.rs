//! `OUT/index.html` in a real browser: a small scene runs (one lobe, one discrete case, one case
//! whose outputs cannot be written), headless Chromium loads the page from disk, and the test
//! reads back what it shows (`--dump-dom`): every case, its verdict, failures first, and every
//! picture of a complete case decoded (the page's own script counts them). The screenshot stays in
//! `$CARGO_TARGET_TMPDIR/html_report/index.png`.
//!
//! Needs Debian's `chromium` (`.ci/install` installs it); without it the test fails, it never
//! skips.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SCENE: &str = "[defaults]\nsamples = 50_000\nbins = [8, 16]\n\n\
[[case]]\nname = \"lobe\"\nlobe = \"ggx\"\nmethod = \"vndf\"\nalpha = 0.4\nincident_theta = 50\nincident_phi = 120\n\n\
[[case]]\nname = \"broken\"\nlobe = \"ward\"\nalpha = 0.3\n\n\
[[case]]\nname = \"items\"\nlobe = \"discrete\"\nweights = [1, 2, 0, 4]\n";

const INSTALL: &str = "apt-get install -y --no-install-recommends chromium (or run .ci/install)";

/// Runs headless Chromium on `page` with `args`, failing loudly when it is not installed.
fn chromium(profile: &Path, page: &Path, args: &[&str]) -> Output {
    let url = format!("file://{}", page.display());
    Command::new("chromium")
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--virtual-time-budget=10000"])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(&url)
        .output()
        .unwrap_or_else(|e| panic!("cannot start chromium ({e}): this test needs a real browser; install it: {INSTALL}"))
}

fn pngs(folder: &Path) -> usize {
    std::fs::read_dir(folder).unwrap().filter_map(Result::ok).filter(|e| e.path().is_file() && e.path().extension().is_some_and(|x| x == "png")).count()
}

#[test]
fn index_html_shows_every_case_in_a_browser() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("html_report");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let dir = dir.canonicalize().unwrap();
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.join("out");
    // the case `broken` cannot write its residual map (a folder is in the way)
    std::fs::create_dir_all(out.join("broken/residual.png/blocker")).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_lobes")).args(["run", "--cpu", "--out"]).arg(&out).arg(&scene).output().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && stderr.contains("error: case 'broken'"), "{stderr}");
    let index = out.join("index.html");
    assert!(index.is_file(), "no index.html: {stderr}");

    let profile = dir.join("chromium-profile");
    let dom = chromium(&profile, &index, &["--dump-dom"]);
    let dom_text = String::from_utf8_lossy(&dom.stdout);
    assert!(dom.status.success() && !dom_text.is_empty(), "chromium --dump-dom failed: {}", String::from_utf8_lossy(&dom.stderr));
    // every picture on disk is on the page, and the browser decoded each one
    let pictures: usize = ["lobe", "items"].iter().map(|c| pngs(&out.join(c))).sum();
    assert_eq!(pictures, 4 + 1, "lobe: maps and marginals; items: bars");
    // `broken` wrote maps before it failed, but an incomplete folder's pictures are not shown
    assert_eq!(pngs(&out.join("broken")), 2);
    assert!(dom_text.contains("No pictures: the case's outputs are incomplete."));
    assert!(dom_text.contains(&format!("data-images=\"loaded {pictures}\"")), "pictures not all loaded: {}", &dom_text[..dom_text.len().min(400)]);
    // the cases and their verdicts, the one that could not run first
    let section = |case: &str| dom_text.find(&format!("id=\"case-{case}\"")).unwrap_or_else(|| panic!("no section for {case}"));
    assert!(section("broken") < section("lobe") && section("lobe") < section("items"));
    assert!(dom_text.contains("<span class=\"verdict\">ERROR</span>"));
    assert_eq!(dom_text.matches("<span class=\"verdict\">pass</span>").count(), 2, "both other cases pass");
    assert!(dom_text.contains("ggx vndf, α 0.4, θi 50°, φi 120°") && dom_text.contains("discrete cdf, weights [1, 2, 0, 4]"));
    assert!(dom_text.contains("writing the outputs into"), "the error is shown");

    let shot = dir.join("index.png");
    let screenshot = format!("--screenshot={}", shot.display());
    let s = chromium(&profile, &index, &[&screenshot, "--window-size=1280,1600"]);
    assert!(s.status.success(), "chromium --screenshot failed: {}", String::from_utf8_lossy(&s.stderr));
    let img = image::open(&shot).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (1280, 1600));
    // the error case's border (#8a4b00) and viridis' dark end (68, 1, 84) of a heat map are drawn
    let has = |rgb: [u8; 3]| img.pixels().any(|p| p.0.iter().zip(rgb).all(|(&a, b)| a.abs_diff(b) <= 3));
    assert!(has([0x8a, 0x4b, 0x00]), "no error border in the screenshot");
    assert!(has([68, 1, 84]), "no heat map in the screenshot");
}
