//! `lobes tradeoff`'s outputs: `tradeoff.md` (the tables), `tradeoff.png` (log-log error
//! against time, one panel per sampler, one curve per precision, with the 1/√N line) and
//! `tradeoff.json`; each written under a temporary name and renamed into place.

use super::heatmap::fill_rect;
use super::text::{draw_text, text_width};
use super::output::write_atomic;
use crate::experiments::tradeoff::{MethodPoint, Precision, QuadraturePoint, Sweep, SweepPoint};
use image::{Rgb, RgbImage};
use serde::Serialize;
use std::path::Path;

/// Everything one `lobes tradeoff` run measured.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub adapter: String,
    pub command: String,
    pub grid: [u32; 2],
    pub seed: u64,
    pub angle_samples: u32,
    /// Timed runs per measurement (medians reported).
    pub runs: u32,
    pub sweep: Sweep,
    pub methods: Vec<MethodPoint>,
    pub quadrature: Vec<QuadraturePoint>,
}

fn sci(x: f64) -> String {
    if x == 0.0 { "0".into() } else { format!("{x:.2e}") }
}

fn pow2(n: u64) -> String {
    if n.is_power_of_two() { format!("2^{}", n.trailing_zeros()) } else { n.to_string() }
}

/// The sweep table, one row per point, and a row per unavailable precision.
pub fn sweep_table(sweep: &Sweep) -> String {
    let mut t = String::from(
        "| sampler | precision | samples | GPU s | wall s | ns/sample | χ²/dof | p | L1 | L1 / noise | max angle vs f64 (rad) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    // each sampler's points, then its unavailable precisions, in sweep order
    let mut names: Vec<&str> = sweep.lobes.iter().map(|l| l.sampler.as_str()).collect();
    for x in sweep.points.iter().map(|p| p.sampler.as_str()).chain(sweep.unavailable.iter().map(|u| u.sampler.as_str())) {
        if !names.contains(&x) {
            names.push(x);
        }
    }
    for name in names {
        for p in sweep.points.iter().filter(|p| p.sampler == name) {
            t += &format!(
                "| {} | {} | {} | {} | {:.3} | {:.1} | {:.3} | {:.3} | {} | {:.2} | {} |\n",
                p.sampler,
                p.precision.name(),
                pow2(p.samples),
                p.gpu_seconds.map_or("–".into(), |g| format!("{g:.3}")),
                p.wall_seconds,
                p.seconds() / p.samples as f64 * 1e9,
                p.chi2 / p.dof.max(1) as f64,
                p.p_value,
                sci(p.l1),
                p.l1 / p.l1_noise,
                sci(p.angle.max_angle_rad),
            );
        }
        for k in sweep.skipped.iter().filter(|k| k.sampler == name) {
            t += &format!(
                "| {} | {} | {} | skipped: ~{:.0} s predicted, over --max-seconds | | | | | | | |\n",
                k.sampler,
                k.precision.name(),
                pow2(k.samples),
                k.predicted_seconds
            );
        }
        for u in sweep.unavailable.iter().filter(|u| u.sampler == name) {
            t += &format!("| {} | {} | – | unavailable: {} | | | | | | | |\n", u.sampler, u.precision.name(), u.reason);
        }
    }
    t
}

/// Per sampler and precision: cost per sample at the largest N, the largest N up to which
/// every point passed χ² at p ≥ 0.01, and the angle.
pub fn summary_table(sweep: &Sweep) -> String {
    let mut t = String::from(
        "| sampler | precision | ns/sample (largest N) | passes χ² (p ≥ 0.01) up to | first failing N | max angle vs f64 (rad) | mean angle (rad) |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for l in &sweep.lobes {
        for prec in Precision::ALL {
            let pts: Vec<&SweepPoint> = sweep.points.iter().filter(|p| p.sampler == l.sampler && p.precision == prec).collect();
            let Some(last) = pts.last() else {
                if let Some(u) = sweep.unavailable.iter().find(|u| u.sampler == l.sampler && u.precision == prec) {
                    t += &format!("| {} | {} | unavailable: {} | | | | |\n", l.sampler, prec.name(), u.reason);
                }
                continue;
            };
            let first_fail = pts.iter().find(|p| p.p_value < 0.01);
            let passes = pts.iter().take_while(|p| p.p_value >= 0.01).last();
            t += &format!(
                "| {} | {} | {:.1} | {} | {} | {} | {} |\n",
                l.sampler,
                prec.name(),
                last.seconds() / last.samples as f64 * 1e9,
                passes.map_or("–".into(), |p| pow2(p.samples)),
                first_fail.map_or("none".into(), |p| pow2(p.samples)),
                sci(last.angle.max_angle_rad),
                sci(last.angle.mean_angle_rad),
            );
        }
    }
    t
}

pub fn methods_table(m: &[MethodPoint]) -> String {
    let mut t = String::from(
        "| α | θi | GGX sampler | ns/sample | below horizon | mean w (albedo) | albedo by quadrature | Var[w] per sample | efficiency 1/(Var·t) (1/s) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for p in m {
        t += &format!(
            "| {} | {}° | {} | {:.2} | {:.4} | {:.5} ± {:.5} | {:.5} | {} | {} |\n",
            p.alpha,
            p.incident_theta_deg,
            p.method,
            p.ns_per_sample,
            p.below_horizon,
            p.mean,
            (p.variance / p.estimator_samples as f64).sqrt(),
            p.albedo_quadrature,
            sci(p.variance),
            sci(p.efficiency),
        );
    }
    t
}

pub fn quadrature_table(q: &[QuadraturePoint]) -> String {
    let mut t = String::from(
        "| sampler | α | θi | rule | CPU f64 s | CPU max err (σ at 1e8) | GPU f32 s | GPU max err (σ at 1e8) | GPU vs CPU same rule: max rel | L1 rel |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("–".to_string(), f);
    for p in q {
        t += &format!(
            "| {} | {} | {}° | {} | {:.4} | {} | {} | {} | {} | {} |\n",
            p.sampler,
            p.alpha,
            p.incident_theta_deg,
            p.rule,
            p.cpu_seconds,
            if p.rule == "adaptive" { format!("{} (own estimate)", sci(p.cpu_max_sigma_at_1e8)) } else { sci(p.cpu_max_sigma_at_1e8) },
            opt(p.gpu_seconds.or(p.gpu_wall_seconds), &|x| format!("{x:.4}")),
            opt(p.gpu_max_sigma_at_1e8, &sci),
            opt(p.gpu_vs_cpu_max_rel, &sci),
            opt(p.gpu_vs_cpu_l1_rel, &sci),
        );
    }
    t
}

/// The whole markdown document.
pub fn markdown(r: &Report) -> String {
    let mut s = format!(
        "# lobes tradeoff\n\n`{}`\n\nAdapter: {}. Grid {} × {} (cos θ × φ), seed {}. Times: median of {} run(s); GPU timestamps where the \
         adapter has them (on lavapipe they measure CPU time), else wall time.\n\n",
        r.command, r.adapter, r.grid[0], r.grid[1], r.seed, r.runs
    );
    let lobe_line = r.sweep.lobes.first().map_or(String::new(), |l| format!("α = {}, θi = {}°", l.alpha, l.incident_theta_deg));
    s += &format!(
        "## Samples × precision ({lobe_line})\n\n\
         L1 = Σ |count/N − p| over all cells (bins and invalid reasons), p from the adaptive f64 quadrature. \
         \"noise\" = the L1 an exact sampler has on average at this N (Σ E|X − Np|/N, X Poisson): L1 / noise near 1 means the \
         histogram is as close as sampling noise allows; a ratio that grows with N is a bias the precision cannot hide any more. \
         The angle is the largest angle between a kernel's ωr and the f64 reference's for the same uniforms, over the first {} \
         samples (the f64 kernel's directions come back as f32 hi + lo pairs).\n\n",
        r.angle_samples
    );
    s += &summary_table(&r.sweep);
    s += "\n";
    s += &sweep_table(&r.sweep);
    if !r.methods.is_empty() {
        s += "\n## GGX visible normals: spherical caps against bounded VNDF\n\n\
              Time from a GPU histogram run (f32-accurate kernel); w = f(ωi, ωr) cos θr / p(ωr) (BRDF without Fresnel, \
              height-correlated G2; 0 for a reflection below the horizon), computed in f64 from the f64 reference samples of the \
              same uniforms; its mean estimates the directional albedo, checked against the quadrature of f cos θr. \
              Higher efficiency = less variance per unit time.\n\n";
        s += &methods_table(&r.methods);
    }
    if !r.quadrature.is_empty() {
        s += "\n## Expected histogram: quadrature rule against cost\n\n\
              gl-n: n × n Gauss–Legendre points per bin, no subdivision, on the CPU in f64 and on the GPU in f32. Errors are \
              max over cells with expected count ≥ 5 at 10⁸ samples of |p − p_adaptive| / √(p_adaptive / 10⁸): the error in \
              standard deviations of a count at 10⁸ samples (the adaptive row gives its own error estimate). GPU time: \
              the dispatch, compilation excluded.\n\n";
        s += &quadrature_table(&r.quadrature);
    }
    s
}

const COLOURS: [(Precision, Rgb<u8>); 3] =
    [(Precision::F32Fast, Rgb([230, 120, 20])), (Precision::F32Accurate, Rgb([30, 90, 200])), (Precision::F64, Rgb([20, 150, 60]))];
const INK: Rgb<u8> = Rgb([20, 20, 20]);
const GRID_C: Rgb<u8> = Rgb([225, 225, 225]);
const REF: Rgb<u8> = Rgb([120, 120, 120]);

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && x < img.width() as i64 && y < img.height() as i64 {
        img.put_pixel(x as u32, y as u32, c);
    }
}

/// A line of width 2 (dashed: every other 6 pixels skipped), by stepping along its longer axis.
fn line(img: &mut RgbImage, (x0, y0): (f64, f64), (x1, y1): (f64, f64), c: Rgb<u8>, dashed: bool) {
    let steps = (x1 - x0).abs().max((y1 - y0).abs()).ceil().max(1.0) as i64;
    for k in 0..=steps {
        if dashed && (k / 6) % 2 == 1 {
            continue;
        }
        let t = k as f64 / steps as f64;
        let (x, y) = ((x0 + t * (x1 - x0)).round() as i64, (y0 + t * (y1 - y0)).round() as i64);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            put(img, x + dx, y + dy, c);
        }
    }
}

