//! PNG encoding of the rendered reports, by `image`.

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, RgbImage};

/// The PNG file of `img`.
pub fn encode(img: &RgbImage) -> image::ImageResult<Vec<u8>> {
    let mut buf = Vec::new();
    PngEncoder::new(&mut buf).write_image(img.as_raw(), img.width(), img.height(), ExtendedColorType::Rgb8)?;
    Ok(buf)
}
