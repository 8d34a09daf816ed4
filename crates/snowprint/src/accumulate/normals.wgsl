// Normals of the snow top derived from the new heightmap, for renderers that want them
// precomputed (only dispatched when the pool keeps normals).
// Reads: `records`, each record's heights region in `pool` (written by the merge).
// Writes: the `normals` region: pack2x16snorm of the normal's local x and z (y is positive and
// follows from unit length).
// CPU reference: accumulate::cpu::normals. Maths: maths.wgsl.

// import maths, texel_write

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read_write> pool: array<u32>;

fn height_at(rec: SurfaceRecord, x: i32, y: i32) -> f32 {
    let cx = u32(clamp(x, 0, i32(rec.width) - 1));
    let cy = u32(clamp(y, 0, i32(rec.height) - 1));
    return snow_height(rec, pool_texel(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, cx, cy).x);
}

@compute @workgroup_size(WORKGROUP, WORKGROUP, 1)
fn normals(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    if rec.normals == NO_NORMALS || gid.x >= rec.width || gid.y >= rec.height {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    // The normals region is stored wrapped like the heights (pool/texel.wgsl).
    let p = pool_wrapped(rec.wrap, rec.width, rec.height, gid.x, gid.y);
    pool[rec.normals + p.y * rec.width + p.x] = packed_normal(
        rec,
        height_at(rec, x - 1, y),
        height_at(rec, x + 1, y),
        height_at(rec, x, y - 1),
        height_at(rec, x, y + 1),
    );
}
