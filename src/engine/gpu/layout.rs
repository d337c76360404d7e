//! What the host and the WGSL kernels share, defined here once: the constants every composed
//! module's header declares ([`consts_wgsl`]), and a check of each `#[repr(C)]` struct the host
//! uploads against naga's layout of its WGSL twin ([`check_struct`]).

use crate::reference::Invalid;
use crate::reference::fresnel::Fresnel;
use crate::reference::masking::Masking;
use crate::stats::weighted::{SQUARE_SCALE, WEIGHT_LIMIT, WEIGHT_SCALE};

/// Samples drawn by each invocation of `sample_histogram`; a workgroup of 256 draws 65280,
/// under the 65535 that a 16-bit packed workgroup counter holds.
pub const SAMPLES_PER_THREAD: u32 = 255;
/// Invocations per workgroup of every kernel (`@workgroup_size(WG_SIZE)`).
pub const WG_SIZE: u32 = 256;
const _: () = assert!(SAMPLES_PER_THREAD * WG_SIZE <= 0xffff);

/// Workgroups of the sampling kernels for `count` samples.
pub fn sampling_groups(count: u64) -> u64 {
    count.div_ceil((WG_SIZE * SAMPLES_PER_THREAD) as u64)
}

/// Counters after a histogram's bins: one per invalid reason, codes 1 ..= N_REASONS in the
/// order of [`Invalid::ALL`] (`shaders/lib/histogram.wgsl`).
pub const N_REASONS: u32 = Invalid::ALL.len() as u32;

/// Cells after a weighted histogram's bins and reasons (`shaders/passes/weighted.wgsl`): Σw² over the
/// bins, Σw² over all samples, the count of weights not summed, and Σw² over the bins below the
/// horizon.
pub const WEIGHT_EXTRA_CELLS: u32 = 4;

/// Group 0 of `lobes run`'s kernels and of `lobes check`'s passes: the binding of each storage
/// and uniform variable `shaders/` declares there, so that the host binds by name (the test
/// `tests::group_0_is_the_wgsls` holds the WGSL to it).
pub mod binding {
    /// `lobes_params`, the uniform block of every kernel and pass (`passes/params.wgsl`).
    pub const PARAMS: u32 = 0;
    /// `counts`: a chunk's u32 counter per cell (`passes/bindings.wgsl`).
    pub const COUNTS: u32 = 1;
    /// `totals`: the 64-bit totals the chunks fold into.
    pub const TOTALS: u32 = 2;
    /// `explicit_u` (`passes/lobe_kernel.wgsl`) or `discrete_f` (`lib/discrete.wgsl`): the
    /// host's uniforms, or a discrete table's CDF or thresholds.
    pub const INPUT: u32 = 3;
    /// `discrete_u`: an alias table's indices.
    pub const ALIASES: u32 = 4;
    /// `directions_out`: the directions pass's samples.
    pub const DIRECTIONS: u32 = 5;
    /// `effect`, the weighted pass's uniform (`passes/effect_uniform.wgsl`).
    pub const EFFECT: u32 = 6;
    /// `weight_sums` and `weight_error`, the weighted pass's fixed-point sums (`passes/weighted.wgsl`).
    pub const WEIGHT_SUMS: u32 = 7;
    pub const WEIGHT_ERROR: u32 = 8;
    /// `slabs`: the per-slab counters of CPU adapters (`passes/counting_slabs.wgsl`).
    pub const SLABS: u32 = 9;
    /// `lobes_draw_counts`: a user sampler's --rand draws past four (`check/user_draw.wgsl`).
    pub const DRAWS: u32 = 10;
    /// `lobes_in`, `lobes_out` and `lobes_probes`: a check pass's items, values and probes
    /// (`check/user_passes.wgsl`).
    pub const CHECK_IN: u32 = 1;
    pub const CHECK_OUT: u32 = 2;
    pub const CHECK_PROBES: u32 = 5;

    /// Each variable with its binding, as the WGSL names it.
    pub const DECLARED: [(&str, u32); 15] = [
        ("lobes_params", PARAMS),
        ("counts", COUNTS),
        ("totals", TOTALS),
        ("explicit_u", INPUT),
        ("discrete_f", INPUT),
        ("discrete_u", ALIASES),
        ("directions_out", DIRECTIONS),
        ("effect", EFFECT),
        ("weight_sums", WEIGHT_SUMS),
        ("weight_error", WEIGHT_ERROR),
        ("slabs", SLABS),
        ("lobes_draw_counts", DRAWS),
        ("lobes_in", CHECK_IN),
        ("lobes_out", CHECK_OUT),
        ("lobes_probes", CHECK_PROBES),
    ];
}

/// `SCREAMING_CASE` of a kebab or snake name.
fn constant_name(prefix: &str, name: &str) -> String {
    format!("{prefix}_{}", name.replace('-', "_").to_uppercase())
}

