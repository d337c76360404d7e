//! Adapter and device: the one place that talks to wgpu's instance, and where the device's
//! errors are collected.

#[cfg(feature = "check")]
use super::pipeline_cache::{self, DiskCache};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Why no GPU could be used.
#[derive(Debug, Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found ({0}). On Debian/Ubuntu install Mesa's software Vulkan driver: \
         `apt-get install mesa-vulkan-drivers libvulkan1` (lavapipe), or a vendor driver"
    )]
    NoAdapter(String),
    /// `WGPU_BACKEND` set to names wgpu does not know (it would then try no backend at all).
    #[error("WGPU_BACKEND='{value}' is not a list of wgpu backends (unknown: {unknown}); set it to a comma-separated list of vulkan, metal, dx12, gl (or unset it: lobes then tries Vulkan, Metal and DX12)")]
    UnknownBackend { value: String, unknown: String },
    /// No adapter of the backends `WGPU_BACKEND` asks for.
    #[error("no GPU adapter of WGPU_BACKEND='{value}' found ({reason}); unset WGPU_BACKEND to try the default backends (Vulkan, Metal, DX12), or install a driver for the one it names")]
    NoAdapterOfBackend { value: String, reason: String },
    #[error("WGPU_ADAPTER_NAME='{wanted}' matches no adapter; the adapters here are: {found}. Set it to part of one of these names (case does not matter), or unset it")]
    AdapterNotNamed { wanted: String, found: String },
    #[error("the adapter '{adapter}' refused a device: {source}")]
    Device { adapter: String, source: wgpu::RequestDeviceError },
    #[error("shader for {what} failed naga validation: {message}")]
    Shader { what: String, message: String },
    #[error("GPU readback failed: {0}")]
    Readback(String),
    #[error("the GPU device was lost or ran out of memory: {0}")]
    Lost(String),
    /// A wait passed its deadline ([`Bounds`]); the device still runs the
    /// work and is abandoned.
    #[error("no result within {seconds} s (the time limit): the GPU was still running {pass}")]
    TimedOut { seconds: f64, pass: String },
    /// A stop was asked for (SIGINT/SIGTERM) while the device ran this work.
    #[error("stopped (SIGINT/SIGTERM) while the GPU was running {0}")]
    Stopped(String),
    /// The device was abandoned earlier (for this reason) and runs nothing more.
    #[error("the GPU device still runs work given up earlier ({0}); nothing more runs on it")]
    Abandoned(String),
    #[error("too large for this GPU adapter: {0}")]
    TooLarge(String),
    /// The engine's passes disagree with each other (the device still works).
    #[error("the GPU engine's results are inconsistent: {0}")]
    Inconsistent(String),
}

impl GpuError {
    /// Whether the device is unusable after this error, so that further work should go
    /// elsewhere; every other error concerns one job only.
    pub fn is_device_lost(&self) -> bool {
        matches!(self, GpuError::Lost(_) | GpuError::TimedOut { .. } | GpuError::Stopped(_) | GpuError::Abandoned(_))
    }

    /// Whether the error is the user's setting, not the machine (the CLI exits with 2).
    pub fn is_bad_input(&self) -> bool {
        matches!(self, GpuError::UnknownBackend { .. })
    }
}

/// The names wgpu's `Backends::from_comma_list` knows (wgpu-types 30, `backend.rs`).
const BACKEND_NAMES: [&str; 11] = ["vulkan", "vk", "dx12", "d3d12", "metal", "mtl", "opengl", "gles", "gl", "webgpu", "noop"];

/// `WGPU_BACKEND`, if set: an error where an item names no backend (wgpu itself only logs it,
/// and with no known item at all tries no backend, which reads as "no adapter").
fn backend_from_env() -> Result<Option<String>, GpuError> {
    let Some(value) = std::env::var_os("WGPU_BACKEND") else { return Ok(None) };
    let value = value.to_string_lossy().into_owned();
    let unknown: Vec<String> =
        value.to_lowercase().split(',').map(str::trim).filter(|b| !BACKEND_NAMES.contains(b)).map(|b| format!("'{b}'")).collect();
    if unknown.is_empty() {
        Ok(Some(value))
    } else {
        Err(GpuError::UnknownBackend { unknown: unknown.join(", "), value })
    }
}

