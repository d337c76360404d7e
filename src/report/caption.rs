//! A case in words: its lobe, method and parameters, and its verdict; the titles of its pictures
//! and its entry in `index.html` say the same.

use super::label::compact;
use crate::run::record::{CaseDescription, Params};
use crate::stats::chi2::Chi2;
use crate::stats::domain::Domain;
use crate::stats::family;

/// The lobe, method and parameters, e.g. `ggx vndf, α 0.3 × 0.1, θi 40°, φi 60°`.
pub fn parameters(d: &CaseDescription) -> String {
    let angles = |theta: f64, phi: f64| if phi == 0.0 { format!("θi {}°", compact(theta)) } else { format!("θi {}°, φi {}°", compact(theta), compact(phi)) };
    match &d.params {
        Params::Lobe { alpha_x, alpha_y, alpha_angle, incident_theta_deg, incident_phi_deg, eta } => {
            let mut alpha = if alpha_x == alpha_y { compact(*alpha_x) } else { format!("{} × {}", compact(*alpha_x), compact(*alpha_y)) };
            if *alpha_angle != 0.0 {
                alpha += &format!(" turned {}°", compact(*alpha_angle));
            }
            let glass = eta.map_or(String::new(), |eta| format!(" dielectric η {}", compact(eta)));
            format!("{} {}{glass}, α {alpha}, {}", d.lobe, d.method, angles(*incident_theta_deg, *incident_phi_deg))
        }
        Params::Discrete { weights } => {
            let shown: Vec<String> = weights.iter().take(12).map(|&w| compact(w)).collect();
            let more = if weights.len() > 12 { format!(", … {} in all", weights.len()) } else { String::new() };
            format!("discrete {}, weights [{}{more}]", d.method, shown.join(", "))
        }
        Params::User { sample, incident_theta_deg, incident_phi_deg, domain, .. } => {
            let at = match (incident_theta_deg, incident_phi_deg) {
                (Some(t), Some(p)) => format!(", {}", angles(*t, *p)),
                _ => String::new(),
            };
            let on = Domain::words_for_name(domain).map_or_else(|| format!("the {domain}"), str::to_string);
            format!("WGSL sampler {sample} on {on}{at}")
        }
    }
}

/// The verdict in words: `pass` or `FAIL`, the fine grid's χ² p-value, and the test of the
/// family that caught a defect where the fine grid did not (`caught at 8 × 16: p = 5e-8`).
pub fn verdict(passed: bool, chi2: &Chi2) -> String {
    let mut text = format!("{}, χ² p = {}", if passed { "pass" } else { "FAIL" }, compact(chi2.p_value));
    if let Some(t) = family::strongest(chi2).filter(|t| t.rejected && chi2.family.first().is_some_and(|fine| !fine.rejected)) {
        text += &format!(", caught at {}: p = {}", t.test, compact(t.p_value));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lobe(alpha_x: f64, alpha_y: f64, phi: f64) -> CaseDescription {
        CaseDescription {
            lobe: "ggx".into(),
            method: "vndf".into(),
            params: Params::Lobe { alpha_x, alpha_y, alpha_angle: 0.0, incident_theta_deg: 40.0, incident_phi_deg: phi, eta: None },
            rows: 64,
            cols: 128,
        }
    }

    #[test]
    fn parameters_in_words() {
        assert_eq!(parameters(&lobe(0.3, 0.3, 0.0)), "ggx vndf, α 0.3, θi 40°");
        assert_eq!(parameters(&lobe(0.5, 0.1, 60.0)), "ggx vndf, α 0.5 × 0.1, θi 40°, φi 60°");
        let mut turned = lobe(0.05, 0.3, 0.0);
        if let Params::Lobe { alpha_angle, .. } = &mut turned.params {
            *alpha_angle = 30.0;
        }
        assert_eq!(parameters(&turned), "ggx vndf, α 0.05 × 0.3 turned 30°, θi 40°");
        let mut glass = lobe(0.3, 0.3, 0.0);
        if let Params::Lobe { eta, .. } = &mut glass.params {
            *eta = Some(1.5);
        }
        assert_eq!(parameters(&glass), "ggx vndf dielectric η 1.5, α 0.3, θi 40°");
        let d = CaseDescription { lobe: "discrete".into(), method: "alias".into(), params: Params::Discrete { weights: vec![0.0, 3.0, 1e-3] }, rows: 1, cols: 3 };
        assert_eq!(parameters(&d), "discrete alias, weights [0, 3, 1e-3]");
        let fine = crate::stats::chi2::test(&[1000, 1300], &[1150.0, 1150.0], 0.01);
        assert_eq!(verdict(false, &fine), format!("FAIL, χ² p = {}", compact(fine.p_value)));
        // a smooth tilt of 1.5 % over 4 × 4 bins: the fine grid's p = 0.09, the 2 × 2 grid's 4.9e-5
        let counts: Vec<u64> = (0..16).map(|i| if i % 4 < 2 { 6344 } else { 6156 }).collect();
        let grid = crate::stats::domain::Domain::UNIT_SQUARE.grid(4, 4);
        let c = crate::stats::family::judge(grid, (&counts, &[6250.0; 16]), (&[0], &[0.0]), 0.01);
        assert_eq!(verdict(false, &c), format!("FAIL, χ² p = {}, caught at 2 × 2: p = {}", compact(c.p_value), compact(c.family[1].p_value)));
    }
}
