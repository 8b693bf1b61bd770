// FSI combination pass (Scherzer & Wimmer 2008 sections 3.4-3.5), a compute pass over the pixels (a full-screen-triangle
// render pass was recompiled by llvmpipe on every draw, costing milliseconds and ~1 MB of memory per frame). The newer LOD buffer is read at
// the pixel; the older one through reprojection by eq. 2, p_old = P_old V_old V_new^-1 P_new^-1 p_new, using
// the newer buffer's stored depth (or at the same pixel with SAME_PIXEL, the `fsi-noreproject` ablation).
// A pixel that reprojects outside the older buffer takes the newer colour. Then per pixel:
//   both ids 0 (two n-instances)              -> the newer colour;
//   the same t-instance id in both            -> the average of the two colours (no depth test: coplanar LODs
//                                                would z-fight), averaged in linear RGB;
//   anything else (one t-instance)            -> the closer fragment, depths compared in the older frame's
//                                                depth space (the newer depth reprojected by eq. 2).
// `fsi-blend` (frame-sequential blending, section 3.3's rejected alternative) replaces the last two cases: the
// LOD buffers hold complete LODs and each t-instance fragment its LOD's blend weight in alpha, and any pixel with a
// t-instance in either buffer is the two colours mixed by that weight (the newer buffer's t-instance, else the
// older's), whatever lies in front of what.
// With `--fsi-check forward` (not in the paper; see `FsiCheck` in src/methods/fsi.rs) the older fragment used
// is one that lands within a pixel of this pixel's centre when reprojected forward with its own depth
// (`forward`, eq. 2 inverted): eq. 2's lookup if it does, else the texel found by moving the lookup by the
// miss (`forward_match`); if none does, the pixel takes the newer colour, as if it reprojected outside.
// Colours are read and written as the stored sRGB-encoded bytes (Rgba8Unorm views), so a pixel that takes one
// buffer's colour is copied bit for bit; only averaged pixels are decoded, mixed and re-encoded.

// The variant is fixed per pipeline (pipeline-overridable constants, one pipeline per FSI variant), not read
// from the uniform: with a uniform-selected branch, llvmpipe (Mesa 22.3) ran every variant's code for every
// pixel and its memory grew by about a frame's bytes per dispatch (docs/findings/timing.md, "FSI's combination
// pass on lavapipe").
// The older buffer read at the same pixel (`fsi-noreproject`, `fsi-sameframe`, lodpop's counterfactuals at one
// pose), not through eq. 2.
override SAME_PIXEL: bool = false;
// The combination: 0 the paper's, 1 with the forward check, 2 frame-sequential blending (`fsi-blend`).
override COMBINATION: u32 = 0u;

struct Combine {
    // P_old * V_old * V_new^-1 * P_new^-1 (clip space of the newer frame to clip space of the older one).
    reproject: mat4x4<f32>,
    // P_new * V_new * V_old^-1 * P_old^-1 (clip space of the older frame to clip space of the newer one).
    forward: mat4x4<f32>,
    // Viewport size in pixels (x, y); z, w unused.
    size: vec4<f32>,
};

@group(0) @binding(0) var new_color: texture_2d<f32>;
@group(0) @binding(1) var new_depth: texture_depth_2d;
@group(0) @binding(2) var new_id: texture_2d<u32>;
@group(0) @binding(3) var old_color: texture_2d<f32>;
@group(0) @binding(4) var old_depth: texture_depth_2d;
@group(0) @binding(5) var old_id: texture_2d<u32>;
@group(0) @binding(6) var<uniform> combine: Combine;
// The combined frame, as the sRGB-encoded bytes; copied into the frame's target afterwards.
@group(0) @binding(7) var output: texture_storage_2d<rgba8unorm, write>;

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

