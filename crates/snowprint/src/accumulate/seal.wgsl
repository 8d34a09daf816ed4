// The indirect dispatch of `fused_listed` (fused.wgsl): one workgroup per entry of the capture's
// tile list, in as few rows as the largest dispatch along one axis (DISPATCH_ROW_MAX) allows, as
// even as can be (gpu::resources::dispatch_rows).
// Reads: the list's entry count (word 3). Writes: the dispatch arguments (words 0-2).
// Imports shared.wgsl only for PRECISION, which the update sets on every one of its passes.

// import shared

@group(0) @binding(0) var<storage, read_write> tile_list: array<u32>;

@compute @workgroup_size(1, 1, 1)
fn seal_tiles() {
    let n = tile_list[3];
    let rows = max((n + DISPATCH_ROW_MAX - 1u) / DISPATCH_ROW_MAX, 1u);
    tile_list[0] = (n + rows - 1u) / rows;
    tile_list[1] = rows;
    tile_list[2] = 1u;
}
