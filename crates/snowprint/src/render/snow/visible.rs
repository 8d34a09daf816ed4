//! The snow pass on the visibility path (`OpaquePath::Visibility`): the relief-mapped surfaces'
//! fragments trace their rays and write the hits into the visibility buffer (`fs_deformable_visible`
//! in `surface.wgsl`: the surface's slot, the box face, the hit's flags, depth, footprint and
//! self-shadow) and a second target (the hit's position), and the `snow_shade` compute pass shades
//! them (`shade_deformable`) with the forward path's own function, one dispatch per surface over the
//! rectangle of the screen its box covers.
//!
//! The trace is cheap in a fragment; the material's shading is not, on GPUs with graphics units in
//! a small part of the chip (`docs/PERFORMANCE.md`, "The snow's shading in compute").

use glam::{Mat4, Vec3, Vec4Swizzles};

use super::super::gpu::SurfaceUniform;
use super::super::pipeline;
use super::super::readback::{Timestamps, compute_pass};
use super::super::targets::Targets;
use super::super::tessellate::snow_shadow::TessSurface;
use crate::gpu::resources::{Growable, KeptGroups};

/// Pixels a workgroup of `shade_deformable` covers along each axis.
const WORKGROUP: u32 = 8;

/// Most surfaces a frame may draw: the slots that the visibility buffer's first word holds above
/// `SNOW_SLOT_SHIFT`, below bit 30 (which keeps the buffer's cleared value apart) and the tag.
pub(crate) const SLOTS: usize = 1 << (30 - crate::wgsl::consts::SNOW_SLOT_SHIFT);

/// The pipelines of the snow pass's visibility path.
pub(super) struct VisiblePath {
    /// The basic material, its colour and a word that nothing is to be shaded.
    pub basic: wgpu::RenderPipeline,
    /// The deformable material's trace, both sides of the box.
    pub deformable: wgpu::RenderPipeline,
    /// The same, front faces only (a box seen from outside).
    pub deformable_outside: wgpu::RenderPipeline,
    shade: wgpu::ComputePipeline,
    targets_layout: wgpu::BindGroupLayout,
    /// Per surface slot: the screen rectangle its dispatch covers.
    rects: Growable,
    /// This frame: the targets' group, and per surface slot its dispatch's workgroups (`None`
    /// where it is not shaded here).
    current: Option<wgpu::BindGroup>,
    dispatches: Vec<Option<(u32, u32)>>,
    /// The targets' group, kept while the targets and the rectangles' buffer stay.
    kept: KeptGroups,
}

/// What the snow pass's pipelines are built from.
pub(super) struct Modules<'a> {
    pub plain: &'a wgpu::ShaderModule,
    /// `surface.wgsl` with conservative depth on the deformable fragment, where the device has it.
    pub outside: &'a wgpu::ShaderModule,
    pub frame_layout: &'a wgpu::BindGroupLayout,
    pub surface_layout: &'a wgpu::BindGroupLayout,
    pub constants: &'a [(&'a str, f64)],
}

