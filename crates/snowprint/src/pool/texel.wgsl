// texel.wgsl: reading (and, for the update, writing) the heights region of a surface in the pool,
// at 8, 16 or 32 bits a channel. The including shader declares `pool: array<u32>` (read or
// read_write). Layouts, as in src/pool/mod.rs:
//   8 bits:  rows padded to even widths; a word holds texels (2k, 2k + 1) of a row, each as 16 bits
//            (depression in the low byte, displaced in the high byte), the even texel low.
//   16 bits: a word a texel, depression low 16 bits, displaced high 16.
//   32 bits: two planes of width x height words: depressions, then displaced.
// Toroidal storage (a terrain window's levels, `window/`): logical texel (x, y), the space every
// pass computes in, lives at ((x + ox) mod width, (y + oy) mod height) of the region, `wrap` =
// ox | oy << 16 (both below the sides; 0 for every ordinary surface, where the mapping is the
// identity). This file is the ONE place the mapping is made on the GPU: every reader and writer of
// the pool goes through `pool_texel`/`pool_store_unit`. At 8 bits ox is even (a unit's two texels
// stay in one word). CPU reference: pool::wrapped.
// CPU reference: pool::PoolFormat::{encode, decode}.

// import channels

// Where logical texel (x, y) is stored: see above.
fn pool_wrapped(wrap: u32, width: u32, height: u32, x: u32, y: u32) -> vec2<u32> {
    if wrap == 0u {
        return vec2<u32>(x, y);
    }
    return vec2<u32>((x + (wrap & 0xffffu)) % width, (y + (wrap >> 16u)) % height);
}

// (depression, displaced) of logical texel (lx, ly) of the heights region at word `base`.
fn pool_texel(bits: u32, base: u32, width: u32, height: u32, wrap: u32, lx: u32, ly: u32) -> vec2<u32> {
    let p = pool_wrapped(wrap, width, height, lx, ly);
    let x = p.x;
    let y = p.y;
    if bits == 8u {
        let word = pool[base + y * ((width + 1u) / 2u) + x / 2u];
        let v = (word >> (16u * (x & 1u))) & 0xffffu;
        return vec2<u32>(v & 0xffu, v >> 8u);
    }
    let i = base + y * width + x;
    if bits == 16u {
        let word = pool[i];
        return vec2<u32>(word & 0xffffu, word >> 16u);
    }
    return vec2<u32>(pool[i], pool[i + width * height]);
}

// Channels as fractions of the snow depth.
fn pool_fractions(bits: u32, base: u32, width: u32, height: u32, wrap: u32, x: u32, y: u32) -> vec2<f32> {
    return vec2<f32>(pool_texel(bits, base, width, height, wrap, x, y)) / f32(channel_max(bits));
}
