//! The glue between a user's sampler and lobes' passes: the generated WGSL that calls the
//! user's functions as the sample, pdf and eval expressions say (`lobes_glue_sample/pdf/eval`,
//! the contract's signatures), the --rand queue whose order `order` gives u's components, the
//! type of each expression (naga's, in a probe function), and the user's files prepared for a
//! composition (their --rand bodies replaced, a composed tree compacted to what the glue reaches).

use super::compose::{Composed, Source};
use super::composition::{Call, UserCode, is_name};
use super::modules::compose_user;
use super::{CheckError, Message, Setting, UserSampler};

/// What the sample call returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Returned {
    /// A function of the contract: (d, pdf).
    Contract,
    /// An expression's vec3 (d, or h) and vec4 ((d, pdf), or (h, pdf of h)).
    Vec3,
    Vec4,
}

/// The path in messages of the generated glue and of the module `lobes::user` that holds it:
/// errors in a call expression point here.
pub(super) const GLUE: &str = "<lobes check glue>";

/// lobes' names for call expressions: `wi`, `u`, `d`, `params`, `p0` … `p15` and `rng`, a
/// `ptr<function, u32>` to a state seeded from the uniforms (or from d in the pdf).
fn names(seed: &str) -> String {
    let mut out = format!("    var lobes_state = {seed};\n    let rng = &lobes_state;\n");
    for row in 0..4 {
        let lets: Vec<String> = (0..4).map(|k| format!("let p{} = params[{row}].{};", 4 * row + k, ["x", "y", "z", "w"][k])).collect();
        out += &format!("    {}\n", lets.join(" "));
    }
    out
}

/// The lines of a call expression `S1; S2; E` (statements before the value, such as those that
/// declare the variables of out parameters: [`super::dialect::out_params`]), the value `E` as
/// `head E;`.
fn statements(expr: &str, head: &str) -> String {
    let parts: Vec<&str> = expr.split(';').map(str::trim).filter(|s| !s.is_empty()).collect();
    let Some((value, before)) = parts.split_last() else { return format!("    {head}{expr};\n") };
    before.iter().map(|s| format!("    {s};\n")).chain([format!("    {head}{value};\n")]).collect()
}

/// The type probe of a call expression: a function `lobes_type_probe` whose `lobes_r` has the
/// expression's type, over the names of its `call` (the sample's wi, u; a normal's wi, p; a
/// density's wi, d).
pub(super) fn type_probe(call: Call, expr: &str) -> String {
    let second = match call {
        Call::Sample => "u: vec4<f32>",
        Call::Normal => "p: vec3<f32>",
        Call::Pdf | Call::Eval => "d: vec3<f32>",
    };
    format!(
        "// the type of the {} expression\nfn lobes_type_probe(wi: vec3<f32>, {second}, params: array<vec4<f32>, 4>) {{\n{}{}}}\n",
        call.setting().key(),
        names("0u"),
        statements(expr, "let lobes_r = ")
    )
}

/// The generated functions that call the user's code as --sample, --pdf and --eval say, under the
/// contract's signatures with `params` an argument (`lobes_glue_sample/pdf/eval`), the queue of
/// --rand (`lobes_rand_take`, in the order `order` of u's components) and the seeding of `rng`.
pub(super) fn glue(sampler: &UserSampler, returned: Returned, order: [u32; 4], reach: bool) -> String {
    let half = sampler.composition.sample_returns == super::SampleReturns::HalfVector;
    let mut sample = match returned {
        Returned::Contract => format!("    let lobes_r = {}(wi, u, params);\n", sampler.sample),
        _ => format!("{}    // the sample expression\n{}", names("lobes_rng_seed(u)"), statements(&sampler.sample, "let lobes_r = ")),
    };
    if sampler.conventions.measure == super::conventions::Measure::Area {
        sample += &area_to_solid_angle(returned);
        return glue_text(sampler, sample, order, reach);
    }
    sample += if half {
        // A half vector facing away from wi (wi·h ≤ 0, h = (0, 0, 0) among them) is rejected before
        // reflecting, as renderers do: there the reflection's density 1 / (4 wi·h) has no finite
        // value (Walter et al. 2007, eq. 14, |dω_h/dω_d| = 1 / (4 |wi·h|)); a NaN h stays NaN.
        "    let lobes_h = lobes_r.xyz;\n\
         \x20   let lobes_wh = dot(wi, lobes_h);\n\
         \x20   let lobes_d = 2.0 * lobes_wh * lobes_h - wi;\n\
         \x20   if (lobes_wh <= 0.0) {\n\
         \x20       return vec4<f32>(lobes_d, 0.0);\n\
         \x20   }\n"
    } else {
        "    let lobes_d = lobes_r.xyz;\n"
    };
    sample += match (returned, half) {
        // the pdf of h over that of d: the reflection's Jacobian
        (Returned::Contract | Returned::Vec4, true) => "    return vec4<f32>(lobes_d, lobes_r.w / (4.0 * lobes_wh));\n",
        (Returned::Contract | Returned::Vec4, false) => "    return vec4<f32>(lobes_d, lobes_r.w);\n",
        (Returned::Vec3, _) => "    return vec4<f32>(lobes_d, lobes_glue_pdf(wi, lobes_d, params));\n",
    };
    glue_text(sampler, sample, order, reach)
}