/// The WGSL declarations of the shared constants: workgroup shape, reason codes, Fresnel and
/// masking modes (the `effect.modes` and override values of `shaders/passes/weighted.wgsl`), and the
/// fixed-point scales of the weighted sums (`src/stats/weighted.rs`).
pub fn consts_wgsl() -> String {
    let mut src = format!(
        "const WG_SIZE: u32 = {WG_SIZE}u;\nconst SAMPLES_PER_THREAD: u32 = {SAMPLES_PER_THREAD}u;\n"
    );
    src += &Invalid::wgsl_consts("REASON");
    let fresnels = [Fresnel::Schlick { f0: 0.0 }, Fresnel::Conductor { eta: 1.0, k: 0.0 }, Fresnel::Dielectric { eta: 1.0 }];
    for f in fresnels {
        src += &format!("const {}: u32 = {}u;\n", constant_name("FRESNEL", f.name()), f.mode());
    }
    for m in Masking::ALL.into_iter().filter(|&m| m != Masking::None) {
        src += &format!("const {}: u32 = {}u;\n", constant_name("MASKING", m.name()), m.mode());
    }
    for (name, value) in [("WEIGHT_SCALE", WEIGHT_SCALE), ("SQUARE_SCALE", SQUARE_SCALE), ("WEIGHT_LIMIT", WEIGHT_LIMIT)] {
        src += &format!("const {name}: f32 = {value:?};\n");
    }
    src
}

/// Checks that the WGSL struct `name` of `source` has the given size, alignment and member
/// offsets under naga's layouter (the WGSL memory layout rules), and returns a description of
/// every difference.
pub fn check_struct(source: &str, name: &str, size: usize, align: usize, members: &[(&str, usize)]) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| format!("{e:?}"))?;
    let (handle, ty) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)).ok_or(format!("no struct {name}"))?;
    let naga::TypeInner::Struct { members: wgsl_members, .. } = &ty.inner else { return Err(format!("{name} is not a struct")) };
    let layout = layouter[handle];
    let mut errors = Vec::new();
    if layout.size as usize != size {
        errors.push(format!("size: WGSL {}, Rust {size}", layout.size));
    }
    if layout.alignment.round_up(1) as usize != align {
        errors.push(format!("alignment: WGSL {}, Rust {align}", layout.alignment));
    }
    let wgsl: Vec<(&str, usize)> = wgsl_members.iter().map(|m| (m.name.as_deref().unwrap_or(""), m.offset as usize)).collect();
    if wgsl != members {
        errors.push(format!("members (name, offset): WGSL {wgsl:?}, Rust {members:?}"));
    }
    if errors.is_empty() { Ok(()) } else { Err(format!("{name}: {}", errors.join("; "))) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_match_the_host() {
        let src = consts_wgsl();
        assert!(src.contains("const REASON_ZERO_PDF: u32 = 4u;"), "{src}");
        assert!(src.contains("const FRESNEL_DIELECTRIC: u32 = 3u;"), "{src}");
        assert!(src.contains("const MASKING_HEIGHT_CORRELATED: u32 = 3u;"), "{src}");
        assert!(src.contains("const WEIGHT_SCALE: f32 = 1048576.0;"), "{src}");
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default()).validate(&module).unwrap();
    }

    /// The value of `const NAME: u32` in a WGSL source.
    fn u32_const(source: &str, name: &str) -> u32 {
        let module = naga::front::wgsl::parse_str(source).unwrap();
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).unwrap();
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name} = {e:?}"),
        }
    }

    /// A constant that stays in a file of its own because renderers embed the file without a
    /// header (`lobes::embed`) is checked against the host's instead.
    #[test]
    fn embedded_constants_match_the_host() {
        let discrete = super::super::library::plain(include_str!("../../../shaders/lib/discrete.wgsl"));
        assert_eq!(u32_const(&discrete, "DISCRETE_BLOCK") as usize, crate::reference::discrete::BLOCK);
    }

    /// Every `@group(0) @binding(N) var… name` of `shaders/passes`, `shaders/check` and
    /// `shaders/lib` is at the binding [`binding::DECLARED`] gives its name, and each name there
    /// is declared.
    #[test]
    fn group_0_is_the_wgsls() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        let mut seen = std::collections::BTreeSet::new();
        for dir in ["passes", "check", "lib"] {
            for entry in std::fs::read_dir(root.join(dir)).unwrap() {
                let path = entry.unwrap().path();
                if path.ends_with("passes/quadrature.wgsl") {
                    continue; // `lobes tradeoff`'s quadrature kernel, a layout of its own
                }
                let text = std::fs::read_to_string(&path).unwrap();
                for line in text.lines().filter_map(|l| l.trim_start().strip_prefix("@group(0) @binding(")) {
                    let (number, rest) = line.split_once(')').unwrap();
                    let decl = rest.split_once("var").unwrap().1;
                    let decl = if decl.starts_with('<') { decl.split_once('>').unwrap().1 } else { decl };
                    let name = decl.split(':').next().unwrap().trim();
                    let Some(&(_, host)) = binding::DECLARED.iter().find(|(n, _)| *n == name) else {
                        panic!("{}: `{name}` at binding {number} is not in binding::DECLARED", path.display());
                    };
                    assert_eq!(number.parse::<u32>().unwrap(), host, "{}: `{name}`", path.display());
                    seen.insert(name.to_owned());
                }
            }
        }
        let missing: Vec<_> = binding::DECLARED.iter().filter(|(n, _)| !seen.contains(*n)).collect();
        assert!(missing.is_empty(), "declared nowhere: {missing:?}");
    }

    #[test]
    fn a_moved_member_is_reported() {
        let src = "struct S { a: vec2<f32>, b: vec4<f32> }";
        assert!(check_struct(src, "S", 32, 16, &[("a", 0), ("b", 16)]).is_ok());
        let e = check_struct(src, "S", 24, 8, &[("a", 0), ("b", 8)]).unwrap_err();
        assert!(e.contains("size") && e.contains("alignment") && e.contains("members"), "{e}");
    }
}
