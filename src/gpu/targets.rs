//! Render targets: the colour and depth attachments of one viewport.

use crate::formats::{COLOR_FORMAT, DEPTH_FORMAT};

/// A `width` x `height` 2D texture, one mip level, one sample: every texture lodbench makes.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// What an attachment that is also read (a shader's texture) and read back is made for.
pub const ATTACHMENT_READ: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// Colour (sRGB) and depth attachments of one viewport. The colour texture can also be viewed as plain
/// Rgba8Unorm, which is how the metric kernels read the stored sRGB-encoded bytes.
pub struct RenderTarget {
    pub width: u32,
    pub height: u32,
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    pub color_bytes_view: wgpu::TextureView,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
}

impl RenderTarget {
    pub fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> RenderTarget {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let color = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{label} colour")),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[wgpu::TextureFormat::Rgba8Unorm],
        });
        let depth = texture_2d(
            device,
            &format!("{label} depth"),
            (width, height),
            DEPTH_FORMAT,
            ATTACHMENT_READ,
        );
        RenderTarget {
            width,
            height,
            color_view: color.create_view(&Default::default()),
            color_bytes_view: color.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{label} colour bytes")),
                format: Some(wgpu::TextureFormat::Rgba8Unorm),
                ..Default::default()
            }),
            depth_view: depth.create_view(&Default::default()),
            color,
            depth,
        }
    }

    /// Records a copy of this target's colour into `to`'s (the same size).
    pub fn copy_color_to(&self, encoder: &mut wgpu::CommandEncoder, to: &RenderTarget) {
        encoder.copy_texture_to_texture(
            self.color.as_image_copy(),
            to.color.as_image_copy(),
            wgpu::Extent3d {
                width: self.width.min(to.width),
                height: self.height.min(to.height),
                depth_or_array_layers: 1,
            },
        );
    }

    /// Writes `rgba` (tightly packed RGBA8, `width` x `height`, sRGB-encoded bytes) into this target's colour
    /// through `queue`: synthetic frames for the metric kernel's bench and tests.
    pub fn write_color(&self, queue: &wgpu::Queue, rgba: &[u8]) {
        queue.write_texture(
            self.color.as_image_copy(),
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(self.width * 4),
                rows_per_image: Some(self.height),
            },
            self.color.size(),
        );
    }

    /// Bytes of colour and depth this target holds.
    pub fn bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * 8
    }
}
