// simulate.wgsl: every particle of the kicked-up snow's ring advances by the frame's dt: gravity,
// then drag, then the move (semi-implicit Euler); a particle whose life runs out stays dead until
// a spawn reuses its slot. One invocation per slot: the cost is the ring's capacity, whatever
// spawned. Runs before `spawn`, so a particle spawned this frame sits where it was spawned.
// `place` (after spawn.wgsl's `fold`) moves this frame's spawns from their surface's frame to the
// world by the record's transform and gives them their material's spray (SprayRecord): below an
// amount of 1, a spawn whose hash of (slot, frame) is at or above the amount dies at once; the others get
// their speed, life and drag scaled and the material's albedo and radius. It too costs one
// invocation a slot.
// Reads and writes: ring (particles). Reads: params, spray_records. CPU references:
// spray::cpu::integrate and spray::cpu::place.

// import particle

@group(0) @binding(0) var<uniform> params: SprayParams;
@group(0) @binding(1) var<storage, read_write> ring: Ring;
@group(0) @binding(2) var<storage, read> spray_records: array<SprayRecord>;

struct Ring {
    counters: array<u32, RING_HEADER>,
    particles: array<Particle>,
}

// The ring slot of invocation `gid` of a dispatch in rows of `groups.x` workgroups of 64
// (gpu::resources::dispatch_rows).
fn slot_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 64u;
}

@compute @workgroup_size(64, 1, 1)
fn simulate(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = slot_index(gid, groups);
    if i >= params.capacity {
        return;
    }
    var p = ring.particles[i];
    if p.life <= 0.0 || p.age < 0.0 {
        return;
    }
    let dt = params.dt;
    var v = p.velocity - vec3<f32>(0.0, params.gravity * dt, 0.0);
    v = v / (1.0 + p.drag * dt);
    p.velocity = v;
    p.position = p.position + v * dt;
    p.life = max(p.life - dt, 0.0);
    p.age = p.age + dt;
    ring.particles[i] = p;
}

@compute @workgroup_size(64, 1, 1)
fn place(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = slot_index(gid, groups);
    if i >= params.capacity {
        return;
    }
    var p = ring.particles[i];
    if p.age >= 0.0 {
        return;
    }
    let rec = spray_records[u32(-p.age) - 1u];
    p.age = 0.0;
    if rec.factors.x < 1.0 && spray_hash(i, params.frame) >= rec.factors.x {
        p.life = 0.0; // thinned out: this material throws fewer grains
        ring.particles[i] = p;
        return;
    }
    let m = rec.local_to_world;
    p.position = (m * vec4<f32>(p.position, 1.0)).xyz;
    p.velocity = (m * vec4<f32>(p.velocity * rec.factors.y, 0.0)).xyz;
    p.life = p.life * rec.factors.z;
    p.drag = params.drag * rec.factors.w;
    p.albedo = pack4x8unorm(vec4<f32>(rec.grain.rgb, 1.0));
    p.radius = rec.grain.w;
    ring.particles[i] = p;
}
