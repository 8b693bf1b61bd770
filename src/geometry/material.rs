//! Materials as glTF 2.0 defines them (section 3.9, the core metallic-roughness model) and the images they
//! sample: what a user scene's triangles are drawn with. The built-in scenes have none (they are drawn in one
//! colour per instance, Lambert and ambient, as the papers' figures were).

/// `--materials`: how a user scene's triangles are drawn.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum MaterialMode {
    /// The file's materials: glTF's metallic-roughness model with its textures, normal maps, alpha modes and
    /// vertex colours, lit by one directional light and a uniform ambient (`shaders/surface_pbr.wgsl`).
    #[default]
    Full,
    /// One colour per model (its first material's base colour factor), Lambert and ambient, no texture read: the
    /// built-in scenes' look, the silhouette's popping alone.
    Flat,
}

/// How a material's alpha is used (glTF 2.0 section 3.9.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlphaMode {
    /// Alpha ignored: the surface is opaque.
    Opaque,
    /// Cut out: a fragment whose alpha is below the cutoff is discarded, every other one is opaque.
    Mask(f32),
    /// Blended over what lies behind it ("over" compositing), drawn after the opaque surfaces.
    Blend,
}

/// A sampler's wrap mode along one texture axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Wrap {
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A texture filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Filter {
    Nearest,
    Linear,
}

/// A glTF sampler: wrap modes and filters (mipmaps: the filter between levels; None = level 0 only).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    pub mag: Filter,
    pub min: Filter,
    pub mipmap: Option<Filter>,
}

impl Default for Sampler {
    /// What a texture without a sampler, or a sampler that leaves a filter undefined, gets: repeat, trilinear
    /// (glTF leaves undefined filters to the implementation; three.js, Babylon.js and the Khronos sample viewer
    /// use these).
    fn default() -> Self {
        Sampler {
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmap: Some(Filter::Linear),
        }
    }
}

/// A material's use of a texture: the image, how it is sampled, which texture coordinates, and the
/// KHR_texture_transform of them.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureRef {
    /// Index into [`Materials::images`].
    pub image: u32,
    pub sampler: Sampler,
    /// TEXCOORD_0 or TEXCOORD_1.
    pub texcoord: u8,
    /// KHR_texture_transform as the rows of a 2x3 matrix: uv' = (r0 . (u, v, 1), r1 . (u, v, 1)); the identity
    /// without the extension.
    pub transform: [[f32; 3]; 2],
}

/// The identity texture transform.
pub const IDENTITY_TRANSFORM: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

impl TextureRef {
    /// KHR_texture_transform's matrix: translation x rotation x scale, the rotation's rows [cos, sin] and
    /// [-sin, cos]: the extension's GLSL listing, `mat3(cos, sin, 0, -sin, cos, 0, 0, 0, 1)`, read row by row. Read
    /// column-major (as GLSL would), it turns the other way, and Khronos's TextureTransformTest shows its red
    /// marker ("the rotation was applied in the opposite direction"); three.js and the Khronos Sample Viewer turn
    /// as here.
    pub fn transform_of(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [[f32; 3]; 2] {
        let (s, c) = rotation.sin_cos();
        [
            [c * scale[0], s * scale[1], offset[0]],
            [-s * scale[0], c * scale[1], offset[1]],
        ]
    }

    /// The transformed texture coordinate.
    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let [a, b] = self.transform;
        [
            a[0] * uv[0] + a[1] * uv[1] + a[2],
            b[0] * uv[0] + b[1] * uv[1] + b[2],
        ]
    }
}

