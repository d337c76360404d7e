//! Generates the texts of `lobes::embed` from `shaders/` at build time, so that a renderer that
//! embeds lobes' WGSL gets `&'static str` constants and parses nothing at run time, and so that
//! each fact stays in one place: the files of `shaders/lib` and `shaders/math` are the only
//! source of every form (plain prefixed WGSL, naga_oil modules, the WESL package), and of each
//! module's names and dependencies. The text rules are `src/embed/text.rs` and
//! `src/embed/namespace.rs` (over the lexer `src/wgsl_tokens.rs`), compiled into this script as
//! they are into the crate;
//! `src/embed/mod.rs`'s unit tests parse the results with naga and compare them with the
//! composition lobes' own kernels run.

use std::fmt::Write;

#[path = "src/embed/namespace.rs"]
#[allow(dead_code)]
mod namespace;
#[path = "src/embed/text.rs"]
#[allow(dead_code)]
mod text;
#[path = "src/wgsl_tokens.rs"]
#[allow(dead_code)]
mod wgsl_tokens;

/// lobes::embed's modules in dependency order (each after those it imports), with their files
/// under `shaders/`: the order and names of `embed::Module::ALL` (a unit test holds the two
/// together). A module is what a renderer imports as one: a lobe's sampler, densities and BRDF.
const MODULES: [(&str, &[&str]); 17] = [
    ("rng", &["lib/rng.wgsl"]),
    ("math", &["math/f32.wgsl"]),
    ("reflect", &["lib/reflect.wgsl"]),
    ("microfacet", &["lib/microfacet.wgsl", "lib/microfacet_eval.wgsl"]),
    ("ward", &["lib/ward.wgsl", "lib/ward_eval.wgsl"]),
    ("ggx", &["lib/ggx.wgsl", "lib/ggx_eval.wgsl"]),
    ("beckmann", &["math/erf_f32.wgsl", "lib/beckmann.wgsl", "lib/beckmann_eval.wgsl"]),
    ("fresnel", &["lib/fresnel.wgsl"]),
    ("masking", &["lib/masking.wgsl"]),
    ("dielectric", &["lib/dielectric.wgsl", "lib/dielectric_eval.wgsl"]),
    ("discrete", &["lib/discrete.wgsl"]),
    ("light", &["lib/light.wgsl"]),
    ("sphere_light", &["lib/sphere_light.wgsl"]),
    ("disk_light", &["lib/disk_light.wgsl"]),
    ("triangle_light", &["lib/triangle_light.wgsl"]),
    ("triangle_area_light", &["lib/triangle_area_light.wgsl"]),
    ("rect_light", &["lib/rect_light.wgsl"]),
];

