// Per-frame image metrics on the GPU, reduced to exact integer sums so the CPU oracle (src/metrics.rs) can be
// matched to 1e-5 (seed 003 section 6 steps 5-6 for rmse; lodbench's temporal popping score for pop).
//
// Both images are read through Rgba8Unorm views of the sRGB targets, i.e. as the stored sRGB-encoded bytes.
// Per pixel, with a and b the method and reference bytes and e = a - b per channel:
//   rmse term  (|e.r| + |e.g| + |e.b|)^2                 -> rmse = sqrt(sum / (9 * 255^2 * pixels))
//   pop term   |e_t - e_{t-1}|^2 summed over R, G, B      -> pop  = sqrt(sum / (3 * 255^2 * pixels))
// e_t is kept per pixel in `prev_error` for the next frame.
//
// One workgroup per row, 64 invocations; invocation i sums the pixels i, i + 64, i + 128, ... of its row
// (neighbouring invocations read neighbouring pixels), then adds its two sums to a 64-bit total made of two u32
// atomics per frame slot. No workgroup barriers: they are cheap on GPUs but very slow on software adapters,
// where CI runs. A run of at most 8192 / 64 = 128 pixels keeps each partial sum below 128 * 780300 < 2^32.

struct Params {
    width: u32,
    height: u32,
    slot: u32,
    has_prev: u32,
};

@group(0) @binding(0) var method_img: texture_2d<f32>;
@group(0) @binding(1) var reference_img: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> prev_error: array<u32>;
@group(0) @binding(3) var<storage, read_write> sums: array<atomic<u32>>;
@group(0) @binding(4) var<uniform> params: Params;

fn to_bytes(v: vec4<f32>) -> vec3<i32> {
    return vec3<i32>(round(clamp(v.rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0));
}

fn add_u64(lo: u32, value: u32) {
    let old = atomicAdd(&sums[lo], value);
    // Carry into the high word when the low word wrapped.
    if (old + value < old) {
        atomicAdd(&sums[lo + 1u], 1u);
    }
}

const LANES: u32 = 64u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let y = gid.y;
    if (y >= params.height) {
        return;
    }
    var rmse_sum = 0u;
    var pop_sum = 0u;
    for (var x = gid.x; x < params.width; x = x + LANES) {
        let p = vec2<i32>(i32(x), i32(y));
        let e = to_bytes(textureLoad(method_img, p, 0)) - to_bytes(textureLoad(reference_img, p, 0));
        let s = u32(abs(e.x) + abs(e.y) + abs(e.z));
        rmse_sum = rmse_sum + s * s;
        let idx = y * params.width + x;
        if (params.has_prev != 0u) {
            let q = prev_error[idx];
            let prev = vec3<i32>(
                i32(q & 1023u),
                i32((q >> 10u) & 1023u),
                i32((q >> 20u) & 1023u),
            ) - vec3<i32>(255);
            let d = e - prev;
            pop_sum = pop_sum + u32(d.x * d.x + d.y * d.y + d.z * d.z);
        }
        let biased = vec3<u32>(e + vec3<i32>(255));
        prev_error[idx] = biased.x | (biased.y << 10u) | (biased.z << 20u);
    }
    if (rmse_sum != 0u) {
        add_u64(params.slot * 4u, rmse_sum);
    }
    if (pop_sum != 0u) {
        add_u64(params.slot * 4u + 2u, pop_sum);
    }
}
