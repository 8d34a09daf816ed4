// texel_write.wgsl: writing the heights region (see texel.wgsl), for the update's passes, which
// bind `pool` read_write. A *unit* is what one invocation writes without racing its neighbours:
// two texels along x at 8 bits (one word), one texel otherwise.

// import texel

// Texels a unit covers.
fn unit_texels(bits: u32) -> u32 {
    return select(1u, 2u, bits == 8u);
}

// Store the unit starting at logical texel (lx, ly) (`wrap`: texel.wgsl): `a` there and, at 8
// bits, `b` at (lx + 1, ly).
fn pool_store_unit(bits: u32, base: u32, width: u32, height: u32, wrap: u32, lx: u32, ly: u32, a: vec2<u32>, b: vec2<u32>) {
    let p = pool_wrapped(wrap, width, height, lx, ly);
    let x = p.x;
    let y = p.y;
    if bits == 8u {
        let lo = (a.x & 0xffu) | ((a.y & 0xffu) << 8u);
        let hi = (b.x & 0xffu) | ((b.y & 0xffu) << 8u);
        pool[base + y * ((width + 1u) / 2u) + x / 2u] = lo | (hi << 16u);
        return;
    }
    let i = base + y * width + x;
    if bits == 16u {
        pool[i] = (a.x & 0xffffu) | (a.y << 16u);
        return;
    }
    pool[i] = a.x;
    pool[i + width * height] = a.y;
}
