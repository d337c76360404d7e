//! A renderer's textures and tables, bound where its sampler reads them: an environment map's
//! radiance and its CDF tables, as the renderer builds them, instead of a stand-in. `--texture
//! NAME=FILE` binds a Radiance `.hdr`, an OpenEXR `.exr` (scanline, NONE/RLE/ZIPS/ZIP) or a
//! `.png` image (its stored values, no sRGB decoding) as `NAME: texture_2d<f32>` (rgba32float,
//! read with `textureLoad`); `--buffer NAME=FILE` binds a
//! `.npy` array of float32, uint32 or int32 (any shape, C order, read as flat), or a raw file of
//! little-endian 32-bit words (`.bin`, `.raw`, typed by the declaration), as
//! `var<storage, read> NAME: array<f32>` (or `u32`, `i32`); `--sampler NAME=linear|nearest` binds
//! `NAME: sampler` (clamp-to-edge, for `textureSampleLevel`).
//! Each resource the passes reach is moved to `@group(1)`, binding 0, 1, … in declaration
//! order (lobes' own are group 0), in the composed text only: the lines stay where they were.

use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a resource item binds: the kind a scene's key (`texture`) or `lobes check`'s flag
/// (`--texture`, named by the command line) names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResourceKind {
    Texture,
    Buffer,
    Sampler,
}

impl ResourceKind {
    /// A scene's `[sampler]` key: `texture`, `buffer`, `filter`.
    pub fn key(self) -> &'static str {
        match self {
            ResourceKind::Texture => "texture",
            ResourceKind::Buffer => "buffer",
            ResourceKind::Sampler => "filter",
        }
    }

    /// An item of this kind, for messages: `env_map=sky.hdr`.
    pub(super) fn example(self) -> &'static str {
        match self {
            ResourceKind::Texture => "env_map=sky.hdr",
            ResourceKind::Buffer => "env_cdf=cdf.npy",
            ResourceKind::Sampler => "lut_sampler=linear",
        }
    }
}

/// A resource item that cannot be bound: its kind, which the caller names by its flag or its
/// scene key, and why (the item quoted).
#[derive(Debug, Clone, PartialEq)]
pub struct ResourceError {
    pub kind: ResourceKind,
    pub message: String,
}

/// What a name is bound to.
#[derive(Debug, Clone, PartialEq)]
pub enum Resource {
    /// A `.hdr`, `.exr` or `.png` image, bound as a `texture_2d<f32>`.
    Texture(PathBuf),
    /// A `.npy` array or raw little-endian 32-bit words (`.bin`, `.raw`), bound as a read-only
    /// storage buffer.
    Buffer(PathBuf),
    /// A `sampler` of this filter, clamp-to-edge.
    Sampler(Filter),
}

impl Resource {
    /// The file read for the resource; `None` for a sampler, which is made, not read.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Resource::Texture(p) | Resource::Buffer(p) => Some(p),
            Resource::Sampler(_) => None,
        }
    }
    /// What it binds.
    pub fn kind(&self) -> ResourceKind {
        match self {
            Resource::Texture(_) => ResourceKind::Texture,
            Resource::Buffer(_) => ResourceKind::Buffer,
            Resource::Sampler(_) => ResourceKind::Sampler,
        }
    }
}

/// How a bound sampler filters (`--sampler NAME=linear|nearest`), for magnification and
/// minification alike; mipmaps are nearest (lobes' textures have one level).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filter {
    Linear,
    Nearest,
}

impl Filter {
    /// `linear` or `nearest`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "linear" => Some(Filter::Linear),
            "nearest" => Some(Filter::Nearest),
            _ => None,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Filter::Linear => "linear",
            Filter::Nearest => "nearest",
        }
    }
}

/// The element type of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    F32,
    U32,
    I32,
}

impl Scalar {
    fn wgsl(self) -> &'static str {
        match self {
            Scalar::F32 => "f32",
            Scalar::U32 => "u32",
            Scalar::I32 => "i32",
        }
    }
}

