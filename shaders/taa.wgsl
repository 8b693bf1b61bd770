// Temporal anti-aliasing resolve (src/taa.rs, src/gpu/taa.rs): the frame just drawn (`current`, read through its
// sRGB view, so in linear values) is blended into the history, h' = h + alpha (c - h), after the history is
// clamped to the min/max of the current frame's 3x3 neighbourhood (Karis 2014). No reprojection: the history
// is read at the same pixel. Writes the new history (linear, Rgba16Float) and the resolved frame (sRGB target).

struct TaaParams {
    alpha: f32,
    // 1: clamp the history to the neighbourhood.
    clamp: u32,
    // 1: the first frame of a sequence, whose history is the frame itself.
    first: u32,
    _pad: u32,
};

@group(0) @binding(0) var current: texture_2d<f32>;
@group(0) @binding(1) var history: texture_2d<f32>;
@group(0) @binding(2) var<uniform> params: TaaParams;

struct ResolveOut {
    @location(0) history: vec4<f32>,
    @location(1) color: vec4<f32>,
};

// One triangle over the viewport.
@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> ResolveOut {
    let p = vec2<i32>(pos.xy);
    let last = vec2<i32>(textureDimensions(current)) - vec2<i32>(1);
    let c = textureLoad(current, p, 0).rgb;
    var h = textureLoad(history, p, 0).rgb;
    if (params.first != 0u) {
        h = c;
    }
    if (params.clamp != 0u) {
        var lo = c;
        var hi = c;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let q = clamp(p + vec2<i32>(dx, dy), vec2<i32>(0), last);
                let s = textureLoad(current, q, 0).rgb;
                lo = min(lo, s);
                hi = max(hi, s);
            }
        }
        h = clamp(h, lo, hi);
    }
    let r = h + params.alpha * (c - h);
    var out: ResolveOut;
    out.history = vec4<f32>(r, 1.0);
    out.color = vec4<f32>(r, 1.0);
    return out;
}