/// The sample of a light sampled by area (`--measure area`): the returned point p becomes the
/// direction d = p/|p| and the area density pdf_A the solid-angle one pdf_A |p|² / |n·d| (pbrt-v4
/// §4.2.3 eq. 4.9; |p|² as p·p, exact to an ulp, and n the expression `--normal` at p). A rejection
/// (pdf_A = 0) stays one; a point at the shading point (p = 0) has no direction and is left NaN,
/// and one seen edge-on (|n·d| = 0) an infinite pdf: invalid samples, each with its reason. An
/// expression that returns p alone takes the pdf function's value at d, as for directions.
fn area_to_solid_angle(returned: Returned) -> String {
    let head = "    let lobes_p = lobes_r.xyz;\n    let lobes_p2 = dot(lobes_p, lobes_p);\n    let lobes_d = lobes_p / sqrt(lobes_p2);\n";
    let tail = match returned {
        Returned::Vec3 => "    return vec4<f32>(lobes_d, lobes_glue_pdf(wi, lobes_d, params));\n",
        Returned::Contract | Returned::Vec4 => {
            "    if (lobes_r.w == 0.0) {\n\
             \x20       return vec4<f32>(lobes_p, 0.0);\n\
             \x20   }\n\
             \x20   return vec4<f32>(lobes_d, lobes_r.w * lobes_p2 / lobes_light_cos(lobes_p, lobes_d, params));\n"
        }
    };
    format!("{head}{tail}")
}

/// `lobes_light_cos(p, d, params)`, |n·d| with n the `--normal` expression at the light's point p
/// (none without `--measure area`).
fn light_cos(sampler: &UserSampler) -> String {
    match sampler.composition.normal.as_deref().filter(|_| sampler.conventions.measure == super::conventions::Measure::Area) {
        Some(normal) => format!(
            "fn lobes_light_cos(p: vec3<f32>, lobes_d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n{}    // the light's normal at p (the composition's normal expression)\n    return abs(dot({normal}, lobes_d));\n}}\n",
            names("0u")
        ),
        None => String::new(),
    }
}

/// The glue's text around the body `sample` of `lobes_glue_sample`.
fn glue_text(sampler: &UserSampler, sample: String, order: [u32; 4], reach: bool) -> String {
    let density = |call: Call, expr: Option<&str>| match expr {
        None => "    return 0.0;\n".to_string(),
        Some(n) if is_name(n) => format!("    return {n}(wi, d, params);\n"),
        Some(e) => format!("{}    // the {} expression\n{}", names("lobes_rng_seed(vec4<f32>(d, 0.0))"), call.setting().key(), statements(e, "return ")),
    };
    let reach = if reach {
        "// (what the glue reaches is what the composed module keeps)\n\
         @compute @workgroup_size(1)\n\
         fn lobes_reach() {\n\
         \x20   let wi = vec3<f32>(0.0, 0.0, 1.0);\n\
         \x20   _ = lobes_glue_sample(wi, vec4<f32>(0.5), array<vec4<f32>, 4>());\n\
         \x20   _ = lobes_glue_pdf(wi, wi, array<vec4<f32>, 4>());\n\
         \x20   _ = lobes_glue_eval(wi, wi, array<vec4<f32>, 4>());\n\
         \x20   _ = lobes_rand_take(0u);\n\
         }\n"
    } else {
        ""
    };
    format!(
        "// Generated by lobes check: the user's functions called as its sample, pdf and eval expressions say.\n\
         var<private> lobes_rand_u: vec4<f32>;\n\
         var<private> lobes_rand_next: u32;\n\
         const LOBES_RAND_ORDER = array<u32, 4>({o0}u, {o1}u, {o2}u, {o3}u);\n\
         {queue}\
         fn lobes_glue_sample(wi: vec3<f32>, u: vec4<f32>, params: array<vec4<f32>, 4>) -> vec4<f32> {{\n\
         \x20   lobes_rand_u = u;\n\
         \x20   lobes_rand_next = 0u;\n\
         {sample}}}\n\
         fn lobes_glue_pdf(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n{pdf}}}\n\
         fn lobes_glue_eval(wi: vec3<f32>, d: vec3<f32>, params: array<vec4<f32>, 4>) -> f32 {{\n{eval}}}\n\
         {light}{reach}",
        o0 = order[0],
        o1 = order[1],
        o2 = order[2],
        o3 = order[3],
        queue = include_str!("../../shaders/check/rand_queue.wgsl"),
        pdf = density(Call::Pdf, Some(&sampler.pdf)),
        eval = density(Call::Eval, sampler.eval.as_deref()),
        light = light_cos(sampler),
    )
}

