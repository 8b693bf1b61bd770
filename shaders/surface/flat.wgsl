// The flat surface (prepended to shaders/mesh.wgsl, src/gpu/pipelines.rs): Lambert plus ambient with the
// instance's colour, the built-in scenes' look (and a user scene's with --materials flat). What the papers'
// figures were measured with; the regression baseline holds it.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(10) aux: vec4<f32>,
};

struct MorphIn {
    @location(8) target_position: vec3<f32>,
    @location(9) target_normal: vec3<f32>,
};

struct VsOut {
    // Invariant: passes that redraw the same geometry (depth-equal tests) get bit-identical depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) params: vec4<f32>,
    @location(3) uv: vec2<f32>,
    @location(4) @interpolate(flat) kind: f32,
    // Object-space position before any animation (FSI's visibility-texture lookup).
    @location(5) object: vec3<f32>,
    // World-space position (the shadow lookup).
    @location(6) world: vec3<f32>,
    // An impostor card's ray from the eye and its selecting eye, object space (shaders/mesh.wgsl).
    @location(7) imp_ray: vec3<f32>,
    @location(8) imp_eye: vec3<f32>,
};

fn vertex(v: VertexIn, inst: InstanceIn) -> VsOut {
    return transform(v.position, v.normal, v.aux, inst);
}

// Each vertex of the finer LOD moves towards its target by the morph weight params.x; the normal is interpolated
// and renormalised.
fn morph_vertex(v: VertexIn, inst: InstanceIn, m: MorphIn) -> VsOut {
    let t = inst.params.x;
    let n = mix(v.normal, m.target_normal, t);
    let len = length(n);
    var normal = v.normal;
    if (len > 1e-6) {
        normal = n / len;
    }
    return transform(mix(v.position, m.target_position, t), normal, v.aux, inst);
}

// True where the fragment is cut out (alpha-tested leaf cards; scenes without them never test).
fn masked(in: VsOut) -> bool {
    if (!ALPHA_TEST) {
        return false;
    }
    return aux_masked(in);
}

// The instance's colour lit by the directional light (its share through the shadow map under --shadows on)
// and the ambient term; alpha 1. An impostor's card: its atlas's normal under the light, both in object space.
fn shade(in: VsOut, front: bool) -> vec4<f32> {
    var n = normalize(in.normal);
    var l = camera.light.xyz;
    var albedo = in.color.rgb;
    if (IMPOSTORS && in.kind == KIND_IMPOSTOR) {
        let t = impostor_texel(in);
        n = t.normal;
        l = in.normal;
        albedo = albedo * t.base.rgb;
    } else if (!front) {
        // Two-sided lighting: scanned meshes have holes, so back faces can be seen.
        n = -n;
    }
    var lambert = max(dot(n, l), 0.0);
    if (camera.shadow.x > 0.5) {
        lambert = lambert * lit(in.world);
    }
    let ambient = camera.light.w;
    let rgb = albedo * (ambient + (1.0 - ambient) * lambert) + shader_work(in.world);
    return vec4<f32>(rgb, 1.0);
}

// The bake's channels: white (the instance's colour multiplies it when the card is drawn), the normal as lit.
fn bake_surface(in: VsOut, front: bool) -> BakeSurface {
    let n = normalize(in.normal) * select(-1.0, 1.0, front);
    return BakeSurface(vec3<f32>(1.0), n, vec3<f32>(1.0, 1.0, 0.0), vec3<f32>(0.0));
}
