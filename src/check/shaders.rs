//! `lobes check`'s own WGSL (`shaders/check`), handed to each composition of a user's sampler
//! beside the files made for it: the passes (`lobes::check`), the histogram's draw (`lobes::draw`) and the binning of each domain
//! (`lobes::domain`, the file [`Domain::binning_wgsl`] names). The engine's library holds
//! `lobes run`'s files only.

use super::Domain;
use crate::engine::gpu::library::{File, shader};

/// The passes: probes, quadrature, weights (`shaders/check/user_passes.wgsl`).
pub(super) const PASSES: File = shader!("check/user_passes.wgsl");

/// The histogram's draw of a user's sampler (`lobes::draw`, `shaders/check/user_draw.wgsl`), in
/// the place of a lobe's in `lobes run`'s counting kernel.
pub(super) const DRAW: File = shader!("check/user_draw.wgsl");

/// `lobes::domain` of every domain.
const DOMAINS: [File; 5] = [
    shader!("check/domain_sphere.wgsl"),
    shader!("check/domain_plane.wgsl"),
    shader!("check/domain_cap.wgsl"),
    shader!("check/domain_latlong.wgsl"),
    shader!("check/domain_equal_area.wgsl"),
];

/// `lobes::domain` of `domain`: where its points lie and which bin each falls in.
pub(super) fn domain_file(domain: Domain) -> File {
    DOMAINS.into_iter().find(|f| f.path == domain.binning_wgsl()).expect("DOMAINS holds every domain's binning_wgsl")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each domain's binning is a file here, and each file is one domain's `lobes::domain`.
    #[test]
    fn every_domain_has_its_binning_file() {
        let domains = [Domain::Sphere, Domain::Plane { bounds: [0.0, 0.0, 1.0, 1.0] }, Domain::cap([0.0, 0.0, 1.0], 0.5).unwrap(), Domain::LatLong, Domain::EqualArea];
        for d in domains {
            assert_eq!(domain_file(d).import_path(), Some("lobes::domain"), "{}", d.binning_wgsl());
        }
        let mut paths: Vec<_> = domains.iter().map(|d| d.binning_wgsl()).collect();
        paths.dedup();
        assert_eq!(paths.len(), DOMAINS.len(), "one file per domain");
    }
}
