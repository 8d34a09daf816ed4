// banks.wgsl: snow banks (berms) from the displaced-snow channel, the talk's "projected
// displacement". A fraction of the snow each texel's captures pushed down is moved sideways onto
// the snow around it, within the bank width, and the rest is compacted. Two passes per deformed
// surface (dispatched over every surface seen; where classify.wgsl left it unshaded, every
// workgroup leaves at once), both gathers (no atomics):
//   bank_norm:   N(y) = sum over x within the bank width of K(x - y) m(x), how much room for banks
//                there is around texel y. m(x) = receptivity: 1 on untouched snow, fading to a
//                floor of RECEPTIVITY_FLOOR at the bottom of trails (snow is pushed onto the snow
//                beside a trail, not back into it, unless nothing else is within reach).
//   bank_gather: bank(x) = fraction * depth * m(x) * sum over y of displaced(y) K(x - y) / N(y).
// Summing bank(x) over x gives fraction * depth * sum of displaced(y) exactly: every source gives
// away exactly what it pushed, normalized over where it lands (texels that hold no snow are not
// receivers), so the volume of the banks is the fraction of the pushed volume, up to rounding.
// The snow is the surface's and that of the surfaces linked beside its sides (`held`,
// heightfield_texels.wgsl): snow pushed across the line where two surfaces meet lands on the
// other, as on one surface over both. The passes run over the surface and, past a linked side, a
// band as wide as the reach and the border (`BankParams::domain`): N over all of it, the banks
// over the surface and the border of HEIGHTFIELD_BORDER texels that the bank texture holds around
// the heightmap's, as the heightfield textures do (past a side with nothing linked, the edge
// repeated: the edge texel's invocation stores it).
// Reads: the surface state table, the surface's heightfield textures (heightfield.wgsl: smoothed depression in .x, the
// displaced channel in the light texture's .g; texel p at p + HEIGHTFIELD_BORDER), past their
// border the pool (this surface's neighbours). Writes: the bank scratch (N over the domain, texel
// p at p - domain.xy) and the bank texture (metres of snow added, .x, p at p + HEIGHTFIELD_BORDER).
// CPU reference: render::tessellate::cpu::bank_field.

// import constants, heightfield_texels

// Must match `BankParams` in src/render/tessellate/mod.rs.
struct BankParams {
    width: u32,
    height: u32,
    reach_x: i32,        // kernel half-width in texels along x
    reach_z: i32,
    texel_x: f32,
    texel_z: f32,
    radius: f32,         // bank width, metres
    fraction: f32,       // share of the pushed volume that goes into banks
    snow_depth: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
    domain: vec4<i32>,   // texels the passes run over: [x0, x1) x [z0, z1), the surface's first at 0
}

@group(0) @binding(0) var<uniform> bank: BankParams;
@group(0) @binding(1) var shape: texture_2d<f32>;
@group(0) @binding(2) var light: texture_2d<f32>;
@group(0) @binding(3) var scratch_in: texture_2d<f32>;
@group(0) @binding(4) var out_texture: texture_storage_2d<rgba16float, write>;
// What heightfield_texels.wgsl reads: the pool and this surface's heightfield parameters.
@group(0) @binding(5) var<storage, read> pool: array<u32>;
@group(0) @binding(6) var<uniform> params: HeightfieldParams;
// The surface state table (classify.wgsl); this surface's words start at `params.slot`'s.
@group(0) @binding(7) var<storage, read> state: array<u32>;

// Whether texel p holds snow (`held`) and is within the domain, where N is: a source of banks.
fn inside(c: i32, r: i32) -> bool {
    if !LINKED {
        return c >= 0 && r >= 0 && c < i32(bank.width) && r < i32(bank.height);
    }
    let d = bank.domain;
    return c >= d.x && r >= d.y && c < d.z && r < d.w && held(c, r);
}

// Whether texel (c, r) is in the textures (the surface and its border).
fn textured(c: i32, r: i32) -> bool {
    let b = HEIGHTFIELD_BORDER;
    return c >= -b && r >= -b && c < i32(bank.width) + b && r < i32(bank.height) + b;
}

// A value as a 16-bit float texel holds it.
fn as_half(x: f32) -> f32 {
    return unpack2x16float(pack2x16float(vec2<f32>(x, 0.0))).x;
}

