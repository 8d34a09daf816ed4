// Reading the capture buffer, shared by blur.wgsl and fused.wgsl (which bind it as `capture`).

// Depression of the captured texel (x, y) of a surface, clamped to its edges.
fn depression(rec: SurfaceRecord, x: i32, y: i32) -> f32 {
    let cx = u32(clamp(x, 0, i32(rec.width) - 1));
    let cy = u32(clamp(y, 0, i32(rec.height) - 1));
    return capture_depression(rec, capture[rec.scratch + cy * rec.width + cx]);
}
