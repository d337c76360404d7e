//! The driver's compiled pipelines kept between processes: wgpu's [`wgpu::PipelineCache`]
//! (Vulkan's VkPipelineCache), where the adapter has [`wgpu::Features::PIPELINE_CACHE`], loaded
//! when the device opens and saved when it closes.
//!
//! The file is `$XDG_CACHE_HOME/lobes/` (else `~/.cache/lobes/`) named by
//! [`wgpu::util::pipeline_cache_key`] (backend, vendor, device) and a hash of the driver's
//! name and version, so that two drivers of one device (Mesa 22.3.6 and 25.0.7's lavapipe) keep
//! a file each. Its content is `MAGIC`, the CRC-32 of the data and wgpu's data; a file that is
//! not that (cut short, altered, another program's) is ignored, and wgpu in turn ignores data
//! from another adapter, driver or wgpu version (`fallback: true`). It is written atomically
//! ([`crate::atomic`]), only when the data changed. `LOBES_PIPELINE_CACHE=off` turns
//! it off.

use std::path::{Path, PathBuf};

/// The environment variable that turns the cache off (`off`, `0` or `false`).
pub const DISABLE_VAR: &str = "LOBES_PIPELINE_CACHE";

const MAGIC: &[u8; 16] = b"lobes-pipelines1";

/// A pipeline cache and the file it is saved to.
pub struct DiskCache {
    pub cache: wgpu::PipelineCache,
    path: PathBuf,
    /// The data as loaded (empty if none), to skip a write that would change nothing.
    loaded: Vec<u8>,
}

/// Whether `LOBES_PIPELINE_CACHE` asks for no cache.
pub fn disabled() -> bool {
    std::env::var(DISABLE_VAR).is_ok_and(|v| matches!(v.trim().to_ascii_lowercase().as_str(), "off" | "0" | "false" | "no"))
}

/// The folder of lobes' caches: `$XDG_CACHE_HOME/lobes` (an absolute path, per the XDG Base
/// Directory specification), else `$HOME/.cache/lobes`; None without either.
pub fn folder() -> Option<PathBuf> {
    let xdg = std::env::var_os("XDG_CACHE_HOME").map(PathBuf::from).filter(|p| p.is_absolute());
    let base = xdg.or_else(|| std::env::var_os("HOME").filter(|h| !h.is_empty()).map(|h| Path::new(&h).join(".cache")))?;
    Some(base.join("lobes"))
}

/// The cache file of an adapter in `folder`; None where wgpu keeps no pipeline cache for its
/// backend.
pub fn file(folder: &Path, info: &wgpu::AdapterInfo) -> Option<PathBuf> {
    let key = wgpu::util::pipeline_cache_key(info)?;
    let driver = crc32fast::hash(format!("{}\n{}", info.driver, info.driver_info).as_bytes());
    Some(folder.join(format!("{key}_{driver:08x}.bin")))
}

/// wgpu's data wrapped for the file: `MAGIC`, CRC-32 (little-endian), data.
pub fn encode(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(MAGIC.len() + 4 + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
    out.extend_from_slice(data);
    out
}

/// The data of a file [`encode`] wrote; None for anything else.
pub fn decode(file: &[u8]) -> Option<&[u8]> {
    let rest = file.strip_prefix(MAGIC.as_slice())?;
    let (crc, data) = rest.split_first_chunk::<4>()?;
    (crc32fast::hash(data) == u32::from_le_bytes(*crc)).then_some(data)
}

impl DiskCache {
    /// The cache of `device` (which must have PIPELINE_CACHE), seeded from its file where that
    /// holds valid data.
    pub fn open(device: &wgpu::Device, path: PathBuf) -> Self {
        let bytes = std::fs::read(&path).unwrap_or_default();
        let data = decode(&bytes).filter(|d| !d.is_empty());
        // SAFETY: `data` is what `PipelineCache::get_data` returned to an earlier process
        // (`save`), unchanged: its CRC-32 matches. wgpu checks that it came from this adapter,
        // driver and wgpu version, and with `fallback` starts empty where it did not.
        let cache = unsafe { device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor { label: Some("lobes"), data, fallback: true }) };
        let loaded = data.map(<[u8]>::to_vec).unwrap_or_default();
        Self { cache, path, loaded }
    }

    /// Writes the cache's data to its file if it changed.
    pub fn save(&self) -> std::io::Result<()> {
        let Some(data) = self.cache.get_data() else { return Ok(()) };
        if data.is_empty() || data == self.loaded {
            return Ok(());
        }
        if let Some(folder) = self.path.parent() {
            std::fs::create_dir_all(folder)?;
        }
        crate::atomic::write_atomic(&self.path, &encode(&data))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_what_encode_wrote_decodes() {
        let data = b"driver data".to_vec();
        let file = encode(&data);
        assert_eq!(decode(&file), Some(data.as_slice()));
        let mut flipped = file.clone();
        *flipped.last_mut().unwrap() ^= 1;
        assert_eq!(decode(&flipped), None, "an altered byte");
        assert_eq!(decode(&file[..file.len() - 1]), None, "cut short");
        assert_eq!(decode(&file[..10]), None, "shorter than the header");
        assert_eq!(decode(b""), None);
        assert_eq!(decode(&data), None, "another program's file");
    }

    #[test]
    fn one_file_per_driver() {
        let info = |driver_info: &str| wgpu::AdapterInfo {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            vendor: 0x10005,
            device: 0,
            device_type: wgpu::DeviceType::Cpu,
            device_pci_bus_id: String::new(),
            driver: "llvmpipe".into(),
            driver_info: driver_info.into(),
            backend: wgpu::Backend::Vulkan,
            subgroup_min_size: 8,
            subgroup_max_size: 8,
            transient_saves_memory: None,
            limit_bucket: None,
        };
        let dir = Path::new("/c");
        let old = file(dir, &info("Mesa 22.3.6 (LLVM 15.0.6)")).unwrap();
        let new = file(dir, &info("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)")).unwrap();
        assert_ne!(old, new);
        assert!(old.starts_with(dir) && old.to_string_lossy().contains("vulkan"), "{}", old.display());
        let gl = wgpu::AdapterInfo { backend: wgpu::Backend::Gl, ..info("Mesa 22.3.6") };
        assert_eq!(file(dir, &gl), None, "wgpu caches Vulkan pipelines only");
    }
}
