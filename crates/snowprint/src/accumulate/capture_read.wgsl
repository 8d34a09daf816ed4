// Reading the capture, shared by blur.wgsl and fused.wgsl (which bind `capture` and `winding`).

// import maths

// Depression of the captured texel (x, y) of a surface, clamped to its edges. Where a mesh solid
// contains the ground point (winding > 0), the texel is pressed to the ground.
fn depression(rec: SurfaceRecord, x: i32, y: i32) -> f32 {
    let cx = u32(clamp(x, 0, i32(rec.width) - 1));
    let cy = u32(clamp(y, 0, i32(rec.height) - 1));
    let i = rec.scratch + cy * rec.width + cx;
    var code = capture[i];
    if (rec.mode & MODE_MESHES) != 0u && winding[i] > 0 {
        code = ONE_BITS; // depth 0: the ground
        if (rec.mode & MODE_GROUND) != 0u {
            // Ground that is not flat: the ground is the bare depth above the column's base, its
            // code in the second half of the surface's winding region.
            code = bitcast<u32>(winding[i + rec.width * rec.height]);
        }
    }
    return capture_depression(rec, code);
}
