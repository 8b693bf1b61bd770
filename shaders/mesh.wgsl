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

// Set per scene when its chains end in impostors (--impostor), so scenes without them compile no impostor code.
override IMPOSTORS: bool = false;

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
    // --impostor: the eye (world) the impostors select their frames by: the camera's own, or the previous
    // frame's in view_pop's counterfactual. While an atlas is baked: the model's bounding sphere (object space).
    impostor_eye: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;
// The shadow map the draw is lit by (a 1x1 placeholder without shadows, never read then).
@group(0) @binding(1) var shadow_map: texture_depth_2d;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;
// --impostor (src/gpu/impostor_atlas.rs): the atlases, two layers each per impostor: sRGB (base colour with
// coverage, emissive) and linear (normal with depth, occlusion-roughness-metallic); 1x1 placeholders without.
@group(0) @binding(3) var impostor_srgb: texture_2d_array<f32>;
@group(0) @binding(4) var impostor_linear: texture_2d_array<f32>;
@group(0) @binding(5) var impostor_sampler: sampler;

struct Impostors {
    // x: frames a side (N); y: layout (0 full, 1 hemi); z: frames a pixel blends (1 or 3); w: parallax (0 or 1).
    settings: vec4<f32>,
    // x: texels a frame's side over the atlas's side.
    atlas: vec4<f32>,
    // Per impostor slot: its model's bounding-sphere centre (object space) and radius (object space).
    spheres: array<vec4<f32>, 64>,
};

@group(0) @binding(6) var<uniform> impostors: Impostors;

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
const KIND_IMPOSTOR: f32 = 5.0;

fn transform(position: vec3<f32>, normal: vec3<f32>, aux: vec4<f32>, inst: InstanceIn) -> VsOut {
    if (IMPOSTORS && aux.z == KIND_IMPOSTOR) {
        return impostor_card(aux, inst);
    }
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
    out.normal = normal_to_world(model, n);
    out.color = inst.color;
    out.params = inst.params;
    out.uv = aux.xy;
    out.kind = aux.z;
    out.object = select(position, aux.xyw, aux.z == KIND_DEFORMED);
    out.world = world.xyz;
    return out;
}