/// The wrappers under the names lobes' passes call, with `params` from the uniforms.
pub(super) fn contract_glue(sampler: &UserSampler) -> String {
    format!(
        "// Generated by lobes check: the glue under the names lobes' passes call.\n\
         fn lobes_contract_sample(wi: vec3<f32>, u: vec4<f32>) -> vec4<f32> {{ return lobes_glue_sample(wi, u, lobes_params.user); }}\n\
         fn lobes_contract_pdf(wi: vec3<f32>, d: vec3<f32>) -> f32 {{ return lobes_glue_pdf(wi, d, lobes_params.user); }}\n\
         fn lobes_contract_eval(wi: vec3<f32>, d: vec3<f32>) -> f32 {{ return lobes_glue_eval(wi, d, lobes_params.user); }}\n\
         // the draws the last lobes_user_sample took from the --rand queue\n\
         fn lobes_user_draws() -> u32 {{ return lobes_rand_next; }}\n{conventions}",
        conventions = sampler.conventions.wgsl(),
    )
}

/// The type of a `call` expression over the user's code (naga's type of it in a probe function);
/// an expression that does not parse or validate is an error keyed by its setting.
fn expression_type(code: &UserCode, call: Call, expr: &str) -> Result<naga::TypeInner, CheckError> {
    let mut c = Composed::default();
    for p in &code.parts {
        c.push(&p.name, &p.text);
    }
    c.push(GLUE, &type_probe(call, expr));
    let (module, info) = c.validate_with(naga::valid::Capabilities::all()).map_err(|e| match e {
        CheckError::Wgsl(m) => call.error(expr, m),
        e => e,
    })?;
    let (h, f) = module.functions.iter().find(|(_, f)| f.name.as_deref() == Some("lobes_type_probe")).ok_or_else(|| CheckError::Internal("no type probe".into()))?;
    let (e, _) = f.named_expressions.iter().find(|(_, n)| n.as_str() == "lobes_r").ok_or_else(|| CheckError::Internal("no lobes_r".into()))?;
    Ok(info[h][*e].ty.inner_with(&module.types).clone())
}

/// The light's normal expression (`--normal`): a vec3<f32> over p.
fn check_normal(code: &UserCode, normal: &str) -> Result<(), CheckError> {
    if normal.trim().is_empty() {
        return Err(CheckError::setting(
            Setting::Normal,
            "the expression is empty; give the light's unit normal at the sampled point p as WGSL, e.g. 'vec3<f32>(0.0, 0.0, -1.0)' or 'normalize(p - p.xyz)'",
        ));
    }
    match expression_type(code, Call::Normal, normal)? {
        naga::TypeInner::Vector { size: naga::VectorSize::Tri, scalar } if scalar == naga::Scalar::F32 => Ok(()),
        other => Err(Call::Normal.returns(normal, format!("{}; expected vec3<f32> (the light's unit normal at p)", super::compose::describe_inner(&other)))),
    }
}

