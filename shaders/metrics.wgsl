// Per-frame image metrics on the GPU, reduced to exact integer sums so the CPU oracle (src/metrics.rs) can be
// matched to 1e-5 (Sheliemietiev et al. 2023 section 6 steps 5-6 for rmse; lodbench's temporal popping score for pop).
//
// Both images are read through Rgba8Unorm views of the sRGB targets, i.e. as the stored sRGB-encoded bytes.
// (Reading storage-buffer copies of the two frames instead measured no faster on lavapipe: docs/findings/timing.md.)
// Per pixel, with a and b the method and reference bytes and e = a - b per channel:
//   rmse term  (|e.r| + |e.g| + |e.b|)^2                 -> rmse = sqrt(sum / (9 * 255^2 * pixels))
//   pop term   |e_t - e_{t-1}|^2 summed over R, G, B      -> pop  = sqrt(sum / (3 * 255^2 * pixels))
//   de2000     CIEDE2000 (sRGB D65 -> XYZ -> CIELAB, as colour-science), only for pixels that differ, in f32,
//              rounded to 1/65536                         -> de2000_mean = sum / (65536 * pixels)
//   uncovered  the method shows the background (its bytes equal `params.background`, the bytes a clear to the
//              background stores) where the reference does not               -> uncovered_px = count
//   crack      an uncovered pixel with the method's own surface within CRACK_REACH pixels on both sides along
//              its row or its column, and the reference's surface on every pixel within CRACK_MARGIN of it (a gap
//              inside the surface, not a silhouette that a coarser LOD moved inwards)
//                                                                                -> crack_px = count
// Uncovered pixels are counted and marked in the loop, then listed (`uncovered_list`) without reading the frames
// again; the crack test runs on the list in a second dispatch, `crack_main` (a fixed number of workgroups of
// CRACK_LANES invocations, each testing every (CRACK_LANES * groups)-th listed pixel).
// e_t is kept per pixel in `prev_error` for the next frame. Each frame slot holds three 64-bit sums and the two
// 32-bit counts (8 words; a count stays below 8192^2 = 2^26).
// Two pipeline-overridable switches: DE2000 adds de2000 (`--metrics de2000`, which costs more than the rest);
// WORKGROUP_REDUCE sums the tile's LANES partial sums in workgroup memory behind a barrier and adds them with one
// invocation (`--metric-reduction workgroup`) instead of each invocation adding its own (the default, `atomics`,
// measured faster on lavapipe: docs/measurement.md, "Cost of the quality pass").
//
// One workgroup per 16 x 16 tile of the frame, LANES invocations, over the tiles listed in `tiles` (the quality
// pass lists those an instance can cover now or covered on the previous frame, src/measure/coverage.rs; every
// tile where it cannot bound them): outside them both frames show the background and e_t = e_(t-1) = 0, so
// every sum is the whole frame's. Invocation i reads the tile's pixels k = i + LANES j, j = 0..PIXELS - 1, at
// (k % 16, k / 16) (neighbouring invocations read neighbouring pixels), then its sums reach a 64-bit total made
// of two u32 atomics per frame slot, directly or through the workgroup reduction. LANES is a pipeline
// constant (src/gpu/compute.rs, `kernel_lanes`): 64 on a GPU, 8 on a CPU adapter, where 8 invocations are one
// vector of lavapipe's 256-bit lanes adding their sums with an eighth of the atomics per pixel that 64 do
// (the reads are the same; benches/metric_kernel.rs). At most 32 pixels per invocation keep each partial sum
// far below 2^32 (32 * 585225 for rmse, 32 * 780300 for pop, 32 * 65536 * 120 for de2000, CIEDE2000 staying
// below 120 between sRGB colours); the reduction carries into the high word. The tiles come in rows of at most
// MAX_ROW workgroups (a dispatch's limit per dimension): tile index = workgroup_id.y * MAX_ROW + workgroup_id.x.

struct Params {
    width: u32,
    height: u32,
    slot: u32,
    has_prev: u32,
    // The background's bytes, r | g << 8 | b << 16.
    background: u32,
    // How many tiles `tiles` lists.
    tile_count: u32,
    pad0: u32,
    pad1: u32,
};

