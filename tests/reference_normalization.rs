//! Numerical integration of every density in the f64 reference (`lobes::reference`), over a
//! grid of roughness α ∈ {0.01, 0.05, 0.2, 0.5, 1} plus the anisotropic pair (0.05, 0.3), and
//! incident angles θi ∈ {0°, 30°, 60°, 85°} (azimuth 40°, so both α axes matter).
//!
//! The quadrature (see `reference_quadrature/mod.rs`) works in stretched slope coordinates,
//! where each lobe has the same shape for every α, split where integrands have kinks. Each
//! integral is computed with two different rules (12 and 16 Gauss–Legendre points per panel,
//! 12 and 16 base φ panels) and the two must agree to 1e-9, so the 1e-6 tolerances below test
//! the reference, not the quadrature. The substitution itself is checked against integrals known in closed form
//! (solid angle of the hemisphere, projected area, and the reflected-direction Jacobian).

use crate::reference_quadrature;

use glam::DVec3;
use lobes::reference::beckmann::Beckmann;
use lobes::reference::ggx::Ggx;
use lobes::reference::microfacet::Microfacet;
use lobes::reference::reflect::{reflect, spherical};
use lobes::reference::{Lobe, LobeKind, Method, ward};
use reference_quadrature::{Cuts, Hemisphere};
use std::f64::consts::PI;

const ALPHAS: [(f64, f64); 6] = [(0.01, 0.01), (0.05, 0.05), (0.2, 0.2), (0.5, 0.5), (1.0, 1.0), (0.05, 0.3)];
const THETA_I_DEG: [f64; 4] = [0.0, 30.0, 60.0, 85.0];
const PHI_I_DEG: f64 = 40.0;

/// Tolerance of the reference's densities (the 1e-6).
const TOL: f64 = 1e-6;
/// Agreement demanded between the two quadrature rules.
const QUAD_TOL: f64 = 1e-9;

fn incident(theta_deg: f64) -> DVec3 {
    spherical(theta_deg.to_radians(), PHI_I_DEG.to_radians())
}

/// ∫ f(h) dωh over the upper hemisphere with two rules; panics unless they agree to
/// `QUAD_TOL` (relative to max(1, |I|)), returns the finer.
fn integrate(ax: f64, ay: f64, cuts: &Cuts, what: &str, f: impl Fn(DVec3) -> f64) -> f64 {
    let coarse = Hemisphere::new(ax, ay, 12, 12, 1).integrate(cuts, &f);
    let fine = Hemisphere::new(ax, ay, 16, 16, 1).integrate(cuts, &f);
    assert!(
        (fine - coarse).abs() <= QUAD_TOL * fine.abs().max(1.0),
        "quadrature not converged for {what} (α = {ax}, {ay}): {coarse} vs {fine}"
    );
    fine
}

fn lobe(kind: LobeKind, method: Method, (ax, ay): (f64, f64)) -> Lobe {
    Lobe { kind, method, alpha_x: ax, alpha_y: ay, alpha_angle: 0.0 }
}

/// Records the worst |got − want| so each test can print how far from the tolerance it was.
#[derive(Default)]
struct Worst(f64, String);
impl Worst {
    fn check(&mut self, got: f64, want: f64, tol: f64, what: String) {
        let err = (got - want).abs();
        assert!(err <= tol, "{what}: got {got:.15}, want {want:.15} (error {err:.3e} > {tol:e})");
        if err > self.0 {
            *self = Worst(err, what);
        }
    }
    fn report(&self, name: &str) {
        eprintln!("{name}: worst error {:.3e} at {}", self.0, self.1);
    }
}