// A normal to world space, up to a positive factor (the fragment normalises it). Under a rotation and a uniform
// scale, the model matrix itself. Under a scale that stretches (a user scene's instance scaled unlike its model,
// src/scene/user/models.rs), the inverse transpose, as the cofactor matrix det(M) M^-T (columns c1 x c2, c2 x c0,
// c0 x c1) times the sign of det(M).
fn normal_to_world(model: mat4x4<f32>, n: vec3<f32>) -> vec3<f32> {
    let c = mat3x3<f32>(model[0].xyz, model[1].xyz, model[2].xyz);
    let len2 = vec3<f32>(dot(c[0], c[0]), dot(c[1], c[1]), dot(c[2], c[2]));
    let tol = 1e-4 * max(len2.x, max(len2.y, len2.z));
    let skew = max(abs(dot(c[0], c[1])), max(abs(dot(c[1], c[2])), abs(dot(c[2], c[0]))));
    if (abs(len2.x - len2.y) <= tol && abs(len2.y - len2.z) <= tol && skew <= tol) {
        return (model * vec4<f32>(n, 0.0)).xyz;
    }
    let cof = mat3x3<f32>(cross(c[1], c[2]), cross(c[2], c[0]), cross(c[0], c[1]));
    return cof * n * sign(dot(c[0], cof[0]));
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

// True where an alpha-tested leaf card (aux kinds 1 and 2) has no leaf, or an impostor's card no model (the
// fragment is discarded by every method).
fn aux_masked(in: VsOut) -> bool {
    if (IMPOSTORS && in.kind == KIND_IMPOSTOR) {
        return impostor_masked(in);
    }
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

// Octahedral impostors (src/geometry/impostor.rs holds the same maps and selection on the CPU, with their
// tests: keep the two in step). A card's vertex has aux = (corner x, corner y, KIND_IMPOSTOR, slot); the card is
// spread across the view on the plane through the model's centre, as large as its bounding sphere's silhouette.
// Lighting happens in object space (models with impostors have instances scaled uniformly, so angles are kept:
// src/scene/user/models.rs keys their placements by shape): `normal` carries the
// light's direction there, `imp_ray` the ray from the eye to the card point, `imp_eye` the selecting eye.

fn impostor_sign(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

fn impostor_encode(d: vec3<f32>) -> vec2<f32> {
    let p = d / (abs(d.x) + abs(d.y) + abs(d.z));
    var q: vec2<f32>;
    if (impostors.settings.y > 0.5) {
        q = vec2<f32>(p.x + p.z, p.x - p.z);
    } else if (p.y >= 0.0) {
        q = p.xz;
    } else {
        q = (vec2<f32>(1.0) - abs(p.zx)) * impostor_sign(p.xz);
    }
    return q * 0.5 + vec2<f32>(0.5);
}

fn impostor_decode(uv: vec2<f32>) -> vec3<f32> {
    let a = uv * 2.0 - vec2<f32>(1.0);
    if (impostors.settings.y > 0.5) {
        let x = (a.x + a.y) * 0.5;
        let z = (a.x - a.y) * 0.5;
        return normalize(vec3<f32>(x, max(1.0 - abs(x) - abs(z), 0.0), z));
    }
    let y = 1.0 - abs(a.x) - abs(a.y);
    if (y >= 0.0) {
        return normalize(vec3<f32>(a.x, y, a.y));
    }
    let q = (vec2<f32>(1.0) - abs(a.yx)) * impostor_sign(a);
    return normalize(vec3<f32>(q.x, y, q.y));
}

// A frame's image axes (right, up) for view direction f.
fn impostor_basis(f: vec3<f32>) -> mat2x3<f32> {
    let up_ref = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, -1.0), abs(f.y) > 0.999);
    let right = normalize(cross(up_ref, f));
    return mat2x3<f32>(right, cross(f, right));
}

fn impostor_card(aux: vec4<f32>, inst: InstanceIn) -> VsOut {
    let slot = u32(aux.w + 0.5);
    let sphere = impostors.spheres[slot];
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    let m3 = mat3x3<f32>(model[0].xyz, model[1].xyz, model[2].xyz);
    let inv = transpose(m3) * (1.0 / dot(m3[0], m3[0]));
    let eye = inv * (camera.eye.xyz - model[3].xyz);
    let to_eye = eye - sphere.xyz;
    let d = max(length(to_eye), 1e-6);
    let axes = impostor_basis(to_eye / d);
    let r = sphere.w;
    // The silhouette's radius on the centre's plane; 4 radii from inside the sphere.
    let half = select(4.0 * r, min(r * d / sqrt(d * d - r * r), 4.0 * r), d > r * 1.0001);
    let p = sphere.xyz + (axes[0] * aux.x + axes[1] * aux.y) * half;
    let world = model * vec4<f32>(p, 1.0);
    var out: VsOut;
    out.clip = camera.view_proj * world;
    out.normal = normalize(transpose(m3) * camera.light.xyz);
    out.color = inst.color;
    out.params = inst.params;
    out.uv = vec2<f32>(f32(slot), 0.0);
    out.kind = KIND_IMPOSTOR;
    out.object = p;
    out.world = world.xyz;
    out.imp_ray = p - eye;
    out.imp_eye = inv * (camera.impostor_eye.xyz - model[3].xyz);
    return out;
}

// What the atlas holds at a card's fragment: coverage (the frames' weighted share of covered texels), and the
// covered texels' base colour, object-space normal, occlusion-roughness-metallic and emissive.
struct ImpostorTexel {
    coverage: f32,
    base: vec4<f32>,
    normal: vec3<f32>,
    orm: vec3<f32>,
    emissive: vec3<f32>,
};

// Where the ray from `eye` along `ray` meets frame `fd`'s plane through the centre, offset `z` along fd, in the
// frame's unit square (outside it: no texel).
fn impostor_frame_uv(eye: vec3<f32>, ray: vec3<f32>, sphere: vec4<f32>, fd: vec3<f32>, z: f32) -> vec2<f32> {
    let axes = impostor_basis(fd);
    let denom = dot(ray, fd);
    let t = dot(sphere.xyz + fd * z - eye, fd) / select(-1e-6, denom, abs(denom) > 1e-6);
    let local = eye + ray * t - sphere.xyz;
    let xy = vec2<f32>(dot(local, axes[0]), dot(local, axes[1])) / sphere.w;
    return vec2<f32>(xy.x * 0.5 + 0.5, 0.5 - xy.y * 0.5);
}

// The frames a view selects, as grid coordinates and weights (src/geometry/impostor.rs `select`).
struct ImpostorFrames {
    cells: array<vec2<f32>, 3>,
    weights: vec3<f32>,
};

fn impostor_frames(from_centre: vec3<f32>) -> ImpostorFrames {
    var d = normalize(from_centre);
    if (impostors.settings.y > 0.5 && d.y < 0.0) {
        let h = vec3<f32>(d.x, 0.0, d.z);
        d = select(vec3<f32>(1.0, 0.0, 0.0), normalize(h), dot(h, h) > 0.0);
    }
    let top = impostors.settings.x - 1.0;
    let g = impostor_encode(d) * top;
    var out: ImpostorFrames;
    if (impostors.settings.z < 1.5) {
        out.cells[0] = clamp(round(g), vec2<f32>(0.0), vec2<f32>(top));
        out.weights = vec3<f32>(1.0, 0.0, 0.0);
        return out;
    }
    let cell = clamp(floor(g), vec2<f32>(0.0), vec2<f32>(top - 1.0));
    let f = g - cell;
    if (f.x + f.y < 1.0) {
        out.cells = array<vec2<f32>, 3>(cell, cell + vec2<f32>(1.0, 0.0), cell + vec2<f32>(0.0, 1.0));
        out.weights = vec3<f32>(1.0 - f.x - f.y, f.x, f.y);
    } else {
        out.cells = array<vec2<f32>, 3>(cell + vec2<f32>(1.0), cell + vec2<f32>(0.0, 1.0), cell + vec2<f32>(1.0, 0.0));
        out.weights = vec3<f32>(f.x + f.y - 1.0, 1.0 - f.x, 1.0 - f.y);
    }
    return out;
}

fn impostor_texel(in: VsOut) -> ImpostorTexel {
    let slot = u32(in.uv.x + 0.5);
    let sphere = impostors.spheres[slot];
    let eye = in.object - in.imp_ray;
    let ray = normalize(in.imp_ray);
    let frames = impostor_frames(in.imp_eye - sphere.xyz);
    let top = impostors.settings.x - 1.0;
    let scale = impostors.atlas.x;
    // Half a texel in from the frame's edge, so the filter never reads the neighbouring frame.
    let margin = 0.5 / (scale * f32(textureDimensions(impostor_srgb).x));
    let layer = i32(slot) * 2;
    var sum = ImpostorTexel(0.0, vec4<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var k = 0; k < 3; k++) {
        let w = frames.weights[k];
        if (w <= 0.0) {
            continue;
        }
        let cell = frames.cells[k];
        let fd = impostor_decode(cell / top);
        var uv = impostor_frame_uv(eye, ray, sphere, fd, 0.0);
        if (impostors.settings.w > 0.5) {
            // One parallax step: the depth the frame holds where the card's ray meets it.
            let a = (cell + clamp(uv, vec2<f32>(margin), vec2<f32>(1.0 - margin))) * scale;
            let nd = textureSampleLevel(impostor_linear, impostor_sampler, a, layer, 0.0);
            let cov = textureSampleLevel(impostor_srgb, impostor_sampler, a, layer, 0.0).a;
            if (cov > 0.0) {
                uv = impostor_frame_uv(eye, ray, sphere, fd, (nd.a / cov * 2.0 - 1.0) * sphere.w);
            }
        }
        if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0))) {
            continue;
        }
        let a = (cell + clamp(uv, vec2<f32>(margin), vec2<f32>(1.0 - margin))) * scale;
        let base = textureSampleLevel(impostor_srgb, impostor_sampler, a, layer, 0.0);
        let emissive = textureSampleLevel(impostor_srgb, impostor_sampler, a, layer + 1, 0.0);
        let nd = textureSampleLevel(impostor_linear, impostor_sampler, a, layer, 0.0);
        let orm = textureSampleLevel(impostor_linear, impostor_sampler, a, layer + 1, 0.0);
        sum.coverage += w * base.a;
        sum.base += w * vec4<f32>(base.rgb, 1.0);
        sum.normal += w * nd.xyz;
        sum.orm += w * orm.xyz;
        sum.emissive += w * emissive.rgb;
    }
    // Uncovered texels hold zeros, so a filtered value over the covered share is the covered texels' mean.
    let c = max(sum.coverage, 1e-6);
    var out: ImpostorTexel;
    out.coverage = sum.coverage;
    out.base = vec4<f32>(sum.base.rgb / c, 1.0);
    let n = sum.normal / c * 2.0 - vec3<f32>(1.0);
    out.normal = select(vec3<f32>(0.0, 0.0, 1.0), normalize(n), dot(n, n) > 1e-12);
    out.orm = sum.orm / c;
    out.emissive = sum.emissive / c;
    return out;
}

