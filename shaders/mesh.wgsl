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
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) params: vec4<f32>,
};

@vertex
fn vs_main(v: VertexIn, inst: InstanceIn) -> VsOut {
    let model = mat4x4<f32>(inst.model_0, inst.model_1, inst.model_2, inst.model_3);
    let world = model * vec4<f32>(v.position, 1.0);
    var out: VsOut;
    out.clip = camera.view_proj * world;
    // Instances are scaled uniformly, so the model matrix transforms normals too.
    out.normal = (model * vec4<f32>(v.normal, 0.0)).xyz;
    out.color = inst.color;
    out.params = inst.params;
    return out;
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
