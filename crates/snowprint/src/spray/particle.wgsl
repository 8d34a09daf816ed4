// particle.wgsl: the kicked-up snow's shared layouts, imported by spawn.wgsl and simulate.wgsl.
// Must match `SprayParams`, `SprayRecord` and `Particle` in src/spray/mod.rs (a test lays this file
// out with naga and compares).

// import shared

// One frame's settings, written by the world before the spray's passes.
struct SprayParams {
    capacity: u32,        // particles in the ring
    threshold_units: u32, // a texel spawns when its depression grows by more units than this
    frame: u32,           // the world's frame number (seeds the jitter)
    _pad0: u32,
    dt: f32,              // seconds the simulation advances
    speed: f32,           // launch speed, metres per second
    lifetime: f32,        // seconds a particle lives
    drag: f32,            // velocity lost per second, as a rate
    gravity: f32,         // metres per second squared, down
    _pad1: u32,
    _pad2: u32,
    _pad3: u32,
}

// Where a surface of the update lies in the world and what its material throws: one per
// `SurfaceRecord`, same order.
struct SprayRecord {
    local_to_world: mat4x4<f32>,
    factors: vec4<f32>, // the material's amount, speed, lifetime and drag factors
    grain: vec4<f32>,   // the material's grain albedo (rgb) and radius (metres)
}

// One particle: alive while `life` > 0. World space.
struct Particle {
    position: vec3<f32>,
    life: f32,     // seconds left
    velocity: vec3<f32>,
    age: f32,      // seconds since it was spawned
    albedo: u32,   // rgba8 unorm
    radius: f32,   // metres, as drawn
    drag: f32,     // velocity lost per second, as a rate
    _pad: u32,
}

// A number in [0, 1] from two words (a PCG-style hash): the spawn's jitter and `place`'s thinning.
fn spray_hash(a: u32, b: u32) -> f32 {
    var v = a * 747796405u + b * 2891336453u + 12345u;
    v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
    v = (v >> 22u) ^ v;
    return f32(v >> 8u) * (1.0 / 16777215.0);
}

// The ring buffer: RING_HEADER counter words, then the particles. Each pass declares it with its own
// view of the counters (atomic where they are counted).
const RING_HEADER: u32 = 8u;

// A particle spawned this frame holds its surface-local position and velocity, and in `age` the
// negated record (+1) whose transform `place` (simulate.wgsl) then applies.

// The ring's counters (u32 words): where this frame's spawns start, spawns asked this frame
// (counted atomically by the spawn pass), and what the last fold kept and dropped.
const RING_HEAD: u32 = 0u;
const RING_REQUESTED: u32 = 1u;
const RING_LAST_REQUESTED: u32 = 2u;
const RING_LAST_DROPPED: u32 = 3u;
const RING_DROPPED_TOTAL: u32 = 4u;
const RING_SPAWNED_TOTAL: u32 = 5u;