@group(0) @binding(0) var method_img: texture_2d<f32>;
@group(0) @binding(1) var reference_img: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> prev_error: array<u32>;
@group(0) @binding(3) var<storage, read_write> sums: array<atomic<u32>>;
@group(0) @binding(4) var<uniform> params: Params;
// The frame's uncovered pixels (indices y * width + x), appended by `main`, checked for cracks by `crack_main`.
@group(0) @binding(5) var<storage, read_write> uncovered_list: array<u32>;
// How many `uncovered_list` holds (zeroed before each frame).
@group(0) @binding(6) var<storage, read_write> uncovered_count: atomic<u32>;
// The tiles this frame reads, each as tx | ty << 16.
@group(0) @binding(7) var<storage, read> tiles: array<u32>;

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

// Invocations per tile (8, 16, 32 or 64: the `uncovered` mask holds PIXELS bits) and the pixels each reads.
override LANES: u32 = 64u;
override PIXELS: u32 = 256u / LANES;
const TILE: u32 = 16u;
const MAX_ROW: u32 = 65535u;
const CRACK_REACH: i32 = 4;
const CRACK_MARGIN: i32 = 2;
const SLOT_WORDS: u32 = 8u;

fn background_bytes() -> vec3<i32> {
    let b = params.background;
    return vec3<i32>(i32(b & 255u), i32((b >> 8u) & 255u), i32((b >> 16u) & 255u));
}

// The method's image shows surface at p (inside the image and not the background's bytes).
fn method_surface(p: vec2<i32>) -> bool {
    if (p.x < 0 || p.y < 0 || p.x >= i32(params.width) || p.y >= i32(params.height)) {
        return false;
    }
    return any(to_bytes(textureLoad(method_img, p, 0)) != background_bytes());
}

// The reference shows surface on every pixel of the (2 CRACK_MARGIN + 1)^2 square around p (inside the image).
fn inside_reference(p: vec2<i32>) -> bool {
    let bg = background_bytes();
    for (var dy = -CRACK_MARGIN; dy <= CRACK_MARGIN; dy = dy + 1) {
        for (var dx = -CRACK_MARGIN; dx <= CRACK_MARGIN; dx = dx + 1) {
            let q = p + vec2<i32>(dx, dy);
            if (q.x < 0 || q.y < 0 || q.x >= i32(params.width) || q.y >= i32(params.height)) {
                return false;
            }
            if (all(to_bytes(textureLoad(reference_img, q, 0)) == bg)) {
                return false;
            }
        }
    }
    return true;
}

// Surface within CRACK_REACH pixels on both sides of p along `step`.
fn enclosed_along(p: vec2<i32>, step: vec2<i32>) -> bool {
    var before = false;
    var after = false;
    for (var d = 1; d <= CRACK_REACH; d = d + 1) {
        before = before || method_surface(p - step * d);
        after = after || method_surface(p + step * d);
    }
    return before && after;
}
const DE_SCALE: f32 = 65536.0;

fn srgb_to_lab(c: vec3<i32>) -> vec3<f32> {
    let v = vec3<f32>(c) / 255.0;
    let lin = select(pow((v + 0.055) / 1.055, vec3<f32>(2.4)), v / 12.92, v <= vec3<f32>(0.04045));
    // IEC 61966-2-1 sRGB to XYZ (columns), then divided by the D65 white (xy 0.3127, 0.3290).
    let m = mat3x3<f32>(
        vec3<f32>(0.4124, 0.2126, 0.0193),
        vec3<f32>(0.3576, 0.7152, 0.1192),
        vec3<f32>(0.1805, 0.0722, 0.9505),
    );
    let xyz = (m * lin) / vec3<f32>(0.950455927, 1.0, 1.089057751);
    let f = select((24389.0 / 27.0 * xyz + 16.0) / 116.0, pow(xyz, vec3<f32>(1.0 / 3.0)), xyz > vec3<f32>(216.0 / 24389.0));
    return vec3<f32>(116.0 * f.y - 16.0, 500.0 * (f.x - f.y), 200.0 * (f.y - f.z));
}

fn hue_deg(b: f32, ap: f32) -> f32 {
    if (b == 0.0 && ap == 0.0) {
        return 0.0;
    }
    let h = degrees(atan2(b, ap));
    return select(h, h + 360.0, h < 0.0);
}

