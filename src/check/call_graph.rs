//! The call graph of a user's module, for what naga itself cannot do with it: a translated
//! module's functions put callees first, as naga's validator requires of its function arena (a
//! function may call only functions before it), and a composed tree cut to what naga's WGSL
//! writer can write.
//!
//! GLSL declares a function before its definition with a prototype (`vec3 Eval(State s);`, so
//! that a function defined earlier can call it); naga's GLSL front end gives the function its
//! handle at the prototype, before the functions its body calls once it is defined, and its
//! validator then refuses the module ("depends on [29] … which has not been processed yet").
//! The order of definitions means nothing to WGSL, so the arena is rebuilt in a depth-first
//! order of the call graph, every handle remapped. The same rebuilding leaves out what naga's
//! WGSL writer cannot write ([`drop_ray_queries`]).

use naga::{Block, Expression, Function, Handle, Module, Statement};

/// Reorders `module.functions` so that each function's callees come before it. A call graph
/// with a cycle (recursion, which neither GLSL nor WGSL allows) is left as it is, for the
/// validator to report.
pub(super) fn callees_first(module: &mut Module) {
    let callees: Vec<Vec<usize>> = module.functions.iter().map(|(_, f)| calls(&f.body).iter().map(|h| h.index()).collect()).collect();
    let Some(order) = depth_first(&callees) else { return };
    if order.iter().enumerate().all(|(i, &old)| i == old) {
        return;
    }
    rebuild(module, &order);
}

/// The functions that use ray queries (naga 30's WGSL writer cannot write them: it panics,
/// "entered unreachable code") and every function and entry point that calls one, left out of
/// `module`; their names. A renderer's tree holds them beside its samplers (Bevy Solari's
/// `scene_bindings` traces shadow rays); a sampler cannot reach them in lobes' compute passes,
/// which have no acceleration structure to trace.
pub(super) fn drop_ray_queries(module: &mut Module) -> Vec<String> {
    let uses = uses_ray_queries;
    let callees: Vec<Vec<usize>> = module.functions.iter().map(|(_, f)| calls(&f.body).iter().map(|h| h.index()).collect()).collect();
    let mut dropped: Vec<bool> = module.functions.iter().map(|(_, f)| uses(f)).collect();
    // callers of a dropped function, until none is added
    while let Some(i) = (0..dropped.len()).find(|&i| !dropped[i] && callees[i].iter().any(|&c| dropped[c])) {
        dropped[i] = true;
    }
    if !dropped.contains(&true) {
        return Vec::new();
    }
    let names = module.functions.iter().filter(|(h, _)| dropped[h.index()]).map(|(_, f)| f.name.clone().unwrap_or_default()).collect();
    module.entry_points.retain(|e| !uses(&e.function) && !calls(&e.function.body).iter().any(|h| dropped[h.index()]));
    let kept: Vec<usize> = (0..dropped.len()).filter(|&i| !dropped[i]).collect();
    rebuild(module, &kept);
    names
}

/// Whether a function or entry point of `module` uses ray queries ([`drop_ray_queries`]).
pub(super) fn needs_cut(module: &Module) -> bool {
    module.functions.iter().any(|(_, f)| uses_ray_queries(f)) || module.entry_points.iter().any(|e| uses_ray_queries(&e.function))
}

/// Whether `f` itself (not its callees) uses a ray query.
fn uses_ray_queries(f: &Function) -> bool {
    let mut found = f.expressions.iter().any(|(_, e)| matches!(e, Expression::RayQueryGetIntersection { .. } | Expression::RayQueryVertexPositions { .. } | Expression::RayQueryProceedResult));
    for_each_block(&f.body, &mut |s| found |= matches!(s, Statement::RayQuery { .. }));
    found
}

/// `module.functions` rebuilt from the functions at the old indices `order`, in that order
/// (those left out are called by none kept), every call remapped.
fn rebuild(module: &mut Module, order: &[usize]) {
    // new index of the function at each old index kept
    let mut new_of = vec![usize::MAX; module.functions.len()];
    for (new, &old) in order.iter().enumerate() {
        new_of[old] = new;
    }
    let handles: Vec<Handle<Function>> = module.functions.iter().map(|(h, _)| h).collect();
    let remap = |h: Handle<Function>| handles[new_of[h.index()]];
    let old: Vec<(Function, naga::Span)> = module.functions.iter().map(|(h, f)| (f.clone(), module.functions.get_span(h))).collect();
    let mut arena = naga::Arena::new();
    for &i in order {
        let (mut f, span) = old[i].clone();
        remap_function(&mut f, &remap);
        arena.append(f, span);
    }
    module.functions = arena;
    for e in &mut module.entry_points {
        remap_function(&mut e.function, &remap);
    }
}

/// The functions `block` calls, its nested blocks included.
fn calls(block: &Block) -> Vec<Handle<Function>> {
    let mut out = Vec::new();
    for_each_block(block, &mut |s| {
        if let Statement::Call { function, .. } = s {
            out.push(*function);
        }
    });
    out
}

/// `f` on every statement of `block` and of the blocks nested in it.
fn for_each_block(block: &Block, f: &mut impl FnMut(&Statement)) {
    for s in block.iter() {
        f(s);
        match s {
            Statement::Block(b) => for_each_block(b, f),
            Statement::If { accept, reject, .. } => {
                for_each_block(accept, f);
                for_each_block(reject, f);
            }
            Statement::Loop { body, continuing, .. } => {
                for_each_block(body, f);
                for_each_block(continuing, f);
            }
            Statement::Switch { cases, .. } => cases.iter().for_each(|c| for_each_block(&c.body, f)),
            _ => {}
        }
    }
}