/// What bounds the device's work: a deadline ([`Gpu::deadline`]) and a stop asked for
/// ([`Gpu::stop_when`], SIGINT/SIGTERM), seen before every submission and every 50 ms of every
/// wait. A wait that gives up leaves its work running on the device (a shader may loop forever,
/// and no API takes a submission back): the device is then abandoned, nothing more is submitted
/// to it, and it is never dropped (dropping a device waits for its work), so that the process
/// can still report and exit.
#[derive(Default)]
pub struct Bounds {
    /// When the work in hand must end, and the time it was given.
    pub(super) deadline: Mutex<Option<(Instant, Duration)>>,
    /// Whether a stop was asked for.
    pub(super) stop: Mutex<Option<fn() -> bool>>,
    /// The label of the pass last submitted, for messages.
    pub(super) pass: Mutex<String>,
    /// Why the device was abandoned, once it was.
    pub(super) abandoned: Mutex<Option<String>>,
}

/// A wgpu device and what its adapter offers.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
    pub features: wgpu::Features,
    /// The driver's compiled pipelines, loaded from and saved to the user's cache folder
    /// ([`super::pipeline_cache`]); None where the adapter has no PIPELINE_CACHE or it is off.
    /// (Not in lobes::embed alone, which opens no device of its own for rendering.)
    #[cfg(feature = "check")]
    pub pipeline_cache: Option<DiskCache>,
    /// The first error the device reported outside a call that returns one (validation, out
    /// of memory, loss), until [`Gpu::check_errors`] takes it.
    errors: Arc<Mutex<Option<String>>>,
    /// The deadline and the stop that bound waits on the device ([`Bounds`]).
    #[cfg(feature = "check")]
    pub(super) bounds: Bounds,
}

/// The first adapter whose name contains `wanted`, ignoring case (what `WGPU_ADAPTER_NAME` means
/// to wgpu's own `util::initialize_adapter_from_env`, which panics where none matches).
fn named_adapter(instance: &wgpu::Instance, wanted: &str) -> Result<wgpu::Adapter, GpuError> {
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
    let names: Vec<String> = adapters.iter().map(|a| a.get_info()).map(|i| format!("'{}' ({:?})", i.name, i.backend)).collect();
    let key = wanted.to_lowercase();
    adapters.into_iter().find(|a| a.get_info().name.to_lowercase().contains(&key)).ok_or_else(|| GpuError::AdapterNotNamed {
        wanted: wanted.to_string(),
        found: if names.is_empty() { "none".to_string() } else { names.join(", ") },
    })
}

impl Gpu {
    /// Opens the default adapter (honouring WGPU_BACKEND, WGPU_ADAPTER_NAME, WGPU_POWER_PREF),
    /// asking for its full limits (lavapipe offers 32 KiB of workgroup storage where wgpu's
    /// default is 16 KiB), for timestamp queries where it has them, and for a pipeline cache
    /// kept on disk where it has one ([`super::pipeline_cache`]).
    pub fn new() -> Result<Self, GpuError> {
        Self::with_limits(|adapter| adapter)
    }

