//! RGBA8 pictures in memory and in files: PNG, JPEG and WebP read (glTF textures, lodbench's own dumps), PNG and
//! GIF written. The codec crates are used directly (`png`, `zune-jpeg`, `image-webp`, `gif`): the `image` crate
//! wrapped the same decoders and added a colour-management stack lodbench never called, a quarter of the release
//! build's compile time. What it did with the decoded samples is kept: 16-bit samples round to 8 bits as
//! (v + 128) / 257, grey is repeated into R, G and B, a missing alpha is 255, a palette is expanded.

use crate::error::{Error, Result};
use std::path::Path;

/// One pixel's R, G, B and A.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgba(pub [u8; 4]);

impl std::ops::Index<usize> for Rgba {
    type Output = u8;
    fn index(&self, c: usize) -> &u8 {
        &self.0[c]
    }
}

/// A picture of RGBA8 pixels, row-major from the top left.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbaImage {
    width: u32,
    height: u32,
    data: Vec<u8>,
}

/// Largest decoded picture read, in bytes (the `image` crate's default limit): a file whose header asks for
/// more is refused before anything is allocated.
pub const MAX_DECODED_BYTES: u64 = 512 << 20;

impl RgbaImage {
    /// A picture of transparent black.
    pub fn new(width: u32, height: u32) -> RgbaImage {
        RgbaImage::from_pixel(width, height, Rgba([0; 4]))
    }

    /// A picture of one colour.
    pub fn from_pixel(width: u32, height: u32, p: Rgba) -> RgbaImage {
        let n = width as usize * height as usize;
        RgbaImage {
            width,
            height,
            data: p.0.repeat(n),
        }
    }

    /// The picture of `data` (RGBA8, row-major); None unless it holds exactly `width` x `height` pixels.
    pub fn from_raw(width: u32, height: u32, data: Vec<u8>) -> Option<RgbaImage> {
        (data.len() == width as usize * height as usize * 4).then_some(RgbaImage {
            width,
            height,
            data,
        })
    }

    /// The picture whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> Rgba) -> RgbaImage {
        let mut data = Vec::with_capacity(width as usize * height as usize * 4);
        for y in 0..height {
            for x in 0..width {
                data.extend_from_slice(&f(x, y).0);
            }
        }
        RgbaImage {
            width,
            height,
            data,
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn dimensions(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside the picture"
        );
        self.index_unchecked(x, y)
    }

    /// Pixel (x, y); panics outside the picture, as slice indexing does.
    pub fn get_pixel(&self, x: u32, y: u32) -> Rgba {
        let i = self.index(x, y);
        let mut p = [0; 4];
        p.copy_from_slice(&self.data[i..i + 4]);
        Rgba(p)
    }

    /// Sets pixel (x, y); panics outside the picture, as slice indexing does.
    pub fn put_pixel(&mut self, x: u32, y: u32, p: Rgba) {
        let i = self.index(x, y);
        self.data[i..i + 4].copy_from_slice(&p.0);
    }

    /// The pixels, row by row.
    pub fn pixels(&self) -> impl Iterator<Item = Rgba> + '_ {
        self.data
            .chunks_exact(4)
            .map(|c| Rgba([c[0], c[1], c[2], c[3]]))
    }

    /// The pixels, row by row, each with its (x, y).
    pub fn enumerate_pixels(&self) -> impl Iterator<Item = (u32, u32, Rgba)> + '_ {
        let w = self.width.max(1);
        self.pixels()
            .enumerate()
            .map(move |(i, p)| (i as u32 % w, i as u32 / w, p))
    }

    /// The RGBA8 bytes.
    pub fn as_raw(&self) -> &[u8] {
        &self.data
    }

    pub fn into_raw(self) -> Vec<u8> {
        self.data
    }

    /// Writes the picture to the PNG file `path` ([`Packing::Balanced`]); an error names the file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        write_png(
            path.as_ref(),
            self.width,
            self.height,
            &self.data,
            Packing::Balanced,
        )
    }

    /// The `w` x `h` pixels from (x, y), clipped to the picture.
    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> RgbaImage {
        let (x, y) = (x.min(self.width), y.min(self.height));
        let (w, h) = (w.min(self.width - x), h.min(self.height - y));
        let mut data = Vec::with_capacity(w as usize * h as usize * 4);
        for row in y..y + h {
            let start = self.index_unchecked(x, row);
            data.extend_from_slice(&self.data[start..start + w as usize * 4]);
        }
        RgbaImage {
            width: w,
            height: h,
            data,
        }
    }

    fn index_unchecked(&self, x: u32, y: u32) -> usize {
        (y as usize * self.width as usize + x as usize) * 4
    }

    /// Copies `top` over this picture with its top-left pixel at (x, y); what falls outside is left out.
    pub fn replace(&mut self, top: &RgbaImage, x: i64, y: i64) {
        for ty in 0..top.height {
            let py = y + i64::from(ty);
            if py < 0 || py >= i64::from(self.height) {
                continue;
            }
            let x0 = x.max(0);
            let x1 = (x + i64::from(top.width)).min(i64::from(self.width));
            if x0 >= x1 {
                continue;
            }
            let n = (x1 - x0) as usize * 4;
            let src = top.index_unchecked((x0 - x) as u32, ty);
            let dst = self.index_unchecked(x0 as u32, py as u32);
            self.data[dst..dst + n].copy_from_slice(&top.data[src..src + n]);
        }
    }
}

