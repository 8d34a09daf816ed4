// heightfield_texels.wgsl: a surface's heightmap texels as the heightfield and bank passes read
// them, past its edges too: where a surface is linked beside a side (render/heightfield/sides.rs),
// the texels beyond that side are that surface's, so that two surfaces side by side read as one;
// elsewhere they clamp to the edge. The importer declares `pool` (the heightmap pool) and `params`
// (this surface's `HeightfieldParams`).

// import texel

// Whether the pipeline serves surfaces with a surface linked beside a side: the others' pipelines
// leave the reads across the line out (their code and registers cost time where nothing is linked).
override LINKED: bool = false;

// The surface beside one side. Must match `HeightfieldSide` in src/render/gpu.rs.
struct HeightfieldSide {
    heights: u32,
    width: u32,
    height: u32,
    bits: u32,
    wrap: u32,
    offset: i32,        // its texel along the side is this surface's plus `offset`
    present: u32,       // 0: nothing beside this side (its texels clamp to the edge)
    _pad: u32,
}

// Must match `HeightfieldParams` in src/render/gpu.rs.
struct HeightfieldParams {
    heights: u32,       // word offset of the heightmap in the pool
    width: u32,
    height: u32,
    bits: u32,          // bits a channel (pool/texel.wgsl)
    snow_depth: f32,
    texel_x: f32,
    texel_z: f32,
    ground: u32,        // first texel of the ground field (ground_texel), or NO_GROUND
    wrap: u32,          // toroidal storage offsets (pool/texel.wgsl)
    slot: u32,          // the surface's slot in the frame (its words in the state table)
    _pad1: u32,
    _pad2: u32,
    light: vec4<f32>,   // xyz: unit direction towards the moon in the surface's local frame
    sides: array<HeightfieldSide, 4>,   // local -x, +x, -z, +z (render/heightfield/sides.rs)
}

// (depression, displaced) at texel `(along, across)` beyond side `k`, read from the surface
// linked there: `along` counts along the side in this surface's texels, `across` outwards from
// the line (0: the first texel past it). x < 0 where no surface beside holds the texel.
fn side_fractions(k: u32, along: i32, across: i32) -> vec3<f32> {
    let n = params.sides[k];
    let t = along + n.offset;
    let length = select(n.width, n.height, k < 2u);
    if n.present == 0u || t < 0 || t >= i32(length) {
        return vec3<f32>(-1.0);
    }
    var x = t;
    var y = t;
    if k == 0u {
        x = i32(n.width) - 1 - across;
    } else if k == 1u {
        x = across;
    } else if k == 2u {
        y = i32(n.height) - 1 - across;
    } else {
        y = across;
    }
    let cx = u32(clamp(x, 0, i32(n.width) - 1));
    let cy = u32(clamp(y, 0, i32(n.height) - 1));
    return vec3<f32>(pool_fractions(n.bits, n.heights, n.width, n.height, n.wrap, cx, cy), 0.0);
}

// (depression, displaced) at texel (c, r), which may lie beyond the surface: read from the
// surface beside that side where one is linked and holds the texel, else clamped to the edge.
fn fractions(c: i32, r: i32) -> vec2<f32> {
    let w = i32(params.width);
    let h = i32(params.height);
    if !LINKED {
        let x = u32(clamp(c, 0, w - 1));
        let y = u32(clamp(r, 0, h - 1));
        return pool_fractions(params.bits, params.heights, params.width, params.height, params.wrap, x, y);
    }
    if c < 0 || c >= w {
        let k = select(1u, 0u, c < 0);
        let f = side_fractions(k, r, select(c - w, -1 - c, c < 0));
        if f.x >= 0.0 {
            return f.xy;
        }
    }
    if r < 0 || r >= h {
        let k = select(3u, 2u, r < 0);
        let f = side_fractions(k, c, select(r - h, -1 - r, r < 0));
        if f.x >= 0.0 {
            return f.xy;
        }
    }
    let x = u32(clamp(c, 0, w - 1));
    let y = u32(clamp(r, 0, h - 1));
    return pool_fractions(params.bits, params.heights, params.width, params.height, params.wrap, x, y);
}

fn depression(c: i32, r: i32) -> f32 {
    return fractions(c, r).x;
}

// The displaced snow at a texel (the talk's projected-displacement channel: what the captures
// pushed deeper, accumulated), as a fraction of the snow depth. Same shape as `depression`.
fn displaced(c: i32, r: i32) -> f32 {
    return fractions(c, r).y;
}

// The depression smoothed by a 3x3 binomial filter: the capture rasterizes deformers with binary
// coverage on the texel grid, so the rim of a pit pressed to the ground is a staircase of texels;
// this (and the renderer's cubic B-spline on top) keeps that staircase out of the picture.
// Must match `smoothed_depression` in cpu.rs.
fn smoothed_depression(c: i32, r: i32) -> f32 {
    var sum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let w = f32((2 - abs(dx)) * (2 - abs(dy)));
            sum += w * depression(c + dx, r + dy);
        }
    }
    return sum / 16.0;
}


// Whether nothing is linked beside side `k` (the border past it repeats the edge).
fn open_side(k: u32) -> bool {
    return !LINKED || params.sides[k].present == 0u;
}

// Whether texel (c, r) holds snow of this surface or of a surface linked beside it (past a side,
// within that surface; not the corners beyond two sides).
fn held(c: i32, r: i32) -> bool {
    let w = i32(params.width);
    let h = i32(params.height);
    if !LINKED {
        return c >= 0 && r >= 0 && c < w && r < h;
    }
    let across_x = c < 0 || c >= w;
    let across_z = r < 0 || r >= h;
    if across_x && across_z {
        return false;
    }
    if across_x {
        let n = params.sides[select(1u, 0u, c < 0)];
        let t = r + n.offset;
        let beyond = select(c - w, -1 - c, c < 0);
        return n.present != 0u && t >= 0 && t < i32(n.height) && beyond < i32(n.width);
    }
    if across_z {
        let n = params.sides[select(3u, 2u, r < 0)];
        let t = c + n.offset;
        let beyond = select(r - h, -1 - r, r < 0);
        return n.present != 0u && t >= 0 && t < i32(n.width) && beyond < i32(n.height);
    }
    return true;
}
