//! One probe of a sampler's map u → d: the sample at u, the samples a small step away along u.x
//! and u.y, which of u.z and u.w move d, and the pdf function at d. The probe pass
//! (`lobes_probe` in `shaders/check/user_passes.wgsl`) writes [`Probe`] as its WGSL twin
//! `LobesProbe`, whose layout a test holds to this one; the Jacobian (`jacobian.rs`), the hard
//! cases (`hard.rs`) and `pdf_consistency` read it.

use bytemuck::{Pod, Zeroable};

/// One probed sample and the map around it (`LobesProbe` in WGSL).
#[repr(C, align(16))]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Probe {
    /// sample(u): (d, the pdf the sampler reported).
    pub sample: [f32; 4],
    /// sample(u ± ε along u.x), then along u.y: +x, −x, +y, −y, each (d, reported pdf).
    pub neighbours: [[f32; 4]; 4],
    /// The share of u.z's and of u.w's range over which d stays put: 1 unused, < 0 where d
    /// moves with it (`lobes_share`).
    pub share_z: f32,
    pub share_w: f32,
    /// The pdf function at the sample's d.
    pub pdf: f32,
    /// The eval function at the sample's d (0 without one).
    pub eval: f32,
    /// |d| of the sample, in f32 as the GPU computed it.
    pub length: f32,
    pub _pad: [f32; 3],
}

impl Probe {
    /// The sampled point d.
    pub fn d(&self) -> [f32; 3] {
        [self.sample[0], self.sample[1], self.sample[2]]
    }

    /// The pdf the sampler reported with its sample.
    pub fn reported_pdf(&self) -> f32 {
        self.sample[3]
    }

    /// Whether the sample is one the contract calls valid: a finite d with a reported pdf
    /// finite and > 0.
    pub fn valid(&self) -> bool {
        self.reported_pdf() > 0.0 && self.reported_pdf().is_finite() && self.d().iter().all(|x| x.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    /// `Probe` has the layout of `LobesProbe` (naga's layouter, WGSL's rules).
    #[test]
    fn probe_layout() {
        let members = [
            ("sample", offset_of!(Probe, sample)),
            ("neighbours", offset_of!(Probe, neighbours)),
            ("share_z", offset_of!(Probe, share_z)),
            ("share_w", offset_of!(Probe, share_w)),
            ("pdf", offset_of!(Probe, pdf)),
            ("eval", offset_of!(Probe, eval)),
            ("length", offset_of!(Probe, length)),
            ("_pad", offset_of!(Probe, _pad)),
        ];
        let source = include_str!("../../shaders/check/user_passes.wgsl");
        let start = source.find("struct LobesProbe {").expect("user_passes.wgsl declares LobesProbe");
        let end = start + source[start..].find("\n}\n").expect("the struct ends") + 3;
        crate::engine::gpu::layout::check_struct(&source[start..end], "LobesProbe", size_of::<Probe>(), align_of::<Probe>(), &members).unwrap();
    }
}
