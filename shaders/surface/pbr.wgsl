// glTF's metallic-roughness materials (prepended to shaders/mesh.wgsl, src/gpu/pipelines.rs): a user scene's
// look with --materials full. Every method draws it through the same entry points, so a LOD change shows in the
// shading (normal maps, texture seams, cut-outs) as a viewer sees it.
//
// - Surface: base colour = factor x texture (sRGB, decoded by the texture view) x COLOR_0; metallic and
//   roughness = factors x the texture's B and G; the normal texture in the tangent frame of TANGENT (or
//   MikkTSpace's, src/geometry/tangents.rs), scaled in x and y by its scale; occlusion = 1 + strength x (R - 1);
//   emissive = factor x texture. Texture coordinates are TEXCOORD_0 or _1 through KHR_texture_transform.
// - Alpha: OPAQUE ignores it; MASK discards where it is below the cutoff (`masked`); BLEND returns it and the
//   pipeline blends (src/gpu/scene_gpu.rs draws BLEND parts after the opaque ones).
// - Light (docs/methods.md, "Materials"): the BRDF of glTF 2.0's Appendix B, i.e. Lambert diffuse weighted by
//   (1 - F) plus the GGX specular lobe (Trowbridge-Reitz D, height-correlated Smith V, Schlick F, F0 = 0.04 for
//   dielectrics), lit by one directional light of irradiance pi x (1 - ambient) at normal incidence from
//   camera.light.xyz (shadowed under --shadows on), plus a uniform ambient environment of radiance `ambient`
//   (camera.light.w) reflected as Fdez-Aguera's multiple-scattering split sum (JCGT 8(1), 2019) has it, the
//   split sum's A and B read from a table integrated at start-up (`dfg`, src/geometry/material.rs dfg_table):
//   specular ambient x (F0 A + B + multiple scattering), diffuse
//   ambient x c_diff x (1 - the specular's largest channel), both x occlusion. It conserves energy (a white
//   rough metal in the uniform environment reflects all of it) and is the image-based lighting three.js computes
//   for a constant environment map. A white matte surface facing the light thus shows about
//   (1 - F) x (1 - ambient) + ambient of its colour, as the flat surface's Lambert shows 1. No tone mapping:
//   the sum is clamped by the sRGB target.

const PI: f32 = 3.141592653589793;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(10) aux: vec4<f32>,
    // TEXCOORD_0 in xy, TEXCOORD_1 in zw.
    @location(11) tex: vec4<f32>,
    // TANGENT: xyz, w the bitangent's sign.
    @location(12) tangent: vec4<f32>,
    // COLOR_0 (linear RGBA; white without it).
    @location(13) vcolor: vec4<f32>,
};

struct MorphIn {
    @location(8) target_position: vec3<f32>,
    @location(9) target_normal: vec3<f32>,
    // The texture coordinates at the target on the coarser LOD, and its tangent and colour packed
    // (SurfaceTarget in src/gpu/pipelines.rs): the tangent's xyz as 16-bit snorm in x and y's low half, the
    // linear RGBA colour as 16-bit unorm in z and w.
    @location(14) target_tex: vec4<f32>,
    @location(15) target_packed: vec4<u32>,
};

struct VsOut {
    // Invariant: passes that redraw the same geometry (depth-equal tests) get bit-identical depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) params: vec4<f32>,
    @location(3) uv: vec2<f32>,
    @location(4) @interpolate(flat) kind: f32,
    @location(5) object: vec3<f32>,
    @location(6) world: vec3<f32>,
    @location(7) tex: vec4<f32>,
    // World-space tangent, w its sign.
    @location(8) tangent: vec4<f32>,
    @location(9) vcolor: vec4<f32>,
    // An impostor card's ray from the eye and its selecting eye, object space (shaders/mesh.wgsl).
    @location(10) imp_ray: vec3<f32>,
    @location(11) imp_eye: vec3<f32>,
};

struct Material {
    base_color: vec4<f32>,
    // rgb: the emissive factor (KHR_materials_emissive_strength applied).
    emissive: vec4<f32>,
    // x: metallic, y: roughness, z: normal scale, w: occlusion strength.
    factors: vec4<f32>,
    // x: alpha mode (0 OPAQUE, 1 MASK, 2 BLEND), y: alpha cutoff, z: 1 when unlit (KHR_materials_unlit).
    alpha: vec4<f32>,
    // Per texture (base colour, metallic-roughness, normal, occlusion, emissive), the two rows of its
    // KHR_texture_transform; row 0's w: the texture coordinate set (0 or 1), -1 when the material has no such
    // texture.
    tex: array<vec4<f32>, 10>,
};

const BASE: u32 = 0u;
const METALLIC_ROUGHNESS: u32 = 1u;
const NORMAL: u32 = 2u;
const OCCLUSION: u32 = 3u;
const EMISSIVE: u32 = 4u;