impl VisiblePath {
    pub(super) fn new(device: &wgpu::Device, m: &Modules<'_>) -> Self {
        let groups = [m.frame_layout, m.surface_layout];
        let targets = pipeline::visibility_targets();
        let raster = |label, module, primitive| {
            pipeline::Raster {
                label,
                module,
                vs: "vs_surface_deformable",
                fs: "fs_deformable_visible",
                buffers: &[],
                groups: &groups,
                primitive,
                depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, true),
                targets: &targets,
                constants: m.constants,
            }
            .build(device)
        };
        let basic = pipeline::Raster {
            label: "snow basic (visibility)",
            module: m.plain,
            vs: "vs_surface",
            fs: "fs_basic_visible",
            buffers: &[],
            groups: &groups,
            primitive: pipeline::back_culled(),
            depth: pipeline::depth_state(wgpu::CompareFunction::LessEqual, true),
            targets: &[
                pipeline::hdr_target()[0].clone(),
                pipeline::visibility_targets()[0].clone(),
            ],
            constants: &[],
        }
        .build(device);
        let deformable = raster(
            "snow deformable (visibility)",
            m.plain,
            wgpu::PrimitiveState::default(),
        );
        let deformable_outside = raster(
            "snow deformable (visibility, outside)",
            m.outside,
            pipeline::back_culled(),
        );
        let targets_layout =
            crate::wgsl::SURFACE.bind_group_layout(device, "snow shade targets", 2);
        let shade = pipeline::compute_with(
            device,
            "snow shade",
            (m.plain, "shade_deformable"),
            &[m.frame_layout, m.surface_layout, &targets_layout],
            m.constants,
        );
        Self {
            basic,
            deformable,
            deformable_outside,
            shade,
            targets_layout,
            rects: Growable::new(
                device,
                "snow shade rectangles",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                16 * 8,
            ),
            current: None,
            dispatches: Vec::new(),
            kept: KeptGroups::default(),
        }
    }

    /// The layout of the shading's targets (group 2), shared with the tessellated tier's shading.
    pub(super) fn targets_layout(&self) -> &wgpu::BindGroupLayout {
        &self.targets_layout
    }

    /// Each shaded surface's rectangle of the screen, uploaded, and the targets' group.
    /// `shaded[s]`: `None` where surface slot `s` is not drawn into the visibility buffer this
    /// frame, else how far above its box's top its snow may rise (metres: the tessellated tier's
    /// banks and waves; 0 for the relief tier, whose trace never leaves the box).
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        targets: &Targets,
        uniforms: &[SurfaceUniform],
        shaded: &[Option<f32>],
        view_proj: Mat4,
    ) {
        let (Some(visibility), Some(hits)) = (&targets.visibility_view, &targets.snow_hits_view)
        else {
            self.current = None;
            return;
        };
        let t = targets.color_view.texture();
        let size = (t.width(), t.height());
        let mut rects = vec![[0u32; 4]; uniforms.len().max(1)];
        self.dispatches.clear();
        for (s, (u, &rise)) in uniforms.iter().zip(shaded).enumerate() {
            let rect = rise.and_then(|rise| screen_rect(u, rise, view_proj, size));
            if let Some(r) = rect {
                rects[s] = r;
            }
            self.dispatches.push(rect.map(|r| {
                (
                    (r[2] - r[0]).div_ceil(WORKGROUP),
                    (r[3] - r[1]).div_ceil(WORKGROUP),
                )
            }));
        }
        let bytes: &[u8] = bytemuck::cast_slice(&rects);
        self.rects.write_whole(device, queue, bytes);
        self.current = Some(self.kept.get(
            device,
            "snow shade targets",
            &self.targets_layout,
            0,
            &[
                wgpu::BindingResource::TextureView(visibility),
                wgpu::BindingResource::TextureView(hits),
                wgpu::BindingResource::TextureView(&targets.color_view),
                wgpu::BindingResource::TextureView(&targets.depth_view),
                self.rects.buffer.as_entire_binding(),
            ],
        ));
    }

    /// The `snow_shade` pass: each relief-mapped surface's dispatch with its group
    /// (`surface_groups`, by slot), then the diced ones'.
    pub(super) fn encode_shade(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
        frame: &wgpu::BindGroup,
        surface_groups: &[Option<wgpu::BindGroup>],
        tess: &TessSurface,
    ) {
        let mut p = compute_pass(encoder, ts, slot);
        let Some(targets) = &self.current else {
            return;
        };
        p.set_pipeline(&self.shade);
        p.set_bind_group(0, frame, &[]);
        p.set_bind_group(2, targets, &[]);
        for (group, dispatch) in surface_groups.iter().zip(&self.dispatches) {
            if let (Some(group), Some((x, y))) = (group, dispatch) {
                p.set_bind_group(1, group, &[]);
                p.dispatch_workgroups(*x, *y, 1);
            }
        }
        tess.encode_shade(&mut p, &self.dispatches);
    }
}