/// The substitution and its breakpoints, against integrals known in closed form: the hemisphere
/// has solid angle 2π and projected area π; ∫ over {h : reflect(ωi,h).z > 0} of 4|ωr·h| dωh is the
/// solid angle of the ωr hemisphere (2π), since dωr = 4|ωr·h| dωh; and the same with the weight
/// cos θr gives π. The last two check the Jacobian the reflected tests below rely on, without
/// using the crate's `reflect::jacobian`.
#[test]
fn quadrature_reproduces_known_integrals() {
    let mut worst = Worst::default();
    for &(ax, ay) in &ALPHAS {
        let none = Cuts::default();
        let area = integrate(ax, ay, &none, "solid angle", |_| 1.0);
        worst.check(area, 2.0 * PI, 1e-10, format!("solid angle, α = ({ax}, {ay})"));
        let proj = integrate(ax, ay, &none, "projected area", |h| h.z);
        worst.check(proj, PI, 1e-10, format!("projected area, α = ({ax}, {ay})"));
        for &t in &THETA_I_DEG {
            let wi = incident(t);
            let cuts = Cuts { wi: Some(wi), cap: None };
            let upper = |w: fn(DVec3) -> f64| {
                move |h: DVec3| {
                    let wr = reflect(wi, h);
                    if wr.z > 0.0 { w(wr) * 4.0 * wr.dot(h).abs() } else { 0.0 }
                }
            };
            let omega = integrate(ax, ay, &cuts, "ωr solid angle", upper(|_| 1.0));
            worst.check(omega, 2.0 * PI, 1e-10, format!("ωr solid angle, α = ({ax}, {ay}), θi = {t}°"));
            let cos = integrate(ax, ay, &cuts, "ωr projected area", upper(|wr| wr.z));
            worst.check(cos, PI, 1e-10, format!("ωr projected area, α = ({ax}, {ay}), θi = {t}°"));
        }
    }
    worst.report("quadrature");
}

/// Half-vector densities integrate to 1 over the hemisphere of h: Ward's p(h) (Walter 2005
/// eq. 9), and D(h) cos θh for Beckmann and GGX, both through `Microfacet::d` and through
/// `Lobe::pdf_h` with `Method::Ndf`.
#[test]
fn half_vector_densities_integrate_to_one() {
    let mut worst = Worst::default();
    for &(ax, ay) in &ALPHAS {
        let none = Cuts::default();
        let wi = incident(30.0); // ignored by these densities
        let ward_direct = integrate(ax, ay, &none, "ward", |h| ward::pdf_h(ax, ay, h));
        worst.check(ward_direct, 1.0, TOL, format!("Ward pdf_h, α = ({ax}, {ay})"));
        let b = Beckmann { ax, ay };
        let g = Ggx { ax, ay };
        let bd = integrate(ax, ay, &none, "beckmann D cos", |h| b.d(h) * h.z);
        worst.check(bd, 1.0, TOL, format!("Beckmann D cos θh, α = ({ax}, {ay})"));
        let gd = integrate(ax, ay, &none, "ggx D cos", |h| g.d(h) * h.z);
        worst.check(gd, 1.0, TOL, format!("GGX D cos θh, α = ({ax}, {ay})"));
        for kind in [LobeKind::Ward, LobeKind::Beckmann, LobeKind::Ggx] {
            let l = lobe(kind, Method::Ndf, (ax, ay));
            let i = integrate(ax, ay, &none, kind.name(), |h| l.pdf_h(wi, h));
            worst.check(i, 1.0, TOL, format!("{} ndf Lobe::pdf_h, α = ({ax}, {ay})", kind.name()));
        }
    }
    worst.report("half-vector densities");
}