// CIEDE2000 (Sharma, Wu, Dalal 2005), kL = kC = kH = 1; the CPU twin is metrics::ciede2000.
fn ciede2000(lab1: vec3<f32>, lab2: vec3<f32>) -> f32 {
    let p25 = 6103515625.0; // 25^7
    let c_bar = (length(lab1.yz) + length(lab2.yz)) * 0.5;
    let c7 = pow(c_bar, 7.0);
    let g = 0.5 * (1.0 - sqrt(c7 / (c7 + p25)));
    let a1p = (1.0 + g) * lab1.y;
    let a2p = (1.0 + g) * lab2.y;
    let c1p = length(vec2<f32>(a1p, lab1.z));
    let c2p = length(vec2<f32>(a2p, lab2.z));
    let h1p = hue_deg(lab1.z, a1p);
    let h2p = hue_deg(lab2.z, a2p);
    let dlp = lab2.x - lab1.x;
    let dcp = c2p - c1p;
    var dhp = 0.0;
    if (c1p * c2p != 0.0) {
        dhp = h2p - h1p;
        if (dhp > 180.0) {
            dhp = dhp - 360.0;
        } else if (dhp < -180.0) {
            dhp = dhp + 360.0;
        }
    }
    let d_hp = 2.0 * sqrt(c1p * c2p) * sin(radians(dhp * 0.5));
    let lbp = (lab1.x + lab2.x) * 0.5;
    let cbp = (c1p + c2p) * 0.5;
    var hbp = h1p + h2p;
    if (c1p * c2p != 0.0) {
        if (abs(h1p - h2p) <= 180.0) {
            hbp = (h1p + h2p) * 0.5;
        } else if (h1p + h2p < 360.0) {
            hbp = (h1p + h2p + 360.0) * 0.5;
        } else {
            hbp = (h1p + h2p - 360.0) * 0.5;
        }
    }
    let t = 1.0 - 0.17 * cos(radians(hbp - 30.0)) + 0.24 * cos(radians(2.0 * hbp))
        + 0.32 * cos(radians(3.0 * hbp + 6.0)) - 0.20 * cos(radians(4.0 * hbp - 63.0));
    let q = (hbp - 275.0) / 25.0;
    let d_theta = 30.0 * exp(-q * q);
    let cb7 = pow(cbp, 7.0);
    let rc = 2.0 * sqrt(cb7 / (cb7 + p25));
    let l50 = (lbp - 50.0) * (lbp - 50.0);
    let sl = 1.0 + 0.015 * l50 / sqrt(20.0 + l50);
    let sc = 1.0 + 0.045 * cbp;
    let sh = 1.0 + 0.015 * cbp * t;
    let rt = -sin(radians(2.0 * d_theta)) * rc;
    let x = dlp / sl;
    let y = dcp / sc;
    let z = d_hp / sh;
    return sqrt(max(x * x + y * y + z * z + rt * y * z, 0.0));
}

// The first LANES entries are used.
var<workgroup> partial: array<vec3<u32>, 64>;

/// Invocations of a `crack_main` workgroup: one vector of lavapipe's, which runs every workgroup's loop body at
/// least once whatever the list holds.
const CRACK_LANES: u32 = 8u;

// The crack test of every uncovered pixel `main` listed (dispatched after it; its workgroup count is the
// kernel's, src/measure/metric_kernel.rs).
@compute @workgroup_size(8, 1, 1)
fn crack_main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let n = atomicLoad(&uncovered_count);
    var cracks = 0u;
    for (var i = gid.x; i < n; i = i + CRACK_LANES * groups.x) {
        let idx = uncovered_list[i];
        let p = vec2<i32>(i32(idx % params.width), i32(idx / params.width));
        let enclosed = enclosed_along(p, vec2<i32>(1, 0)) || enclosed_along(p, vec2<i32>(0, 1));
        cracks = cracks + select(0u, 1u, enclosed && inside_reference(p));
    }
    if (cracks != 0u) {
        atomicAdd(&sums[params.slot * SLOT_WORDS + 7u], cracks);
    }
}

// Adds `v` to the 64-bit (lo, hi) pair.
fn add_pair(acc: vec2<u32>, v: u32) -> vec2<u32> {
    let lo = acc.x + v;
    return vec2<u32>(lo, acc.y + select(0u, 1u, lo < v));
}

fn add_u64_pair(lo: u32, v: vec2<u32>) {
    if (v.x != 0u) {
        add_u64(lo, v.x);
    }
    if (v.y != 0u) {
        atomicAdd(&sums[lo + 1u], v.y);
    }
}