fn marker(img: &mut RgbImage, x: f64, y: f64, c: Rgb<u8>) {
    let (x, y) = (x.round() as i64, y.round() as i64);
    for dy in -3..=3 {
        for dx in -3..=3 {
            put(img, x + dx, y + dy, c);
        }
    }
}

fn decade_label(e: i32) -> String {
    format!("1e{e}")
}

/// The plot: one panel per sampler, L1 against time on log-log axes.
pub fn plot(sweep: &Sweep) -> RgbImage {
    let (pw, ph) = (460u32, 340u32);
    let cols = 2u32.min(sweep.lobes.len().max(1) as u32);
    let rows = (sweep.lobes.len().max(1) as u32).div_ceil(cols);
    let legend_h = 40u32;
    let mut img = RgbImage::from_pixel(pw * cols, ph * rows + legend_h, Rgb([255, 255, 255]));
    // legend
    let mut x = 12i64;
    for (prec, c) in COLOURS {
        fill_rect(&mut img, x as u32, 14, 24, 6, c);
        draw_text(&mut img, x + 30, 10, prec.name(), INK);
        x += 30 + text_width(prec.name()) as i64 + 24;
    }
    line(&mut img, (x as f64, 17.0), (x as f64 + 24.0, 17.0), REF, true);
    draw_text(&mut img, x + 30, 10, "c/sqrt(N), f32-accurate speed", INK);
    for (i, lobe) in sweep.lobes.iter().enumerate() {
        let (ox, oy) = ((i as u32 % cols) * pw, legend_h + (i as u32 / cols) * ph);
        let pts: Vec<&SweepPoint> = sweep.points.iter().filter(|p| p.sampler == lobe.sampler).collect();
        let (l, r, t, b) = (ox as f64 + 70.0, (ox + pw) as f64 - 16.0, oy as f64 + 28.0, (oy + ph) as f64 - 44.0);
        draw_text(&mut img, l as i64, oy as i64 + 6, &format!("{} (L1 vs seconds)", lobe.sampler), INK);
        if pts.is_empty() {
            continue;
        }
        let xs: Vec<f64> = pts.iter().map(|p| p.seconds().max(1e-9).log10()).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p.l1.max(1e-12).log10()).collect();
        let (x0, x1) = (xs.iter().copied().fold(f64::MAX, f64::min).floor(), xs.iter().copied().fold(f64::MIN, f64::max).ceil());
        let (y0, y1) = (ys.iter().copied().fold(f64::MAX, f64::min).floor(), ys.iter().copied().fold(f64::MIN, f64::max).ceil());
        let (x1, y1) = (x1.max(x0 + 1.0), y1.max(y0 + 1.0));
        let px = |v: f64| l + (v - x0) / (x1 - x0) * (r - l);
        let py = |v: f64| b - (v - y0) / (y1 - y0) * (b - t);
        for e in x0 as i32..=x1 as i32 {
            let gx = px(e as f64);
            line(&mut img, (gx, t), (gx, b), GRID_C, false);
            let s = decade_label(e);
            draw_text(&mut img, gx as i64 - text_width(&s) as i64 / 2, b as i64 + 10, &s, INK);
        }
        for e in y0 as i32..=y1 as i32 {
            let gy = py(e as f64);
            line(&mut img, (l, gy), (r, gy), GRID_C, false);
            let s = decade_label(e);
            draw_text(&mut img, l as i64 - text_width(&s) as i64 - 6, gy as i64 - 7, &s, INK);
        }
        draw_text(&mut img, ((l + r) / 2.0) as i64 - 40, b as i64 + 26, "seconds", INK);
        // frame
        line(&mut img, (l, t), (r, t), INK, false);
        line(&mut img, (l, b), (r, b), INK, false);
        line(&mut img, (l, t), (l, b), INK, false);
        line(&mut img, (r, t), (r, b), INK, false);
        // reference: L1 = c / sqrt(N), N = seconds / (seconds per sample of f32-accurate at its largest N)
        if let Some(a) = pts.iter().rfind(|p| p.precision == Precision::F32Accurate) {
            let sps = a.seconds() / a.samples as f64;
            // log L1 = log c − (log t − log sps)/2: the part inside the panel's y range
            let (lc, ls) = (lobe.l1_noise_coefficient.log10(), sps.log10());
            let f = |lx: f64| lc - 0.5 * (lx - ls);
            let (a, z) = (x0.max(ls + 2.0 * (lc - y1)), x1.min(ls + 2.0 * (lc - y0)));
            if a < z {
                line(&mut img, (px(a), py(f(a))), (px(z), py(f(z))), REF, true);
            }
        }
        for (prec, c) in COLOURS {
            let curve: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| p.precision == prec)
                .map(|p| (px(p.seconds().max(1e-9).log10()), py(p.l1.max(1e-12).log10())))
                .collect();
            for w in curve.windows(2) {
                line(&mut img, w[0], w[1], c, false);
            }
            for &(x, y) in &curve {
                marker(&mut img, x, y, c);
            }
        }
    }
    img
}

/// Writes tradeoff.png, tradeoff.json and tradeoff.md into `dir` (created if missing).
pub fn write(dir: &Path, r: &Report) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    write_atomic(&dir.join("tradeoff.png"), &super::png::encode(&plot(&r.sweep))?)?;
    write_atomic(&dir.join("tradeoff.json"), serde_json::to_string_pretty(r)?.as_bytes())?;
    write_atomic(&dir.join("tradeoff.md"), markdown(r).as_bytes())?;
    Ok(())
}