/// Visible normals: ∫ D_ωi(h) dωh = 1 (`Lobe::pdf_h` with `Method::Vndf`), and the projected
/// area identities of Heitz 2014 (§3, eqs. 13 and 29), which check Λ and G1 independently of
/// the sampling code: ∫ (ωi·h) D(h) dωh = cos θi (signed, the whole hemisphere),
/// ∫ max(0, ωi·h) D(h) dωh = (1 + Λ(ωi)) cos θi, hence ∫ G1(ωi) max(0, ωi·h) D(h) dωh = cos θi.
#[test]
fn visible_normal_densities_and_the_projected_area_identity() {
    let mut worst = Worst::default();
    for &(ax, ay) in &ALPHAS {
        for &t in &THETA_I_DEG {
            let wi = incident(t);
            let cuts = Cuts { wi: Some(wi), cap: None };
            let tag = format!("α = ({ax}, {ay}), θi = {t}°");
            let check_identities = |m: &dyn Microfacet, name: &str, worst: &mut Worst| {
                let signed = integrate(ax, ay, &cuts, name, |h| wi.dot(h) * m.d(h));
                worst.check(signed, wi.z, TOL, format!("{name} ∫(ωi·h) D, {tag}"));
                let visible = integrate(ax, ay, &cuts, name, |h| wi.dot(h).max(0.0) * m.d(h));
                // relative to the size of the projected area (1 + Λ) cos θi, which reaches ≈ 1.6 at 85°
                let want = (1.0 + m.lambda(wi)) * wi.z;
                worst.check(visible, want, TOL * want.max(1.0), format!("{name} ∫(ωi·h)+ D = (1+Λ) cos θi, {tag}"));
                worst.check(m.g1(wi) * visible, wi.z, TOL, format!("{name} G1 ∫(ωi·h)+ D = cos θi, {tag}"));
            };
            check_identities(&Beckmann { ax, ay }, "beckmann", &mut worst);
            check_identities(&Ggx { ax, ay }, "ggx", &mut worst);
            for kind in [LobeKind::Beckmann, LobeKind::Ggx] {
                let l = lobe(kind, Method::Vndf, (ax, ay));
                let i = integrate(ax, ay, &cuts, kind.name(), |h| l.pdf_h(wi, h));
                worst.check(i, 1.0, TOL, format!("{} vndf Lobe::pdf_h, {tag}", kind.name()));
            }
        }
    }
    worst.report("visible normals");
}

/// ∫ over the upper ωr hemisphere of `lobe.pdf_r(ωi, ωr)` dωr, computed over h (dωr = 4|ωr·h| dωh).
fn reflected_mass_above(l: &Lobe, wi: DVec3, cuts: &Cuts) -> f64 {
    integrate(l.alpha_x, l.alpha_y, cuts, "pdf_r above the horizon", |h| {
        let wr = reflect(wi, h);
        if wr.z > 0.0 { l.pdf_r(wi, wr) * 4.0 * wr.dot(h).abs() } else { 0.0 }
    })
}

/// Reflected densities of the NDF and VNDF methods: ∫ pdf_r over the upper hemisphere of ωr
/// equals 1 − P(below), where P(below) is the mass of the half-vector density `pdf_h` over
/// those h whose reflection of ωi is at or below the horizon, i.e. the probability that a sample
/// is flagged `OutsideDomain`.
#[test]
fn reflected_densities_integrate_to_the_mass_above_the_horizon() {
    let mut worst = Worst::default();
    let mut max_below: f64 = 0.0;
    for &alpha in &ALPHAS {
        for &t in &THETA_I_DEG {
            let wi = incident(t);
            let cuts = Cuts { wi: Some(wi), cap: None };
            for (kind, method) in [
                (LobeKind::Ward, Method::Ndf),
                (LobeKind::Beckmann, Method::Ndf),
                (LobeKind::Beckmann, Method::Vndf),
                (LobeKind::Ggx, Method::Ndf),
                (LobeKind::Ggx, Method::Vndf),
            ] {
                let l = lobe(kind, method, alpha);
                let above = reflected_mass_above(&l, wi, &cuts);
                let below = integrate(alpha.0, alpha.1, &cuts, "pdf_h below", |h| {
                    if reflect(wi, h).z <= 0.0 { l.pdf_h(wi, h) } else { 0.0 }
                });
                max_below = max_below.max(below);
                let tag = format!("{} {}, α = {alpha:?}, θi = {t}°", kind.name(), method.name());
                worst.check(above, 1.0 - below, TOL, format!("∫pdf_r = 1 − P(below) [{below:.3e}], {tag}"));
            }
        }
    }
    eprintln!("largest mass below the horizon: {max_below:.4}");
    worst.report("reflected densities");
}

