// Replenish the heightmaps of the surfaces that refill snow, before the fused pass deepens them
// where the capture reached. Refilling subtracts the same units from both channels of every
// texel, saturating at the untouched top, so it does not depend on a texel's place: the pass
// streams each heights region's words in order (wrapped storage and row padding included; a
// padding texel holds zeros and keeps them), every channel of a word refilled as a lane.
// A workgroup takes REFILL_GROUP x REFILL_VECTORS consecutive 16-byte vectors of one record, each
// invocation REFILL_VECTORS of them a workgroup apart, all loaded before any is stored, so that
// the memory system has as many bytes in flight as a copy would; a vector is written back only
// where it changed (untouched snow stays as it is). A region starts on a slot, 256-byte aligned,
// and its slot is a whole number of 256 bytes, so its last vector lies in its own slot: the words
// of that vector past the region (padding, or the first normals) are written back unchanged, and
// nothing else writes them during this pass.
// The fused pass (fused.wgsl) then merges the blurred capture into the refilled words with no
// replenishment of its own: replenishing by r and then deepening equals merge_channels(old,
// blurred, r) (CPU reference: accumulate::cpu::refill_word). The world streams the refill only
// over many words (WorldConfig::refill_stream_from): it costs a few microseconds more in all.
// Reads: `records` (the first records of the frame's update, those marked MODE_REFILLED; `z` of
// the dispatch), their heights regions in `pool`. Writes: the same regions.

// import shared

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read_write> pool: array<vec4<u32>>;

// Words of a heights region (pool/texel.wgsl's layouts).
fn region_words(rec: SurfaceRecord) -> u32 {
    if PRECISION == 8u {
        return rec.height * ((rec.width + 1u) / 2u);
    }
    if PRECISION == 16u {
        return rec.width * rec.height;
    }
    return 2u * rec.width * rec.height;
}

// One channel refilled by `rep` units, saturating at 0 (the untouched top).
fn lane(v: u32, rep: u32) -> u32 {
    return max(v, rep) - rep;
}

// Two 8-bit channels held in the low bytes of a word's 16-bit fields (0x00bb00aa), each refilled
// by `rep` (at most 255): a field with its bit 8 set, less `rep`, keeps bit 8 exactly where the
// channel was at least `rep`, and never borrows from the field above.
fn refilled_pair(fields: u32, rep: u32) -> u32 {
    let t = (fields | 0x01000100u) - rep * 0x00010001u;
    let kept = ((t >> 8u) & 0x00010001u) * 0xffu;
    return t & kept;
}

// Every channel of a word refilled: four 8-bit lanes, two 16-bit lanes or one 32-bit word.
fn refilled(word: u32, rep: u32) -> u32 {
    if PRECISION == 8u {
        // A channel of 8 bits refilled by 255 units or more is untouched snow.
        let r = min(rep, 0xffu);
        return refilled_pair(word & 0x00ff00ffu, r) | (refilled_pair((word >> 8u) & 0x00ff00ffu, r) << 8u);
    }
    if PRECISION == 16u {
        return lane(word & 0xffffu, rep) | (lane(word >> 16u, rep) << 16u);
    }
    return lane(word, rep);
}

// Vector `i` of a region of `n` words refilled by `rep`: its words past the region unchanged.
fn refilled_vector(v: vec4<u32>, i: u32, n: u32, rep: u32) -> vec4<u32> {
    let r = vec4<u32>(refilled(v.x, rep), refilled(v.y, rep), refilled(v.z, rep), refilled(v.w, rep));
    let inside = vec4<u32>(4u * i) + vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(n);
    return select(v, r, inside);
}

@compute @workgroup_size(REFILL_GROUP, 1, 1)
fn refill(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let rec = records[wid.z];
    let n = region_words(rec);
    let vectors = (n + 3u) / 4u;
    let chunk = wid.x + wid.y * groups.x;
    let first = chunk * REFILL_GROUP * REFILL_VECTORS;
    if first >= vectors || (rec.mode & MODE_REFILLED) == 0u {
        return;
    }
    let base = rec.heights / 4u;
    var old: array<vec4<u32>, REFILL_VECTORS>;
    for (var k = 0u; k < REFILL_VECTORS; k++) {
        let i = first + k * REFILL_GROUP + lid;
        if i < vectors {
            old[k] = pool[base + i];
        }
    }
    for (var k = 0u; k < REFILL_VECTORS; k++) {
        let i = first + k * REFILL_GROUP + lid;
        let r = refilled_vector(old[k], i, n, rec.replenish_units);
        if i < vectors && any(r != old[k]) {
            pool[base + i] = r;
        }
    }
}
