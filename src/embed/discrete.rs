//! Uploading a discrete distribution for `shaders/lib/discrete.wgsl`.

use crate::reference::discrete::{self, AliasTable, DiscreteMethod, Distribution};

/// Items per block of the two-level CDF, and the most items sampled with one uniform
/// (`crate::reference::discrete::BLOCK`; `DISCRETE_BLOCK` in the WGSL).
pub const BLOCK: usize = discrete::BLOCK;
use bytemuck::{Pod, Zeroable};
#[cfg(feature = "wgpu")]
use wgpu::util::DeviceExt;

/// Where [`Module::Discrete`](super::Module::Discrete)'s two storage buffers are bound: both in
/// `group`, the f32 table (`lobes_discrete_f`) at binding `table` and the u32 aliases (`lobes_discrete_u`)
/// at binding `alias`. The default is the file's own: group 0, bindings 3 and 4.
///
/// ```
/// use lobes::embed::DiscreteBindings;
/// assert_eq!(DiscreteBindings::default(), DiscreteBindings { group: 0, table: 3, alias: 4 });
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DiscreteBindings {
    /// The bind group index (`@group`).
    pub group: u32,
    /// The binding of `lobes_discrete_f: array<f32>`: the CDF, or the alias thresholds.
    pub table: u32,
    /// The binding of `lobes_discrete_u: array<u32>`: the alias indices.
    pub alias: u32,
}

impl Default for DiscreteBindings {
    fn default() -> Self {
        Self { group: 0, table: 3, alias: 4 }
    }
}

/// The two scalars the WGSL sampling functions take besides the uniforms, laid out for a
/// uniform or storage buffer: 16 bytes, `#[repr(C)]`, [`Pod`], matching [`DISCRETE_INFO_WGSL`].
/// Pass `n_items` as `n` to both samplers and `last_positive` to `lobes_discrete_sample_cdf`.
///
/// ```
/// assert_eq!(std::mem::size_of::<lobes::embed::DiscreteInfo>(), 16);
/// ```
#[repr(C, align(8))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct DiscreteInfo {
    /// The number of items n (the length of the tables).
    pub n_items: u32,
    /// The largest index with a positive weight (`lobes_discrete_sample_cdf` never returns more).
    pub last_positive: u32,
    /// Padding to 16 bytes (uniform buffers round structs up to 16).
    pub _pad: [u32; 2],
}

/// The WGSL twin of [`DiscreteInfo`], for a renderer that binds it as its own uniform:
/// `struct LobesDiscreteInfo { n_items: u32, last_positive: u32, _pad: vec2<u32> }` (prefixed
/// like every name lobes exports).
///
/// ```
/// let src = format!("{}\n@group(0) @binding(0) var<uniform> info: LobesDiscreteInfo;",
///                   lobes::embed::DISCRETE_INFO_WGSL);
/// lobes::embed::validate(&src).unwrap();
/// ```
pub const DISCRETE_INFO_WGSL: &str = "struct LobesDiscreteInfo {\n    n_items: u32,\n    last_positive: u32,\n    _pad: vec2<u32>,\n}\n";

/// A distribution's tables as the WGSL reads them, on the host. Both are arrays of plain
/// little-endian 4-byte scalars ([`Pod`]: upload with `bytemuck::cast_slice`):
///
/// - `table: Vec<f32>` → `lobes_discrete_f: array<f32>`, n entries. For the CDF method entry i is
///   (Σ_{j≤i} w_j) / Σ w, formed in f64 and rounded to f32 (so the last positive entry is
///   exactly 1); beyond [`BLOCK`] items, the two-level layout of [`DiscreteTable::cdf`]. For
///   the alias method entry i is column i's threshold in [0, 1] (Vose's construction in f64,
///   rounded to f32).
/// - `alias: Vec<u32>` → `lobes_discrete_u: array<u32>`: for the alias method n entries, column i's
///   alias; for the CDF method a single 0 (the binding must exist; a storage buffer may not be
///   empty).
///
/// These are exactly the tables the χ²-tested kernels of `lobes run` use.
///
/// ```
/// use lobes::embed::DiscreteTable;
/// use lobes::reference::discrete::Distribution;
/// let d = Distribution::new(&[1.0, 0.0, 3.0]).unwrap();
/// let cdf = DiscreteTable::cdf(&d);
/// assert_eq!(cdf.table, [0.25, 0.25, 1.0]);
/// assert_eq!((cdf.info.n_items, cdf.info.last_positive), (3, 2));
/// let alias = DiscreteTable::alias(&d);
/// assert_eq!(alias.table.len(), 3);
/// assert_eq!(alias.alias.len(), 3);
/// let bytes: &[u8] = bytemuck::cast_slice(&alias.table); // what goes into the buffer
/// assert_eq!(bytes.len(), 12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteTable {
    /// Which sampler the tables are for.
    pub method: DiscreteMethod,
    /// `lobes_discrete_f`: the CDF or the alias thresholds, n × f32.
    pub table: Vec<f32>,
    /// `lobes_discrete_u`: the aliases, n × u32 (one 0 for the CDF method).
    pub alias: Vec<u32>,
    /// n and the last positive index.
    pub info: DiscreteInfo,
}