/// Bounded VNDF (Eto & Tokuyoshi 2023). Its sampler draws a uniform point c on the cap
/// z ≥ −b of the unit sphere (b = k ωs.z) instead of z ≥ −ωs.z; the h it maps to has the VNDF
/// density scaled by the ratio of the cap areas, (1 + ωs.z)/(1 + b), on the image of the cap and
/// 0 elsewhere. Given h, c is the reflection of ωs about the stretched normal h̃
/// (c = 2(h̃·ωs)h̃ − ωs, the point with c + ωs ∥ h̃ and |c| = 1), which decides membership.
///
/// Checked: that density integrates to 1; its mass above the horizon equals ∫ pdf_r over the
/// upper ωr hemisphere (pdf_r is the true density of the valid samples) and the integral of
/// `Lobe::pdf_h` over the h that reflect above the horizon; that mass is ≤ 1 and at
/// least the plain VNDF's (the bound only removes samples below the horizon); and at normal
/// incidence on an isotropic lobe the cap excludes exactly the h that reflect below the horizon
/// (k = (1 − α²)/(1 + α²) there), so no sample is lost at all.
#[test]
fn bounded_vndf_reflected_density() {
    let mut worst = Worst::default();
    let mut max_gain: f64 = 0.0;
    for &(ax, ay) in &ALPHAS {
        for &t in &THETA_I_DEG {
            let wi = incident(t);
            let tag = format!("α = ({ax}, {ay}), θi = {t}°");
            // k from the paper's listing 1, typed again here rather than calling Ggx::bounded_k.
            let a = ax.min(ay).clamp(0.0, 1.0);
            let s = 1.0 + (wi.x * wi.x + wi.y * wi.y).sqrt();
            let k = (1.0 - a * a) * s * s / (s * s + a * a * wi.z * wi.z);
            let ws = DVec3::new(ax * wi.x, ay * wi.y, wi.z).normalize();
            let b = k * ws.z;
            let cuts = Cuts { wi: Some(wi), cap: Some((ws, b)) };

            let vndf = lobe(LobeKind::Ggx, Method::Vndf, (ax, ay));
            let bounded = lobe(LobeKind::Ggx, Method::Bounded, (ax, ay));
            let density = |h: DVec3| {
                let hs = DVec3::new(h.x / ax, h.y / ay, h.z).normalize();
                let cz = 2.0 * hs.dot(ws) * hs.z - ws.z;
                if cz >= -b { vndf.pdf_h(wi, h) * (1.0 + ws.z) / (1.0 + b) } else { 0.0 }
            };
            let total = integrate(ax, ay, &cuts, "bounded density", density);
            worst.check(total, 1.0, TOL, format!("bounded h density total, {tag}"));
            let valid = integrate(ax, ay, &cuts, "bounded density above", |h| {
                if reflect(wi, h).z > 0.0 { density(h) } else { 0.0 }
            });
            let above = reflected_mass_above(&bounded, wi, &cuts);
            worst.check(above, valid, TOL, format!("bounded ∫pdf_r = its samples' mass above, {tag}"));
            // `Lobe::pdf_h` is the h density of the valid samples (0 for the others)
            let pdf_h_mass = integrate(ax, ay, &cuts, "bounded pdf_h", |h| {
                if reflect(wi, h).z > 0.0 { bounded.pdf_h(wi, h) } else { 0.0 }
            });
            worst.check(pdf_h_mass, valid, TOL, format!("bounded ∫Lobe::pdf_h over valid h, {tag}"));
            let plain = reflected_mass_above(&vndf, wi, &cuts);
            assert!(above <= 1.0 + TOL, "bounded ∫pdf_r = {above} > 1, {tag}");
            assert!(above >= plain - TOL, "bounded ∫pdf_r = {above} < plain VNDF's {plain}, {tag}");
            max_gain = max_gain.max(above - plain);
            if t == 0.0 && ax == ay {
                worst.check(above, 1.0, TOL, format!("bounded at normal incidence loses nothing, {tag}"));
            }
        }
    }
    eprintln!("largest gain of bounded over plain VNDF in valid mass: {max_gain:.4}");
    worst.report("bounded vndf");
}