// Where pixel position `pos` of one frame, at depth `depth`, lies in the other frame by the clip-to-clip matrix
// `m`: (x, y) in pixels (possibly outside the viewport), z its depth there; w < 0 when behind the camera.
fn map_pixel(m: mat4x4<f32>, pos: vec2<f32>, depth: f32) -> vec4<f32> {
    let size = combine.size.xy;
    let ndc = vec4<f32>(pos.x / size.x * 2.0 - 1.0, 1.0 - pos.y / size.y * 2.0, depth, 1.0);
    let c = m * ndc;
    if (c.w <= 0.0) {
        return vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    let o = c.xyz / c.w;
    return vec4<f32>((o.x + 1.0) * 0.5 * size.x, (1.0 - o.y) * 0.5 * size.y, o.z, 1.0);
}

// Where pixel centre `pos` of the newer frame, at depth `depth`, lies in the older frame (eq. 2); w < 0 when it
// falls outside the older viewport or behind its camera.
fn reproject(pos: vec2<f32>, depth: f32) -> vec4<f32> {
    let r = map_pixel(combine.reproject, pos, depth);
    if (any(r.xy < vec2<f32>(0.0)) || any(r.xy >= combine.size.xy)) {
        return vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    return r;
}

// How many texels `forward_match` tries, and how far (in pixels, in x and in y) from the pixel's centre the
// older fragment may land: a pixel's own footprint (0.5) would leave gaps wherever the image magnifies between
// frames (samples land further apart than a pixel), so it is one pixel.
const FORWARD_STEPS: i32 = 4;
const FORWARD_TOLERANCE: f32 = 1.0;

// `--fsi-check forward`: the texel of the older buffer whose fragment, reprojected into the newer frame with
// its own depth, lands within FORWARD_TOLERANCE of pixel `p`'s centre. The search starts at `q` (eq. 2's
// lookup) and moves the lookup by how far the fragment missed, rounded, at most FORWARD_STEPS texels in all;
// (-1, -1) when none lands near `p`.
fn forward_match(p: vec2<i32>, q0: vec2<i32>) -> vec2<i32> {
    let size = vec2<i32>(combine.size.xy);
    let centre = vec2<f32>(p) + vec2<f32>(0.5);
    var q = q0;
    for (var i = 0; i < FORWARD_STEPS; i++) {
        let r = map_pixel(combine.forward, vec2<f32>(q) + vec2<f32>(0.5), textureLoad(old_depth, q, 0));
        if (r.w < 0.0) {
            break;
        }
        let miss = centre - r.xy;
        if (all(abs(miss) <= vec2<f32>(FORWARD_TOLERANCE))) {
            return q;
        }
        q += vec2<i32>(round(miss));
        if (any(q < vec2<i32>(0)) || any(q >= size)) {
            break;
        }
    }
    return vec2<i32>(-1);
}

@compute @workgroup_size(8, 8)
fn cs_combine(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(combine.size.xy);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let p = vec2<i32>(id.xy);
    textureStore(output, p, combine_pixel(p, vec2<f32>(id.xy) + vec2<f32>(0.5)));
}

fn combine_pixel(p: vec2<i32>, pos: vec2<f32>) -> vec4<f32> {
    let cn = textureLoad(new_color, p, 0);
    let dn = textureLoad(new_depth, p, 0);
    let idn = textureLoad(new_id, p, 0).r;
    var q = p;
    var dn_old = dn;
    if (!SAME_PIXEL) {
        let r = reproject(pos, dn);
        if (r.w < 0.0) {
            return cn;
        }
        q = vec2<i32>(floor(r.xy));
        dn_old = r.z;
        if (COMBINATION == 1u) {
            q = forward_match(p, q);
            if (q.x < 0) {
                return cn;
            }
        }
    }
    let co = textureLoad(old_color, q, 0);
    let ido = textureLoad(old_id, q, 0).r;
    if (idn == 0u && ido == 0u) {
        return cn;
    }
    if (COMBINATION == 2u) {
        // Frame-sequential blending: the two finished buffers mixed by the weight of the t-instance's LOD in
        // the newer buffer (its alpha), or, where only the older shows a t-instance, by that LOD's own weight.
        let w_new = select(1.0 - co.a, cn.a, idn != 0u);
        let mixed = mix(srgb_to_linear(co.rgb), srgb_to_linear(cn.rgb), w_new);
        return vec4<f32>(linear_to_srgb(mixed), 1.0);
    }
    if (idn == ido) {
        let mixed = 0.5 * (srgb_to_linear(cn.rgb) + srgb_to_linear(co.rgb));
        return vec4<f32>(linear_to_srgb(mixed), 1.0);
    }
    let d_old = textureLoad(old_depth, q, 0);
    if (d_old < dn_old) {
        return co;
    }
    return cn;
}