/// A resource's contents, read before any GPU work.
#[derive(Debug, Clone, PartialEq)]
pub enum Data {
    /// rgba texels, row-major from the image's top row, alpha 1.
    Texture { width: u32, height: u32, texels: Vec<[f32; 4]> },
    /// The array's elements as 32-bit words, and their type: `None` for raw words, whose type is
    /// the declaration's.
    Buffer { scalar: Option<Scalar>, words: Vec<u32> },
    /// A sampler's filter: nothing to read.
    Sampler(Filter),
}

/// A user's resource bound at `@group(1) @binding(binding)`, and the passes that read it.
#[derive(Debug, Clone)]
pub struct Bound {
    pub name: String,
    pub binding: u32,
    pub data: Arc<Data>,
    pub entries: Vec<String>,
}

/// Reads `r`; the error's message says what is wrong with the file, after `NAME=FILE: `.
pub fn load(name: &str, r: &Resource) -> Result<Data, ResourceError> {
    let Some(path) = r.path() else {
        return Ok(match r {
            Resource::Sampler(f) => Data::Sampler(*f),
            _ => unreachable!("only a sampler has no file"),
        });
    };
    let error = |e: String| ResourceError { kind: r.kind(), message: format!("{name}={}: {e}", path.display()) };
    let bytes = std::fs::read(path).map_err(|e| error(format!("cannot read the file: {e}")))?;
    match r {
        Resource::Texture(_) => read_image(path, &bytes).map_err(error),
        Resource::Buffer(_) => read_table(path, &bytes).map_err(error),
        Resource::Sampler(_) => unreachable!("a sampler has no file"),
    }
}

/// A Radiance RGBE image (the `image` crate's decoder) as rgba32float texels.
fn read_hdr(bytes: &[u8]) -> Result<Data, String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Hdr).map_err(|e| format!("not a Radiance .hdr image: {e}"))?.into_rgb32f();
    let (width, height) = img.dimensions();
    let texels = img.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect();
    Ok(Data::Texture { width, height, texels })
}

/// A texture file by its extension: a Radiance `.hdr` ([`read_hdr`]), an OpenEXR `.exr` (its
/// channels' values, [`super::exr`]) or a `.png`, whose stored
/// values are the texels (8-bit v as v / 255, 16-bit as v / 65535, alpha kept, no sRGB decoding:
/// what a renderer's lookup table holds when it is loaded as a unorm texture).
fn read_image(path: &Path, bytes: &[u8]) -> Result<Data, String> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("hdr") => read_hdr(bytes),
        Some("png") => read_png(bytes),
        Some("exr") => super::exr::read(bytes).map(|(width, height, texels)| Data::Texture { width, height, texels }).map_err(|e| format!("OpenEXR: {e}")),
        _ => Err("a texture is a Radiance .hdr, an OpenEXR .exr or a .png image (by its extension)".into()),
    }
}

fn read_png(bytes: &[u8]) -> Result<Data, String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png).map_err(|e| format!("not a PNG image: {e}"))?.into_rgba32f();
    let (width, height) = img.dimensions();
    let texels = img.pixels().map(|p| p.0).collect();
    Ok(Data::Texture { width, height, texels })
}

/// A table file by its extension: a NumPy `.npy` array ([`read_npy`]), or raw little-endian
/// 32-bit words (`.bin`, `.raw`: what a renderer's `fwrite` of a `float` or `uint32_t` array
/// writes), typed by the WGSL declaration it is bound to.
fn read_table(path: &Path, bytes: &[u8]) -> Result<Data, String> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("npy") => read_npy(bytes).map(|(scalar, words)| Data::Buffer { scalar: Some(scalar), words }),
        Some("bin" | "raw") => read_raw(bytes).map(|words| Data::Buffer { scalar: None, words }),
        _ => Err("a table is a NumPy .npy array or raw little-endian 32-bit words (.bin, .raw), by its extension".into()),
    }
}

