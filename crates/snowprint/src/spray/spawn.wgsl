// spawn.wgsl: kicked-up snow is spawned where this update deepens a print by more than a
// threshold, read from the update's own inputs (the capture and the heights it is about to
// overwrite), so no deformer is tracked on the CPU. It runs after the capture and before the
// accumulation, which updates the heights in place: this pass reads them first and writes nothing
// the update reads, so the update is the same with or without it.
// One invocation per texel of every captured surface (`z` is the record), only on the tiles the
// capture flagged. A texel's growth is exactly what merge_channels (maths.wgsl) will push out:
// the blurred capture in units, less the old depression after this update's replenishment.
// `fold` (one invocation, after `spawn`) moves the ring's head past the spawns kept and counts
// those dropped.
// A particle is written in the surface's frame; `place` (simulate.wgsl) moves it to the world
// (six storage buffers a stage is WebGPU's least limit, and the update's take five).
// Reads: records, capture, winding, tiles, pool (heights), params.
// Writes: ring (counters and particles). CPU reference: spray::cpu::spawning_texels (from the heights
// before and after the update) and spray::cpu::ring_fold.

// import maths, capture_read, texel, particle

@group(0) @binding(0) var<storage, read> records: array<SurfaceRecord>;
@group(0) @binding(1) var<storage, read> capture: array<u32>;
@group(0) @binding(2) var<storage, read> pool: array<u32>;
@group(0) @binding(3) var<storage, read> winding: array<i32>;
@group(0) @binding(4) var<storage, read> tiles: array<u32>;
@group(0) @binding(5) var<uniform> params: SprayParams;
@group(0) @binding(6) var<storage, read_write> ring: Ring;

struct Ring {
    counters: array<atomic<u32>, RING_HEADER>,
    particles: array<Particle>,
}

@compute @workgroup_size(TILE, TILE, 1)
fn spawn(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rec = records[gid.z];
    let x = gid.x;
    let y = gid.y;
    if rec.batch == NO_CAPTURE || x >= rec.width || y >= rec.height {
        return;
    }
    let tiles_x = (rec.width + TILE - 1u) / TILE;
    if tiles[rec.tiles + (y / TILE) * tiles_x + x / TILE] == 0u {
        return;
    }
    let ix = i32(x);
    let iy = i32(y);
    let l = depression(rec, ix - 1, iy);
    let r = depression(rec, ix + 1, iy);
    let b = depression(rec, ix, iy - 1);
    let f = depression(rec, ix, iy + 1);
    let blurred = blur_taps(
        depression(rec, ix - 1, iy - 1), b, depression(rec, ix + 1, iy - 1),
        l, depression(rec, ix, iy), r,
        depression(rec, ix - 1, iy + 1), f, depression(rec, ix + 1, iy + 1),
    );
    let old = pool_texel(PRECISION, rec.heights, rec.width, rec.height, rec.wrap, x, y).x;
    let rep = rec.replenish_units;
    let depressed = max(old, rep) - rep;
    let captured = to_units(blurred);
    if captured <= depressed || captured - depressed <= params.threshold_units {
        return;
    }
    let i = atomicAdd(&ring.counters[RING_REQUESTED], 1u);
    if i >= params.capacity {
        return; // dropped: `fold` counts it
    }
    let slot = (atomicLoad(&ring.counters[RING_HEAD]) + i) % params.capacity;
    // On the new snow top at the texel's centre (local frame: origin on the ground at the
    // surface's centre, see surface.rs).
    let cmax = f32(channel_max(PRECISION));
    let local = vec3<f32>(
        (f32(x) + 0.5 - 0.5 * f32(rec.width)) * rec.texel_x,
        rec.snow_depth * (1.0 - f32(captured) / cmax),
        (f32(y) + 0.5 - 0.5 * f32(rec.height)) * rec.texel_z,
    );
    // Outward: down the depression's gradient, away from what pressed it; a flat spot (the floor
    // of a pit) throws in a direction of its own.
    let key = (y * rec.width + x) ^ (gid.z << 20u);
    var out = -vec2<f32>(r - l, f - b);
    if dot(out, out) < 1e-8 {
        let a = 6.2831853 * spray_hash(key, params.frame * 4u);
        out = vec2<f32>(cos(a), sin(a));
    }
    out = normalize(out);
    let growth = f32(captured - depressed) / cmax;
    let lift = 0.6 + 0.4 * spray_hash(key, params.frame * 4u + 1u);
    let speed = params.speed * lift * (0.5 + min(growth * 4.0, 1.0));
    let dir = normalize(vec3<f32>(0.7 * out.x, 1.0, 0.7 * out.y));
    var p: Particle;
    p.position = local;
    p.velocity = dir * speed;
    p.life = params.lifetime * (0.7 + 0.3 * spray_hash(key, params.frame * 4u + 2u));
    p.age = -f32(gid.z + 1u); // to `place`
    ring.particles[slot] = p;
}

// After `spawn`: keep min(requested, capacity) spawns, move the head past them, count the rest as
// dropped, and start the next frame's count at 0.
@compute @workgroup_size(1, 1, 1)
fn fold() {
    let requested = atomicLoad(&ring.counters[RING_REQUESTED]);
    let kept = min(requested, params.capacity);
    let head = atomicLoad(&ring.counters[RING_HEAD]);
    atomicStore(&ring.counters[RING_HEAD], (head + kept) % max(params.capacity, 1u));
    atomicStore(&ring.counters[RING_LAST_REQUESTED], requested);
    atomicStore(&ring.counters[RING_LAST_DROPPED], requested - kept);
    atomicAdd(&ring.counters[RING_DROPPED_TOTAL], requested - kept);
    atomicAdd(&ring.counters[RING_SPAWNED_TOTAL], kept);
    atomicStore(&ring.counters[RING_REQUESTED], 0u);
}
