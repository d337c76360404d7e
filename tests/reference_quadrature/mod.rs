//! Quadrature shared by the reference's integration tests (`reference_normalization.rs`,
//! `reference_monte_carlo.rs`): composite Gauss–Legendre (the library's rule) and an integrator over the upper
//! hemisphere of half vectors h that stays accurate for very peaked lobes (α = 0.01).
//!
//! The hemisphere is parameterised by *stretched slopes*: h ∝ (αx r cos φ, αy r sin φ, 1), so
//! the slope of h is s = (hx/hz, hy/hz) = r (αx cos φ, αy sin φ). In these coordinates every
//! lobe of this crate has an α-independent shape (the Beckmann/Ward density D(h) cos θh dωh is
//! e^{−r²} r dr dφ / π, the GGX one r dr dφ / (π (1 + r²)²)), so the peak at α = 0.01 gets as
//! many points as the one at α = 1. The solid-angle element is dωh = hz³ d²s =
//! hz³ αx αy r dr dφ, and r = tan ψ maps r ∈ [0, ∞) to ψ ∈ [0, π/2) (dr = (1 + r²) dψ).
//!
//! Integrands with kinks or jumps are integrated piecewise: the ψ range is split where the
//! reflected direction crosses the horizon, where ωi·h changes sign, and where h leaves the
//! spherical cap of bounded VNDF sampling (all three are roots of quadratics in r along a ray
//! of fixed φ), plus geometric splits r = 2^k that resolve the region near the horizon where
//! r ~ 1/α; the φ range is split where the ωi·h = 0 boundary goes off to infinity. Between
//! breakpoints the integrands are smooth and composite Gauss–Legendre converges fast.

#![allow(dead_code)]

use glam::DVec3;
pub use lobes::stats::gauss_legendre::GaussLegendre;
use std::f64::consts::{FRAC_PI_2, TAU};

/// ∫_a^b f by the rule `gl` composite over `panels` equal panels.
pub fn composite(gl: &GaussLegendre, a: f64, b: f64, panels: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let step = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let (lo, hi) = (a + k as f64 * step, if k + 1 == panels { b } else { a + (k + 1) as f64 * step });
        for (x, w) in gl.on(lo, hi) {
            sum += w * f(x);
        }
    }
    sum
}

/// Where the integrand may be non-smooth, as seen from the hemisphere integrator.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cuts {
    /// The incident direction: split where reflect(ωi, h) crosses the horizon and where ωi·h = 0.
    pub wi: Option<DVec3>,
    /// Bounded VNDF's cap in the stretched configuration: (ωs, b), split where
    /// c.z = 2(h̃·ωs) h̃.z − ωs.z crosses −b (h̃ the stretched normal).
    pub cap: Option<(DVec3, f64)>,
}

/// Integration over the upper hemisphere of h in stretched-slope coordinates.
#[derive(Debug, Clone)]
pub struct Hemisphere {
    pub ax: f64,
    pub ay: f64,
    pub gl: GaussLegendre,
    /// Equal φ panels before the extra splits.
    pub phi_panels: usize,
    /// Equal sub-panels in every ψ interval between breakpoints.
    pub psi_sub: usize,
}

/// The positive root of A r² − 2 B r − C = 0 with A ≥ 0, C > 0 (roots of opposite signs when
/// A > 0), written without cancellation; ∞ where there is none (A = 0 and B ≤ 0).
fn positive_root(a: f64, b: f64, c: f64) -> f64 {
    let disc = (b * b + a * c).sqrt();
    if b >= 0.0 {
        if a > 0.0 { (b + disc) / a } else { f64::INFINITY }
    } else {
        c / (disc - b)
    }
}

impl Hemisphere {
    pub fn new(ax: f64, ay: f64, nodes: usize, phi_panels: usize, psi_sub: usize) -> Self {
        Self { ax, ay, gl: GaussLegendre::new(nodes), phi_panels, psi_sub }
    }

