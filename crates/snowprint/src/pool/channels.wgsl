// channels.wgsl: the range of a heightmap channel at 8, 16 or 32 bits (pool::Precision).

// The value of a channel pressed to the ground.
fn channel_max(bits: u32) -> u32 {
    if bits == 8u {
        return 0xffu;
    }
    if bits == 16u {
        return 0xffffu;
    }
    return 0xffffffffu;
}