/// The call expressions of --sample, --pdf, --eval and --normal: none empty, each density an f32
/// and the normal a vec3<f32>.
pub(super) fn check_expressions(code: &UserCode, sampler: &UserSampler) -> Result<(), CheckError> {
    if let Some(normal) = &sampler.composition.normal {
        check_normal(code, normal)?;
    }
    let calls = [(Call::Sample, Some(sampler.sample.as_str())), (Call::Pdf, Some(sampler.pdf.as_str())), (Call::Eval, sampler.eval.as_deref())];
    for (call, expr) in calls {
        let Some(expr) = expr else { continue };
        if expr.trim().is_empty() {
            let example = if call == Call::Sample { "'sample_ggx(wi, u.xy, p0)'" } else { "'ggx_pdf(wi, d, p0)'" };
            let message = format!("the expression is empty; give a function name of the contract or a call expression over lobes' names, e.g. {example}");
            return Err(CheckError::setting(call.setting(), message));
        }
        if call == Call::Sample || is_name(expr) {
            continue;
        }
        match expression_type(code, call, expr)? {
            naga::TypeInner::Scalar(s) if s == naga::Scalar::F32 => {}
            other => {
                let what = if call == Call::Pdf { "density at d" } else { "value f·|cos θ| at d" };
                return Err(call.returns(expr, format!("{}; expected f32 (the {what})", super::compose::describe_inner(&other))));
            }
        }
    }
    Ok(())
}

/// What the sample expression returns (the contract's function: `Contract`), from naga's types
/// of the expression in a probe function.
pub(super) fn returned(code: &UserCode, sampler: &UserSampler) -> Result<Returned, CheckError> {
    check_expressions(code, sampler)?;
    if is_name(&sampler.sample) {
        return Ok(Returned::Contract);
    }
    match expression_type(code, Call::Sample, &sampler.sample)? {
        naga::TypeInner::Vector { size: naga::VectorSize::Tri, scalar } if scalar == naga::Scalar::F32 => Ok(Returned::Vec3),
        naga::TypeInner::Vector { size: naga::VectorSize::Quad, scalar } if scalar == naga::Scalar::F32 => Ok(Returned::Vec4),
        other => Err(Call::Sample.returns(
            &sampler.sample,
            format!("{}; a sample expression returns vec3<f32> (d) or vec4<f32> (d, pdf)", super::compose::describe_inner(&other)),
        )),
    }
}

/// The replacement body of a --rand function returning `inner`: the next 1 to 4 uniforms.
fn rand_body(name: &str, module: &naga::Module, f: &naga::Function) -> Result<String, CheckError> {
    let ty = f.result.as_ref().map(|r| &module.types[r.ty].inner);
    let n = match ty {
        Some(naga::TypeInner::Scalar(s)) if *s == naga::Scalar::F32 => 1,
        Some(naga::TypeInner::Vector { size, scalar }) if *scalar == naga::Scalar::F32 => *size as u32,
        other => {
            let returns = other.map_or("nothing".to_string(), super::compose::describe_inner);
            return Err(CheckError::setting(Setting::Rand, format!("{name} returns {returns}; lobes hands out uniforms in [0, 1] as f32, vec2<f32>, vec3<f32> or vec4<f32>")));
        }
    };
    let swizzle = ["", ".x", ".xy", ".xyz", ""][n as usize];
    Ok(format!("{{ return lobes_rand_take({n}u){swizzle}; }}"))
}

/// The parts with the bodies of the --rand functions replaced by lobes' queue (lines kept). A
/// function that is absent is an error naming the functions there.
fn replace_rand(parts: &[Source], code: &UserCode, rand: &[String]) -> Result<Vec<Source>, CheckError> {
    if rand.is_empty() {
        return Ok(parts.to_vec());
    }
    let mut c = Composed::default();
    for p in parts {
        c.push(&p.name, &p.text);
    }
    let module = naga::front::wgsl::parse_str(&c.text).map_err(|e| CheckError::Internal(format!("the composed WGSL does not parse: {}", e.message())))?;
    let mut bodies = Vec::new();
    for name in rand {
        let found = code.functions_named(&module, name);
        if found.is_empty() {
            let known: Vec<String> = module
                .functions
                .iter()
                .filter_map(|(_, f)| f.name.as_deref())
                .filter(|n| !n.starts_with("lobes_"))
                .map(|n| code.origins.iter().find(|o| o.0 == n).map_or(n.to_string(), |o| format!("{}::{}", o.1, o.2)))
                .collect();
            return Err(CheckError::setting(Setting::Rand, format!(
                "{name}: no function `{name}` in {}{} (functions there: {})",
                code.files.join(", "),
                crate::suggest::did_you_mean(name, known.iter().map(String::as_str)),
                known.join(", ")
            )));
        }
        // one function named twice (`rnd` and `rnd`, or `rand_f` and `package::utils::rand_f`) is one
        for h in found {
            if !bodies.iter().any(|(b, _)| *b == h) {
                bodies.push((h, rand_body(name, &module, &module.functions[h])?));
            }
        }
    }
    let text = super::compose::replace_bodies(&c.text, &module, &bodies)?;
    // the lines are kept: each part takes back as many as it had
    let mut lines = text.lines();
    Ok(parts
        .iter()
        .map(|p| {
            let n = p.text.lines().count();
            let mut t: String = lines.by_ref().take(n).map(|l| format!("{l}\n")).collect();
            if n == 0 {
                t.clear();
            }
            Source { name: p.name.clone(), text: t }
        })
        .collect())
}