/// One material: the core metallic-roughness model and the few extensions that change only its factors
/// (KHR_materials_emissive_strength, KHR_materials_unlit).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    /// Linear RGBA.
    pub base_color: [f32; 4],
    pub base_color_texture: Option<TextureRef>,
    pub metallic: f32,
    pub roughness: f32,
    /// Roughness in G, metalness in B.
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// Occlusion in R.
    pub occlusion_texture: Option<TextureRef>,
    pub occlusion_strength: f32,
    /// Linear RGB, KHR_materials_emissive_strength applied.
    pub emissive: [f32; 3],
    pub emissive_texture: Option<TextureRef>,
    pub alpha: AlphaMode,
    pub double_sided: bool,
    /// KHR_materials_unlit: the base colour is the colour.
    pub unlit: bool,
}

impl Default for Material {
    /// glTF's default material (section 3.9.6): white, fully metallic and rough, opaque, single-sided.
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: [1.0; 4],
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive: [0.0; 3],
            emissive_texture: None,
            alpha: AlphaMode::Opaque,
            double_sided: false,
            unlit: false,
        }
    }
}

impl Material {
    /// Every texture the material samples, with what it holds.
    pub fn textures(&self) -> impl Iterator<Item = (TextureSlot, &TextureRef)> {
        [
            (TextureSlot::BaseColor, &self.base_color_texture),
            (
                TextureSlot::MetallicRoughness,
                &self.metallic_roughness_texture,
            ),
            (TextureSlot::Normal, &self.normal_texture),
            (TextureSlot::Occlusion, &self.occlusion_texture),
            (TextureSlot::Emissive, &self.emissive_texture),
        ]
        .into_iter()
        .filter_map(|(slot, t)| t.as_ref().map(|t| (slot, t)))
    }

    /// Whether the material needs tangents (a normal map).
    pub fn needs_tangents(&self) -> bool {
        self.normal_texture.is_some() && !self.unlit
    }
}

/// What a texture slot holds, which decides the colour space its image is read in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TextureSlot {
    BaseColor,
    MetallicRoughness,
    Normal,
    Occlusion,
    Emissive,
}

impl TextureSlot {
    /// Colour textures are sRGB-encoded; the others hold data, read linearly (glTF 2.0 section 3.9.2).
    pub fn is_srgb(self) -> bool {
        matches!(self, TextureSlot::BaseColor | TextureSlot::Emissive)
    }
}

/// A decoded image: RGBA8, rows top to bottom (glTF's texture coordinate origin is the top-left corner).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    /// The bytes it was decoded from and their MIME type, where glTF's core reads them (PNG or JPEG): what an
    /// exported file carries, so that it decodes to the same pixels without an encoder's time or size.
    pub encoded: Option<(Vec<u8>, &'static str)>,
}

/// A scene's materials and the images they sample. Material indices of [`crate::geometry::mesh::Part`] point
/// into `materials`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Materials {
    pub materials: Vec<Material>,
    pub images: Vec<Image>,
}

impl Materials {
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// Whether any material is alpha-tested (MASK).
    pub fn any_mask(&self) -> bool {
        self.materials
            .iter()
            .any(|m| matches!(m.alpha, AlphaMode::Mask(_)))
    }
}

/// Side of the split-sum table ([`dfg_table`]).
pub const DFG_SIDE: usize = 16;

/// The split-sum table of the GGX specular lobe (Karis 2013, "Real Shading in Unreal Engine 4"): for roughness
/// r = (i + 0.5) / 16 and n.v = (j + 0.5) / 16, at `[j * 16 + i]`, the scale A and the bias B of F0 in the
/// directional albedo `F0 A + F90 B` of the lobe (height-correlated Smith visibility, Schlick's Fresnel, alpha =
/// r^2), each the mean over 4096 Hammersley samples of the half vector drawn from the GGX distribution. The PBR
/// surface reads it bilinearly, as a texture would be (shaders/surface/pbr.wgsl, `env_brdf`).
pub fn dfg_table() -> Vec<[f32; 2]> {
    const SAMPLES: u32 = 4096;
    let mut out = Vec::with_capacity(DFG_SIDE * DFG_SIDE);
    for j in 0..DFG_SIDE {
        let nv = (j as f64 + 0.5) / DFG_SIDE as f64;
        for i in 0..DFG_SIDE {
            let r = (i as f64 + 0.5) / DFG_SIDE as f64;
            out.push(split_sum(r, nv, SAMPLES));
        }
    }
    out
}