/// An encoded picture's format, from its first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Png,
    Jpeg,
    WebP,
    /// Formats lodbench does not read, named in its refusals.
    Other(&'static str),
}

/// The format of encoded bytes, from their signature; None when it is none of those known.
pub fn format_of(bytes: &[u8]) -> Option<Format> {
    const SIGNATURES: [(&[u8], usize, Format); 9] = [
        (b"\x89PNG\r\n\x1a\n", 0, Format::Png),
        (b"\xff\xd8\xff", 0, Format::Jpeg),
        (b"WEBP", 8, Format::WebP),
        (b"ftypavif", 4, Format::Other("AVIF")),
        (b"GIF8", 0, Format::Other("GIF")),
        (b"BM", 0, Format::Other("BMP")),
        (b"II*\0", 0, Format::Other("TIFF")),
        (b"MM\0*", 0, Format::Other("TIFF")),
        (b"\xABKTX 20\xBB", 0, Format::Other("KTX2")),
    ];
    let riff = bytes.starts_with(b"RIFF");
    SIGNATURES
        .iter()
        .find(|(sig, at, f)| {
            (*f != Format::WebP || riff) && bytes.get(*at..*at + sig.len()) == Some(*sig)
        })
        .map(|s| s.2)
}

/// PNG, JPEG or WebP bytes as RGBA8; the error says what is wrong with them.
pub fn decode(bytes: &[u8]) -> std::result::Result<RgbaImage, String> {
    match format_of(bytes) {
        Some(Format::Png) => decode_png(bytes),
        Some(Format::Jpeg) => decode_jpeg(bytes),
        Some(Format::WebP) => decode_webp(bytes),
        Some(Format::Other(name)) => Err(format!("it is {name}, not PNG, JPEG or WebP")),
        None => Err("its format is none lodbench knows (not PNG, JPEG or WebP)".into()),
    }
}

/// Refuses a picture whose decoded size passes [`MAX_DECODED_BYTES`].
fn check_size(width: u32, height: u32) -> std::result::Result<(), String> {
    let bytes = u64::from(width) * u64::from(height) * 4;
    if bytes > MAX_DECODED_BYTES {
        return Err(format!(
            "{width}x{height} pixels decode to {bytes} bytes, over the {MAX_DECODED_BYTES} lodbench reads"
        ));
    }
    Ok(())
}

/// Samples of `channels` per pixel (grey, grey and alpha, RGB or RGBA) as RGBA8.
fn to_rgba(width: u32, height: u32, samples: &[u8], channels: usize) -> RgbaImage {
    let data = match channels {
        1 => samples.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        2 => samples
            .chunks_exact(2)
            .flat_map(|c| [c[0], c[0], c[0], c[1]])
            .collect(),
        3 => samples
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        _ => samples.to_vec(),
    };
    RgbaImage {
        width,
        height,
        data,
    }
}

fn decode_png(bytes: &[u8]) -> std::result::Result<RgbaImage, String> {
    let limits = png::Limits {
        bytes: MAX_DECODED_BYTES as usize,
    };
    let mut decoder = png::Decoder::new_with_limits(std::io::Cursor::new(bytes), limits);
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let (width, height) = (reader.info().width, reader.info().height);
    check_size(width, height)?;
    let size = reader
        .output_buffer_size()
        .ok_or("its size overflows memory")?;
    let mut buf = vec![0; size];
    let frame = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    buf.truncate(frame.buffer_size());
    let channels = frame.color_type.samples();
    if frame.bit_depth == png::BitDepth::Sixteen {
        // Big-endian 16-bit samples, rounded to 8 bits.
        buf = buf
            .chunks_exact(2)
            .map(|c| ((u32::from(u16::from_be_bytes([c[0], c[1]])) + 128) / 257) as u8)
            .collect();
    }
    Ok(to_rgba(width, height, &buf, channels))
}