@group(2) @binding(0) var<uniform> material: Material;
@group(2) @binding(1) var base_color_texture: texture_2d<f32>;
@group(2) @binding(2) var metallic_roughness_texture: texture_2d<f32>;
@group(2) @binding(3) var normal_texture: texture_2d<f32>;
@group(2) @binding(4) var occlusion_texture: texture_2d<f32>;
@group(2) @binding(5) var emissive_texture: texture_2d<f32>;
@group(2) @binding(6) var base_color_sampler: sampler;
@group(2) @binding(7) var metallic_roughness_sampler: sampler;
@group(2) @binding(8) var normal_sampler: sampler;
@group(2) @binding(9) var occlusion_sampler: sampler;
@group(2) @binding(10) var emissive_sampler: sampler;
// The split sum's (A, B) at roughness (i + 0.5) / 16 and n.v (j + 0.5) / 16, texel j * 16 + i, two texels a vec4.
@group(2) @binding(11) var<uniform> dfg: array<vec4<f32>, 128>;

fn vertex(v: VertexIn, inst: InstanceIn) -> VsOut {
    var out = transform(v.position, v.normal, v.aux, inst);
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    out.tex = v.tex;
    out.tangent = vec4<f32>((model * vec4<f32>(v.tangent.xyz, 0.0)).xyz, v.tangent.w);
    out.vcolor = v.vcolor;
    return out;
}

// Geomorphing: position, normal, texture coordinates, tangent and colour move together towards the target.
fn morph_vertex(v: VertexIn, inst: InstanceIn, m: MorphIn) -> VsOut {
    let target_tangent = vec3<f32>(unpack2x16snorm(m.target_packed.x), unpack2x16snorm(m.target_packed.y).x);
    let target_color = vec4<f32>(unpack2x16unorm(m.target_packed.z), unpack2x16unorm(m.target_packed.w));
    let t = inst.params.x;
    let n = mix(v.normal, m.target_normal, t);
    var normal = v.normal;
    if (length(n) > 1e-6) {
        normal = normalize(n);
    }
    var out = transform(mix(v.position, m.target_position, t), normal, v.aux, inst);
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    out.tex = mix(v.tex, m.target_tex, t);
    var tangent = v.tangent.xyz;
    let tm = mix(v.tangent.xyz, target_tangent, t);
    if (length(tm) > 1e-6) {
        tangent = normalize(tm);
    }
    out.tangent = vec4<f32>((model * vec4<f32>(tangent, 0.0)).xyz, v.tangent.w);
    out.vcolor = mix(v.vcolor, target_color, t);
    return out;
}

fn has(slot: u32) -> bool {
    return material.tex[slot * 2u].w >= 0.0;
}

// Texture `slot`'s coordinates: its set through its KHR_texture_transform.
fn uv_of(slot: u32, in: VsOut) -> vec2<f32> {
    let r0 = material.tex[slot * 2u];
    let r1 = material.tex[slot * 2u + 1u];
    let p = vec3<f32>(select(in.tex.xy, in.tex.zw, r0.w > 0.5), 1.0);
    return vec2<f32>(dot(r0.xyz, p), dot(r1.xyz, p));
}

fn base_color(in: VsOut) -> vec4<f32> {
    var c = material.base_color * in.vcolor;
    if (has(BASE)) {
        c = c * textureSample(base_color_texture, base_color_sampler, uv_of(BASE, in));
    }
    return c;
}

// True where the fragment is cut out: a leaf card's mask, or a MASK material's alpha below its cutoff.
fn masked(in: VsOut) -> bool {
    if (!ALPHA_TEST) {
        return false;
    }
    if (aux_masked(in)) {
        return true;
    }
    if (IMPOSTORS && in.kind == KIND_IMPOSTOR) {
        return false;
    }
    return material.alpha.x == 1.0 && base_color(in).a < material.alpha.y;
}

fn dfg_texel(i: u32, j: u32) -> vec2<f32> {
    let k = j * 16u + i;
    let v = dfg[k / 2u];
    return select(v.xy, v.zw, (k & 1u) == 1u);
}

// The split sum of the specular lobe: (scale of F0, bias), read from `dfg` bilinearly, as a texture's texel
// centres at (i + 0.5) / 16, clamped at the edges.
fn env_brdf(roughness: f32, nv: f32) -> vec2<f32> {
    let p = clamp(vec2<f32>(roughness, nv) * 16.0 - 0.5, vec2<f32>(0.0), vec2<f32>(15.0));
    let i0 = vec2<u32>(floor(p));
    let i1 = min(i0 + vec2<u32>(1u), vec2<u32>(15u));
    let t = p - floor(p);
    let bottom = mix(dfg_texel(i0.x, i0.y), dfg_texel(i1.x, i0.y), t.x);
    let top = mix(dfg_texel(i0.x, i1.y), dfg_texel(i1.x, i1.y), t.x);
    return mix(bottom, top, t.y);
}

// A surface point's inputs to the BRDF.
struct PbrSurface {
    base: vec3<f32>,
    metallic: f32,
    roughness: f32,
    // The shading normal, as seen (flipped on back faces).
    n: vec3<f32>,
    occlusion: f32,
    emissive: vec3<f32>,
};