// True where a card's fragment shows no part of the model (under half the frames' weighted coverage).
fn impostor_masked(in: VsOut) -> bool {
    return impostor_texel(in).coverage < 0.5;
}

// --impostor's baking (src/gpu/impostor_atlas.rs): a frame's channels. The camera's eye is on the frame's
// direction, impostor_eye holds the bounding sphere; depth is the signed distance along the frame's direction
// over the radius, mapped to [0, 1].
// What a surface gives the bake (each surface's `bake_surface`): linear base colour, the object-space normal as
// seen (flipped on back faces), occlusion-roughness-metallic, emissive.
struct BakeSurface {
    base: vec3<f32>,
    normal: vec3<f32>,
    orm: vec3<f32>,
    emissive: vec3<f32>,
};

struct BakeOut {
    @location(0) base: vec4<f32>,
    @location(1) emissive: vec4<f32>,
    @location(2) normal_depth: vec4<f32>,
    @location(3) orm: vec4<f32>,
};

@fragment
fn fs_bake(in: VsOut, @builtin(front_facing) front: bool) -> BakeOut {
    if (masked(in)) {
        discard;
    }
    let s = bake_surface(in, front);
    let sphere = camera.impostor_eye;
    let f = normalize(camera.eye.xyz - sphere.xyz);
    let depth = clamp(0.5 + 0.5 * dot(in.world - sphere.xyz, f) / sphere.w, 0.0, 1.0);
    var out: BakeOut;
    out.base = vec4<f32>(s.base.rgb, 1.0);
    out.emissive = vec4<f32>(s.emissive, 1.0);
    out.normal_depth = vec4<f32>(s.normal * 0.5 + vec3<f32>(0.5), depth);
    out.orm = vec4<f32>(s.orm, 1.0);
    return out;
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
