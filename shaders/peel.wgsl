// `alpha-sorted` (src/methods/alpha_sorted.rs): `alpha`'s blend composited in exact depth order per pixel, by
// depth peeling. Each peeled layer (the nearest translucent fragment behind the previous layer and not behind the
// opaque surface: colour in linear RGB, alpha) is accumulated front to back, premultiplied:
//   acc' = acc + (1 - acc.a) * (a * c, a),
// which equals drawing the layers back to front with the "over" blend. The resolve puts the accumulation over
// the opaque frame: out = acc.rgb + (1 - acc.a) * opaque, in linear RGB, encoded to sRGB bytes; a pixel with no
// translucent layer keeps the opaque frame's bytes as they are. It also clears the accumulation for the next
// frame.

struct Params {
    // Viewport width and height in pixels.
    size: vec4<u32>,
};

// The layer, as the sRGB colour target it was drawn into: textureLoad returns linear values.
@group(0) @binding(0) var layer: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> acc: array<vec4<f32>>;
@group(0) @binding(2) var<uniform> params: Params;
// The opaque frame, as its stored sRGB bytes (an Rgba8Unorm view).
@group(0) @binding(3) var opaque: texture_2d<f32>;
@group(0) @binding(4) var output: texture_storage_2d<rgba8unorm, write>;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - vec3<f32>(0.055);
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

@compute @workgroup_size(8, 8)
fn cs_accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.size.x || id.y >= params.size.y) {
        return;
    }
    let c = textureLoad(layer, vec2<i32>(id.xy), 0);
    let i = id.y * params.size.x + id.x;
    let a = acc[i];
    acc[i] = a + (1.0 - a.a) * vec4<f32>(c.rgb * c.a, c.a);
}

@compute @workgroup_size(8, 8)
fn cs_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.size.x || id.y >= params.size.y) {
        return;
    }
    let p = vec2<i32>(id.xy);
    let i = id.y * params.size.x + id.x;
    let a = acc[i];
    acc[i] = vec4<f32>(0.0);
    let o = textureLoad(opaque, p, 0);
    if (a.a <= 0.0) {
        textureStore(output, p, o);
        return;
    }
    let c = a.rgb + (1.0 - a.a) * srgb_to_linear(o.rgb);
    textureStore(output, p, vec4<f32>(linear_to_srgb(c), 1.0));
}