/// Raw little-endian 32-bit words: a whole, non-zero number of them.
fn read_raw(bytes: &[u8]) -> Result<Vec<u32>, String> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(4) {
        return Err(format!("raw table of {} bytes: expected a non-zero multiple of 4 (32-bit little-endian words)", bytes.len()));
    }
    Ok(bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect())
}

/// A `.npy` file (NumPy's format, version 1–3: the magic, a header dict, the raw data) of
/// little-endian float32, uint32 or int32 in C order. Written here: no crate for it builds on
/// this toolchain offline, and lobes needs only these three types of it.
fn read_npy(bytes: &[u8]) -> Result<(Scalar, Vec<u32>), String> {
    const MAGIC: &[u8] = b"\x93NUMPY";
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("not a .npy file (no \\x93NUMPY magic)".into());
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(format!(".npy version {v} is not one lobes reads (1, 2, 3)")),
    };
    let header = bytes.get(start..start + len).and_then(|h| std::str::from_utf8(h).ok()).ok_or("the .npy header is cut short")?;
    let field = |key: &str| header.split_once(&format!("'{key}':")).map(|(_, rest)| rest.trim_start());
    let descr = field("descr").and_then(|r| r.strip_prefix('\'')).and_then(|r| r.split_once('\'')).map(|(d, _)| d).ok_or("the .npy header has no 'descr'")?;
    let scalar = match descr {
        "<f4" => Scalar::F32,
        "<u4" => Scalar::U32,
        "<i4" => Scalar::I32,
        d => return Err(format!("dtype '{d}' is not allowed: give little-endian float32 ('<f4'), uint32 ('<u4') or int32 ('<i4'), e.g. numpy's a.astype(np.float32)")),
    };
    if field("fortran_order").is_some_and(|r| r.starts_with("True")) {
        return Err("the array is in Fortran order: save it in C order (np.ascontiguousarray)".into());
    }
    let shape = field("shape").and_then(|r| r.strip_prefix('(')).and_then(|r| r.split_once(')')).map(|(s, _)| s).ok_or("the .npy header has no 'shape'")?;
    let count = shape.split(',').map(str::trim).filter(|s| !s.is_empty()).try_fold(1usize, |n, s| s.parse::<usize>().ok().and_then(|d| n.checked_mul(d))).ok_or("the .npy shape is not a tuple of whole numbers")?;
    let data = &bytes[start + len..];
    if data.len() != count * 4 {
        return Err(format!("the shape ({shape}) holds {count} elements, {} bytes, but the file has {} bytes of data", count * 4, data.len()));
    }
    Ok((scalar, data.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()))
}

/// Whether `data` fits the declared global `g`: a texture for `texture_2d<f32>`, a table of the
/// array's element type for `var<storage, read>`; else what the declaration needs.
pub fn fits(name: &str, data: &Data, g: &naga::GlobalVariable, module: &naga::Module) -> Result<(), String> {
    use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};
    let inner = &module.types[g.ty].inner;
    match (data, inner) {
        (Data::Texture { .. }, TypeInner::Image { dim: ImageDimension::D2, arrayed: false, class: ImageClass::Sampled { kind: ScalarKind::Float, multi: false } }) => Ok(()),
        (Data::Texture { .. }, _) => Err(format!("`{name}` is not declared as a texture_2d<f32>, and its texture is an image, bound as one")),
        (Data::Buffer { scalar, .. }, TypeInner::Array { base, .. }) if matches!(g.space, naga::AddressSpace::Storage { .. }) => {
            let want = match module.types[*base].inner {
                TypeInner::Scalar(s) if s.width == 4 => match s.kind {
                    ScalarKind::Float => Some(Scalar::F32),
                    ScalarKind::Uint => Some(Scalar::U32),
                    ScalarKind::Sint => Some(Scalar::I32),
                    _ => None,
                },
                _ => None,
            };
            match want {
                Some(w) if scalar.is_none_or(|s| s == w) => Ok(()),
                Some(w) => Err(format!("the buffer file of `{name}` holds {} and `{name}` is an array<{}>", scalar.map_or("raw words", Scalar::wgsl), w.wgsl())),
                None => Err(format!("`{name}` is not an array of f32, u32 or i32, and its buffer file is a flat table")),
            }
        }
        (Data::Buffer { .. }, _) => Err(format!("`{name}` is not declared as var<storage, read> {name}: array<f32> (or u32, i32), which its buffer file is bound as")),
        (Data::Sampler(_), TypeInner::Sampler { comparison: false }) => Ok(()),
        (Data::Sampler(f), TypeInner::Sampler { comparison: true }) => Err(format!("`{name}` is a sampler_comparison (a depth comparison), which lobes does not bind: its filter ({}) makes a filtering `sampler`; give the test a stand-in module without it", f.name())),
        (Data::Sampler(f), _) => Err(format!("`{name}` is not declared as a `sampler`, which its filter ({}) makes (var {name}: sampler;)", f.name())),
    }
}

