//! The markdown tables of `tradeoff.md`.

use crate::experiments::tradeoff::detection::{Detected, Detection};
use crate::experiments::tradeoff::{MethodPoint, Precision, QuadraturePoint, Sweep, SweepPoint};

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
                "| {} | {} | {} | skipped: ~{:.0} s predicted, over the time limit per point | | | | | | | |\n",
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

/// The detection table: a row per test (the family first, then each test alone), a column per
/// ε; each cell the count from which the test catches the turn at the table's power, and the
/// seconds of a whole check there. Then the other checks' verdicts per ε.
pub fn detection_table(d: &Detection) -> String {
    let mut t = String::from("| test |");
    for e in &d.epsilons {
        t += &format!(" ε = {} |", e.epsilon);
    }
    t += "\n|---|";
    t += &"---|".repeat(d.epsilons.len());
    t += "\n";
    let tests = d.epsilons.first().map_or(&[][..], |e| &e.tests[..]);
    for (k, test) in tests.iter().enumerate() {
        t += &format!("| {test} |");
        for e in &d.epsilons {
            let cell = match e.detected.get(k) {
                Some(Detected { samples: Some(n), seconds, .. }) => format!("{} ({:.1} s)", pow2(*n), seconds.unwrap_or(f64::NAN)),
                _ => format!("> {}", e.points.last().map_or("-".into(), |p| pow2(p.samples))),
            };
            t += &format!(" {cell} |");
        }
        t += "\n";
    }
    for e in &d.epsilons {
        let failed: Vec<&str> = e.other_checks_passed.iter().filter(|(_, ok)| !ok).map(|(n, _)| n.as_str()).collect();
        let checks: Vec<&str> = e.other_checks_passed.iter().map(|(n, _)| n.as_str()).collect();
        t += &if failed.is_empty() {
            format!("\nε = {}: the other checks ({}) pass at {}: only the χ² tests see the turn.", e.epsilon, checks.join(", "), pow2(e.checked_at))
        } else {
            format!("\nε = {}: other checks see it too: {} failed at {}.", e.epsilon, failed.join(", "), pow2(e.checked_at))
        };
    }
    t += "\n";
    t
}
