//! OpenGL's loose uniforms (`uniform float x;` at global scope, outside any block: the default
//! uniform block that a renderer sets with `glUniform*`), which Vulkan GLSL and so naga's GLSL
//! front end refuse ("uniform/buffer blocks require layout(binding=X)").
//!
//! An OpenGL renderer's shared files declare them beside its samplers (GLSL-PathTracer's
//! `uniforms.glsl` and `globals.glsl`). lobes binds no values to them, so:
//! - a plain one (`bool`, `int`, `vec3`, a struct, an array of them) becomes a module variable,
//!   0 until set, and a sampler that reads one is told so unless a call expression sets it
//!   ([`super::super::gpu`]'s `prepare`);
//! - an opaque one (`sampler2D`, `samplerBuffer`, `image2D`, …: combined image samplers and
//!   buffer textures, which naga does not take at all) is left out, and a function that uses it
//!   is an error naming the declaration.

/// One loose uniform: its name and whether it is opaque.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Uniform {
    pub name: String,
    pub opaque: bool,
}

/// The line as lobes compiles it, and the uniforms it declared, where `line` declares loose
/// uniforms (`uniform [precision] TYPE NAME[N] [, NAME…];` on one line, no `layout`); `None`
/// for any other line (a block's `uniform Name {`, a `layout(…) uniform`, code).
pub(super) fn rewrite(line: &str) -> Option<(String, Vec<Uniform>)> {
    let rest = line.trim_start().strip_prefix("uniform")?;
    if !rest.starts_with(char::is_whitespace) {
        return None;
    }
    let (decl, after) = rest.split_once(';')?;
    if decl.contains('{') || !after.trim().is_empty() && !after.trim_start().starts_with("//") {
        return None;
    }
    let mut words = decl.split_whitespace().filter(|w| !["lowp", "mediump", "highp"].contains(w));
    let ty = words.next()?;
    let names: String = words.collect::<Vec<_>>().join(" ");
    let names: Vec<String> = names.split(',').filter_map(|n| n.split('[').next()).map(|n| n.trim().to_string()).collect();
    if names.iter().any(|n| n.is_empty() || !n.chars().all(|c| c.is_alphanumeric() || c == '_')) {
        return None;
    }
    let opaque = is_opaque(ty);
    let uniforms = names.into_iter().map(|name| Uniform { name, opaque }).collect();
    let indent = &line[..line.len() - line.trim_start().len()];
    let text = if opaque { String::new() } else { format!("{indent}{};", decl.trim_start()) };
    Some((text, uniforms))
}

/// Whether a GLSL type is opaque (a sampler, texture, image or atomic counter).
fn is_opaque(ty: &str) -> bool {
    let base = ty.trim_start_matches(['i', 'u']);
    ["sampler", "texture", "image", "subpassInput"].iter().any(|p| base.starts_with(p)) || ty == "atomic_uint"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(line: &str) -> Option<(String, Vec<(String, bool)>)> {
        rewrite(line).map(|(t, u)| (t, u.into_iter().map(|u| (u.name, u.opaque)).collect()))
    }

    #[test]
    fn loose_uniforms_become_variables_or_are_left_out() {
        assert_eq!(names("uniform int numOfLights;"), Some(("int numOfLights;".into(), vec![("numOfLights".into(), false)])));
        assert_eq!(names("  uniform highp vec2 a, b[4]; // sizes"), Some(("  highp vec2 a, b[4];".into(), vec![("a".into(), false), ("b".into(), false)])));
        assert_eq!(names("uniform Camera camera;"), Some(("Camera camera;".into(), vec![("camera".into(), false)])));
        assert_eq!(names("uniform sampler2D envMapTex;"), Some((String::new(), vec![("envMapTex".into(), true)])));
        assert_eq!(names("uniform isamplerBuffer vertexIndicesTex;"), Some((String::new(), vec![("vertexIndicesTex".into(), true)])));
    }

    #[test]
    fn blocks_and_bound_uniforms_are_left_to_naga() {
        for line in ["uniform Lights {", "uniform Lights { vec4 l[4]; };", "layout(binding = 0) uniform sampler2D t;", "uniformity = 1;", "// uniform int x;", "uniform int x; int y;"] {
            assert_eq!(rewrite(line), None, "{line}");
        }
    }
}