/// Whether the composed module's global `global` is the user's `name`: the same, or as naga_oil
/// (`nameX_naga_oil_mod_X…`) or the wesl crate (`…_1name`) renamed it.
pub fn names(global: &str, name: &str) -> bool {
    global == name || global.strip_prefix(name).is_some_and(|r| r.starts_with("X_naga_oil_mod_X")) || global.ends_with(&format!("_1{name}"))
}

/// A naga_oil name `nameX_naga_oil_mod_X…X` as the user's plain name and the module that
/// declares it (naga_oil's own `Composer::undecorate` is private); `None` for any other name.
pub fn undecorated(global: &str) -> Option<(&str, String)> {
    let (name, rest) = global.split_once("X_naga_oil_mod_X")?;
    let module = base32(rest.strip_suffix('X')?)?;
    Some((name, String::from_utf8(module).ok()?))
}

/// RFC 4648 base32 without padding (naga_oil's module decoration), decoded.
fn base32(text: &str) -> Option<Vec<u8>> {
    const ALPHABET: &[u8; 32] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ234567";
    let (mut bits, mut held, mut out) = (0u32, 0u32, Vec::new());
    for c in text.bytes() {
        bits = (bits << 5) | ALPHABET.iter().position(|&a| a == c)? as u32;
        held += 5;
        if held >= 8 {
            held -= 8;
            out.push((bits >> held) as u8);
            bits &= (1 << held) - 1;
        }
    }
    Some(out)
}

/// `text` with the `@group(…)` and `@binding(…)` attributes of the declaration that ends at
/// `end` (from the previous `;` or `}` on) set to group 1 and `binding`; `None` where they are
/// not found.
pub fn rebind(text: &str, decl: std::ops::Range<usize>, binding: u32) -> Option<String> {
    let from = text[..decl.start].rfind([';', '}']).map_or(0, |i| i + 1);
    let mut window = text[from..decl.end].to_string();
    set_attribute(&mut window, "@group", 1)?;
    set_attribute(&mut window, "@binding", binding)?;
    Some(format!("{}{window}{}", &text[..from], &text[decl.end..]))
}

