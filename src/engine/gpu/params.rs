//! The uniform block every pass reads (`LobesParams` in `shaders/passes/params.wgsl`, bound at
//! `binding::PARAMS`): `lobes run`'s sampling kernels (the counting and the weighted layouts) and `lobes
//! check`'s passes, and the layout entries those share.

use super::layout::binding;
use crate::engine::job::{Job, SampleRange};
use bytemuck::{Pod, Zeroable};

/// The passes' uniform block (`LobesParams` in `shaders/passes/params.wgsl`; `tests::params_layout`
/// checks the two layouts agree). A pass reads the fields of its job; the others stay 0.
#[repr(C, align(16))]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct Params {
    pub seed: [u32; 2],
    /// The index of the dispatch's first sample, (lo, hi).
    pub base: [u32; 2],
    pub count: u32,
    /// A discrete job's items and the last of them with a positive weight.
    pub n_items: u32,
    pub last_positive: u32,
    /// First bin of the tile being counted (see [`super::GpuEngine::tiling`]; 0 when untiled).
    pub tile_first: u32,
    /// A built-in lobe's α.
    pub alpha: [f32; 2],
    /// (cos, sin) of the lobe's frame angle (rotated anisotropy, `lobe_frame()` of the kernels).
    pub frame: [f32; 2],
    /// ωi in xyz, a dielectric's η in w (0 for a reflection).
    pub wi: [f32; 4],
    /// A user's sampler's 16 numbers (`lobes check --params`), zero-padded.
    pub user: [[f32; 4]; 4],
    /// A plane domain's box (x0, y0, x1, y1); unused on the sphere.
    pub bounds: [f32; 4],
    /// The finite-difference step of `lobes check`'s probe pass.
    pub eps: f32,
    /// The samples each invocation of `lobes check`'s weights pass draws.
    pub samples_per_thread: u32,
    /// `lobes check`'s histogram grid (its binning reads it; the counting kernel's are
    /// constants).
    pub rows: u32,
    pub cols: u32,
}

impl Params {
    /// The parameters of one dispatch over `range` (at most 2^32 − 1 samples) of `job`.
    pub fn new(job: &Job, range: SampleRange) -> Self {
        let count = u32::try_from(range.count).expect("one dispatch draws fewer than 2^32 samples");
        let mut p = Params {
            seed: [range.seed as u32, (range.seed >> 32) as u32],
            base: [range.first as u32, (range.first >> 32) as u32],
            count,
            frame: [1.0, 0.0],
            ..Zeroable::zeroed()
        };
        match job {
            Job::Lobe { lobe, incident, scatter, .. } => {
                let frame = lobe.frame();
                p.alpha = [lobe.alpha_x as f32, lobe.alpha_y as f32];
                p.frame = [frame.cos as f32, frame.sin as f32];
                p.wi = [incident.x as f32, incident.y as f32, incident.z as f32, scatter.eta() as f32];
            }
            Job::Discrete { dist, .. } => {
                p.n_items = dist.len() as u32;
                p.last_positive = dist.pmf().iter().rposition(|&x| x > 0.0).unwrap_or(0) as u32;
            }
        }
        p
    }

    /// A user's sampler's numbers (at most 16) as the WGSL reads them, `params[i / 4][i % 4]`,
    /// rounded to f32 and zero-padded.
    pub fn user_numbers(numbers: &[f64]) -> [[f32; 4]; 4] {
        let mut user = [[0f32; 4]; 4];
        for (i, x) in numbers.iter().enumerate() {
            user[i / 4][i % 4] = *x as f32;
        }
        user
    }

    /// As `self`, counting the tile of bins from `first` on.
    pub fn tile(self, first: u32) -> Self {
        Self { tile_first: first, ..self }
    }

    /// [`binding::PARAMS`]: the parameters, at a dynamic offset per dispatch.
    pub fn layout_entry() -> wgpu::BindGroupLayoutEntry {
        wgpu::BindGroupLayoutEntry {
            binding: binding::PARAMS,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
            },
            count: None,
        }
    }

    /// [`binding::PARAMS`] bound to one `Params` of `buffer` (the dispatch picks which by its
    /// offset).
    pub fn bind_entry(buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding: binding::PARAMS,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer,
                offset: 0,
                size: wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64),
            }),
        }
    }
}

/// One element of the per-sample passes' input (`ExplicitInput` in
/// `shaders/passes/lobe_kernel.wgsl`, at `binding::INPUT`; `tests::explicit_input_layout` checks the two
/// layouts agree): a sample's uniforms u.xyz (`explicit_samples`: u.xy draw h, u.z a dielectric's
/// event) or a direction (`bin_explicit`).
#[repr(C, align(16))]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ExplicitInput {
    pub xyz: [f32; 3],
    unused: f32,
}

impl ExplicitInput {
    pub fn new(xyz: [f32; 3]) -> Self {
        Self { xyz, unused: 0.0 }
    }
}

/// A compute storage buffer entry at `binding`.
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::job::DiscreteMethod;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn params_layout() {
        let members = [
            ("seed", offset_of!(Params, seed)),
            ("base", offset_of!(Params, base)),
            ("count", offset_of!(Params, count)),
            ("n_items", offset_of!(Params, n_items)),
            ("last_positive", offset_of!(Params, last_positive)),
            ("tile_first", offset_of!(Params, tile_first)),
            ("alpha", offset_of!(Params, alpha)),
            ("frame", offset_of!(Params, frame)),
            ("wi", offset_of!(Params, wi)),
            ("user", offset_of!(Params, user)),
            ("bounds", offset_of!(Params, bounds)),
            ("eps", offset_of!(Params, eps)),
            ("samples_per_thread", offset_of!(Params, samples_per_thread)),
            ("rows", offset_of!(Params, rows)),
            ("cols", offset_of!(Params, cols)),
        ];
        let dist = crate::reference::discrete::Distribution::new(&[1.0, 2.0]).unwrap();
        let source = super::super::compose::compose(&Job::Discrete { dist, method: DiscreteMethod::Alias }, 4096);
        super::super::layout::check_struct(&source, "LobesParams", size_of::<Params>(), align_of::<Params>(), &members).unwrap();
    }

    #[test]
    fn explicit_input_layout() {
        use crate::reference::{Lobe, LobeKind, Method};
        let lobe = Lobe { kind: LobeKind::Ggx, method: Method::Vndf, alpha_x: 0.3, alpha_y: 0.3, alpha_angle: 0.0 };
        let grid = crate::stats::histogram::SphereGrid { rows: 2, cols: 1 };
        let job = Job::Lobe { lobe, incident: glam::DVec3::Z, grid, scatter: crate::engine::job::Scatter::Reflect };
        let source = super::super::compose::compose(&job, 4096);
        let members = [("xyz", offset_of!(ExplicitInput, xyz)), ("unused", offset_of!(ExplicitInput, unused))];
        super::super::layout::check_struct(&source, "ExplicitInput", size_of::<ExplicitInput>(), align_of::<ExplicitInput>(), &members).unwrap();
    }
}
