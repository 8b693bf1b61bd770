// The RMS difference of two frames, per frame slot, as an exact integer sum (the CPU twin is
// metrics::rms_difference): lodbench's lodpop (a method's frame against the same frame rendered with the
// previous frame's LOD schedule) and FSI's lag_rmse (its frame against the same combination without the lag).
//
// Both images are read through Rgba8Unorm views of the sRGB targets, i.e. as the stored sRGB-encoded bytes.
// Per pixel, with d = a - b per channel: |d.r|^2 + |d.g|^2 + |d.b|^2 -> rms = sqrt(sum / (3 * 255^2 * pixels)).
// The sum is also split by where the pixel is: a pixel that is the background's colour (the device's encoding of
// the clear colour, `params.bg`) in exactly one of the two frames is coverage (an object covers it in one frame
// and not in the other); the rest is shading (covered in both, its colour changed). Each slot holds two 64-bit
// sums, the whole and its coverage part: coverage^2 + shading^2 = rms^2 exactly in the sums.
// One workgroup per row of the rectangle `x0..x1` by `y0..y1` (outside it the two frames are known to be equal:
// lodpop's counterfactual is drawn only there, src/measure/quality.rs), LANES invocations (a pipeline constant,
// as in shaders/metrics.wgsl: 64 on a GPU, 8 on a CPU adapter, one vector of lavapipe's 256-bit lanes adding an
// eighth of the atomics 64 would), no barriers (as shaders/metrics.wgsl, for the same reasons); a run of at
// most 8192 / 8 = 1024 pixels keeps each partial sum below 2^32 (1024 * 3 * 255^2).

struct Params {
    width: u32,
    height: u32,
    slot: u32,
    pad: u32,
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
    // The background's bytes (r, g, b) and a pad.
    bg: vec4<u32>,
};

@group(0) @binding(0) var a_img: texture_2d<f32>;
@group(0) @binding(1) var b_img: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> sums: array<atomic<u32>>;
@group(0) @binding(3) var<uniform> params: Params;

override LANES: u32 = 64u;

fn to_bytes(v: vec4<f32>) -> vec3<i32> {
    return vec3<i32>(round(clamp(v.rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0));
}

@compute @workgroup_size(LANES, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let y = params.y0 + gid.y;
    if (y >= params.y1) {
        return;
    }
    var sum = 0u;
    var coverage = 0u;
    let bg = vec3<i32>(params.bg.xyz);
    for (var x = params.x0 + gid.x; x < params.x1; x = x + LANES) {
        let p = vec2<i32>(i32(x), i32(y));
        let a = to_bytes(textureLoad(a_img, p, 0));
        let b = to_bytes(textureLoad(b_img, p, 0));
        let d = a - b;
        let e = u32(d.x * d.x + d.y * d.y + d.z * d.z);
        sum = sum + e;
        if (all(a == bg) != all(b == bg)) {
            coverage = coverage + e;
        }
    }
    add(params.slot * 4u, sum);
    add(params.slot * 4u + 2u, coverage);
}

// Adds `v` to the 64-bit sum in words `lo` and `lo + 1`.
fn add(lo: u32, v: u32) {
    if (v != 0u) {
        let old = atomicAdd(&sums[lo], v);
        if (old + v < old) {
            atomicAdd(&sums[lo + 1u], 1u);
        }
    }
}