    /// As [`Gpu::new`], with the adapter's limits passed through `shrink` first: tests use it to
    /// impose small limits and prove that work is split to fit them.
    pub fn with_limits(shrink: impl FnOnce(wgpu::Limits) -> wgpu::Limits) -> Result<Self, GpuError> {
        let backend = backend_from_env()?;
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if backend.is_none() {
            desc.backends = wgpu::Backends::PRIMARY;
        }
        let instance = wgpu::Instance::new(desc);
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env().unwrap_or(wgpu::PowerPreference::HighPerformance),
            ..Default::default()
        };
        let adapter = match std::env::var("WGPU_ADAPTER_NAME") {
            Ok(wanted) if !wanted.is_empty() => named_adapter(&instance, &wanted)?,
            _ => pollster::block_on(instance.request_adapter(&options)).map_err(|e| match backend {
                Some(value) => GpuError::NoAdapterOfBackend { value, reason: e.to_string() },
                None => GpuError::NoAdapter(e.to_string()),
            })?,
        };
        let info = adapter.get_info();
        // SHADER_F64 where offered: only `lobes tradeoff`'s f64 kernels use it. FLOAT32_FILTERABLE
        // where offered: `lobes check --texture` (rgba32float) read through a `--sampler`.
        #[cfg(feature = "check")]
        let cache_file = pipeline_cache::folder().filter(|_| !pipeline_cache::disabled()).and_then(|f| pipeline_cache::file(&f, &info));
        #[cfg(not(feature = "check"))]
        let cache_file: Option<()> = None;
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::SHADER_F64
            | wgpu::Features::FLOAT32_FILTERABLE
            | if cache_file.is_some() { wgpu::Features::PIPELINE_CACHE } else { wgpu::Features::empty() };
        let features = adapter.features() & wanted;
        let limits = shrink(adapter.limits());
        let desc = wgpu::DeviceDescriptor {
            label: Some("lobes"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(|source| GpuError::Device { adapter: info.name.clone(), source })?;
        #[cfg(feature = "check")]
        let pipeline_cache = cache_file.filter(|_| features.contains(wgpu::Features::PIPELINE_CACHE)).map(|path| DiskCache::open(&device, path));
        let errors = Arc::new(Mutex::new(None));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap().get_or_insert_with(|| e.to_string());
        }));
        Ok(Self {
            device,
            queue,
            info,
            limits,
            features,
            #[cfg(feature = "check")]
            pipeline_cache,
            errors,
            #[cfg(feature = "check")]
            bounds: Default::default(),
        })
    }

    /// The error the device reported since the last check, as [`GpuError::Lost`].
    pub fn check_errors(&self) -> Result<(), GpuError> {
        match self.errors.lock().unwrap().take() {
            Some(e) => Err(GpuError::Lost(e)),
            None => Ok(()),
        }
    }

    /// "name (backend, driver)" for reports.
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?}, {} {})", self.info.name, self.info.backend, self.info.driver, self.info.driver_info)
            .trim()
            .to_string()
    }

    pub fn has_timestamps(&self) -> bool {
        self.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Whether a float32 texture (`lobes check --texture`, rgba32float) may be read through a
    /// sampler (the adapter has FLOAT32_FILTERABLE): wgpu's derived layouts mark a texture that
    /// an entry point samples as filterable, which rgba32float is only with this feature.
    pub fn float32_filterable(&self) -> bool {
        self.features.contains(wgpu::Features::FLOAT32_FILTERABLE)
    }

    /// Whether the device runs WGSL `f64` (the adapter has SHADER_F64).
    pub fn has_f64(&self) -> bool {
        self.features.contains(wgpu::Features::SHADER_F64)
    }
}

#[cfg(feature = "check")]
impl Drop for Gpu {
    /// Saves the pipeline cache; a cache that cannot be written costs the next process time,
    /// not this one its results, so that is a note.
    fn drop(&mut self) {
        // an abandoned device still runs work that may never end, and dropping the last handle
        // of a device or queue waits for it: those handles are kept, and the cache is not saved
        if self.abandoned().is_some() {
            std::mem::forget(self.device.clone());
            std::mem::forget(self.queue.clone());
            return;
        }
        if let Some(Err(e)) = self.pipeline_cache.as_ref().map(DiskCache::save) {
            crate::console::say(format_args!("lobes: note: pipeline cache not saved ({e}); set {}=off to stop using it", pipeline_cache::DISABLE_VAR));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::GpuError;

    #[test]
    fn only_a_lost_device_is_device_loss() {
        assert!(GpuError::Lost("device lost".into()).is_device_lost());
        // A tile that counted invalid samples unlike the first one is the engine's fault, not
        // the device's: the remaining cases may still run on it.
        let tile = GpuError::Inconsistent("tile 1 of 2 counted invalid samples [1, 0, 0, 0] where tile 0 counted [0, 0, 0, 0]".into());
        assert!(!tile.is_device_lost());
        for e in [
            GpuError::NoAdapter("none".into()),
            GpuError::AdapterNotNamed { wanted: "x".into(), found: "none".into() },
            GpuError::Shader { what: "w".into(), message: "m".into() },
            GpuError::Readback("r".into()),
            GpuError::TooLarge("t".into()),
        ] {
            assert!(!e.is_device_lost(), "{e}");
        }
    }
}
