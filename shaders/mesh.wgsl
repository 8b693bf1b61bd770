// Mesh drawing shared by every method, the part of it that does not depend on the scene's surfaces. A mesh
// pipeline's shader is this file after one of shaders/surface/*.wgsl (src/gpu/pipelines.rs, `mesh_wgsl`):
// `surface/flat.wgsl` (Lambert plus ambient with a per-instance colour: the built-in scenes, and user scenes with
// --materials flat) or `surface/pbr.wgsl` (glTF's metallic-roughness materials with their textures). Each
// defines VertexIn, MorphIn, VsOut (with at least the fields `transform` below writes), `vertex`,
// `morph_vertex`, `masked` and `shade`; the entry points below call them. Colours are written to an sRGB target
// (the hardware encodes). Instance data carries the object-to-world matrix, the colour (w: the instance's
// animation angle in radians) and the transition parameters (x = k, y = alpha, z = LOD, w = instance id) that
// the methods read.
//
// Per-vertex `aux` = (u, v, kind, hub_y) (src/geometry/mesh.rs): kind 1 and 2 are alpha-tested leaf cards (masks
// over (u, v) below), kind 3 a windmill blade vertex, rotated about the axis parallel to +z through (0, hub_y) by
// the instance's animation angle. Animation happens after the object-space position is taken (`object`), which is
// what FSI's visibility texture reads (Scherzer & Wimmer 2008 section 3.3, Fig. 5). Kind 4 is a vertex of a mesh
// deformed on the CPU each frame (a skin, morph weights): its position is the frame's, and aux = (x, y, 4, z) its
// rest position, which is its `object` position.

// Set per scene when its models have alpha-tested geometry (every fragment entry then applies the mask), so
// scenes without it keep shaders with no discard.
override ALPHA_TEST: bool = false;

struct Camera {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: unit vector towards the light; w: ambient term.
    light: vec4<f32>,
    // --shadows on (src/shadow.rs): world to the shadow map's clip space.
    light_view_proj: mat4x4<f32>,
    // x: 1 with shadows; y: the shadow map's side in texels; z: depth bias.
    shadow: vec4<f32>,
    // --shader-work (src/gpu/scene_gpu.rs): x: ALU iterations per shaded fragment; y: the weight their result is
    // added with (0 in every run: the image is unchanged; a uniform, so the loop cannot be compiled away).
    work: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;
// The shadow map the draw is lit by (a 1x1 placeholder without shadows, never read then).
@group(0) @binding(1) var shadow_map: texture_depth_2d;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;

struct InstanceIn {
    @location(2) model_0: vec4<f32>,
    @location(3) model_1: vec4<f32>,
    @location(4) model_2: vec4<f32>,
    @location(5) model_3: vec4<f32>,
    @location(6) color: vec4<f32>,
    @location(7) params: vec4<f32>,
};

const KIND_LEAF: f32 = 1.0;
const KIND_LEAF_CLUSTER: f32 = 2.0;
const KIND_BLADE: f32 = 3.0;
const KIND_DEFORMED: f32 = 4.0;

fn transform(position: vec3<f32>, normal: vec3<f32>, aux: vec4<f32>, inst: InstanceIn) -> VsOut {
    var p = position;
    var n = normal;
    if (aux.z == KIND_BLADE) {
        let c = cos(inst.color.w);
        let s = sin(inst.color.w);
        let r = mat2x2<f32>(c, s, -s, c);
        let xy = r * vec2<f32>(p.x, p.y - aux.w);
        p = vec3<f32>(xy.x, xy.y + aux.w, p.z);
        n = vec3<f32>(r * n.xy, n.z);
    }
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    let world = model * vec4<f32>(p, 1.0);
    var out: VsOut;
    out.clip = camera.view_proj * world;
    // Instances are scaled uniformly, so the model matrix transforms normals too.
    out.normal = (model * vec4<f32>(n, 0.0)).xyz;
    out.color = inst.color;
    out.params = inst.params;
    out.uv = aux.xy;
    out.kind = aux.z;
    out.object = select(position, aux.xyw, aux.z == KIND_DEFORMED);
    out.world = world.xyz;
    return out;
}

@vertex
fn vs_main(v: VertexIn, inst: InstanceIn) -> VsOut {
    return vertex(v, inst);
}

// Geomorphing (Sheliemietiev et al. 2023 sections 10-11): each vertex of the finer LOD moves towards its target on
// the coarser LOD by the morph weight params.x (`morph_vertex`).
@vertex
fn vs_morph(v: VertexIn, inst: InstanceIn, m: MorphIn) -> VsOut {
    return morph_vertex(v, inst, m);
}

// The leaf masks of src/geometry/procgen.rs (`leaf_mask`, `leaf_cluster_mask`): keep the two in step.
fn leaf_mask(uv: vec2<f32>) -> bool {
    let x = uv.x * 2.0 - 1.0;
    let y = uv.y * 2.0 - 1.0;
    return abs(x) <= 0.8 * (1.0 - y * y);
}

fn leaf_cluster_mask(uv: vec2<f32>) -> bool {
    let c = clamp(floor(uv * 3.0), vec2<f32>(0.0), vec2<f32>(2.0));
    let cell = c.x + 3.0 * c.y;
    if (cell == 2.0 || cell == 6.0) {
        return false;
    }
    return leaf_mask(uv * 3.0 - c);
}

// True where an alpha-tested leaf card (aux kinds 1 and 2) has no leaf (the fragment is discarded by every
// method).
fn aux_masked(in: VsOut) -> bool {
    if (in.kind == KIND_LEAF) {
        return !leaf_mask(in.uv);
    }
    if (in.kind == KIND_LEAF_CLUSTER) {
        return !leaf_cluster_mask(in.uv);
    }
    return false;
}

// --shader-work: a chain of dependent multiply-adds, each result in [0, 1), added with weight work.y.
fn shader_work(world: vec3<f32>) -> vec3<f32> {
    var w = fract(dot(world, vec3<f32>(0.1, 0.2, 0.3)));
    let iterations = u32(camera.work.x);
    for (var i = 0u; i < iterations; i = i + 1u) {
        w = fract(w * 1.618034 + 0.318310);
    }
    return vec3<f32>(w * camera.work.y);
}

// The share of the light reaching `world`: a 3x3 percentage-closer filter of 2x2 bilinear depth comparisons
// (16 texels), 1 outside the shadow map.
fn lit(world: vec3<f32>) -> f32 {
    let p = camera.light_view_proj * vec4<f32>(world, 1.0);
    let ndc = p.xyz / p.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || ndc.z > 1.0) {
        return 1.0;
    }
    let texel = 1.0 / camera.shadow.y;
    let depth = ndc.z - camera.shadow.z;
    var sum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let o = vec2<f32>(f32(dx), f32(dy)) * texel;
            sum += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + o, depth);
        }
    }
    return sum / 9.0;
}

