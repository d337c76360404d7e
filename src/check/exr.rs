//! OpenEXR scanline images, as renderers store environment maps: the single-part scanline
//! layout of the OpenEXR file format ("OpenEXR File Layout", openexr.com) with HALF, FLOAT or
//! UINT channels and the lossless compressions NONE, RLE, ZIPS and ZIP. The R, G, B and A
//! channels (Y for a luminance image) become rgba texels; a tiled, multi-part or deep file, a
//! subsampled channel and the other compressions (PIZ, PXR24, B44, DWA) are refused by name.

/// The four bytes every OpenEXR file starts with (20000630 as a little-endian int).
const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// A channel's sample type (`chlist`'s pixel type).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Sample {
    Uint,
    Half,
    Float,
}

impl Sample {
    fn bytes(self) -> usize {
        if self == Sample::Half { 2 } else { 4 }
    }
    fn read(self, b: &[u8]) -> f32 {
        match self {
            Sample::Uint => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            Sample::Half => half::f16::from_bits(u16::from_le_bytes([b[0], b[1]])).to_f32(),
            Sample::Float => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        }
    }
}

/// How the chunks are compressed, with the scanlines each chunk holds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Compression {
    None,
    Rle,
    Zips,
    Zip,
}

impl Compression {
    fn of(code: u8) -> Result<Self, String> {
        const NAMES: [&str; 10] = ["NONE", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB"];
        match code {
            0 => Ok(Compression::None),
            1 => Ok(Compression::Rle),
            2 => Ok(Compression::Zips),
            3 => Ok(Compression::Zip),
            c => Err(format!(
                "its compression is {}; lobes reads NONE, RLE, ZIPS and ZIP (write the map with one of them, e.g. `oiiotool in.exr --compression zip -o out.exr`)",
                NAMES.get(c as usize).unwrap_or(&"unknown")
            )),
        }
    }
    fn lines(self) -> usize {
        if self == Compression::Zip { 16 } else { 1 }
    }
}

/// The header's facts lobes needs.
struct Header {
    /// (name, sample type) in the file's order (sorted by name).
    channels: Vec<(String, Sample)>,
    compression: Compression,
    width: usize,
    height: usize,
    y_min: i32,
}

/// Reads an OpenEXR scanline image as `(width, height, rgba texels)`, rows from the top.
pub fn read(bytes: &[u8]) -> Result<(u32, u32, Vec<[f32; 4]>), String> {
    if bytes.get(..4) != Some(&MAGIC[..]) {
        return Err("not an OpenEXR image (no 76 2f 31 01 magic)".into());
    }
    let flags = u32::from_le_bytes(bytes.get(4..8).ok_or("the OpenEXR version field is cut short")?.try_into().unwrap());
    if flags & 0x1a00 != 0 {
        return Err("a tiled, deep or multi-part OpenEXR file; lobes reads single-part scanline images".into());
    }
    let (header, mut at) = header(bytes, 8)?;
    let slots = [channel(&header, "R").or(channel(&header, "Y")), channel(&header, "G").or(channel(&header, "Y")), channel(&header, "B").or(channel(&header, "Y")), channel(&header, "A")];
    if slots[..3].iter().any(Option::is_none) {
        return Err(format!("no R, G, B (or Y) channels: it has {}", header.channels.iter().map(|c| c.0.as_str()).collect::<Vec<_>>().join(", ")));
    }
    let line_bytes: usize = header.channels.iter().map(|c| c.1.bytes() * header.width).sum();
    let chunks = header.height.div_ceil(header.compression.lines());
    at += 8 * chunks; // the offset table: the chunks follow it in the file's line order
    let mut texels = vec![[0.0, 0.0, 0.0, 1.0]; header.width * header.height];
    for _ in 0..chunks {
        let y = i32::from_le_bytes(take(bytes, at, 4)?.try_into().unwrap());
        let size = u32::from_le_bytes(take(bytes, at + 4, 4)?.try_into().unwrap()) as usize;
        let first = usize::try_from(y - header.y_min).ok().filter(|&f| f < header.height).ok_or_else(|| format!("a chunk of scanline {y} outside the data window"))?;
        let lines = header.compression.lines().min(header.height - first);
        let raw = uncompress(header.compression, take(bytes, at + 8, size)?, lines * line_bytes)?;
        for (l, line) in raw.chunks_exact(line_bytes).enumerate() {
            store(&header, &slots, line, &mut texels[(first + l) * header.width..][..header.width]);
        }
        at += 8 + size;
    }
    Ok((header.width as u32, header.height as u32, texels))
}

/// The index in `header.channels` of the channel called `name`.
fn channel(header: &Header, name: &str) -> Option<usize> {
    header.channels.iter().position(|c| c.0 == name)
}

/// One scanline's channels (each a run of `width` samples) into its texels.
fn store(header: &Header, slots: &[Option<usize>; 4], line: &[u8], row: &mut [[f32; 4]]) {
    let mut start = 0;
    for (c, &(_, sample)) in header.channels.iter().enumerate() {
        let run = &line[start..start + sample.bytes() * header.width];
        for (slot, _) in slots.iter().enumerate().filter(|(_, s)| **s == Some(c)) {
            for (texel, b) in row.iter_mut().zip(run.chunks_exact(sample.bytes())) {
                texel[slot] = sample.read(b);
            }
        }
        start += run.len();
    }
}

/// `len` bytes at `at`, or an error saying the file is cut short.
fn take(bytes: &[u8], at: usize, len: usize) -> Result<&[u8], String> {
    bytes.get(at..at.saturating_add(len)).ok_or_else(|| format!("the file is cut short at byte {at}"))
}

/// A null-terminated string at `at`, and the position after its null.
fn string(bytes: &[u8], at: usize) -> Result<(&str, usize), String> {
    let len = bytes.get(at..).and_then(|b| b.iter().position(|&c| c == 0)).ok_or("the header is cut short")?;
    let s = std::str::from_utf8(&bytes[at..at + len]).map_err(|_| format!("a header name at byte {at} is not UTF-8"))?;
    Ok((s, at + len + 1))
}

/// The header's attributes from `at` to its closing null, and the position after it.
fn header(bytes: &[u8], mut at: usize) -> Result<(Header, usize), String> {
    let (mut channels, mut compression, mut window) = (None, None, None);
    loop {
        let (name, next) = string(bytes, at)?;
        if name.is_empty() {
            at = next;
            break;
        }
        let (_, next) = string(bytes, next)?;
        let size = u32::from_le_bytes(take(bytes, next, 4)?.try_into().unwrap()) as usize;
        let value = take(bytes, next + 4, size)?;
        match name {
            "channels" => channels = Some(chlist(value)?),
            "compression" => compression = Some(Compression::of(*value.first().ok_or("an empty compression attribute")?)?),
            "dataWindow" if size == 16 => window = Some(value.chunks_exact(4).map(|b| i32::from_le_bytes(b.try_into().unwrap())).collect::<Vec<_>>()),
            _ => {}
        }
        at = next + 4 + size;
    }
    let w = window.ok_or("the header has no dataWindow")?;
    let (width, height) = (i64::from(w[2]) - i64::from(w[0]) + 1, i64::from(w[3]) - i64::from(w[1]) + 1);
    if !(1..=1 << 14).contains(&width) || !(1..=1 << 14).contains(&height) {
        return Err(format!("a data window of {width} × {height} texels; lobes reads 1 to 16384 a side"));
    }
    let channels = channels.ok_or("the header has no channels")?;
    let compression = compression.ok_or("the header has no compression")?;
    Ok((Header { channels, compression, width: width as usize, height: height as usize, y_min: w[1] }, at))
}

/// A `chlist` attribute: each channel's name, sample type, linearity, reserved bytes and x, y
/// sampling, up to a closing null.
fn chlist(value: &[u8]) -> Result<Vec<(String, Sample)>, String> {
    let mut out = Vec::new();
    let mut at = 0;
    loop {
        let (name, next) = string(value, at)?;
        if name.is_empty() {
            return Ok(out);
        }
        let field = |k: usize| take(value, next + 4 * k, 4).map(|b| i32::from_le_bytes(b.try_into().unwrap()));
        let sample = match field(0)? {
            0 => Sample::Uint,
            1 => Sample::Half,
            2 => Sample::Float,
            t => return Err(format!("channel {name} has sample type {t}; OpenEXR's are 0 (UINT), 1 (HALF), 2 (FLOAT)")),
        };
        if (field(2)?, field(3)?) != (1, 1) {
            return Err(format!("channel {name} is subsampled; lobes reads channels with x and y sampling 1"));
        }
        out.push((name.to_string(), sample));
        at = next + 16;
    }
}

/// A chunk's data as its scanlines' raw bytes (`raw` of them). ZIP and RLE undo the writer's
/// two steps in reverse: the byte predictor (each byte stored as its difference from the one
/// before, plus 128) and the interleaving (the even bytes first, then the odd ones). A chunk
/// that compression would not have made smaller is stored as it is.
fn uncompress(c: Compression, data: &[u8], raw: usize) -> Result<Vec<u8>, String> {
    if c == Compression::None || data.len() == raw {
        return if data.len() == raw { Ok(data.to_vec()) } else { Err(format!("an uncompressed chunk of {} bytes where its scanlines need {raw}", data.len())) };
    }
    let mut t = if c == Compression::Rle { unrle(data, raw)? } else { inflate(data, raw)? };
    for i in 1..t.len() {
        t[i] = t[i - 1].wrapping_add(t[i]).wrapping_sub(128);
    }
    let half = t.len().div_ceil(2);
    Ok((0..t.len()).map(|i| if i % 2 == 0 { t[i / 2] } else { t[half + i / 2] }).collect())
}

/// A zlib stream of exactly `raw` bytes (flate2, already built for the PNG decoder).
fn inflate(data: &[u8], raw: usize) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let mut out = Vec::with_capacity(raw);
    flate2::read::ZlibDecoder::new(data).take(raw as u64 + 1).read_to_end(&mut out).map_err(|e| format!("a ZIP chunk does not inflate: {e}"))?;
    if out.len() != raw {
        return Err(format!("a ZIP chunk inflates to {} bytes where its scanlines need {raw}", out.len()));
    }
    Ok(out)
}

