// Reading the capture, shared by blur.wgsl and fused.wgsl (which bind `capture` and `winding`).

// import maths

// Depression of the captured texel (x, y) of a surface, x in -APRON..width + APRON (and y alike):
// the capture region holds the surface's texels and the apron around them (capture/write.wgsl), so
// the blur of an edge texel reads the capture one texel beyond the surface, as one surface over
// both sides of the line would. Coordinates past the apron (a workgroup's staging past the
// surface's last tile) are clamped to it; no texel of the surface reads them. Where a mesh solid
// contains the ground point (winding > 0), the texel is pressed to the ground.
fn depression(rec: SurfaceRecord, x: i32, y: i32) -> f32 {
    let a = i32(APRON);
    let rw = rec.width + 2u * APRON;
    let rh = rec.height + 2u * APRON;
    let cx = u32(clamp(x + a, 0, i32(rw) - 1));
    let cy = u32(clamp(y + a, 0, i32(rh) - 1));
    let i = rec.scratch + cy * rw + cx;
    var code = capture[i];
    if (rec.mode & MODE_MESHES) != 0u && winding[i] > 0 {
        code = ONE_BITS; // depth 0: the ground
        if (rec.mode & MODE_GROUND) != 0u {
            // Ground that is not flat: the ground is the bare depth above the column's base, its
            // code in the second half of the surface's winding region.
            code = bitcast<u32>(winding[i + rw * rh]);
        }
    }
    return capture_depression(rec, code);
}