/// Function indices in post-order of the call graph (callees first), the arena's order kept
/// among functions that do not call each other; `None` where the graph has a cycle.
fn depth_first(callees: &[Vec<usize>]) -> Option<Vec<usize>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    fn visit(i: usize, callees: &[Vec<usize>], marks: &mut [Mark], order: &mut Vec<usize>) -> bool {
        match marks[i] {
            Mark::Done => return true,
            Mark::Open => return false,
            Mark::New => {}
        }
        marks[i] = Mark::Open;
        if !callees[i].iter().all(|&c| visit(c, callees, marks, order)) {
            return false;
        }
        marks[i] = Mark::Done;
        order.push(i);
        true
    }
    let mut marks = vec![Mark::New; callees.len()];
    let mut order = Vec::with_capacity(callees.len());
    (0..callees.len()).all(|i| visit(i, callees, &mut marks, &mut order)).then_some(order)
}

/// Every function handle in `f` (its call statements and call results) through `remap`.
fn remap_function(f: &mut Function, remap: &impl Fn(Handle<Function>) -> Handle<Function>) {
    for (_, e) in f.expressions.iter_mut() {
        if let Expression::CallResult(h) = e {
            *h = remap(*h);
        }
    }
    remap_block(&mut f.body, remap);
}

fn remap_block(block: &mut Block, remap: &impl Fn(Handle<Function>) -> Handle<Function>) {
    for s in block.iter_mut() {
        match s {
            Statement::Call { function, .. } => *function = remap(*function),
            Statement::Block(b) => remap_block(b, remap),
            Statement::If { accept, reject, .. } => {
                remap_block(accept, remap);
                remap_block(reject, remap);
            }
            Statement::Loop { body, continuing, .. } => {
                remap_block(body, remap);
                remap_block(continuing, remap);
            }
            Statement::Switch { cases, .. } => cases.iter_mut().for_each(|c| remap_block(&mut c.body, remap)),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Module {
        naga::front::glsl::Frontend::default().parse(&naga::front::glsl::Options::from(naga::ShaderStage::Compute), text).unwrap_or_else(|e| panic!("{e:?}"))
    }

    fn validate(m: &Module) -> Result<(), String> {
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(m).map(|_| ()).map_err(|e| format!("{e:?}"))
    }

    /// A prototype declares `eval` before `helper`, which `eval`'s body calls: naga's validator
    /// refuses the arena as parsed and takes it reordered, with every call still reaching the
    /// function it named.
    #[test]
    fn a_prototype_no_longer_puts_a_caller_first() {
        let text = "#version 450\nfloat eval(float x);\nfloat helper(float x) { return x * 2.0; }\nfloat draw(float x) { return eval(x) + 1.0; }\nfloat eval(float x) { return helper(x) + helper(x + 1.0); }\nvoid main() { float y = draw(0.5); }\n";
        let mut m = parse(text);
        assert!(validate(&m).is_err(), "naga's GLSL front end now orders prototypes itself: this module is no longer needed");
        callees_first(&mut m);
        validate(&m).unwrap();
        let names: Vec<&str> = m.functions.iter().map(|(_, f)| f.name.as_deref().unwrap()).collect();
        let at = |n: &str| names.iter().position(|x| *x == n).unwrap();
        assert!(at("helper") < at("eval") && at("eval") < at("draw"), "{names:?}");
        let called: Vec<&str> = calls(&m.functions.iter().find(|(_, f)| f.name.as_deref() == Some("eval")).unwrap().1.body).iter().map(|h| m.functions[*h].name.as_deref().unwrap()).collect();
        assert_eq!(called, ["helper", "helper"]);
    }

    /// A tree with a shadow-ray function (a ray query) and its caller beside a sampler: naga's
    /// WGSL writer panics on the query; both are left out and the rest is written.
    #[test]
    fn ray_queries_and_their_callers_are_left_out_of_the_written_tree() {
        let text = "enable wgpu_ray_query;\n\
            @group(0) @binding(0) var tlas: acceleration_structure;\n\
            fn visible(o: vec3<f32>, d: vec3<f32>) -> bool { var q: ray_query; rayQueryInitialize(&q, tlas, RayDesc(0u, 0xFFu, 0.001, 10.0, o, d)); rayQueryProceed(&q); return rayQueryGetCommittedIntersection(&q).kind == RAY_QUERY_INTERSECTION_NONE; }\n\
            fn shade(o: vec3<f32>) -> f32 { return select(0.0, 1.0, visible(o, vec3(0.0, 0.0, 1.0))); }\n\
            fn cosine(u: vec2<f32>) -> vec3<f32> { let r = sqrt(u.x); return vec3(r * cos(6.2831853 * u.y), r * sin(6.2831853 * u.y), sqrt(1.0 - u.x)); }\n";
        let mut m = naga::front::wgsl::parse_str(text).unwrap_or_else(|e| panic!("{}", e.emit_to_string(text)));
        assert!(needs_cut(&m));
        assert_eq!(drop_ray_queries(&mut m), ["visible", "shade"]);
        assert!(!needs_cut(&m));
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all()).validate(&m).unwrap();
        let written = naga::back::wgsl::write_string(&m, &info, naga::back::wgsl::WriterFlags::empty()).unwrap();
        assert!(written.contains("fn cosine(") && !written.contains("fn shade("), "{written}");
    }

    #[test]
    fn a_cycle_has_no_order() {
        assert_eq!(depth_first(&[vec![1], vec![0]]), None);
        assert_eq!(depth_first(&[vec![2], vec![], vec![1]]), Some(vec![1, 2, 0]));
    }
}
