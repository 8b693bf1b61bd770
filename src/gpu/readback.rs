//! Read-back of textures to the CPU: the one place that knows wgpu's 256-byte row alignment. The runner reads
//! the method and reference frames through it (`--dump-frames`, `--metrics flip`), FSI its LOD buffers.

use crate::error::Result;
use crate::gpu::context::GpuContext;
use crate::gpu::targets::RenderTarget;

/// A mappable buffer that one plane of a texture is copied into (rows padded to
/// `wgpu::COPY_BYTES_PER_ROW_ALIGNMENT`), and read back tightly packed.
pub struct TextureReadback {
    pub buffer: wgpu::Buffer,
    pub padded_row: u32,
    pub width: u32,
    pub height: u32,
    pub bytes_per_texel: u32,
}

impl TextureReadback {
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        width: u32,
        height: u32,
        bytes_per_texel: u32,
    ) -> Self {
        let padded_row = (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        TextureReadback {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: padded_row as u64 * height as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            padded_row,
            width,
            height,
            bytes_per_texel,
        }
    }

    /// A read-back of a render target's colour (RGBA8, sRGB-encoded bytes).
    pub fn color(device: &wgpu::Device, label: &str, width: u32, height: u32) -> Self {
        Self::new(device, label, width, height, 4)
    }

    /// Records the copy of `aspect` of `texture` (of this read-back's size) into the buffer.
    pub fn encode_copy_plane(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) {
        self.encode_copy_region(encoder, texture, aspect, [0, 0, self.width, self.height]);
    }

    /// Records the copy of a render target's colour.
    pub fn encode_copy(&self, encoder: &mut wgpu::CommandEncoder, target: &RenderTarget) {
        self.encode_copy_plane(encoder, &target.color, wgpu::TextureAspect::All);
    }

    /// Records the copy of the rectangle `rect`, `[x, y, width, height]` (within this read-back's size), of a
    /// render target's colour into the buffer, its rows from the buffer's start ([`TextureReadback::read_rect`]).
    pub fn encode_copy_rect(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        rect: [u32; 4],
    ) {
        self.encode_copy_region(encoder, &target.color, wgpu::TextureAspect::All, rect);
    }

    /// The rows of a rectangle `width` texels wide, padded to the copy alignment (no wider than `padded_row`).
    fn padded_row_of(&self, width: u32) -> u32 {
        (width * self.bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
    }

    fn encode_copy_region(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
        [x, y, width, height]: [u32; 4],
    ) {
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row_of(width)),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
    }

    /// The copied plane, tightly packed, after the copy's submission (waits for the GPU).
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<u8>> {
        self.read_rect(ctx, [0, 0, self.width, self.height])
    }

    /// The rectangle `rect` copied by [`TextureReadback::encode_copy_rect`], tightly packed, after the copy's
    /// submission (waits for the GPU).
    pub fn read_rect(&self, ctx: &GpuContext, [_, _, width, height]: [u32; 4]) -> Result<Vec<u8>> {
        let (h, row) = (height as usize, self.padded_row_of(width) as usize);
        let tight = (width * self.bytes_per_texel) as usize;
        ctx.read_buffer(&self.buffer, |bytes| {
            let mut out = Vec::with_capacity(tight * h);
            for y in 0..h {
                out.extend_from_slice(&bytes[y * row..y * row + tight]);
            }
            out
        })
    }
}

/// Copies one plane of `texture` (`bytes_per_texel` bytes per texel) to the CPU now, tightly packed.
pub fn read_texture(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let rb = TextureReadback::new(
        &ctx.device,
        "texture read-back",
        texture.width(),
        texture.height(),
        bytes_per_texel,
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    rb.encode_copy_plane(&mut encoder, texture, aspect);
    ctx.queue.submit([encoder.finish()]);
    rb.read(ctx)
}
