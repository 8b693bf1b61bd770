// Mesh shading shared by every method: Lambert plus ambient with a per-instance colour, written to an sRGB
// target (the hardware encodes). Instance data carries the object-to-world matrix, the colour and the
// transition parameters (x = k, y = alpha, z = LOD, w = instance id) that later methods read.

struct Camera {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: unit vector towards the light; w: ambient term.
    light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

struct InstanceIn {
    @location(2) model_0: vec4<f32>,
    @location(3) model_1: vec4<f32>,
    @location(4) model_2: vec4<f32>,
    @location(5) model_3: vec4<f32>,
    @location(6) color: vec4<f32>,
    @location(7) params: vec4<f32>,
};

struct VsOut {
    // Invariant: passes that redraw the same geometry (depth-equal tests) get bit-identical depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) params: vec4<f32>,
};

fn transform(position: vec3<f32>, normal: vec3<f32>, inst: InstanceIn) -> VsOut {
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    let world = model * vec4<f32>(position, 1.0);
    var out: VsOut;
    out.clip = camera.view_proj * world;
    // Instances are scaled uniformly, so the model matrix transforms normals too.
    out.normal = (model * vec4<f32>(normal, 0.0)).xyz;
    out.color = inst.color;
    out.params = inst.params;
    return out;
}

@vertex
fn vs_main(v: VertexIn, inst: InstanceIn) -> VsOut {
    return transform(v.position, v.normal, inst);
}

// Geomorphing (seed 003 sections 10-11): each vertex of the finer LOD moves towards its target on the coarser
// LOD by the morph weight params.x; the normal is interpolated and renormalised.
struct MorphIn {
    @location(8) target_position: vec3<f32>,
    @location(9) target_normal: vec3<f32>,
};

@vertex
fn vs_morph(v: VertexIn, inst: InstanceIn, m: MorphIn) -> VsOut {
    let t = inst.params.x;
    let n = mix(v.normal, m.target_normal, t);
    let len = length(n);
    var normal = v.normal;
    if (len > 1e-6) {
        normal = n / len;
    }
    return transform(mix(v.position, m.target_position, t), normal, inst);
}

fn shade(in: VsOut, front: bool) -> vec3<f32> {
    var n = normalize(in.normal);
    // Two-sided lighting: scanned meshes have holes, so back faces can be seen.
    if (!front) {
        n = -n;
    }
    let lambert = max(dot(n, camera.light.xyz), 0.0);
    let ambient = camera.light.w;
    return in.color.rgb * (ambient + (1.0 - ambient) * lambert);
}

@fragment
fn fs_opaque(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(shade(in, front), 1.0);
}

// Translucent draws (alpha blending methods): the instance's alpha is params.y.
@fragment
fn fs_translucent(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(shade(in, front), in.params.y);
}

// alpha-2pass colour pass: the depth attachment holds this object's own nearest surface (depth-equal test);
// the rest of the scene's depth is read here, and fragments behind it are dropped, so the object stays occluded
// by whatever was drawn in front of it.
@group(1) @binding(2) var scene_depth: texture_depth_2d;

@fragment
fn fs_translucent_occluded(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let behind = textureLoad(scene_depth, vec2<i32>(in.clip.xy), 0);
    if (in.clip.z > behind) {
        discard;
    }
    return vec4<f32>(shade(in, front), in.params.y);
}

// Noise blending (seed 003 section 9, eq. 3): a pixel of a t-instance keeps the incoming LOD where
// k > noise(x, y) and the outgoing LOD elsewhere. params.x = k; params.y = role: 1 incoming, 0 outgoing.
struct NoiseParams {
    // Side of the tiled threshold texture; 0 = interleaved gradient noise computed here.
    size: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(1) @binding(0) var noise_tex: texture_2d<f32>;
@group(1) @binding(1) var<uniform> noise: NoiseParams;

fn threshold(p: vec2<f32>) -> f32 {
    if (noise.size == 0u) {
        // Jimenez 2014, interleaved gradient noise.
        return fract(52.9829189 * fract(dot(floor(p), vec2<f32>(0.06711056, 0.00583715))));
    }
    let q = vec2<u32>(floor(p)) % vec2<u32>(noise.size);
    return textureLoad(noise_tex, vec2<i32>(q), 0).r;
}

@fragment
fn fs_dither(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let keep_incoming = in.params.x > threshold(in.clip.xy);
    let incoming = in.params.y > 0.5;
    if (keep_incoming != incoming) {
        discard;
    }
    return vec4<f32>(shade(in, front), 1.0);
}
