//! Render passes begun for a view: cleared or loaded, colour and depth or depth alone, its shadow map bound,
//! its scissor set, its fragments counted where the view asks ([`crate::gpu::fragments`]).

use crate::gpu::fragments::Pass;
use crate::gpu::scene_gpu::build::SceneGpu;
use crate::gpu::scene_gpu::view::View;
use crate::gpu::targets::RenderTarget;
use crate::scene::BACKGROUND;

impl SceneGpu {
    /// `pass`, begun for `view`, with a fragment query in it where the view counts fragments and the device can
    /// ([`FragmentQueries`](super::fragments::FragmentQueries)): for a pass a method begins itself.
    pub fn counted<'e>(&self, view: View, pass: wgpu::RenderPass<'e>) -> Pass<'e> {
        match &self.fragments {
            Some(f) if view.count_fragments => f.wrap(pass),
            _ => Pass::plain(pass),
        }
    }

    /// Begins a pass of `view` that clears `target` to the background and its depth to 1.
    pub fn begin_clear_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        target: &RenderTarget,
        view: View,
        label: &str,
    ) -> Pass<'e> {
        let views = (&target.color_view, &target.depth_view);
        self.begin_pass(encoder, views, view, label, true)
    }

    /// A depth-only pass of `view` into `depth`, cleared to 1 (alpha-2pass's nearest surface, the shadow pass),
    /// with the camera bind group of the view's shadow map bound (the scissor is for colour passes).
    pub fn begin_depth_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
        view: View,
        label: &str,
    ) -> Pass<'e> {
        let mut pass = self.counted(
            view,
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            }),
        );
        pass.set_bind_group(0, self.camera_group(view.shadow), &[]);
        pass
    }

    /// Begins a pass of `view` on a colour and a depth view, clearing both (`clear`) or keeping what they hold:
    /// the camera bind group of the view's shadow map bound, the view's scissor set.
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        (color, depth): (&wgpu::TextureView, &wgpu::TextureView),
        view: View,
        label: &str,
        clear: bool,
    ) -> Pass<'e> {
        let [r, g, b] = BACKGROUND;
        let color_load = if clear {
            wgpu::LoadOp::Clear(wgpu::Color {
                r: r as f64,
                g: g as f64,
                b: b as f64,
                a: 1.0,
            })
        } else {
            wgpu::LoadOp::Load
        };
        let mut pass = self.counted(
            view,
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: color,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: color_load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
                    depth_ops: Some(wgpu::Operations {
                        load: if clear {
                            wgpu::LoadOp::Clear(1.0)
                        } else {
                            wgpu::LoadOp::Load
                        },
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            }),
        );
        self.apply_view(&mut pass, view);
        pass
    }

    /// Sets `view` on a colour pass begun elsewhere than [`SceneGpu::begin_pass`] (a method's own attachments):
    /// the camera bind group of its shadow map, and its scissor.
    pub fn apply_view(&self, pass: &mut wgpu::RenderPass<'_>, view: View) {
        pass.set_bind_group(0, self.camera_group(view.shadow), &[]);
        if let Some([x, y, w, h]) = view.scissor {
            pass.set_scissor_rect(x, y, w, h);
        }
    }
}