    /// The radial breakpoints (values of r) along the ray of azimuth φ.
    fn radial_breaks(&self, cuts: &Cuts, phi: f64) -> Vec<f64> {
        let (s, c) = phi.sin_cos();
        let e = (self.ax * c, self.ay * s); // slope per unit r
        let e2 = e.0 * e.0 + e.1 * e.1;
        // geometric splits from r = 1/4 to r ≈ 8/α: near hz ~ 1 at small α, r ~ 1/α
        let top = (8.0 / self.ax.min(self.ay)).log2().ceil() as i32;
        let mut rs: Vec<f64> = (-2..=top).map(|k| 2f64.powi(k)).collect();
        if let Some(wi) = cuts.wi {
            // h = (r e, 1)/n: ωi·h ∝ ωi.z + r q, and reflect(ωi, h).z ≤ 0 ⟺
            // ωi.z e² r² − 2 q r − ωi.z ≥ 0 (n² = 1 + r² e²).
            let q = wi.x * e.0 + wi.y * e.1;
            rs.push(positive_root(wi.z * e2, q, wi.z));
            if q < 0.0 {
                rs.push(wi.z / -q);
            }
        }
        if let Some((ws, b)) = cuts.cap {
            // h̃ = (r cos φ, r sin φ, 1)/√(1+r²): c.z ≥ −b ⟺ (ωs.z − b) r² − 2 q̃ r − (ωs.z + b) ≤ 0.
            let q = ws.x * c + ws.y * s;
            rs.push(positive_root((ws.z - b).max(0.0), q, ws.z + b));
        }
        rs
    }

    /// The azimuths where ωi·h = 0 meets r = ∞ (q(φ) = 0), where the breakpoints change kind.
    fn phi_breaks(&self, cuts: &Cuts) -> Vec<f64> {
        let mut phis: Vec<f64> = (0..=self.phi_panels).map(|k| TAU * k as f64 / self.phi_panels as f64).collect();
        if let Some(wi) = cuts.wi {
            let (qx, qy) = (wi.x * self.ax, wi.y * self.ay);
            if qx != 0.0 || qy != 0.0 {
                // Near grazing incidence the horizon boundary passes close to the origin of the
                // slope plane and its polar description r(φ) bends sharply near these azimuths
                // (over ≈ sin((π/2 − θi)/2) radians): grade the panels geometrically towards them.
                let p0 = qy.atan2(qx);
                for side in [FRAC_PI_2, -FRAC_PI_2] {
                    phis.push((p0 + side).rem_euclid(TAU));
                    for d in [1e-3, 4e-3, 0.016, 0.064, 0.25] {
                        phis.push((p0 + side + d).rem_euclid(TAU));
                        phis.push((p0 + side - d).rem_euclid(TAU));
                    }
                }
            }
        }
        phis.sort_by(f64::total_cmp);
        phis.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        phis
    }

    /// ∫ f(h) dωh over hz > 0.
    pub fn integrate(&self, cuts: &Cuts, mut f: impl FnMut(DVec3) -> f64) -> f64 {
        let phis = self.phi_breaks(cuts);
        let mut total = 0.0;
        for pair in phis.windows(2) {
            for (phi, wphi) in self.gl.on(pair[0], pair[1]) {
                let (s, c) = phi.sin_cos();
                let e = (self.ax * c, self.ay * s);
                let mut psis: Vec<f64> = self
                    .radial_breaks(cuts, phi)
                    .into_iter()
                    .map(f64::atan)
                    .filter(|p| *p > 0.0 && *p < FRAC_PI_2)
                    .collect();
                psis.push(0.0);
                psis.push(FRAC_PI_2);
                psis.sort_by(f64::total_cmp);
                psis.dedup_by(|a, b| (*a - *b).abs() < 1e-14);
                let mut ray = 0.0;
                for seg in psis.windows(2) {
                    ray += composite(&self.gl, seg[0], seg[1], self.psi_sub, |psi| {
                        let r = psi.tan();
                        let (sx, sy) = (r * e.0, r * e.1);
                        let hz = 1.0 / (1.0 + sx * sx + sy * sy).sqrt();
                        let h = DVec3::new(sx * hz, sy * hz, hz);
                        // dωh = hz³ αx αy r dr dφ, dr = (1 + r²) dψ
                        let jac = hz * hz * hz * self.ax * self.ay * r * (1.0 + r * r);
                        let v = f(h);
                        if v == 0.0 { 0.0 } else { v * jac }
                    });
                }
                total += wphi * ray;
            }
        }
        total
    }
}