/// The user's code with the glue: plain files as they are (their --rand bodies replaced) and the
/// glue after them; a composed tree with the glue, compacted to what the glue reaches, written
/// back as WGSL.
pub(super) fn prepare(sampler: &UserSampler, order: [u32; 4]) -> Result<Vec<Source>, CheckError> {
    let code = compose_user(&sampler.sources, &sampler.composition)?;
    // qualified names in call expressions, as the composed text names those items
    let root = &sampler.sources[0].text;
    let resolved = UserSampler {
        sample: code.resolve_qualified(Call::Sample, &sampler.sample, root)?,
        pdf: code.resolve_qualified(Call::Pdf, &sampler.pdf, root)?,
        eval: sampler.eval.as_deref().map(|e| code.resolve_qualified(Call::Eval, e, root)).transpose()?,
        ..sampler.clone()
    };
    let sampler = &resolved;
    let returned = returned(&code, sampler)?;
    let rand = &sampler.composition.rand;
    if code.dialect == super::composition::Dialect::Wgsl {
        let mut parts = replace_rand(&code.parts, &code, rand)?;
        parts.push(Source { name: GLUE.into(), text: glue(sampler, returned, order, false) });
        return Ok(parts);
    }
    // the --rand bodies replaced in the tree as composed, where each function is found by its
    // name there (before naga's writer renames any: `würfel` → `wrfel`); their calls of the
    // queue reach the glue's `lobes_rand_take` in the one module below
    let parts = replace_rand(&code.parts, &code, rand)?;
    let mut c = Composed::default();
    c.push(&parts[0].name, &parts[0].text);
    c.push(GLUE, &glue(sampler, returned, order, true));
    let (mut module, _) = c.validate_with(naga::valid::Capabilities::all())?;
    // compacted and written on a large stack, as parsed (a tree thousands of calls deep)
    let uniforms = code.uniforms.clone();
    let expressions: Vec<String> = [Some(&sampler.sample), Some(&sampler.pdf), sampler.eval.as_ref()].into_iter().flatten().cloned().collect();
    let text = crate::engine::gpu::stack::with_big_stack(move || {
        naga::compact::compact(&mut module, naga::compact::KeepUnused::No);
        module.entry_points.clear();
        unset_uniform(&module, &uniforms, &expressions)?;
        super::compose::write_wgsl(&module, naga::valid::Capabilities::all())
    })?;
    Ok(vec![Source { name: code.parts[0].name.clone(), text }])
}

/// An OpenGL uniform (a GLSL file's loose `uniform int n;`, 0 here: `dialect::gl_uniforms`)
/// that the sampler, pdf or eval reads (it survived compaction to what the glue reaches) and no
/// call expression names, to set it: bad input, since its value in the renderer is unknown.
fn unset_uniform(module: &naga::Module, uniforms: &[(String, String)], expressions: &[String]) -> Result<(), CheckError> {
    let reached = |name: &str| module.global_variables.iter().any(|(_, g)| g.name.as_deref() == Some(name));
    let set = |name: &str| expressions.iter().any(|e| e.split(|c: char| !(c.is_alphanumeric() || c == '_')).any(|w| w == name));
    match uniforms.iter().find(|(name, _)| reached(name) && !set(name)) {
        Some((name, at)) => Err(CheckError::Advised(
            Message::text(format!("{at}: the sampler reads the OpenGL uniform `{name}`, which the renderer sets with glUniform and lobes cannot (it is 0 here); set it where the call expression starts, e.g. "))
                .setting(Setting::Sample)
                .then(format!(" '{name} = 1; …' (or "))
                .setting(Setting::Params)
                .then(" and p0)"),
        )),
        None => Ok(()),
    }
}