// The smoothed depression at a held texel: the texture's, or past its border the pool's, as the
// surface beside holds it in its own texture.
fn smoothed_at(p: vec2<i32>) -> f32 {
    if !LINKED || textured(p.x, p.y) {
        return textureLoad(shape, p + HEIGHTFIELD_BORDER, 0).x;
    }
    return as_half(smoothed_depression(p.x, p.y));
}

// The displaced snow at a held texel, likewise.
fn displaced_at(p: vec2<i32>) -> f32 {
    if !LINKED || textured(p.x, p.y) {
        return textureLoad(light, p + HEIGHTFIELD_BORDER, 0).g;
    }
    return as_half(displaced(p.x, p.y));
}

fn room_at(p: vec2<i32>) -> f32 {
    return textureLoad(scratch_in, p - bank.domain.xy, 0).x;
}

// Must match `receptivity` in cpu.rs.
fn receptivity(depression: f32) -> f32 {
    return max(1.0 - smoothstep(0.05, 0.35, depression), RECEPTIVITY_FLOOR);
}

// Must match `bank_kernel` in cpu.rs: a smooth bump of radius `bank.radius`.
fn kernel(dc: i32, dr: i32) -> f32 {
    let d = vec2<f32>(f32(dc) * bank.texel_x, f32(dr) * bank.texel_z);
    let q = dot(d, d) / (bank.radius * bank.radius);
    if q >= 1.0 {
        return 0.0;
    }
    return (1.0 - q) * (1.0 - q);
}

// The texels within reach of a workgroup's 8 x 8 are read once into workgroup memory, and each
// texel's sum reads them there, in the same order as from the textures (the same sums, bit for
// bit); a reach beyond TILE_REACH texels reads the textures directly.
const TILE_REACH: i32 = 18;
const TILE_TEXELS: u32 = 1936u; // (8 + 2 * TILE_REACH)^2, 15.5 KB for both tiles
var<workgroup> tile_a: array<f32, TILE_TEXELS>;
var<workgroup> tile_b: array<f32, TILE_TEXELS>;
// Whether any texel within the reach of this workgroup's texels had snow displaced.
var<workgroup> displaced_near: atomic<u32>;
var<workgroup> shaded: u32;

// Whether the passes run over the surface this frame (classify.wgsl's STATE_SHADED): they are
// dispatched over every surface seen, and a workgroup of one left unshaded leaves at once. Called
// by every invocation, in uniform control flow; the result is uniform.
fn runs(lane: u32) -> bool {
    if lane == 0u {
        shaded = state[params.slot * STATE_WORDS + STATE_SHADED];
    }
    return workgroupUniformLoad(&shaded) != 0u;
}

// A workgroup's neighbourhood: its first texel less the reach, and its side.
struct Neighbourhood {
    origin: vec2<i32>,
    span: vec2<i32>,
    tiled: bool,
}

fn neighbourhood(group: vec3<u32>) -> Neighbourhood {
    let reach = vec2<i32>(bank.reach_x, bank.reach_z);
    let tiled = bank.reach_x <= TILE_REACH && bank.reach_z <= TILE_REACH;
    let first = vec2<i32>(group.xy * 8u) + bank.domain.xy;
    return Neighbourhood(first - reach, vec2<i32>(8) + 2 * reach, tiled);
}

// Index in the tiles of texel `p` of the neighbourhood `n`.
fn tile_index(n: Neighbourhood, p: vec2<i32>) -> u32 {
    let q = p - n.origin;
    return u32(q.y * n.span.x + q.x);
}