@fragment
fn fs_opaque(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    if (masked(in)) {
        discard;
    }
    return shade(in, front);
}

// The shadow pass (src/gpu/shadow.rs): the caster seen from the light.
@vertex
fn vs_shadow(v: VertexIn, inst: InstanceIn) -> VsOut {
    var out = vertex(v, inst);
    out.clip = camera.light_view_proj * vec4<f32>(out.world, 1.0);
    return out;
}

// A dithered caster (a t-instance of a blending method, src/shadow.rs): params.x = k, params.y = role (1 the
// incoming LOD, 0 the outgoing); the incoming LOD keeps the texels where k exceeds interleaved gradient noise.
@fragment
fn fs_shadow_dither(in: VsOut) {
    let p = floor(in.clip.xy);
    let t = fract(52.9829189 * fract(dot(p, vec2<f32>(0.06711056, 0.00583715))));
    let keep_incoming = in.params.x > t;
    if (keep_incoming != (in.params.y > 0.5) || masked(in)) {
        discard;
    }
}

// Depth-only passes of scenes with alpha-tested geometry (the mask must cut the depth too).
@fragment
fn fs_depth_masked(in: VsOut) {
    if (masked(in)) {
        discard;
    }
}

// Translucent draws (alpha blending methods): the instance's alpha is params.y.
@fragment
fn fs_translucent(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    if (masked(in)) {
        discard;
    }
    let c = shade(in, front);
    return vec4<f32>(c.rgb, c.a * in.params.y);
}

// alpha-2pass colour pass: the depth attachment holds this object's own nearest surface (depth-equal test);
// the rest of the scene's depth is read here, and fragments behind it are dropped, so the object stays occluded
// by whatever was drawn in front of it.
@group(1) @binding(2) var scene_depth: texture_depth_2d;

@fragment
fn fs_translucent_occluded(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let behind = textureLoad(scene_depth, vec2<i32>(in.clip.xy), 0);
    if (in.clip.z > behind || masked(in)) {
        discard;
    }
    let c = shade(in, front);
    return vec4<f32>(c.rgb, c.a * in.params.y);
}

// alpha-sorted's peel (src/methods/alpha_sorted.rs, shaders/peel.wgsl): the translucent fragment, kept only behind the
// previous layer's depth (the depth attachment, a copy of the opaque depth with a less-equal test, keeps the
// nearest of them in front of the opaque surface).
@group(1) @binding(3) var peel_previous: texture_depth_2d;