/// The rectangle of pixels `[x0, x1) x [y0, y1)` of a `size` target that the box a surface's
/// deformable material draws (`surface.wgsl`'s `box_vertex`, raised by the room for rims, and by
/// `rise` metres more) can cover under `view_proj`, a pixel wider on every side; the whole target
/// where a corner lies behind the eye (or on its plane), and `None` where the box is off screen.
pub(super) fn screen_rect(
    u: &SurfaceUniform,
    rise: f32,
    view_proj: Mat4,
    size: (u32, u32),
) -> Option<[u32; 4]> {
    let to_clip = view_proj * Mat4::from_cols_array_2d(&u.local_to_world);
    let (hx, hz) = (u.half_size[0], u.half_size[1]);
    let (low, top) = (u.terrain_low, u.terrain_top + u.translucency[3] + rise);
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for k in 0..8 {
        let corner = Vec3::new(
            if k & 1 == 0 { -hx } else { hx },
            if k & 2 == 0 { low } else { top },
            if k & 4 == 0 { -hz } else { hz },
        );
        let clip = to_clip * corner.extend(1.0);
        if clip.w <= 1e-6 * clip.xyz().length().max(1.0) {
            return Some([0, 0, size.0, size.1]);
        }
        let ndc = clip.xy() / clip.w;
        // Pixels from the top left corner.
        let px = glam::Vec2::new(
            (ndc.x * 0.5 + 0.5) * size.0 as f32,
            (0.5 - ndc.y * 0.5) * size.1 as f32,
        );
        lo = lo.min(px);
        hi = hi.max(px);
    }
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
    let (x0, y0) = (
        clamp(lo.x.floor() - 1.0, size.0),
        clamp(lo.y.floor() - 1.0, size.1),
    );
    let (x1, y1) = (
        clamp(hi.x.ceil() + 1.0, size.0),
        clamp(hi.y.ceil() + 1.0, size.1),
    );
    (x0 < x1 && y0 < y1).then_some([x0, y0, x1, y1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera's view and projection, 90 degrees high on a square target.
    fn view_proj(eye: Vec3, target: Vec3) -> Mat4 {
        let camera = crate::Camera {
            eye,
            target,
            fov_y_degrees: 90.0,
        };
        camera.projection(1.0, 0.1, 100.0) * camera.view()
    }

    fn surface(local_to_world: Mat4, half: [f32; 2], depth: f32) -> SurfaceUniform {
        SurfaceUniform {
            local_to_world: local_to_world.to_cols_array_2d(),
            world_to_local: local_to_world.inverse().to_cols_array_2d(),
            half_size: half,
            terrain_low: 0.0,
            terrain_top: depth,
            ..bytemuck::Zeroable::zeroed()
        }
    }

    /// A 2 m square of snow 0.3 m deep, stood up to face a camera 5 m away (its local up along
    /// the world's +z) that sees it with a 90 degree field of view on a 100 x 100 target: its
    /// top, 4.7 m away, is the nearer and larger square, at +-1 / 4.7 = +-0.2128 of the half
    /// screen: pixels 50 -+ 10.64, 39.36 to 60.64, widened to whole pixels and by one, 38 to 62.
    #[test]
    fn a_box_in_view_covers_its_projection_and_a_pixel_more() {
        let facing = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let u = surface(facing, [1.0, 1.0], 0.3);
        let view_proj = view_proj(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        assert_eq!(
            screen_rect(&u, 0.0, view_proj, (100, 100)),
            Some([38, 38, 62, 62])
        );
    }

    /// The frame check's sentence names the limit as a number.
    #[test]
    fn the_slots_are_the_limit_the_frame_check_names() {
        assert_eq!(SLOTS, 131_072);
    }

    /// A box with a corner behind the eye may cover any pixel: the whole target. One wholly to
    /// the side of the view covers none.
    #[test]
    fn a_box_behind_or_beside_the_eye() {
        let view_proj = view_proj(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -1.0));
        let around = surface(Mat4::IDENTITY, [10.0, 10.0], 0.3);
        assert_eq!(
            screen_rect(&around, 0.0, view_proj, (64, 32)),
            Some([0, 0, 64, 32])
        );
        let beside = surface(
            Mat4::from_translation(Vec3::new(50.0, 0.0, -5.0)),
            [1.0, 1.0],
            0.3,
        );
        assert_eq!(screen_rect(&beside, 0.0, view_proj, (64, 32)), None);
    }
}
