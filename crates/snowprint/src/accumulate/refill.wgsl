// Replenish the heightmaps of the surfaces that refill snow, before the fused pass deepens them
// where the capture reached. Refilling subtracts the same units from both channels of every
// texel, saturating at the untouched top, so it does not depend on a texel's place: the pass
// streams each heights region's words in order (wrapped storage and row padding included; a
// padding texel holds zeros and keeps them), every channel of a word refilled as a lane. A
// workgroup takes REFILL_GROUP x REFILL_WORDS consecutive words of one record, each invocation
// REFILL_WORDS of them a workgroup apart, all loaded before any is stored, so that the memory
// system has as many bytes in flight as a copy would; a word is written back only where it
// changed (untouched snow stays as it is).
// The fused pass (fused.wgsl) then merges the blurred capture into the refilled words with no
// replenishment of its own: replenishing by r and then deepening equals merge_channels(old,
// blurred, r) (CPU reference: accumulate::cpu::refill_word). The world streams the refill only
// over many words (WorldConfig::refill_stream_from): it costs a few microseconds more in all.
// Reads: `records` (the first records of the frame's update, those marked MODE_REFILLED; `z` of
// the dispatch), their heights regions in `pool`. Writes: the same regions.

// import shared

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read_write> pool: array<u32>;

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

// Every channel of a word refilled: four 8-bit lanes, two 16-bit lanes or one 32-bit word.
fn refilled(word: u32, rep: u32) -> u32 {
    if PRECISION == 8u {
        var out = 0u;
        for (var s = 0u; s < 32u; s += 8u) {
            out |= lane((word >> s) & 0xffu, rep) << s;
        }
        return out;
    }
    if PRECISION == 16u {
        return lane(word & 0xffffu, rep) | (lane(word >> 16u, rep) << 16u);
    }
    return lane(word, rep);
}

@compute @workgroup_size(REFILL_GROUP, 1, 1)
fn refill(
    @builtin(local_invocation_index) lid: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let rec = records[wid.z];
    let n = region_words(rec);
    let chunk = wid.x + wid.y * groups.x;
    let first = chunk * REFILL_GROUP * REFILL_WORDS;
    if first >= n || (rec.mode & MODE_REFILLED) == 0u {
        return;
    }
    var words: array<u32, REFILL_WORDS>;
    for (var k = 0u; k < REFILL_WORDS; k++) {
        let i = first + k * REFILL_GROUP + lid;
        if i < n {
            words[k] = pool[rec.heights + i];
        }
    }
    for (var k = 0u; k < REFILL_WORDS; k++) {
        let i = first + k * REFILL_GROUP + lid;
        let r = refilled(words[k], rec.replenish_units);
        if i < n && r != words[k] {
            pool[rec.heights + i] = r;
        }
    }
}