impl DiscreteTable {
    fn info(dist: &Distribution) -> DiscreteInfo {
        let last_positive = dist.pmf().iter().rposition(|&p| p > 0.0).unwrap_or(0) as u32;
        DiscreteInfo { n_items: dist.len() as u32, last_positive, _pad: [0; 2] }
    }

    /// The CDF tables. Up to [`BLOCK`] items the table is the CDF itself, for
    /// `lobes_discrete_sample_cdf(u.x, info.n_items, info.last_positive)`. Longer tables are beyond
    /// what one 24-bit uniform and an f32 CDF can resolve; they take the two-level layout of
    /// `lobes_discrete_sample_cdf_blocks(u.xy, info.n_items, info.last_positive)`: first the CDF over
    /// blocks of [`BLOCK`] items (⌈n / BLOCK⌉ entries: the global CDF at each block's last item),
    /// then each block's own CDF (n entries in all), so `table.len()` = n + ⌈n / BLOCK⌉.
    /// [`DiscreteTable::two_level`] says which.
    ///
    /// ```
    /// use lobes::embed::{DiscreteTable, BLOCK};
    /// use lobes::reference::discrete::Distribution;
    /// let long = Distribution::new(&vec![1.0; BLOCK + 1]).unwrap();
    /// let t = DiscreteTable::cdf(&long);
    /// assert!(t.two_level());
    /// assert_eq!(t.table.len(), BLOCK + 1 + 2);
    /// assert_eq!(t.table[1], 1.0); // the CDF over the 2 blocks ends at 1
    /// ```
    pub fn cdf(dist: &Distribution) -> Self {
        let cdf = dist.cdf();
        let table = if dist.len() > BLOCK {
            let blocks = discrete::block_cdf(cdf);
            let local = (0..blocks.len()).flat_map(|b| discrete::local_cdf(cdf, b));
            blocks.iter().copied().chain(local).map(|c| c as f32).collect()
        } else {
            cdf.iter().map(|&c| c as f32).collect()
        };
        Self { method: DiscreteMethod::Cdf, table, alias: vec![0], info: Self::info(dist) }
    }

    /// Whether the table has the two-level CDF layout (the CDF method with more than [`BLOCK`]
    /// items), to be sampled with `lobes_discrete_sample_cdf_blocks`.
    pub fn two_level(&self) -> bool {
        self.method == DiscreteMethod::Cdf && self.info.n_items as usize > BLOCK
    }

    /// The alias tables, for `lobes_discrete_sample_alias(u2, info.n_items)`.
    pub fn alias(dist: &Distribution) -> Self {
        let t = AliasTable::new(dist);
        let table = t.threshold.iter().map(|&x| x as f32).collect();
        Self { method: DiscreteMethod::Alias, table, alias: t.alias, info: Self::info(dist) }
    }

    /// The tables for `method`.
    pub fn new(dist: &Distribution, method: DiscreteMethod) -> Self {
        match method {
            DiscreteMethod::Cdf => Self::cdf(dist),
            DiscreteMethod::Alias => Self::alias(dist),
        }
    }
}