fn decode_jpeg(bytes: &[u8]) -> std::result::Result<RgbaImage, String> {
    use zune_jpeg::zune_core::bytestream::ZCursor;
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let options = DecoderOptions::default()
        .set_strict_mode(false)
        .set_max_width(usize::MAX)
        .set_max_height(usize::MAX);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder.decode_headers().map_err(|e| e.to_string())?;
    let (w, h) = decoder.dimensions().ok_or("it has no frame header")?;
    let (width, height) = (w as u32, h as u32);
    check_size(width, height)?;
    let source = decoder.input_colorspace().ok_or("it has no colour space")?;
    // Grey and RGB as they are; YCbCr, CMYK and the rest converted to RGB by the decoder.
    let out = match source {
        ColorSpace::RGB | ColorSpace::RGBA | ColorSpace::Luma | ColorSpace::LumaA => source,
        _ => ColorSpace::RGB,
    };
    decoder.set_options(decoder.options().jpeg_set_out_colorspace(out));
    let samples = decoder.decode().map_err(|e| e.to_string())?;
    Ok(to_rgba(width, height, &samples, out.num_components()))
}

fn decode_webp(bytes: &[u8]) -> std::result::Result<RgbaImage, String> {
    let mut decoder =
        image_webp::WebPDecoder::new(std::io::Cursor::new(bytes)).map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions();
    check_size(width, height)?;
    let size = decoder
        .output_buffer_size()
        .ok_or("its size overflows memory")?;
    let mut buf = vec![0; size];
    decoder.read_image(&mut buf).map_err(|e| e.to_string())?;
    let channels = if decoder.has_alpha() { 4 } else { 3 };
    Ok(to_rgba(width, height, &buf, channels))
}

/// The picture in the file `path` (PNG, JPEG or WebP); an error names the file.
pub fn read(path: impl AsRef<Path>) -> Result<RgbaImage> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    decode(&bytes).map_err(|e| Error::image(path, e))
}

/// How hard a PNG is compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Packing {
    /// The `png` crate's fastest level (fdeflate): textures a glTF file carries, written once and read back.
    Fast,
    /// Its balanced level: dumps, written many a run.
    Balanced,
    /// Its best: grids of flat colour and upscaled blocks, about 3 times smaller.
    Best,
}

/// `rgba` (`width` x `height` RGBA8 pixels) as PNG bytes into `out`, adaptive filtering.
fn encode_png(
    out: impl std::io::Write,
    (width, height): (u32, u32),
    rgba: &[u8],
    packing: Packing,
) -> std::result::Result<(), png::EncodingError> {
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(match packing {
        Packing::Fast => png::Compression::Fast,
        Packing::Balanced => png::Compression::Balanced,
        Packing::Best => png::Compression::High,
    });
    encoder.set_filter(png::Filter::Adaptive);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgba)?;
    writer.finish()
}

/// `rgba` (`width` x `height` RGBA8 pixels) as the bytes of a PNG file.
pub fn png_bytes(width: u32, height: u32, rgba: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::new();
    encode_png(&mut out, (width, height), rgba, Packing::Fast).map_err(|e| e.to_string())?;
    Ok(out)
}

/// Writes `rgba` (`width` x `height` RGBA8 pixels) to the PNG file `path`; an error names the file.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[u8],
    packing: Packing,
) -> Result<()> {
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut out = std::io::BufWriter::new(file);
    encode_png(&mut out, (width, height), rgba, packing).map_err(|e| Error::image(path, e))?;
    std::io::Write::flush(&mut out).map_err(|e| Error::io(path, e))
}

