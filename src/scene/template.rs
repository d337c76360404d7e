//! `lobes scene --template`: a scene with every key, its default and what it allows, written
//! from the constants the parser uses ([`super::DEFAULT_SAMPLES`] …), so the two cannot
//! disagree. The template parses as it is; keys that exclude each other are commented out.

use super::{DEFAULT_ALPHA_ANGLE, DEFAULT_BINS, DEFAULT_DISCRETE_METHOD, DEFAULT_INCIDENT_PHI, DEFAULT_INCIDENT_THETA, DEFAULT_METHOD, DEFAULT_SAMPLES, DEFAULT_SEED, MAX_SAMPLES};
use crate::check::{Domain, MAX_PARAMS, Settings};

/// The commented template scene.
pub fn template() -> String {
    let user = Settings::default();
    let (sphere, plane) = (user.grid(&Domain::Sphere), user.grid(&Domain::UNIT_SQUARE));
    format!(
        r#"# A lobes scene: every key with its default. Run it with `lobes run scene.toml`.
# Any key with one number or name sweeps when given an array: one case per value, and several
# swept keys make every combination, named after the case and the values
# (alpha = [0.1, 0.3] and incident_theta = [0, 45] in case "ggx" make ggx-alpha0.1-theta0, …).
# `lobes scene scene.toml` lists the cases; `lobes run --case 'ggx-*'` runs some of them.

[defaults]                # optional; every case may set these too
samples = {samples}        # whole number, 1 ..= 2^40 ({max_samples}); a weighted case ..= 2^32
bins = [{rows}, {cols}]          # [rows over cos θ, columns over φ]; rows even, rows × cols ≤ 2^24
seed = {seed}                  # whole number ≥ 0

[[case]]
name = "ggx"              # letters, digits, - _ . (it names the output folder)
lobe = "ggx"              # ward | beckmann | ggx | discrete
method = "{method}"            # ndf | vndf | bounded (ward: ndf; beckmann: ndf, vndf)
alpha = 0.3               # roughness > 0, required; or anisotropic:
# alpha_x = 0.3
# alpha_y = 0.1
# alpha_angle = {angle:?}       # degrees from +x to the alpha_x axis about the normal, [-360, 360]
incident_theta = {theta:?}      # degrees from the normal, 0 ≤ θ < 90 (dielectric: < 180, > 90 from inside)
incident_phi = {phi:?}        # degrees, −360 ≤ φ ≤ 360
# scatter = "reflect"     # reflect | dielectric: rough glass, reflection and refraction over the
#                         # whole sphere (ggx or beckmann, ndf or vndf; with eta; masking
#                         # none, g1 or separable, no fresnel)
# samples, bins, seed     # as in [defaults], for this case only
# Effects: any of fresnel and masking makes the case weighted (Σ f cos θ / pdf per bin,
# judged against the albedo); without them the case counts samples only.
# weighted = false        # true: a weighted histogram without Fresnel or masking
# fresnel = "none"        # none | schlick (f0) | conductor (eta, k) | dielectric (eta)
# f0 = 0.04               # schlick: reflectance at normal incidence, 0 ≤ f0 ≤ 1
# eta = 1.5               # conductor: index of refraction > 0; dielectric: n_t / n_i > 0;
#                         # scatter = "dielectric": n_below / n_above, > 0 and ≠ 1
# k = 0.0                 # conductor: absorption ≥ 0
# masking = "none"        # none | g1 | separable | height-correlated (not for ward)

[[case]]
name = "discrete"
lobe = "discrete"
method = "{discrete}"            # cdf | alias
weights = [15, 5, 25, 0]  # finite numbers ≥ 0, not all zero; one bin per weight

# A sampler of your own in WGSL, judged by the checks of `lobes check`:
# [[case]]
# name = "my-ggx"
# sampler = {{ wgsl = ["my_ggx.wgsl"], sample = "my_sample", pdf = "my_pdf", eval = "my_eval" }}
#                         # files relative to the scene; eval is optional; sample, pdf and eval
#                         # are function names or WGSL calls over wi, u, d, params, p0…p15, rng
# (more keys of sampler, as the flags of lobes check; docs/check-reference.md):
#   shader_root = ["shaders"], define = {{ NAME = true }}, stub = {{ "package::bindings" = "stub.wesl" }}
#   package = {{ bevy_render = "bevy_render/src" }}   # another WESL package's folder
#   texture = {{ env_radiance = "sky.hdr" }}, buffer = {{ env_marginal = "marginal.npy" }}   # the renderer's resources
#   filter = {{ brdf_dfg_lut_sampler = "linear" }}   # a renderer's sampler (--sampler): "linear" or "nearest"
#   rand = ["rand_f"], rand_order = "event,x,y", sample_returns = "half-vector"
#   incident = "upper", reflection_only = true, u_open = true, measure = "projected", frame = "y-up"
#   measure = "area", normal = "vec3<f32>(0.0, 0.0, -1.0)"   # a light sampled by area: (p, pdf_A)
# sampler = {{ light = "sphere" }}   # instead: one of lobes' built-in lights ({lights}),
#                         # its geometry in params (docs/lights-and-environment-maps.md)
# params = [0.3, 0.3]     # up to {max_params} numbers, params[i / 4][i % 4] in WGSL; default none
# domain = "sphere"       # sphere | plane (then bounds = [x0, y0, x1, y1])
# incident_theta = {user_theta:?}   # degrees, 0 ≤ θ ≤ 180 (a user sampler's default)
# bins = [{srows}, {scols}]        # default [{srows}, {scols}] on the sphere, [{prows}, {pcols}] on the plane
# timeout = {timeout}           # seconds all its checks may take (a sampler that loops forever fails here)
# budget = "ci"           # seconds, or "ci" (20 s) / "thorough" (300 s): pilot checks pick the
#                         # samples one check fits in on this adapter (not with samples)
"#,
        samples = DEFAULT_SAMPLES,
        max_samples = MAX_SAMPLES,
        rows = DEFAULT_BINS.rows,
        cols = DEFAULT_BINS.cols,
        seed = DEFAULT_SEED,
        method = DEFAULT_METHOD.name(),
        theta = DEFAULT_INCIDENT_THETA,
        phi = DEFAULT_INCIDENT_PHI,
        angle = DEFAULT_ALPHA_ANGLE,
        discrete = DEFAULT_DISCRETE_METHOD.name(),
        max_params = MAX_PARAMS,
        lights = crate::reference::light::registry::names(),
        user_theta = user.incident_theta,
        srows = sphere.0,
        scols = sphere.1,
        prows = plane.0,
        pcols = plane.1,
        timeout = user.timeout.as_secs(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::job::{DiscreteMethod, Job};
    use crate::reference::Method;
    use crate::scene::Scene;

    /// The template parses, and its values are what a case that sets nothing gets, and the
    /// documented defaults (docs/scenes.md: 10 000 000 samples, 64 × 128 bins, seed 1, ndf, cdf, θ 0).
    #[test]
    fn the_template_parses_and_states_the_defaults() {
        let t = Scene::parse("template.toml", &template()).unwrap();
        let bare = Scene::parse("bare.toml", "[[case]]\nname = \"ggx\"\nlobe = \"ggx\"\nalpha = 0.3\n\n[[case]]\nname = \"discrete\"\nlobe = \"discrete\"\nweights = [15, 5, 25, 0]\n").unwrap();
        let (a, b) = (&t.cases[0], &bare.cases[0]);
        assert_eq!((a.samples, a.seed, a.incident_deg, a.effects), (b.samples, b.seed, b.incident_deg, b.effects));
        assert_eq!((a.samples, a.seed, a.incident_deg, a.effects), (10_000_000, 1, (0.0, 0.0), None));
        let (Job::Lobe { lobe: la, grid: ga, .. }, Job::Lobe { lobe: lb, grid: gb, .. }) = (&a.job, &b.job) else { panic!("lobe cases") };
        assert_eq!((la.method, ga.rows, ga.cols), (lb.method, gb.rows, gb.cols));
        assert_eq!((la.method, ga.rows, ga.cols), (Method::Ndf, 64, 128));
        let (Job::Discrete { method: ma, .. }, Job::Discrete { method: mb, .. }) = (&t.cases[1].job, &bare.cases[1].job) else { panic!("discrete cases") };
        assert_eq!((*ma, *mb), (DiscreteMethod::Cdf, DiscreteMethod::Cdf));
    }

    /// Every key a case or `[defaults]` accepts (as serde lists them for an unknown key) is in
    /// the template.
    #[test]
    fn the_template_names_every_key() {
        let text = template();
        for scene in ["[[case]]\nnot_a_key = 1\n", "[defaults]\nnot_a_key = 1\n[[case]]\nname = \"a\"\n", "[[case]]\nname = \"a\"\nsampler = { not_a_key = 1 }\n"] {
            let err = Scene::parse("s.toml", scene).unwrap_err().message;
            let keys: Vec<&str> = err.split('`').skip(3).step_by(2).collect();
            assert!(keys.len() >= 3, "{err}");
            for key in keys {
                assert!(text.contains(&format!("{key} = ")), "the template lacks `{key}`");
            }
        }
    }
}
