//! lobes' WGSL for a renderer that writes GLSL: the same texts as [`super::wgsl_with`] (every
//! name prefixed `lobes_`), translated by naga's GLSL back end into GLSL 450 for `#include`
//! (`lobes wgsl --glsl`). naga's writer needs an entry point: an empty compute one is added for it
//! and taken out of the text again, with its `#version` line (the including file has its own).

use super::{DiscreteBindings, Module};

/// The modules (and those they use) as GLSL 450 functions, constants and (the discrete module's)
/// buffer blocks, for `#include` in a `#version 450` shader.
///
/// ```
/// use lobes::embed::{self, Module};
/// let glsl = embed::glsl(&[Module::Ggx], embed::DiscreteBindings::default()).unwrap();
/// assert!(glsl.contains("lobes_ggx_d(") && !glsl.lines().any(|l| l.starts_with("#version")) && !glsl.contains("void main()"));
/// ```
pub fn glsl(modules: &[Module], discrete: DiscreteBindings) -> Result<String, super::InvalidWgsl> {
    const MAIN: &str = "lobes_glsl_entry_point";
    let wgsl = format!("{}\n@compute @workgroup_size(1)\nfn {MAIN}() {{}}\n", super::wgsl_with(modules, discrete));
    let invalid = |message: String| super::InvalidWgsl { message };
    let module = naga::front::wgsl::parse_str(&wgsl).map_err(|e| invalid(format!("embedded lobes WGSL: {}", e.emit_to_string(&wgsl))))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .map_err(|e| invalid(format!("embedded lobes WGSL: {e:?}")))?;
    let options = naga::back::glsl::Options { version: naga::back::glsl::Version::Desktop(450), ..Default::default() };
    let pipeline = naga::back::glsl::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: MAIN.into(), multiview: None };
    let mut out = String::new();
    naga::back::glsl::Writer::new(&mut out, &module, &info, &options, &pipeline, naga::proc::BoundsCheckPolicies::default())
        .and_then(|mut w| w.write().map(|_| ()))
        .map_err(|e| invalid(format!("naga's GLSL writer: {e}")))?;
    // the entry point (written `void main()`), its workgroup size and the #version line go
    let main = out.find("void main()").ok_or_else(|| invalid("naga's GLSL writer wrote no entry point".into()))?;
    let body: String = out[..main]
        .lines()
        .filter(|l| !l.starts_with("#version") && !l.starts_with("layout(local_size_x") && !l.starts_with("#extension GL_ARB_compute_shader"))
        .map(|l| format!("{l}\n"))
        .collect();
    Ok(format!(
        "// lobes {} GLSL 450 (lobes wgsl --glsl): for #include in a #version 450 shader; every name lobes defines\n\
         // starts with lobes_, Lobes or LOBES_. Written from lobes' WGSL by naga's GLSL back end.\n{}",
        env!("CARGO_PKG_VERSION"),
        body.trim_start()
    ))
}