/// A looping GIF of `frames` (all one size) at `fps`, each frame's palette by NeuQuant at speed 10 (the `gif`
/// crate's), as the `image` crate wrote it.
pub fn write_gif(path: &Path, frames: &[RgbaImage], fps: u32) -> Result<()> {
    let Some(first) = frames.first() else {
        return Ok(());
    };
    let side = |v: u32| {
        u16::try_from(v).map_err(|_| Error::image(path, "over 65535 pixels a side for a GIF"))
    };
    let (w, h) = (side(first.width)?, side(first.height)?);
    let gif_error = |e: gif::EncodingError| Error::image(path, e);
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut encoder =
        gif::Encoder::new(std::io::BufWriter::new(file), w, h, &[]).map_err(gif_error)?;
    encoder
        .set_repeat(gif::Repeat::Infinite)
        .map_err(gif_error)?;
    // Centiseconds, rounded down, of 1000 / fps milliseconds rounded down.
    let delay = u16::try_from(1000 / fps.max(1) / 10).unwrap_or(u16::MAX);
    for f in frames {
        let mut rgba = f.data.clone();
        let mut frame = gif::Frame::from_rgba_speed(side(f.width)?, side(f.height)?, &mut rgba, 10);
        frame.delay = delay;
        frame.dispose = gif::DisposalMethod::Background;
        encoder.write_frame(&frame).map_err(gif_error)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PNG bytes of one colour type and depth, written by the `png` crate.
    fn png_of(
        color: png::ColorType,
        depth: png::BitDepth,
        w: u32,
        h: u32,
        samples: &[u8],
    ) -> Vec<u8> {
        let mut out = Vec::new();
        let mut e = png::Encoder::new(&mut out, w, h);
        e.set_color(color);
        e.set_depth(depth);
        let mut writer = e.write_header().unwrap();
        writer.write_image_data(samples).unwrap();
        writer.finish().unwrap();
        out
    }

    /// Each PNG colour type and depth glTF files carry reads as RGBA8 the way the `image` crate converted it:
    /// grey repeated, alpha 255 where there is none, 16-bit samples rounded by (v + 128) / 257.
    #[test]
    fn png_colour_types_read_as_rgba8() {
        use png::{BitDepth::*, ColorType::*};
        let grey = png_of(Grayscale, Eight, 2, 1, &[7, 200]);
        assert_eq!(
            decode(&grey).unwrap().into_raw(),
            [7, 7, 7, 255, 200, 200, 200, 255]
        );
        let grey_alpha = png_of(GrayscaleAlpha, Eight, 1, 1, &[9, 30]);
        assert_eq!(decode(&grey_alpha).unwrap().into_raw(), [9, 9, 9, 30]);
        let rgb = png_of(Rgb, Eight, 1, 1, &[1, 2, 3]);
        assert_eq!(decode(&rgb).unwrap().into_raw(), [1, 2, 3, 255]);
        // (v + 128) / 257: 0x807f -> 128, 0x0081 -> 1 and 0x01ff -> 2 (the high byte alone: 0 and 1), 0xffff -> 255.
        let samples = [0x80, 0x7f, 0x00, 0x81, 0x01, 0xff, 0xff, 0xff];
        let deep = png_of(Rgba, Sixteen, 1, 1, &samples);
        assert_eq!(decode(&deep).unwrap().into_raw(), [128, 1, 2, 255]);
        let bits = png_of(Grayscale, One, 8, 1, &[0b1010_0000]);
        let px = decode(&bits).unwrap().into_raw();
        assert_eq!(&px[..8], [255, 255, 255, 255, 0, 0, 0, 255]);
    }

    /// A picture written as PNG reads back the same; formats lodbench does not read are named.
    #[test]
    fn a_png_round_trips_and_other_formats_are_named() {
        let img = RgbaImage::from_fn(3, 2, |x, y| Rgba([x as u8, y as u8, 9, 200]));
        let bytes = png_bytes(3, 2, img.as_raw()).unwrap();
        assert_eq!(decode(&bytes).unwrap(), img);
        assert_eq!(format_of(b"RIFF\0\0\0\0WEBPVP8 "), Some(Format::WebP));
        assert_eq!(
            format_of(b"\0\0\0\x1cftypavif"),
            Some(Format::Other("AVIF"))
        );
        assert!(decode(b"GIF89a").unwrap_err().contains("GIF"));
        assert!(decode(b"nothing")
            .unwrap_err()
            .contains("not PNG, JPEG or WebP"));
        assert!(decode(&bytes[..40]).is_err(), "a cut PNG");
    }

    /// A header asking for more than MAX_DECODED_BYTES is refused before the pixels are allocated.
    #[test]
    fn a_huge_header_is_refused() {
        let mut bytes = png_bytes(1, 1, &[0; 4]).unwrap();
        // IHDR's width and height (bytes 16..24), the chunk's CRC (29..33) made to match.
        bytes[16..20].copy_from_slice(&60000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&60000u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = decode(&bytes).unwrap_err();
        assert!(e.contains("60000x60000"), "{e}");
    }

    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    /// crop and replace keep pixels where they belong and clip at the edges.
    #[test]
    fn crop_and_replace_clip_at_the_edges() {
        let img = RgbaImage::from_fn(4, 3, |x, y| Rgba([x as u8, y as u8, 0, 255]));
        let c = img.crop(2, 1, 5, 5);
        assert_eq!(c.dimensions(), (2, 2));
        assert_eq!(c.get_pixel(1, 1), Rgba([3, 2, 0, 255]));
        let mut base = RgbaImage::new(3, 3);
        base.replace(&img, -2, 1);
        assert_eq!(base.get_pixel(0, 1), Rgba([2, 0, 0, 255]));
        assert_eq!(base.get_pixel(1, 2), Rgba([3, 1, 0, 255]));
        assert_eq!(base.get_pixel(2, 2), Rgba([0, 0, 0, 0]));
        assert_eq!(base.get_pixel(0, 0), Rgba([0, 0, 0, 0]));
    }
}
