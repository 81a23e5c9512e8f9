// Exclusive prefix sum over u32, in blocks of 512 (256 invocations, two elements each):
// `scan_blocks` scans each block in place in workgroup memory and writes the block's total
// to `sums`; the totals are scanned the same way (recursively, by the host), then
// `add_sums` adds each block's scanned total to its elements.

const WG: u32 = 256u;
const BLOCK: u32 = 512u;

@group(0) @binding(0) var<storage, read_write> data: array<u32>;
@group(0) @binding(1) var<storage, read_write> sums: array<u32>;
@group(0) @binding(2) var<uniform> len: vec4<u32>;

var<workgroup> tile: array<u32, 512>;

@compute @workgroup_size(WG)
fn scan_blocks(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let n = len.x;
    let base = wid.x * BLOCK;
    let a = base + 2u * lid.x;
    let b = a + 1u;
    tile[2u * lid.x] = select(0u, data[a], a < n);
    tile[2u * lid.x + 1u] = select(0u, data[b], b < n);
    // Blelloch scan: up-sweep.
    var offset = 1u;
    for (var d = BLOCK >> 1u; d > 0u; d = d >> 1u) {
        workgroupBarrier();
        if (lid.x < d) {
            let ai = offset * (2u * lid.x + 1u) - 1u;
            let bi = offset * (2u * lid.x + 2u) - 1u;
            tile[bi] += tile[ai];
        }
        offset = offset << 1u;
    }
    workgroupBarrier();
    if (lid.x == 0u) {
        sums[wid.x] = tile[BLOCK - 1u];
        tile[BLOCK - 1u] = 0u;
    }
    // Down-sweep.
    for (var d = 1u; d < BLOCK; d = d << 1u) {
        offset = offset >> 1u;
        workgroupBarrier();
        if (lid.x < d) {
            let ai = offset * (2u * lid.x + 1u) - 1u;
            let bi = offset * (2u * lid.x + 2u) - 1u;
            let t = tile[ai];
            tile[ai] = tile[bi];
            tile[bi] += t;
        }
    }
    workgroupBarrier();
    if (a < n) {
        data[a] = tile[2u * lid.x];
    }
    if (b < n) {
        data[b] = tile[2u * lid.x + 1u];
    }
}

@compute @workgroup_size(WG)
fn add_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let n = len.x;
    let add = sums[wid.x];
    let a = wid.x * BLOCK + 2u * lid.x;
    if (a < n) {
        data[a] += add;
    }
    if (a + 1u < n) {
        data[a + 1u] += add;
    }
}