@compute @workgroup_size(8, 8, 1)
fn bank_norm(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if !runs(lane) {
        return;
    }
    let hood = neighbourhood(group);
    if hood.tiled {
        for (var k = i32(lane); k < hood.span.x * hood.span.y; k += 64) {
            let p = hood.origin + vec2<i32>(k % hood.span.x, k / hood.span.x);
            if held(p.x, p.y) {
                tile_a[k] = receptivity(smoothed_at(p));
            }
        }
    }
    workgroupBarrier();
    let y = vec2<i32>(gid.xy) + bank.domain.xy;
    if y.x >= bank.domain.z || y.y >= bank.domain.w {
        return;
    }
    // bank_gather reads N only where snow was displaced: elsewhere it is not summed.
    if !inside(y.x, y.y) || displaced_at(y) <= 0.0 {
        textureStore(out_texture, vec2<i32>(gid.xy), vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    // Where the snow lands needs no norm of its own: any held texel, in the domain or past it.
    var n = 0.0;
    for (var dr = -bank.reach_z; dr <= bank.reach_z; dr++) {
        for (var dc = -bank.reach_x; dc <= bank.reach_x; dc++) {
            let p = y + vec2<i32>(dc, dr);
            if held(p.x, p.y) {
                let k = kernel(dc, dr);
                if k > 0.0 {
                    var m: f32;
                    if hood.tiled {
                        m = tile_a[tile_index(hood, p)];
                    } else {
                        m = receptivity(smoothed_at(p));
                    }
                    n += k * m;
                }
            }
        }
    }
    textureStore(out_texture, vec2<i32>(gid.xy), vec4<f32>(n, 0.0, 0.0, 1.0));
}

// The texels of the bank texture that hold texel `p`'s bank, as offsets from it along each axis:
// itself and, at an edge with no surface linked beyond it, the border there (the edge repeated).
fn held_spans(p: vec2<i32>) -> vec4<i32> {
    let b = HEIGHTFIELD_BORDER;
    let w = i32(bank.width) - 1;
    let h = i32(bank.height) - 1;
    return vec4<i32>(
        select(0, -b, p.x == 0 && open_side(0u)),
        select(0, b, p.x == w && open_side(1u)),
        select(0, -b, p.y == 0 && open_side(2u)),
        select(0, b, p.y == h && open_side(3u)),
    );
}

// Store texel p's bank (and, at an edge with nothing linked beyond it, the border's).
fn store_bank(p: vec2<i32>, value: f32) {
    let v = vec4<f32>(value, 0.0, 0.0, 1.0);
    let last = vec2<i32>(i32(bank.width), i32(bank.height)) - 1;
    if all(p > vec2<i32>(0)) && all(p < last) {
        textureStore(out_texture, p + HEIGHTFIELD_BORDER, v);
        return;
    }
    let spans = held_spans(p);
    for (var y = spans.z; y <= spans.w; y++) {
        for (var x = spans.x; x <= spans.y; x++) {
            textureStore(out_texture, p + vec2<i32>(x, y) + HEIGHTFIELD_BORDER, v);
        }
    }
}

@compute @workgroup_size(8, 8, 1)
fn bank_gather(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    // The workgroup first reads the displaced snow within reach of its texels (and the room for
    // banks there), each lane a share: where none was displaced, every bank here is 0 (most of a
    // surface, away from its trails), and the gather's taps are skipped.
    if !runs(lane) {
        return;
    }
    let hood = neighbourhood(group);
    for (var k = i32(lane); k < hood.span.x * hood.span.y; k += 64) {
        let p = hood.origin + vec2<i32>(k % hood.span.x, k / hood.span.x);
        if inside(p.x, p.y) {
            let d = displaced_at(p);
            if d > 0.0 {
                atomicOr(&displaced_near, 1u);
            }
            if hood.tiled {
                tile_a[k] = d;
                tile_b[k] = room_at(p);
            }
        }
    }
    workgroupBarrier();
    // The banks are over the surface and the border past its linked sides; the border past the
    // others repeats the edge, which stores it.
    let x = vec2<i32>(gid.xy) + bank.domain.xy;
    if !textured(x.x, x.y) || x.x >= bank.domain.z || x.y >= bank.domain.w {
        return;
    }
    if atomicLoad(&displaced_near) == 0u {
        store_bank(x, 0.0);
        return;
    }
    let tiled = hood.tiled;
    var sum = 0.0;
    for (var dr = -bank.reach_z; dr <= bank.reach_z; dr++) {
        for (var dc = -bank.reach_x; dc <= bank.reach_x; dc++) {
            let p = x + vec2<i32>(dc, dr);
            if inside(p.x, p.y) {
                let k = kernel(dc, dr);
                var d: f32;
                var room: f32;
                if tiled {
                    let i = tile_index(hood, p);
                    d = tile_a[i];
                    room = tile_b[i];
                } else {
                    d = displaced_at(p);
                    room = room_at(p);
                }
                if k > 0.0 && d > 0.0 {
                    sum += d * k / max(room, 1e-6);
                }
            }
        }
    }
    let m = receptivity(smoothed_at(x));
    store_bank(x, bank.fraction * bank.snow_depth * m * sum);
}
