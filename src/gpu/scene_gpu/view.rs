//! What a pass sees of the frame beyond its instances: the shadow map its shading reads and its scissor.

/// One of the scene's shadow maps: the one a shadow pass writes, and the one draws are lit by. The layer above
/// decides what each map stands for; the GPU layer only keeps them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShadowMap(usize);

impl ShadowMap {
    /// The 1x1 placeholder: draws with shadows off, and the shadow passes themselves (so the map being written
    /// is never the one bound).
    pub const NONE: ShadowMap = ShadowMap(0);

    /// The `i`-th of the maps a scene with `--shadows on` has ([`SceneGpu::with_shadow_maps`]).
    pub const fn lit(i: usize) -> ShadowMap {
        ShadowMap(i + 1)
    }

    /// Index into `SceneGpu::shadows`' views and maps, and the camera's bind groups.
    pub fn index(self) -> usize {
        self.0
    }
}

/// What a pass sees of the frame beyond its instances: the shadow map its shading reads (the camera bind group
/// with that map, group 0) and the scissor rectangle `[x, y, width, height]` its colour passes draw within (None:
/// the whole target; clears still cover the whole target). The quality pass draws one frame under several views
/// (the method's, the reference's, lodpop's counterfactual inside the rectangle where it can differ); the view
/// travels with the frame's input (`FrameInput::view`) to every pass begun for it ([`SceneGpu::begin_pass`]).
/// `count_fragments`: the passes begun for it count their fragments ([`crate::gpu::fragments`]): the quality
/// pass's view of the method's own frame, never a timed frame's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct View {
    pub shadow: ShadowMap,
    pub scissor: Option<[u32; 4]>,
    pub count_fragments: bool,
}

impl View {
    /// The whole target, lit by shadow map `shadow`.
    pub const fn lit_by(shadow: ShadowMap) -> View {
        View {
            shadow,
            scissor: None,
            count_fragments: false,
        }
    }

    /// This view with the fragments of its passes counted.
    pub fn counting_fragments(self) -> View {
        View {
            count_fragments: true,
            ..self
        }
    }

    /// This view with its colour passes limited to `rect`, `[x, y, width, height]`.
    pub fn scissored(self, rect: [u32; 4]) -> View {
        View {
            scissor: Some(rect),
            ..self
        }
    }
}