/// One entry of [`dfg_table`]: the split sum's (A, B) at roughness `r` and n.v `nv`, from `samples` samples.
fn split_sum(r: f64, nv: f64, samples: u32) -> [f32; 2] {
    let a = r * r;
    let a2 = a * a;
    let v = [(1.0 - nv * nv).max(0.0).sqrt(), 0.0, nv];
    let (mut sa, mut sb) = (0.0f64, 0.0f64);
    for k in 0..samples {
        // Hammersley point: (k / n, radical inverse of k in base 2).
        let u = k as f64 / samples as f64;
        let w = k.reverse_bits() as f64 / 4_294_967_296.0;
        let phi = 2.0 * std::f64::consts::PI * u;
        let cos_t = ((1.0 - w) / (1.0 + (a2 - 1.0) * w)).sqrt();
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let h = [sin_t * phi.cos(), sin_t * phi.sin(), cos_t];
        let vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        let l = [
            2.0 * vh * h[0] - v[0],
            2.0 * vh * h[1] - v[1],
            2.0 * vh * h[2] - v[2],
        ];
        let (nl, nh) = (l[2], h[2]);
        if nl <= 0.0 || vh <= 0.0 {
            continue;
        }
        let vis = 0.5
            / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
        // The sample's weight: the BRDF x cos over the half vector's density, F left out (D cancels).
        let g = 4.0 * vis * nl * vh / nh;
        let fc = (1.0 - vh).powi(5);
        sa += (1.0 - fc) * g;
        sb += fc * g;
    }
    [(sa / samples as f64) as f32, (sb / samples as f64) as f32]
}

