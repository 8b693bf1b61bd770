// The adapter's memory bandwidth as a compute pass sees it (src/gpu/probe.rs, `lodbench probe`).

// Bandwidth probe: each invocation reads `reads` consecutive vec4<u32> of the buffer (16 bytes each); a
// workgroup sums them and adds one value to the output, so the reads cannot be dropped.
struct ReadParams {
    // vec4s in the buffer to read.
    count: u32,
    // vec4s each invocation reads.
    reads: u32,
};

@group(0) @binding(0) var<uniform> read_params: ReadParams;
@group(0) @binding(1) var<storage, read> source: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> sink: array<atomic<u32>>;

var<workgroup> partial: atomic<u32>;

@compute @workgroup_size(64)
fn cs_read(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>,
           @builtin(local_invocation_index) local: u32) {
    let invocation = id.x + id.y * groups.x * 64u;
    var sum = 0u;
    for (var k = 0u; k < read_params.reads; k = k + 1u) {
        let at = invocation * read_params.reads + k;
        if (at < read_params.count) {
            let v = source[at];
            sum = sum + (v.x ^ v.y ^ v.z ^ v.w);
        }
    }
    atomicAdd(&partial, sum);
    workgroupBarrier();
    if (local == 0u) {
        atomicAdd(&sink[0], atomicLoad(&partial));
    }
}
