// classify.wgsl: which snow material each surface needs this frame, decided on the GPU. A surface
// whose heightmap is all zero (nothing ever pressed it, or the snow has filled every print back)
// gets the basic material; any other the deformable one, and so does every surface on ground that is
// not flat (the basic material draws a flat top) or with a hole (a coarser terrain window level:
// the basic material cannot meet the step at the hole's edge). The pass writes, per surface, the
// indirect draw arguments of both snow pipelines (one of them with zero instances), whether its
// heightfield and bank passes run (not when basic, or when nothing of the frame can show the
// surface: render/frame/seen.rs), and the flag the report reads.
// Reads: the heightmap pool, the surface list. Writes: the surface state table.

// import texel, constants

// Must match `ClassifyRecord` in src/render/gpu.rs.
struct ClassifyRecord {
    heights: u32,     // word offset of the heightmap in the pool
    width: u32,
    height: u32,
    box_vertices: u32,
    bits: u32,        // bits a channel (pool/texel.wgsl)
    always_deformable: u32, // 1 on ground that is not flat, or with a hole (ClassifyRecord)
    wrap: u32,        // toroidal storage offsets (pool/texel.wgsl)
    seen: u32,        // 1 when anything of the frame can show the surface (render/frame/seen.rs)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: u32,
}

@group(0) @binding(0) var<storage, read> pool: array<u32>;
@group(0) @binding(1) var<storage, read> records: array<ClassifyRecord>;
@group(0) @binding(2) var<storage, read_write> state: array<u32>;

var<workgroup> deepest: atomic<u32>;

@compute @workgroup_size(256, 1, 1)
fn classify(@builtin(local_invocation_index) li: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let rec = records[wg.x];
    if li == 0u {
        atomicStore(&deepest, 0u);
    }
    workgroupBarrier();
    let count = rec.width * rec.height;
    var local_max = 0u;
    for (var i = li; i < count; i += 256u) {
        let t = pool_texel(rec.bits, rec.heights, rec.width, rec.height, rec.wrap, i % rec.width, i / rec.width);
        local_max = max(local_max, t.x);
    }
    atomicMax(&deepest, local_max);
    workgroupBarrier();
    if li == 0u {
        let d = atomicLoad(&deepest);
        let touched = select(0u, 1u, d > 0u);
        let deformable = max(touched, rec.always_deformable);
        let base = wg.x * STATE_WORDS;
        // Basic material draw: vertex count, instance count, first vertex, first instance.
        state[base + 0u] = rec.box_vertices;
        state[base + 1u] = 1u - deformable;
        state[base + 2u] = 0u;
        state[base + 3u] = 0u;
        // Deformable material draw.
        state[base + 4u] = rec.box_vertices;
        state[base + 5u] = deformable;
        state[base + 6u] = 0u;
        state[base + 7u] = 0u;
        // Whether the heightfield and bank passes run over it: deformable, where the frame shows
        // it (they are dispatched over every surface seen, and leave at once where this is 0).
        state[base + STATE_SHADED] = select(0u, 1u, deformable == 1u && rec.seen == 1u);
        state[base + STATE_TOUCHED] = touched;
        state[base + 12u] = bitcast<u32>(f32(d) / f32(channel_max(rec.bits)));
    }
}