/// The names each module offers a renderer, in `MODULES`' order: its API, which
/// `embed::Module`'s documentation and docs/embedding.md's module table list (a unit test holds
/// the table to it). Every other name a module's files declare is an internal helper: the
/// naga_oil and WESL forms put those in the submodule `lobes::NAME::internal` (neither module
/// system hides names), so that `lobes::NAME` holds only these.
const API: [&[&str]; 17] = [
    &["rng_uniforms", "pcg4d", "rng_to_unit", "add64"],
    &["math_log", "math_exp", "math_sin", "math_cos", "math_atan2", "math_is_finite", "neg_ln", "UNDERFLOW_EXPONENT"],
    &[
        "PI", "LobeSample", "lobe_sample", "reflect_about", "reflect_sample", "reflection_half_vector", "from_tan_theta", "frame_to_local", "frame_to_world",
        "sample_to_local", "sample_to_world",
    ],
    &["stretch", "microfacet_ndf_weight", "microfacet_eval", "microfacet_pdf_ndf", "microfacet_pdf_vndf"],
    &["ward_sample", "ward_pdf", "ward_eval", "ward_weight", "ward_pdf_h", "ward_sample_h"],
    &[
        "ggx_sample_ndf", "ggx_sample_vndf", "ggx_sample_bounded", "ggx_pdf_ndf", "ggx_pdf_vndf", "ggx_pdf_bounded", "ggx_eval", "ggx_d", "ggx_g1", "ggx_lambda",
        "ggx_g2", "ggx_vndf_weight", "ggx_bounded_weight",
    ],
    &[
        "beckmann_sample_ndf", "beckmann_sample_vndf", "beckmann_pdf_ndf", "beckmann_pdf_vndf", "beckmann_eval", "beckmann_d", "beckmann_g1", "beckmann_lambda",
        "beckmann_g2", "beckmann_vndf_weight",
    ],
    &["fresnel_schlick", "fresnel_dielectric", "fresnel_dielectric_transmittance", "fresnel_cos_transmitted", "fresnel_conductor"],
    &["masking_separable", "masking_height_correlated", "masking_height_correlated_transmitted", "masking_ln_beta"],
    &[
        "dielectric_ggx_ndf", "dielectric_ggx_vndf", "dielectric_beckmann_ndf", "dielectric_beckmann_vndf", "dielectric_ggx_ndf_pdf", "dielectric_ggx_vndf_pdf",
        "dielectric_beckmann_ndf_pdf", "dielectric_beckmann_vndf_pdf", "dielectric_ggx_eval", "dielectric_beckmann_eval", "dielectric_ggx_vndf_weight",
        "dielectric_beckmann_vndf_weight",
    ],
    &["discrete_f", "discrete_u", "DISCRETE_BLOCK", "discrete_sample_cdf", "discrete_sample_cdf_blocks", "discrete_sample_alias", "discrete_search"],
    &["LightSample", "LIGHT_PI", "light_to_world", "light_triangle_solid_angle", "light_area_to_solid_angle"],
    &["sphere_light_sample", "sphere_light_pdf", "sphere_light_solid_angle"],
    &["disk_light_sample", "disk_light_pdf"],
    &["triangle_light_sample", "triangle_light_pdf", "triangle_light_solid_angle"],
    &["triangle_area_light_sample", "triangle_area_light_pdf"],
    &["rect_light_sample", "rect_light_pdf", "rect_light_solid_angle"],
];

