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

    #[test]
    fn a_moved_member_is_reported() {
        let src = "struct S { a: vec2<f32>, b: vec4<f32> }";
        assert!(check_struct(src, "S", 32, 16, &[("a", 0), ("b", 16)]).is_ok());
        let e = check_struct(src, "S", 24, 8, &[("a", 0), ("b", 8)]).unwrap_err();
        assert!(e.contains("size") && e.contains("alignment") && e.contains("members"), "{e}");
    }
}