/// A distribution's tables in two wgpu storage buffers (usage `STORAGE | COPY_DST`), laid out
/// as [`DiscreteTable`] describes, ready to bind where [`DiscreteBindings`] says. Feature
/// `wgpu` (in `check` and the default): a renderer on another wgpu version, or none, uploads
/// [`DiscreteTable`]'s vectors itself.
///
/// This example needs a device, so it is only compiled here; `tests/embed.rs`
/// (`embedded_discrete_sampling_counts_exactly_like_the_engine`) runs the same calls on the GPU.
///
/// ```no_run
/// # fn demo(device: &wgpu::Device) {
/// use lobes::embed::{self, DiscreteBindings, DiscreteBuffers, Module};
/// use lobes::reference::discrete::Distribution;
///
/// let dist = Distribution::new(&[15.0, 5.0, 5.0, 25.0]).unwrap();
/// let bindings = DiscreteBindings { group: 1, table: 0, alias: 1 };
/// let buffers = DiscreteBuffers::alias(device, &dist);
/// let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
///     label: Some("discrete"),
///     entries: &DiscreteBuffers::layout_entries(bindings, wgpu::ShaderStages::COMPUTE),
/// });
/// let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
///     label: Some("discrete"),
///     layout: &layout,
///     entries: &buffers.bind_group_entries(bindings),
/// });
/// // In WGSL (from embed::wgsl_with(&[Module::Rng, Module::Discrete], bindings)):
/// //   let index = lobes_discrete_sample_alias(u.xy, N_ITEMS);   // N_ITEMS = buffers.info.n_items
/// # let _ = (group, embed::wgsl_with(&[Module::Discrete], bindings));
/// # }
/// ```
#[cfg(feature = "wgpu")]
#[derive(Debug, Clone)]
pub struct DiscreteBuffers {
    /// Which sampler the tables are for.
    pub method: DiscreteMethod,
    /// `lobes_discrete_f`: the CDF or the thresholds, n × f32.
    pub table: wgpu::Buffer,
    /// `lobes_discrete_u`: the aliases, n × u32 (one 0 for the CDF method).
    pub alias: wgpu::Buffer,
    /// n and the last positive index.
    pub info: DiscreteInfo,
}

#[cfg(feature = "wgpu")]
impl DiscreteBuffers {
    /// Uploads the CDF of `dist` (see [`DiscreteTable::cdf`]).
    pub fn cdf(device: &wgpu::Device, dist: &Distribution) -> Self {
        Self::upload(device, &DiscreteTable::cdf(dist))
    }

    /// Uploads the alias table of `dist` (see [`DiscreteTable::alias`]).
    pub fn alias(device: &wgpu::Device, dist: &Distribution) -> Self {
        Self::upload(device, &DiscreteTable::alias(dist))
    }

    /// Uploads host tables.
    pub fn upload(device: &wgpu::Device, t: &DiscreteTable) -> Self {
        let make = |label, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        Self {
            method: t.method,
            table: make("lobes discrete_f", bytemuck::cast_slice(&t.table)),
            alias: make("lobes discrete_u", bytemuck::cast_slice(&t.alias)),
            info: t.info,
        }
    }

    /// The two read-only storage entries of a bind group layout, at `bindings`.
    pub fn layout_entries(bindings: DiscreteBindings, visibility: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 2] {
        let entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(4),
            },
            count: None,
        };
        [entry(bindings.table), entry(bindings.alias)]
    }

    /// The two entries of a bind group, at `bindings`.
    pub fn bind_group_entries(&self, bindings: DiscreteBindings) -> [wgpu::BindGroupEntry<'_>; 2] {
        [
            wgpu::BindGroupEntry { binding: bindings.table, resource: self.table.as_entire_binding() },
            wgpu::BindGroupEntry { binding: bindings.alias, resource: self.alias.as_entire_binding() },
        ]
    }
}

#[cfg(all(test, feature = "check"))]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn info_layout() {
        let members = [
            ("n_items", offset_of!(DiscreteInfo, n_items)),
            ("last_positive", offset_of!(DiscreteInfo, last_positive)),
            ("_pad", offset_of!(DiscreteInfo, _pad)),
        ];
        crate::engine::gpu::layout::check_struct(DISCRETE_INFO_WGSL, "LobesDiscreteInfo", size_of::<DiscreteInfo>(), align_of::<DiscreteInfo>(), &members).unwrap();
    }
}