/// sRGB-encoded value (0..=1) to linear light (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light (0..=1) to the sRGB encoding.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The mipmap chain of an RGBA8 image, level 0 first, down to 1x1: each level the 2x2 box filter of the one
/// before (an odd side's last row or column averaged with itself), colour channels in linear light when `srgb`
/// (averaging encoded values darkens: a black and white checker must average to mid-grey light, 188 encoded,
/// not 128), alpha always linear.
pub fn mip_chain(width: u32, height: u32, rgba: &[u8], srgb: bool) -> Vec<(u32, u32, Vec<u8>)> {
    let decode: Vec<f32> = (0..256)
        .map(|b| {
            let c = b as f32 / 255.0;
            if srgb {
                srgb_to_linear(c)
            } else {
                c
            }
        })
        .collect();
    let encode = |v: f32| -> u8 {
        let c = if srgb { linear_to_srgb(v) } else { v };
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    let mut levels = vec![(width, height, rgba.to_vec())];
    let (mut w, mut h) = (width, height);
    let mut linear: Vec<f32> = rgba
        .chunks_exact(4)
        .flat_map(|p| {
            [
                decode[p[0] as usize],
                decode[p[1] as usize],
                decode[p[2] as usize],
                p[3] as f32 / 255.0,
            ]
        })
        .collect();
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = vec![0.0f32; (nw * nh * 4) as usize];
        for y in 0..nh {
            for x in 0..nw {
                let xs = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
                let ys = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
                for c in 0..4 {
                    let mut sum = 0.0;
                    for &sy in &ys {
                        for &sx in &xs {
                            sum += linear[((sy * w + sx) * 4 + c) as usize];
                        }
                    }
                    next[((y * nw + x) * 4 + c) as usize] = sum * 0.25;
                }
            }
        }
        let bytes = next
            .chunks_exact(4)
            .flat_map(|p| {
                [
                    encode(p[0]),
                    encode(p[1]),
                    encode(p[2]),
                    (p[3].clamp(0.0, 1.0) * 255.0).round() as u8,
                ]
            })
            .collect();
        levels.push((nw, nh, bytes));
        linear = next;
        (w, h) = (nw, nh);
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    /// KHR_texture_transform: the extension's own example (offset, rotation, scale) maps as its matrix says,
    /// and the identity leaves coordinates alone.
    #[test]
    fn texture_transform_is_translation_rotation_scale() {
        let t = TextureRef {
            image: 0,
            sampler: Sampler::default(),
            texcoord: 0,
            transform: TextureRef::transform_of(
                [0.5, 0.25],
                std::f32::consts::FRAC_PI_2,
                [2.0, 3.0],
            ),
        };
        // scale: (1, 1) -> (2, 3); rotation by +90 degrees: (x, y) -> (y, -x); then the offset.
        let [u, v] = t.apply([1.0, 1.0]);
        assert!((u - (3.0 + 0.5)).abs() < 1e-6, "{u}");
        assert!((v - (-2.0 + 0.25)).abs() < 1e-6, "{v}");
        let id = TextureRef {
            transform: IDENTITY_TRANSFORM,
            ..t
        };
        assert_eq!(id.apply([0.3, 0.7]), [0.3, 0.7]);
    }

    /// Mipmaps of sRGB colour are averaged in linear light: a black and white checker's 1x1 level is mid-grey
    /// light (188 encoded), not the encoded average (128, which a data texture does get).
    #[test]
    fn mipmaps_average_light_not_encoded_values() {
        let px = |v: u8| [v, v, v, 255];
        let rgba: Vec<u8> = [px(0), px(255), px(255), px(0)].concat();
        let srgb = mip_chain(2, 2, &rgba, true);
        assert_eq!(srgb.len(), 2);
        assert_eq!(srgb[1].2, vec![188, 188, 188, 255]);
        let data = mip_chain(2, 2, &rgba, false);
        assert_eq!(data[1].2, vec![128, 128, 128, 255]);
        // A 5x3 image goes 2x1, then 1x1.
        let odd = mip_chain(5, 3, &[255; 5 * 3 * 4], true);
        let sizes: Vec<(u32, u32)> = odd.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, vec![(5, 3), (2, 1), (1, 1)]);
        assert!(odd.iter().all(|l| l.2.iter().all(|&b| b == 255)));
    }

    /// The split sum at its limits: a near-mirror (roughness 1/32) reflects everything at every angle (A + B = 1),
    /// its Fresnel weight B growing towards grazing view; a rough lobe loses energy to single scattering (A + B below
    /// 1), more as it roughens; no entry outside [0, 1] beyond the integration's noise. (three.js 0.187's own table,
    /// DFGLUTData.js, agrees with this one within 0.015 at every entry.)
    #[test]
    fn the_split_sum_table_has_its_limits() {
        let t = dfg_table();
        let at = |i: usize, j: usize| t[j * DFG_SIDE + i];
        for j in 0..DFG_SIDE {
            let [a, b] = at(0, j);
            assert!((a + b - 1.0).abs() < 0.01, "n.v row {j}: {a} + {b}");
        }
        assert!(at(0, 0)[1] > 0.8 && at(0, DFG_SIDE - 1)[1] < 0.001);
        let e = |i| at(i, DFG_SIDE - 1)[0] + at(i, DFG_SIDE - 1)[1];
        assert!(e(DFG_SIDE - 1) < e(DFG_SIDE / 2) && e(DFG_SIDE / 2) < e(0));
        assert!(e(DFG_SIDE - 1) < 0.4, "{}", e(DFG_SIDE - 1));
        assert!(t.iter().flatten().all(|&x| (0.0..=1.001).contains(&x)));
    }

    #[test]
    fn srgb_round_trip() {
        for b in 0..=255u8 {
            let c = b as f32 / 255.0;
            let back = (linear_to_srgb(srgb_to_linear(c)) * 255.0).round() as u8;
            assert_eq!(back, b);
        }
    }
}