@fragment
fn fs_translucent_peel(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let previous = textureLoad(peel_previous, vec2<i32>(in.clip.xy), 0);
    if (in.clip.z <= previous || masked(in)) {
        discard;
    }
    let c = shade(in, front);
    return vec4<f32>(c.rgb, c.a * in.params.y);
}

// Noise blending (Sheliemietiev et al. 2023 section 9, eq. 3): a pixel of a t-instance keeps the incoming LOD where
// k > noise(x, y) and the outgoing LOD elsewhere. params.x = k; params.y = role: 1 incoming, 0 outgoing.
struct NoiseParams {
    // Side of the tiled threshold texture; 0 = interleaved gradient noise computed here.
    size: u32,
    _pad0: u32,
    // The pattern's offset in pixels this frame (--noise-temporal; 0 otherwise).
    offset: vec2<f32>,
};

@group(1) @binding(0) var noise_tex: texture_2d<f32>;
@group(1) @binding(1) var<uniform> noise: NoiseParams;

fn threshold(p: vec2<f32>) -> f32 {
    let at = floor(p) + noise.offset;
    if (noise.size == 0u) {
        // Jimenez 2014, interleaved gradient noise.
        return fract(52.9829189 * fract(dot(at, vec2<f32>(0.06711056, 0.00583715))));
    }
    let q = vec2<u32>(at) % vec2<u32>(noise.size);
    return textureLoad(noise_tex, vec2<i32>(q), 0).r;
}

@fragment
fn fs_dither(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let keep_incoming = in.params.x > threshold(in.clip.xy);
    let incoming = in.params.y > 0.5;
    if (keep_incoming != incoming || masked(in)) {
        discard;
    }
    return shade(in, front);
}

// Frame Sequential Interpolation (Scherzer & Wimmer 2008 sections 3.2-3.5): the scene is drawn into a LOD buffer of colour,
// depth and instance id. n-instances write id 0; a t-instance writes its own id (params.w) and keeps a fragment
// only where visTex(p) <= tau (eq. 1: discard where visTex(p) > tau), p the object-space position before
// animation, the texture read at (p.x + p.z, p.y + p.z) * params.x (params.x = texture repeats per object-space
// unit), wrapping, nearest texel; params.y = tau.
struct FsiOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
};

@group(1) @binding(0) var visibility_texture: texture_2d<f32>;

@fragment
fn fs_fsi_n(in: VsOut, @builtin(front_facing) front: bool) -> FsiOut {
    if (masked(in)) {
        discard;
    }
    var out: FsiOut;
    out.color = shade(in, front);
    out.id = 0u;
    return out;
}

fn visibility(p: vec3<f32>, repeats_per_unit: f32) -> f32 {
    let size = vec2<i32>(textureDimensions(visibility_texture));
    let uv = vec2<f32>(p.x + p.z, p.y + p.z) * repeats_per_unit;
    let texel = vec2<i32>(floor(uv * vec2<f32>(size)));
    return textureLoad(visibility_texture, ((texel % size) + size) % size, 0).r;
}

@fragment
fn fs_fsi_t(in: VsOut, @builtin(front_facing) front: bool) -> FsiOut {
    if (visibility(in.object, in.params.x) > in.params.y || masked(in)) {
        discard;
    }
    return fsi_t_out(in, front);
}

// `--vis-space world` (Scherzer & Wimmer 2008 section 3.3 rejects it): the same lookup at the world-space
// position, so the pattern stays in place while an animated object moves through it.
@fragment
fn fs_fsi_t_world(in: VsOut, @builtin(front_facing) front: bool) -> FsiOut {
    if (visibility(in.world, in.params.x) > in.params.y || masked(in)) {
        discard;
    }
    return fsi_t_out(in, front);
}

// `fsi-blend` (frame-sequential blending, Scherzer & Wimmer 2008 section 3.3, Fig. 4): the LOD complete, no
// visibility texture; the LOD's blend weight (params.y: k for the incoming LOD, 1 - k for the outgoing one) in
// the colour's alpha, which the combination pass mixes by.
@fragment
fn fs_fsi_t_blend(in: VsOut, @builtin(front_facing) front: bool) -> FsiOut {
    if (masked(in)) {
        discard;
    }
    var out = fsi_t_out(in, front);
    out.color.a = in.params.y;
    return out;
}

fn fsi_t_out(in: VsOut, front: bool) -> FsiOut {
    var out: FsiOut;
    out.color = shade(in, front);
    // params is interpolated: a constant can come out a hair below the integer. Back faces write the next id
    // (src/methods/fsi.rs, `back_id`), so the combination never averages an object's inside with its front.
    let id = u32(round(in.params.w));
    out.id = select(id + 1u, id, front);
    return out;
}
