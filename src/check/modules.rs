//! A user's sampler as it is in its repository, composed the way the renderer composes it into
//! the WGSL that lobes' glue (`glue::glue`) calls: the front end of the files' dialect
//! ([`super::dialect`]) composes them, and the trees composed are kept (`compose_user`).
//!
//! A composed tree becomes one WGSL text: the naga module of the tree and the glue, compacted to
//! what the glue's calls reach (so a module's bind groups, ray queries or other entry points need
//! not suit lobes' passes), written back by naga's WGSL writer. Errors in the user's modules are
//! the composer's, at the module's file:line:column; an import that no root holds names the
//! module, the roots searched and the closest module names.

use super::CheckError;
use super::compose::Source;
use super::composition::{Call, Composition, Dialect, UserCode};
use super::dialect::roots::{roots, scan, show_roots};
use super::dialect::sniff;
use super::dialect::stage::Stage;
use std::path::PathBuf;

pub use super::dialect::stage::composing;

impl UserCode {
    /// `expr` (the sample's, pdf's or eval's call expression, `call`) with each name as the user's
    /// files name it (WESL's `ggx::pdf` or `package::sampling::ggx::pdf`, naga_oil's `ggx::pdf`
    /// or an `#import … as` alias's `alias::pdf`, a GLSL function WGSL cannot spell) replaced by
    /// that item's name in the composed text, as the dialect's front end reads it. A name no
    /// imported module holds is an error naming the imported items.
    pub fn resolve_qualified(&self, call: Call, expr: &str, root_text: &str) -> Result<String, CheckError> {
        self.dialect.front_end().call(self, call, expr, root_text)
    }
}

/// What a composed tree was made from: the files given, the composition, and each file under
/// the roots and each stub by its path, size and modification time.
type TreeKey = (Vec<Source>, Composition, Vec<(PathBuf, u64, Option<std::time::SystemTime>)>);

/// The trees this process composed (a check composes its sampler's tree for validation, for
/// each --rand order probed and for the passes; a run composes each case's): naga_oil's
/// composer is superlinear in a tree's depth (each module's header holds its imports' imports),
/// so a tree is composed once per process, and again only when a file under its roots changed.
static TREES: std::sync::Mutex<Vec<(TreeKey, UserCode)>> = std::sync::Mutex::new(Vec::new());

/// The trees kept: a run's cases share a few.
const TREES_KEPT: usize = 8;

fn tree_key(sources: &[Source], c: &Composition) -> TreeKey {
    let mut files = Vec::new();
    for r in roots(sources, c) {
        scan(&r, &["wgsl", "wesl"], &mut files);
    }
    for (_, dir) in &c.packages {
        scan(dir, &["wgsl", "wesl"], &mut files);
    }
    files.extend(c.stubs.iter().map(|(_, f)| f.clone()));
    let stamp = files
        .into_iter()
        .map(|f| {
            let m = std::fs::metadata(&f).ok();
            let len = m.as_ref().map_or(0, std::fs::Metadata::len);
            let modified = m.and_then(|m| m.modified().ok());
            (f, len, modified)
        })
        .collect();
    (sources.to_vec(), c.clone(), stamp)
}

/// The user's files composed as their dialect composes them (a tree composed before in this
/// process, from the same files, is taken from [`TREES`]).
pub(super) fn compose_user(sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
    if sources.is_empty() || (sniff(sources) == Dialect::Wgsl && c.defines.is_empty()) {
        return compose_anew(sources, c);
    }
    let _stage = Stage::enter(format!("reading {} and the modules it imports under the shader roots ({}), and composing them", sources[0].name, show_roots(&roots(sources, c))));
    let key = tree_key(sources, c);
    let kept = TREES.lock().unwrap_or_else(|p| p.into_inner()).iter().find(|(k, _)| *k == key).map(|(_, code)| code.clone());
    if let Some(code) = kept {
        return Ok(code);
    }
    // on a large stack: naga_oil recurses once per module along a chain of imports
    let code = crate::engine::gpu::stack::with_big_stack(|| compose_anew(sources, c))?;
    let mut trees = TREES.lock().unwrap_or_else(|p| p.into_inner());
    if trees.len() >= TREES_KEPT {
        trees.remove(0);
    }
    trees.push((key, code.clone()));
    Ok(code)
}

/// The user's files composed by the front end of their dialect.
fn compose_anew(sources: &[Source], c: &Composition) -> Result<UserCode, CheckError> {
    if sources.is_empty() {
        return Err(CheckError::Input("no WGSL file given: name at least one file that defines the sampler".into()));
    }
    c.validate()?;
    sniff(sources).front_end().compose(sources, c)
}