struct File {
    path: String,
    source: String,
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/embed/text.rs");
    println!("cargo:rerun-if-changed=src/embed/namespace.rs");
    let read = |f: &str| {
        let path = format!("shaders/{f}");
        println!("cargo:rerun-if-changed={path}");
        let source = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        File { path, source }
    };
    let files: Vec<Vec<File>> = MODULES.iter().map(|(_, fs)| fs.iter().map(|f| read(f)).collect()).collect();
    let owner = |import_path: &str| -> usize {
        files
            .iter()
            .position(|fs| fs.iter().any(|f| text::import_path(&f.source) == Some(import_path)))
            .unwrap_or_else(|| panic!("no embedded module holds the import path {import_path}"))
    };
    let n = MODULES.len();
    // the modules each imports from (by any name, `Real` included: the plain text needs its alias)
    let mut deps: Vec<Vec<usize>> = Vec::new();
    // the names it imports, by module, without `Real` (the naga_oil and WESL forms spell it f32)
    let mut items: Vec<Vec<(usize, Vec<String>)>> = Vec::new();
    for (m, fs) in files.iter().enumerate() {
        let mut d: Vec<usize> = Vec::new();
        let mut by_module: Vec<(usize, Vec<String>)> = Vec::new();
        for f in fs {
            for (path, names) in text::imports(&f.source) {
                let o = owner(path);
                if o == m {
                    continue;
                }
                assert!(o < m, "{} imports {path}, which comes later in MODULES", f.path);
                if !d.contains(&o) {
                    d.push(o);
                }
                let names: Vec<String> = names.into_iter().filter(|&i| i != "Real").map(str::to_string).collect();
                if names.is_empty() {
                    continue;
                }
                match by_module.iter_mut().find(|(k, _)| *k == o) {
                    Some((_, v)) => v.extend(names.into_iter().filter(|x| !v.contains(x)).collect::<Vec<_>>()),
                    None => by_module.push((o, names)),
                }
            }
        }
        d.sort();
        by_module.sort_by_key(|(k, _)| *k);
        deps.push(d);
        items.push(by_module);
    }
    let closure = |m: usize| -> Vec<usize> {
        let mut wanted = vec![false; n];
        let mut stack = vec![m];
        while let Some(k) = stack.pop() {
            if !std::mem::replace(&mut wanted[k], true) {
                stack.extend(&deps[k]);
            }
        }
        (0..n).filter(|&k| wanted[k]).collect()
    };
    let short_names: Vec<Vec<String>> = files
        .iter()
        .map(|fs| {
            let mut names: Vec<String> = fs.iter().flat_map(|f| text::declared(&f.source)).map(str::to_string).collect();
            names.sort();
            names.dedup();
            names
        })
        .collect();
    let version = std::env::var("CARGO_PKG_VERSION").unwrap();
    let mut out = String::from("// Generated by build.rs from shaders/lib and shaders/math: do not edit.\n");
    let list = |v: Vec<String>| format!("&[{}]", v.join(", "));
    let strs = |v: &[String]| list(v.iter().map(|s| format!("{s:?}")).collect());
    let array = |name: &str, ty: &str, v: Vec<String>| format!("pub(super) const {name}: [{ty}; {n}] = [\n    {},\n];\n", v.join(",\n    "));
    out += &array("NAMES", "&str", MODULES.iter().map(|(name, _)| format!("{name:?}")).collect());
    out += &array("DEPENDENCIES", "&[usize]", deps.iter().map(|d| list(d.iter().map(usize::to_string).collect())).collect());
    out += &array("FILES", "&[&str]", files.iter().map(|fs| strs(&fs.iter().map(|f| f.path.clone()).collect::<Vec<_>>())).collect());
    out += &array("SHORT_NAMES", "&[&str]", short_names.iter().map(|v| strs(v)).collect());
    out += &array("API", "&[&str]", API.iter().map(|v| strs(&v.iter().map(|s| s.to_string()).collect::<Vec<_>>())).collect());
    out += &array("SYMBOLS", "&[&str]", short_names.iter().map(|v| strs(&v.iter().map(|s| namespace::prefixed("lobes", s)).collect::<Vec<_>>())).collect());
    // plain WGSL: each file with its directive lines blanked, after a marker line (as the
    // engine's composition writes them), under its short names and with every name prefixed
    let short: Vec<String> = files.iter().map(|fs| fs.iter().map(|f| format!("// ---- {} ----\n{}\n", f.path, text::plain(&f.source))).collect()).collect();
    let prefixed: Vec<String> = (0..n)
        .map(|m| {
            let defined: Vec<&String> = closure(m).into_iter().flat_map(|k| &short_names[k]).collect();
            namespace::rename(&short[m], |t| defined.iter().any(|d| *d == t).then(|| namespace::prefixed("lobes", t)))
        })
        .collect();
    out += &array("SHORT_WGSL", "&str", short.iter().map(|s| format!("{s:?}")).collect());
    out += &array("WGSL", "&str", prefixed.iter().map(|s| format!("{s:?}")).collect());
    // naga_oil and WESL, in f32: per module the unit `lobes::NAME`, its API, and where it has
    // internal helpers the unit `lobes::NAME::internal` before it; each imports what its code uses
    for (m, names) in short_names.iter().enumerate() {
        for a in API[m] {
            assert!(names.iter().any(|n| n == a), "build.rs API: {} declares no {a}", MODULES[m].0);
        }
    }
    // where each module's files import a name from another module: name -> that module
    let imported: Vec<Vec<(String, usize)>> = items.iter().map(|by| by.iter().flat_map(|(k, names)| names.iter().map(|n| (n.clone(), *k))).collect()).collect();
    struct Unit {
        module: usize,
        internal: bool,
        code: String,
        names: Vec<String>,
    }
    let mut units: Vec<Unit> = Vec::new();
    for (m, fs) in files.iter().enumerate() {
        let (mut public, mut internal) = (Unit { module: m, internal: false, code: String::new(), names: Vec::new() }, Unit { module: m, internal: true, code: String::new(), names: Vec::new() });
        for f in fs {
            let (mut p, mut q, mut opening) = (String::new(), String::new(), String::new());
            for (name, chunk) in declarations(&text::in_f32(&f.source)) {
                match name {
                    None => opening = chunk,
                    Some(n) if API[m].contains(&n.as_str()) => {
                        p += &chunk;
                        public.names.push(n);
                    }
                    Some(n) => {
                        q += &chunk;
                        internal.names.push(n);
                    }
                }
            }
            // the file's opening comments go with its API, or with its helpers if it has no API
            let marker = format!("// ---- {} ----\n", f.path);
            if p.is_empty() {
                q = opening + &q;
            } else {
                public.code += &(marker.clone() + &opening + &p);
            }
            if !q.is_empty() {
                internal.code += &(marker + &q);
            }
        }
        if !internal.code.is_empty() {
            units.push(internal);
        }
        units.push(public);
    }
    let unit_of = |m: usize, name: &str| -> usize {
        let internal = !API[m].contains(&name);
        units.iter().position(|u| u.module == m && u.internal == internal).unwrap()
    };
    // per unit: the units it imports from, with the names
    let mut unit_imports: Vec<Vec<(usize, Vec<String>)>> = Vec::new();
    for u in &units {
        let used = identifiers(&u.code);
        let mut by_unit: Vec<(usize, Vec<String>)> = Vec::new();
        let mut add = |k: usize, n: &str| match by_unit.iter_mut().find(|(j, _)| *j == k) {
            Some((_, v)) => v.push(n.to_string()),
            None => by_unit.push((k, vec![n.to_string()])),
        };
        for (n, k) in &imported[u.module] {
            if used.contains(n) {
                add(unit_of(*k, n), n);
            }
        }
        for other in units.iter().filter(|o| o.module == u.module && o.internal != u.internal) {
            for n in other.names.iter().filter(|n| used.contains(*n)) {
                assert!(!u.internal, "{}: the internal helpers use {n}, which is its API: add their names to build.rs's API, or take {n} out of it", MODULES[u.module].0);
                add(unit_of(u.module, n), n);
            }
        }
        by_unit.sort_by_key(|(k, _)| *k);
        for (_, v) in &mut by_unit {
            v.sort();
            v.dedup();
        }
        unit_imports.push(by_unit);
    }
    let path = |u: &Unit| format!("{}{}", MODULES[u.module].0, if u.internal { "::internal" } else { "" });
    let header = |u: &Unit, form: &str| {
        let fs: Vec<&str> = files[u.module].iter().map(|f| f.path.as_str()).collect();
        let what = if u.internal {
            format!("{form}: the internal helpers of lobes::{}, not its API; they may change in any release", MODULES[u.module].0)
        } else {
            format!("{form}, lobes {version}")
        };
        format!("// lobes::{} ({what}), from {}; see docs/embedding.md.\n", path(u), fs.join(", "))
    };
    let mut table = String::from("pub(super) const UNITS: &[Unit] = &[\n");
    for (i, u) in units.iter().enumerate() {
        let mut naga_oil = format!("#define_import_path lobes::{}\n", path(u));
        // a unit's WESL file is lobes/NAME.wesl or lobes/NAME/internal.wesl: the package's root is
        // one or two levels up
        let up = if u.internal { "super::super" } else { "super" };
        let mut wesl = String::new();
        for (k, names) in &unit_imports[i] {
            assert!(*k < i, "unit {} imports a later one", path(u));
            writeln!(naga_oil, "#import lobes::{}::{{{}}}", path(&units[*k]), names.join(", ")).unwrap();
            writeln!(wesl, "import {up}::{}::{{{}}};", path(&units[*k]), names.join(", ")).unwrap();
        }
        naga_oil += &(header(u, "naga_oil module") + &u.code);
        wesl += &(header(u, "WESL module") + &u.code);
        let imports: Vec<String> = unit_imports[i].iter().map(|(k, _)| k.to_string()).collect();
        writeln!(
            table,
            "    Unit {{ module: {}, internal: {}, import_path: {:?}, naga_oil: {naga_oil:?}, wesl: {wesl:?}, imports: &[{}] }},",
            u.module,
            u.internal,
            format!("lobes::{}", path(u)),
            imports.join(", ")
        )
        .unwrap();
    }
    out += &(table + "];\n");
    // the WESL package for the `wesl` crate (feature wesl): module NAME with its submodule internal
    let mut package = String::from("// Generated by build.rs: lobes::embed::WESL_PACKAGE's modules.\n");
    let mut refs = Vec::new();
    for (m, (name, _)) in MODULES.iter().enumerate() {
        let public = units.iter().position(|u| u.module == m && !u.internal).unwrap();
        let submodules = match units.iter().position(|u| u.module == m && u.internal) {
            Some(i) => {
                writeln!(package, "static INTERNAL_{m}: CodegenModule = CodegenModule {{ name: \"internal\", source: UNITS[{i}].wesl, submodules: &[] }};").unwrap();
                format!("&[&INTERNAL_{m}]")
            }
            None => "&[]".into(),
        };
        writeln!(package, "static MODULE_{m}: CodegenModule = CodegenModule {{ name: {name:?}, source: UNITS[{public}].wesl, submodules: {submodules} }};").unwrap();
        refs.push(format!("&MODULE_{m}"));
    }
    writeln!(package, "static MODULES: [&CodegenModule; {n}] = [{}];", refs.join(", ")).unwrap();
    let dir = std::env::var("OUT_DIR").unwrap();
    std::fs::write(format!("{dir}/embed_generated.rs"), out).unwrap();
    std::fs::write(format!("{dir}/embed_wesl_package.rs"), package).unwrap();
}