override DE2000: bool = false;
override WORKGROUP_REDUCE: bool = false;

// Pixel j (0..PIXELS - 1) of invocation `lid` in the tile at `origin`: (x, y), and whether it lies inside the
// frame.
fn tile_pixel(origin: vec2<u32>, lid: u32, j: u32) -> vec3<u32> {
    let k = lid + LANES * j;
    let x = origin.x + k % TILE;
    let y = origin.y + k / TILE;
    return vec3<u32>(x, y, select(0u, 1u, x < params.width && y < params.height));
}

@compute @workgroup_size(LANES, 1, 1)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let listed = wid.y * MAX_ROW + wid.x;
    // Workgroups past the list still take part in the workgroup's barrier, with nothing to add.
    let pixels = select(0u, PIXELS, listed < params.tile_count);
    let packed = tiles[min(listed, max(params.tile_count, 1u) - 1u)];
    let origin = vec2<u32>(packed & 0xffffu, packed >> 16u) * TILE;
    var rmse_sum = 0u;
    var pop_sum = 0u;
    var de_sum = 0u;
    // Bit j: pixel j is uncovered.
    var uncovered = 0u;
    let bg = background_bytes();
    for (var j = 0u; j < pixels; j = j + 1u) {
        let q = tile_pixel(origin, lid, j);
        if (q.z == 0u) {
            continue;
        }
        let p = vec2<i32>(i32(q.x), i32(q.y));
        let a = to_bytes(textureLoad(method_img, p, 0));
        let b = to_bytes(textureLoad(reference_img, p, 0));
        let e = a - b;
        uncovered = uncovered | select(0u, 1u << j, all(a == bg) && any(b != bg));
        let s = u32(abs(e.x) + abs(e.y) + abs(e.z));
        rmse_sum = rmse_sum + s * s;
        if (DE2000 && s != 0u) {
            de_sum = de_sum + u32(round(ciede2000(srgb_to_lab(a), srgb_to_lab(b)) * DE_SCALE));
        }
        let idx = q.y * params.width + q.x;
        if (params.has_prev != 0u) {
            let w = prev_error[idx];
            let prev = vec3<i32>(
                i32(w & 1023u),
                i32((w >> 10u) & 1023u),
                i32((w >> 20u) & 1023u),
            ) - vec3<i32>(255);
            let d = e - prev;
            pop_sum = pop_sum + u32(d.x * d.x + d.y * d.y + d.z * d.z);
        }
        let biased = vec3<u32>(e + vec3<i32>(255));
        prev_error[idx] = biased.x | (biased.y << 10u) | (biased.z << 20u);
    }
    let slot = params.slot * SLOT_WORDS;
    // The marked pixels listed, from the mask: no second read of the frames (lavapipe runs a branch's body for
    // every pixel of a vector whatever the condition, so the listing costs what it reads). The neighbourhood
    // reads of the crack test run in `crack_main`, on the list: in this loop they slowed every frame several
    // times over.
    if (uncovered != 0u) {
        atomicAdd(&sums[slot + 6u], countOneBits(uncovered));
    }
    var marked = uncovered;
    loop {
        if (marked == 0u) {
            break;
        }
        let j = firstTrailingBit(marked);
        marked = marked & (marked - 1u);
        let q = tile_pixel(origin, lid, j);
        uncovered_list[atomicAdd(&uncovered_count, 1u)] = q.y * params.width + q.x;
    }
    if (!WORKGROUP_REDUCE) {
        add_u64_pair(slot, vec2<u32>(rmse_sum, 0u));
        add_u64_pair(slot + 2u, vec2<u32>(pop_sum, 0u));
        add_u64_pair(slot + 4u, vec2<u32>(de_sum, 0u));
        return;
    }
    partial[lid] = vec3<u32>(rmse_sum, pop_sum, de_sum);
    workgroupBarrier();
    if (lid == 0u) {
        var r = vec2<u32>(0u);
        var p = vec2<u32>(0u);
        var d = vec2<u32>(0u);
        for (var i = 0u; i < LANES; i = i + 1u) {
            let v = partial[i];
            r = add_pair(r, v.x);
            p = add_pair(p, v.y);
            d = add_pair(d, v.z);
        }
        add_u64_pair(slot, r);
        add_u64_pair(slot + 2u, p);
        add_u64_pair(slot + 4u, d);
    }
}