fn pbr_surface(in: VsOut, front: bool) -> PbrSurface {
    let base = base_color(in);
    var metallic = material.factors.x;
    var roughness = material.factors.y;
    if (has(METALLIC_ROUGHNESS)) {
        let mr = textureSample(metallic_roughness_texture, metallic_roughness_sampler,
                               uv_of(METALLIC_ROUGHNESS, in));
        roughness = roughness * mr.g;
        metallic = metallic * mr.b;
    }
    // Back faces (double-sided materials) are lit as seen: their normal and tangent frame reversed.
    let side = select(-1.0, 1.0, front);
    let ng = normalize(in.normal) * side;
    var n = ng;
    if (has(NORMAL) && length(in.tangent.xyz) > 1e-6) {
        var tn = textureSample(normal_texture, normal_sampler, uv_of(NORMAL, in)).xyz * 2.0 - 1.0;
        tn = vec3<f32>(tn.xy * material.factors.z, tn.z);
        let t0 = in.tangent.xyz * side;
        let t = normalize(t0 - ng * dot(ng, t0));
        let b = cross(ng, t) * in.tangent.w;
        let mapped = mat3x3<f32>(t, b, ng) * tn;
        if (length(mapped) > 1e-6) {
            n = normalize(mapped);
        }
    }
    var occlusion = 1.0;
    if (has(OCCLUSION)) {
        let ao = textureSample(occlusion_texture, occlusion_sampler, uv_of(OCCLUSION, in)).r;
        occlusion = 1.0 + material.factors.w * (ao - 1.0);
    }
    var emissive = material.emissive.rgb;
    if (has(EMISSIVE)) {
        emissive = emissive * textureSample(emissive_texture, emissive_sampler, uv_of(EMISSIVE, in)).rgb;
    }
    return PbrSurface(base.rgb, metallic, roughness, n, occlusion, emissive);
}

// The light a surface point reflects towards `v` (unit, towards the eye) from the light `l` and the ambient
// environment, plus its emission; `world` is where the shadow map is read.
fn pbr_light(s: PbrSurface, v: vec3<f32>, l: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    let n = s.n;
    let h = normalize(l + v);
    let nl = clamp(dot(n, l), 0.0, 1.0);
    let nv = clamp(abs(dot(n, v)), 1e-4, 1.0);
    let nh = clamp(dot(n, h), 0.0, 1.0);
    let vh = clamp(dot(v, h), 0.0, 1.0);
    let c_diff = mix(s.base, vec3<f32>(0.0), s.metallic);
    let f0 = mix(vec3<f32>(0.04), s.base, s.metallic);
    let a = s.roughness * s.roughness;
    let a2 = max(a * a, 1e-7);
    let f = f0 + (vec3<f32>(1.0) - f0) * pow(1.0 - vh, 5.0);
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * dd * dd);
    let vis_den = nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2);
    let vis = select(0.0, 0.5 / vis_den, vis_den > 0.0);
    let brdf = (vec3<f32>(1.0) - f) * c_diff / PI + f * d * vis;
    let ambient = camera.light.w;
    var irradiance = PI * (1.0 - ambient) * nl;
    if (camera.shadow.x > 0.5) {
        irradiance = irradiance * lit(world);
    }
    let ab = env_brdf(s.roughness, nv);
    let single = f0 * ab.x + vec3<f32>(ab.y);
    let e_ss = ab.x + ab.y;
    let f_avg = f0 + (vec3<f32>(1.0) - f0) / 21.0;
    let multiple = single * f_avg / (vec3<f32>(1.0) - (1.0 - e_ss) * f_avg) * (1.0 - e_ss);
    let specular = single + multiple;
    let diffuse = c_diff * (1.0 - max(max(specular.r, specular.g), specular.b));
    let indirect = (specular + diffuse) * ambient * s.occlusion;
    return brdf * irradiance + indirect + s.emissive + shader_work(world);
}

// An impostor's card is lit from its atlas in object space (`normal` holds the light's direction there); its
// material's alpha mode and unlit flag are the baked model's, not applied again.
fn shade(in: VsOut, front: bool) -> vec4<f32> {
    if (IMPOSTORS && in.kind == KIND_IMPOSTOR) {
        let t = impostor_texel(in);
        let s = PbrSurface(t.base.rgb, t.orm.z, t.orm.y, t.normal, t.orm.x, t.emissive);
        return vec4<f32>(pbr_light(s, normalize(-in.imp_ray), in.normal, in.world), 1.0);
    }
    let base = base_color(in);
    let alpha = select(1.0, base.a, material.alpha.x == 2.0);
    if (material.alpha.z > 0.5) {
        return vec4<f32>(base.rgb, alpha);
    }
    let s = pbr_surface(in, front);
    return vec4<f32>(pbr_light(s, normalize(camera.eye.xyz - in.world), camera.light.xyz, in.world), alpha);
}

// The bake's channels: the surface as `shade` lights it (an unlit material is baked as its base colour and lit
// when drawn: said in docs/methods.md).
fn bake_surface(in: VsOut, front: bool) -> BakeSurface {
    let s = pbr_surface(in, front);
    return BakeSurface(s.base, s.n, vec3<f32>(s.occlusion, s.roughness, s.metallic), s.emissive);
}