/// A file's code cut before each module-scope declaration (with the comment lines right above
/// it): (the name it declares, its text), the file's opening lines first, with no name.
fn declarations(code: &str) -> Vec<(Option<String>, String)> {
    let lines: Vec<&str> = code.lines().collect();
    let mut starts: Vec<(usize, String)> = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if let Some(name) = text::declared(line).first() {
            let mut s = i;
            while s > 0 && lines[s - 1].starts_with("//") && starts.last().is_none_or(|(p, _)| *p < s - 1) {
                s -= 1;
            }
            starts.push((s, name.to_string()));
        }
    }
    let text = |a: usize, b: usize| lines[a..b].iter().map(|l| format!("{l}\n")).collect::<String>();
    let mut out = vec![(None, text(0, starts.first().map_or(lines.len(), |(s, _)| *s)))];
    for (j, (s, name)) in starts.iter().enumerate() {
        let end = starts.get(j + 1).map_or(lines.len(), |(e, _)| *e);
        out.push((Some(name.clone()), text(*s, end)));
    }
    out
}

/// The identifier tokens of WGSL code outside comments (`namespace::rename`'s reading).
fn identifiers(code: &str) -> Vec<String> {
    let found = std::cell::RefCell::new(Vec::new());
    namespace::rename(code, |t| {
        found.borrow_mut().push(t.to_string());
        None
    });
    let mut v = found.into_inner();
    v.sort();
    v.dedup();
    v
}