/// `attr(…)` in `text` set to `attr(value)`.
fn set_attribute(text: &mut String, attr: &str, value: u32) -> Option<()> {
    let at = text.find(attr)?;
    let open = at + text[at..].find('(')?;
    let close = open + text[open..].find(')')?;
    text.replace_range(open + 1..close, &value.to_string());
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.bytes());
        out.extend(data);
        out
    }

    #[test]
    fn a_npy_array_is_read_as_numpy_writes_it() {
        let data: Vec<u8> = [0.5f32, -2.0, 3.25, 1e-30].iter().flat_map(|v| v.to_le_bytes()).collect();
        let (s, words) = read_npy(&npy("<f4", "(2, 2)", &data)).unwrap();
        assert_eq!(s, Scalar::F32);
        assert_eq!(words.iter().map(|w| f32::from_bits(*w)).collect::<Vec<_>>(), vec![0.5, -2.0, 3.25, 1e-30]);
        let (s, words) = read_npy(&npy("<u4", "(3,)", &[1, 0, 0, 0, 2, 0, 0, 0, 255, 255, 255, 255])).unwrap();
        assert_eq!((s, words), (Scalar::U32, vec![1, 2, u32::MAX]));
    }

    /// examples/envmap's sky as an OpenEXR file (HALF, ZIP) and as Radiance RGBE, written from
    /// the same texels by make.py (integers times powers of two, exact in both) and read by two
    /// decoders (this crate's and the `image` crate's): the same texels, bit for bit.
    #[test]
    fn the_maps_exr_and_hdr_hold_the_same_texels() {
        let map = |file: &str| load("env_radiance", &Resource::Texture(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/envmap").join(file))).unwrap();
        let (exr, hdr) = (map("sky.exr"), map("sky.hdr"));
        let Data::Texture { width: 64, height: 32, texels } = &exr else { panic!("a 64 × 32 texture: {exr:?}") };
        assert_eq!(exr, hdr);
        // the sun: 2 × 2 texels of (250, 230, 200) · 2⁶ at rows 8, 9 and columns 42, 43
        assert_eq!(texels[8 * 64 + 42], [16000.0, 14720.0, 12800.0, 1.0]);
    }

    #[test]
    fn a_raw_table_is_little_endian_words_typed_by_its_declaration() {
        let path = Path::new("cdf.bin");
        let bytes: Vec<u8> = [0.25f32, 1.0].iter().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(read_table(path, &bytes).unwrap(), Data::Buffer { scalar: None, words: vec![0x3e80_0000, 0x3f80_0000] });
        assert!(read_table(Path::new("cdf.raw"), &bytes[..7]).unwrap_err().contains("7 bytes"));
        assert!(read_table(path, &[]).unwrap_err().contains("non-zero multiple of 4"));
        assert!(read_table(Path::new("cdf.csv"), &bytes).unwrap_err().contains(".npy array or raw little-endian"));
        // bound to a declaration of any 32-bit element type; a .npy's type must match it
        let module = naga::front::wgsl::parse_str("@group(0) @binding(0) var<storage, read> t: array<u32>;").unwrap();
        let (_, g) = module.global_variables.iter().next().unwrap();
        assert_eq!(fits("t", &Data::Buffer { scalar: None, words: vec![1] }, g, &module), Ok(()));
        let typed = fits("t", &Data::Buffer { scalar: Some(Scalar::F32), words: vec![1] }, g, &module).unwrap_err();
        assert!(typed.contains("holds f32 and `t` is an array<u32>"), "{typed}");
    }

    #[test]
    fn a_bad_npy_says_what_is_wrong() {
        assert!(read_npy(b"P6 not numpy").unwrap_err().contains("magic"));
        assert!(read_npy(&npy("<f8", "(1,)", &[0; 8])).unwrap_err().contains("'<f8' is not allowed"));
        assert!(read_npy(&npy("<f4", "(3,)", &[0; 8])).unwrap_err().contains("holds 3 elements"));
        let fortran = npy("<f4", "(1,)", &[0; 4]);
        let fortran = String::from_utf8_lossy(&fortran).replace("False", "True ").into_bytes();
        assert!(read_npy(&fortran).is_err());
    }

    #[test]
    fn a_declarations_group_and_binding_are_rewritten_in_place() {
        let text = "const a = 1;\n@group(2) @binding(7)\nvar<storage, read> t: array<f32>;\nfn f() {}\n";
        let decl = text.find("var").unwrap()..text.find("f32>;").unwrap() + 4;
        let out = rebind(text, decl, 3).unwrap();
        assert_eq!(out, "const a = 1;\n@group(1) @binding(3)\nvar<storage, read> t: array<f32>;\nfn f() {}\n");
        let text = "@binding(0) @group(0) var tex: texture_2d<f32>;";
        let out = rebind(text, text.find("var").unwrap()..text.len() - 1, 5).unwrap();
        assert_eq!(out, "@binding(5) @group(1) var tex: texture_2d<f32>;");
    }

    #[test]
    fn renamed_globals_are_the_users_name() {
        assert!(names("env_cdf", "env_cdf"));
        assert!(names("env_cdfX_naga_oil_mod_XMJSXM6K7", "env_cdf"));
        assert!(names("_1bevy_pbr_1env_cdf", "env_cdf"));
        assert!(!names("env_cdf2", "env_cdf"));
    }

    #[test]
    fn a_naga_oil_name_is_undecorated_to_its_name_and_module() {
        // naga_oil's decoration of `bevy_pbr::utils` (BASE32_NOPAD of the module's path)
        assert_eq!(undecorated("lutX_naga_oil_mod_XMJSXM6K7OBRHEOR2OV2GS3DTX"), Some(("lut", "bevy_pbr::utils".to_string())));
        assert_eq!(undecorated("lut"), None);
    }

    #[test]
    fn a_sampler_fits_a_sampler_only() {
        let module = naga::front::wgsl::parse_str("@group(0) @binding(0) var s: sampler;\n@group(0) @binding(1) var c: sampler_comparison;\n@group(0) @binding(2) var t: texture_2d<f32>;").unwrap();
        let fit = |name: &str| {
            let (_, g) = module.global_variables.iter().find(|(_, g)| g.name.as_deref() == Some(name)).unwrap();
            fits(name, &Data::Sampler(Filter::Linear), g, &module)
        };
        assert_eq!(fit("s"), Ok(()));
        assert!(fit("c").unwrap_err().contains("`c` is a sampler_comparison (a depth comparison), which lobes does not bind"));
        assert!(fit("t").unwrap_err().contains("`t` is not declared as a `sampler`, which its filter (linear) makes"));
    }

    #[test]
    fn a_sampler_is_a_filter_and_no_file() {
        assert_eq!(Filter::parse("linear"), Some(Filter::Linear));
        assert_eq!(Filter::parse("nearest"), Some(Filter::Nearest));
        assert_eq!(Filter::parse("bilinear"), None);
        assert_eq!(load("s", &Resource::Sampler(Filter::Nearest)), Ok(Data::Sampler(Filter::Nearest)));
    }

    /// A 16-bit and an 8-bit PNG written by the image crate read back as their stored values
    /// over 65535 and 255 (a lookup table loaded as unorm), alpha kept; another extension is
    /// refused naming the three formats, and PNG bytes named .exr are refused as not OpenEXR.
    #[test]
    fn a_png_texture_holds_its_stored_values() {
        let mut png = std::io::Cursor::new(Vec::new());
        let wide = image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(2, 1, vec![0, 65535, 32768, 65535, 13107, 0, 65535, 0]).unwrap();
        image::DynamicImage::ImageRgba16(wide).write_to(&mut png, image::ImageFormat::Png).unwrap();
        let Data::Texture { width, height, texels } = read_image(Path::new("lut.png"), png.get_ref()).unwrap() else { panic!("not a texture") };
        assert_eq!((width, height), (2, 1));
        assert_eq!(texels[0], [0.0, 1.0, 32768.0 / 65535.0, 1.0]);
        assert_eq!(texels[1], [0.2, 0.0, 1.0, 0.0]);
        let mut png = std::io::Cursor::new(Vec::new());
        let narrow = image::ImageBuffer::<image::Rgba<u8>, _>::from_raw(1, 1, vec![51, 255, 0, 128]).unwrap();
        image::DynamicImage::ImageRgba8(narrow).write_to(&mut png, image::ImageFormat::Png).unwrap();
        let Data::Texture { texels, .. } = read_image(Path::new("LUT.PNG"), png.get_ref()).unwrap() else { panic!("not a texture") };
        assert_eq!(texels[0], [0.2, 1.0, 0.0, 128.0 / 255.0]);
        let e = read_image(Path::new("lut.tga"), png.get_ref()).unwrap_err();
        assert!(e.contains("a Radiance .hdr, an OpenEXR .exr or a .png image"), "{e}");
        let e = read_image(Path::new("lut.exr"), png.get_ref()).unwrap_err();
        assert!(e.contains("not an OpenEXR image"), "{e}");
    }
}
