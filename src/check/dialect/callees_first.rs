//! A translated module's functions put callees first, as naga's validator requires of its
//! function arena (a function may call only functions before it).
//!
//! GLSL declares a function before its definition with a prototype (`vec3 Eval(State s);`, so
//! that a function defined earlier can call it); naga's GLSL front end gives the function its
//! handle at the prototype, before the functions its body calls once it is defined, and its
//! validator then refuses the module ("depends on [29] … which has not been processed yet").
//! The order of definitions means nothing to WGSL, so the arena is rebuilt in a depth-first
//! order of the call graph, every handle remapped.

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
    // new index of the function at each old index
    let mut new_of = vec![0; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_of[old] = new;
    }
    let handles: Vec<Handle<Function>> = module.functions.iter().map(|(h, _)| h).collect();
    let remap = |h: Handle<Function>| handles[new_of[h.index()]];
    let old: Vec<(Function, naga::Span)> = module.functions.iter().map(|(h, f)| (f.clone(), module.functions.get_span(h))).collect();
    let mut arena = naga::Arena::new();
    for &i in &order {
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

    #[test]
    fn a_cycle_has_no_order() {
        assert_eq!(depth_first(&[vec![1], vec![0]]), None);
        assert_eq!(depth_first(&[vec![2], vec![], vec![1]]), Some(vec![1, 2, 0]));
    }
}
