// The adapter's ceilings (src/gpu/probe.rs, `lodbench probe`): microbenchmarks that each load one stage of the
// pipeline and leave the others idle. Positions come from the vertex and instance indices, so no vertex fetch.

struct Params {
    // The target's size in pixels.
    size: vec2<f32>,
    // Patches (triangle probe) or pixels per row of the degenerate vertices' grid.
    per_row: u32,
    // Quads per side of a full-screen layer (fill and depth probes): 1 draws it as 2 triangles, 2 as 8.
    grid: u32,
};

@group(0) @binding(0) var<uniform> params: Params;

// Pixel (x, y) plus an offset in pixels to clip space (y up).
fn to_clip(pixel: vec2<f32>) -> vec4<f32> {
    let ndc = pixel / params.size * 2.0 - vec2<f32>(1.0, 1.0);
    return vec4<f32>(ndc.x, -ndc.y, 0.5, 1.0);
}

// The pixel a patch or vertex number lands in: row by row over the target, wrapping.
fn pixel_of(n: u32) -> vec2<f32> {
    let w = u32(params.size.x);
    let h = u32(params.size.y);
    let p = n % (w * h);
    return vec2<f32>(f32(p % w), f32(p / w));
}

// Triangle probe: a patch is 9 vertices in a 3x3 grid 0.15 px apart in its pixel's top-left corner (8 triangles
// by the index buffer); no triangle reaches the pixel's centre, so nothing is rasterised. Non-instanced: the
// patch is vertex_index / 9; instanced: instance_index, the patch's own vertex vertex_index.
fn patch_vertex(which: u32, corner: u32) -> vec4<f32> {
    let offset = vec2<f32>(f32(corner % 3u), f32(corner / 3u)) * 0.15 + vec2<f32>(0.05, 0.05);
    return to_clip(pixel_of(which) + offset);
}

@vertex
fn vs_patches(@builtin(vertex_index) v: u32) -> @builtin(position) vec4<f32> {
    return patch_vertex(v / 9u, v % 9u);
}

@vertex
fn vs_patches_instanced(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> @builtin(position) vec4<f32> {
    return patch_vertex(i, v);
}

// Vertex probe: every triangle's three vertices at one point (zero area: assembled, then dropped before any
// rasterisation), so the time is the vertex shader's and the primitive assembly's.
@vertex
fn vs_degenerate(@builtin(vertex_index) v: u32) -> @builtin(position) vec4<f32> {
    return to_clip(pixel_of(v / 3u) + vec2<f32>(0.25, 0.25));
}

// Fill and depth probes: one full-screen layer as grid x grid quads, 6 vertices each.
@vertex
fn vs_layer(@builtin(vertex_index) v: u32) -> @builtin(position) vec4<f32> {
    let quad = v / 6u;
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
    )[v % 6u];
    let g = f32(params.grid);
    let cell = vec2<f32>(f32(quad % params.grid), f32(quad / params.grid));
    return to_clip((cell + corner) / g * params.size);
}

@fragment
fn fs_colour() -> @location(0) vec4<f32> {
    return vec4<f32>(0.6, 0.4, 0.2, 0.5);
}
