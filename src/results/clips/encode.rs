//! The files of `lodbench clips` (`commands/clips.rs`): PNG frames read and written, and the animations: APNG
//! (the `png` crate), GIF (the `gif` crate, crate::raster) and MP4 (H.264 through `ffmpeg`, when it is on the PATH).

use crate::error::{Error, Result};
use crate::raster::{Packing, RgbaImage};
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

pub fn load(path: &Path) -> Result<RgbaImage> {
    crate::raster::read(path)
}

/// PNG at the best compression: the grids are mostly flat colour and upscaled blocks, which it packs about 3x
/// smaller than the default level.
pub fn save(path: &Path, img: &RgbaImage) -> Result<()> {
    let (w, h) = img.dimensions();
    crate::raster::write_png(path, w, h, img.as_raw(), Packing::Best)
}

/// An animated PNG (APNG) of `frames` (all one size), looping, with the `png` crate.
pub fn write_apng(path: &Path, frames: &[RgbaImage], fps: u32) -> Result<()> {
    let Some(first) = frames.first() else {
        return Ok(());
    };
    let png_error = |e: png::EncodingError| Error::image(path, e);
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut encoder =
        png::Encoder::new(std::io::BufWriter::new(file), first.width(), first.height());
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::High);
    encoder
        .set_animated(frames.len() as u32, 0)
        .map_err(png_error)?;
    encoder
        .set_frame_delay(1, fps.min(u16::MAX as u32) as u16)
        .map_err(png_error)?;
    let mut writer = encoder.write_header().map_err(png_error)?;
    for f in frames {
        writer.write_image_data(f.as_raw()).map_err(png_error)?;
    }
    writer.finish().map_err(png_error)
}

pub fn write_gif(path: &Path, frames: &[RgbaImage], fps: u32) -> Result<()> {
    crate::raster::write_gif(path, frames, fps)
}

pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// H.264 (yuv420p, CRF 18) through `ffmpeg`, the frames piped in as raw RGBA.
pub fn write_mp4(path: &Path, frames: &[RgbaImage], fps: u32) -> Result<()> {
    let Some(first) = frames.first() else {
        return Ok(());
    };
    let size = format!("{}x{}", first.width(), first.height());
    let mut child = Command::new("ffmpeg")
        .args([
            "-loglevel",
            "error",
            "-y",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgba",
        ])
        .args(["-s", &size, "-r", &fps.to_string(), "-i", "-"])
        .args(["-c:v", "libx264", "-crf", "18", "-pix_fmt", "yuv420p"])
        .args(["-movflags", "+faststart"])
        .arg(path)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| Error::io(Path::new("ffmpeg"), e))?;
    if let Some(mut stdin) = child.stdin.take() {
        for f in frames {
            stdin
                .write_all(f.as_raw())
                .map_err(|e| Error::io(path, e))?;
        }
    }
    let output = child
        .wait_with_output()
        .map_err(|e| Error::io(Path::new("ffmpeg"), e))?;
    if !output.status.success() {
        return Err(Error::image(
            path,
            format!(
                "ffmpeg failed: {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ),
        ));
    }
    Ok(())
}