/// OpenEXR's run-length code: a signed count byte, then −count literal bytes (count < 0) or
/// one byte repeated count + 1 times.
fn unrle(data: &[u8], raw: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(raw);
    let mut at = 0;
    while at < data.len() && out.len() < raw {
        let count = data[at] as i8;
        if count < 0 {
            out.extend_from_slice(take(data, at + 1, count.unsigned_abs() as usize)?);
            at += 1 + count.unsigned_abs() as usize;
        } else {
            out.extend(std::iter::repeat_n(*take(data, at + 1, 1)?.first().unwrap(), count as usize + 1));
            at += 2;
        }
    }
    if out.len() != raw {
        return Err(format!("an RLE chunk expands to {} bytes where its scanlines need {raw}", out.len()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header attribute: name, type name, size, value.
    fn attribute(name: &str, kind: &str, value: &[u8]) -> Vec<u8> {
        [name.as_bytes(), &[0], kind.as_bytes(), &[0], &(value.len() as u32).to_le_bytes(), value].concat()
    }

    /// A 2 × 2 image, FLOAT channels B, G, R, uncompressed (compression 0), by the layout's
    /// definition: magic, version 2, attributes, a null, the offset table, chunks (y, size, the
    /// line's channels one after another).
    fn two_by_two(compression: u8, lines: [[[f32; 3]; 2]; 2]) -> Vec<u8> {
        let chlist: Vec<u8> = ["B", "G", "R"].iter().flat_map(|n| [n.as_bytes(), &[0], &2i32.to_le_bytes(), &[0, 0, 0, 0], &1i32.to_le_bytes(), &1i32.to_le_bytes()].concat()).chain([0]).collect();
        let window: Vec<u8> = [0i32, 5, 1, 6].iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut out = [&MAGIC[..], &2u32.to_le_bytes()].concat();
        out.extend(attribute("channels", "chlist", &chlist));
        out.extend(attribute("compression", "compression", &[compression]));
        out.extend(attribute("dataWindow", "box2i", &window));
        out.extend(attribute("lineOrder", "lineOrder", &[0]));
        out.push(0);
        let chunks: Vec<Vec<u8>> = lines.iter().enumerate().map(|(y, line)| {
            let data: Vec<u8> = (0..3).rev().flat_map(|c| line.iter().flat_map(move |t| t[c].to_le_bytes())).collect();
            [&(5 + y as i32).to_le_bytes()[..], &(data.len() as u32).to_le_bytes(), &data].concat()
        }).collect();
        let mut offset = (out.len() + 16) as u64;
        for c in &chunks {
            out.extend(offset.to_le_bytes());
            offset += c.len() as u64;
        }
        out.extend(chunks.concat());
        out
    }

    #[test]
    fn an_uncompressed_float_image_is_read_as_written() {
        let lines = [[[1.0, 2.0, 3.0], [0.5, 0.25, 0.125]], [[1e-3, 7.0, 65504.0], [0.0, -1.0, 3.5]]];
        let (w, h, texels) = read(&two_by_two(0, lines)).unwrap();
        assert_eq!((w, h), (2, 2));
        let want: Vec<[f32; 4]> = lines.iter().flatten().map(|t| [t[0], t[1], t[2], 1.0]).collect();
        assert_eq!(texels, want);
    }

    #[test]
    fn the_predictor_and_the_interleaving_are_undone() {
        // bytes 10, 20, 30, 40, 50 interleaved (10, 30, 50, 20, 40), then differences + 128
        let stored = [10u8, 148, 148, 98, 148];
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        std::io::Write::write_all(&mut z, &stored).unwrap();
        assert_eq!(uncompress(Compression::Zips, &z.finish().unwrap(), 5).unwrap(), [10, 20, 30, 40, 50]);
        // RLE: 10 twice (count 1), then three literals (count −3): 10, 10, 1, 2, 3; with the
        // predictor undone 10, 148, 21, 151, 26, and de-interleaved
        assert_eq!(uncompress(Compression::Rle, &[1, 10, 0xfd, 1, 2, 3], 5).unwrap(), [10, 151, 148, 26, 21]);
        // five repeats of 10 (count 4): 10, 148, 30, 168, 50 → 10, 168, 148, 50, 30
        assert_eq!(uncompress(Compression::Rle, &[4, 10], 5).unwrap(), [10, 168, 148, 50, 30]);
        assert!(uncompress(Compression::Rle, &[4, 10], 6).unwrap_err().contains("expands to 5 bytes"));
    }

    #[test]
    fn what_lobes_does_not_read_is_named() {
        let mut piz = two_by_two(4, [[[0.0; 3]; 2]; 2]);
        assert!(read(&piz).unwrap_err().contains("compression is PIZ"));
        piz[5] = 0x02; // the tiled flag, bit 9
        assert!(read(&piz).unwrap_err().contains("tiled"));
        assert!(read(b"#?RADIANCE").unwrap_err().contains("not an OpenEXR image"));
        let cut = two_by_two(0, [[[1.0; 3]; 2]; 2]);
        assert!(read(&cut[..cut.len() - 3]).unwrap_err().contains("cut short"));
    }
}
