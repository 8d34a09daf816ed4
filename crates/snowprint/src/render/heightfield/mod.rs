//! The `heightfield` pass (compute, indirect, `heightfield.wgsl`): each deformed surface's
//! heightmap becomes its shading textures: depression, normal and ambient occlusion (`shape`),
//! moon visibility and displaced snow (`light`). Surfaces left untouched dispatch nothing.
//! The pass owns those textures (and the banks' two, which the tessellated tier writes).

use std::collections::HashMap;

use glam::Vec3;

use super::error::{RenderError, RenderResult};
use super::frame::FrameSurface;
use super::gpu::{HeightfieldParams, HeightfieldSide, UNIFORM_STRIDE};
use super::pipeline;
use super::readback::{Timestamps, compute_pass, f16_to_f32, map_staging};
use super::targets::HEIGHTFIELD_FORMAT;
use super::tessellate::SurfaceFields;
use crate::gpu::resources::{Growable, KeptGroups, uniform_block};
use crate::surface::SurfaceId;

mod sides;
pub(super) use sides::{Beside, SIDES, besides};

/// What the pass reads of the surface beside a side (all zero where there is none).
fn side_params(side: Option<Beside<'_>>) -> HeightfieldSide {
    let Some(side) = side else {
        return HeightfieldSide::default();
    };
    let n = side.view;
    HeightfieldSide {
        heights: n.heights,
        width: n.layout.width,
        height: n.layout.height,
        bits: n.precision.bits(),
        wrap: n.wrap,
        offset: side.offset,
        present: 1,
        _pad: 0,
    }
}

/// A deformed surface's shading textures, written by the heightfield pass.
pub(super) struct HeightfieldTexture {
    /// The heightmap's texels.
    pub size: (u32, u32),
    /// Depression, normal x and z, ambient occlusion; with a border of one texel around the
    /// heightmap's (`heightfield.wgsl`).
    pub shape: wgpu::TextureView,
    /// Moon visibility, displaced snow; with the same border.
    pub light: wgpu::TextureView,
    /// Room for banks around each texel of the bank passes' domain (their scratch).
    pub bank_scratch: wgpu::TextureView,
    /// Bank heights, metres; with the same border as the shape.
    pub bank: wgpu::TextureView,
    /// The scratch's texels.
    scratch_size: (u32, u32),
    /// The textures of shape, light and bank, for readbacks.
    pub textures: [wgpu::Texture; 3],
}

impl HeightfieldTexture {
    fn new(device: &wgpu::Device, size: (u32, u32), scratch_size: (u32, u32)) -> Self {
        let texture = |label, (width, height): (u32, u32)| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: HEIGHTFIELD_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let bordered = (size.0 + 2 * BORDER, size.1 + 2 * BORDER);
        let shape = texture("snow heightfield", bordered);
        let light = texture("snow heightfield light", bordered);
        let bank = texture("snow banks", bordered);
        let scratch = texture("snow bank scratch", scratch_size);
        Self {
            size,
            shape: view(&shape),
            light: view(&light),
            bank: view(&bank),
            bank_scratch: view(&scratch),
            scratch_size,
            textures: [shape, light, bank],
        }
    }
}

/// Texels the shape, light and bank textures hold beyond each side of the heightmap.
pub(super) const BORDER: u32 = crate::wgsl::consts::HEIGHTFIELD_BORDER as u32;

/// A pass's pipelines for surfaces with nothing beside them and for those with a surface linked
/// beside a side (`LINKED` in `heightfield/texels.wgsl`).
pub(super) fn linked_pipelines(
    device: &wgpu::Device,
    label: &str,
    (module, entry): (&wgpu::ShaderModule, &str),
    layout: &wgpu::BindGroupLayout,
) -> [wgpu::ComputePipeline; 2] {
    [0.0, 1.0].map(|linked| {
        pipeline::compute_with(
            device,
            label,
            (module, entry),
            &[layout],
            &[("LINKED", linked)],
        )
    })
}

/// Whether a surface lies beside any of a frame's surface's sides.
pub(super) fn linked(surface: &FrameSurface<'_>) -> bool {
    surface.sides.iter().any(Option::is_some)
}

pub(super) struct HeightfieldPass {
    layout: wgpu::BindGroupLayout,
    /// For surfaces with nothing beside them, and with a surface beside a side.
    pipelines: [wgpu::ComputePipeline; 2],
    /// Per surface: `HeightfieldParams` in a uniform block.
    params: Growable,
    /// Every surface's textures (kept while its size holds).
    textures: HashMap<SurfaceId, HeightfieldTexture>,
    /// This frame's bind groups of the surfaces it shows, in surface order, whether each is
    /// linked, and its workgroups.
    bind_groups: Vec<(wgpu::BindGroup, bool, (u32, u32))>,
    /// The groups by surface slot, kept while what they bind stays.
    kept: KeptGroups,
}

impl HeightfieldPass {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let layout = crate::wgsl::HEIGHTFIELD.bind_group_layout(device, "heightfield", 0);
        let module = pipeline::shader(device, "heightfield.wgsl", crate::wgsl::HEIGHTFIELD.wgsl());
        let pipelines = linked_pipelines(device, "heightfield", (&module, "heightfield"), &layout);
        Self {
            params: Growable::new(
                device,
                "heightfield params",
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                UNIFORM_STRIDE * 8,
            ),
            layout,
            pipelines,
            textures: HashMap::new(),
            bind_groups: Vec::new(),
            kept: KeptGroups::default(),
        }
    }

    /// The heightfield parameters of the frame's surface `s` (after [`HeightfieldPass::prepare`]),
    /// which the bank passes read too.
    pub(super) fn params(&self, s: usize) -> wgpu::BindingResource<'_> {
        uniform_block(
            &self.params.buffer,
            s,
            std::mem::size_of::<HeightfieldParams>(),
        )
    }

    /// A surface's textures (after [`HeightfieldPass::prepare`] of a frame that drew it).
    pub(super) fn texture(&self, id: SurfaceId) -> Option<&HeightfieldTexture> {
        self.textures.get(&id)
    }

    /// Upload each surface's parameters (with the moon in its frame and the surfaces beside it),
    /// make its textures at its heightmap's size, and bind them.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (pool, ground, state): (&wgpu::Buffer, &wgpu::Buffer, &wgpu::Buffer),
        surfaces: &[FrameSurface<'_>],
        moon_direction: Vec3,
    ) {
        let stride = UNIFORM_STRIDE as usize;
        let mut bytes = vec![0u8; surfaces.len().max(1) * stride];
        for (s, surface) in surfaces.iter().enumerate() {
            let (desc, layout) = (surface.view.desc, surface.view.layout);
            let local_to_world = desc.local_to_world();
            let p = HeightfieldParams {
                heights: surface.view.heights,
                width: layout.width,
                height: layout.height,
                bits: surface.view.precision.bits(),
                snow_depth: desc.snow_depth,
                texel_x: desc.size.x / layout.width as f32,
                texel_z: desc.size.y / layout.height as f32,
                ground: surface.view.ground,
                wrap: surface.view.wrap,
                slot: s as u32,
                _pad: [0; 2],
                light: {
                    let l = local_to_world
                        .inverse()
                        .transform_vector3(moon_direction)
                        .normalize();
                    [l.x, l.y, l.z, 0.0]
                },
                sides: surface.sides.map(side_params),
            };
            bytes[s * stride..s * stride + std::mem::size_of::<HeightfieldParams>()]
                .copy_from_slice(bytemuck::bytes_of(&p));
        }
        self.params.write_whole(device, queue, &bytes);
        for s in surfaces {
            let size = (s.view.layout.width, s.view.layout.height);
            let [x0, z0, x1, z1] = s.bank_domain();
            let scratch = ((x1 - x0) as u32, (z1 - z0) as u32);
            if self
                .textures
                .get(&s.view.id)
                .is_none_or(|t| t.size != size || t.scratch_size != scratch)
            {
                self.textures
                    .insert(s.view.id, HeightfieldTexture::new(device, size, scratch));
            }
        }
        self.kept.truncate(surfaces.len());
        self.bind_groups.clear();
        // A surface nothing of the frame shows is not dispatched (as the banks').
        for (s, surface) in surfaces.iter().enumerate().filter(|(_, s)| s.seen) {
            let tex = &self.textures[&surface.view.id];
            let group = self.kept.get(
                device,
                "heightfield",
                &self.layout,
                s,
                &[
                    pool.as_entire_binding(),
                    uniform_block(
                        &self.params.buffer,
                        s,
                        std::mem::size_of::<HeightfieldParams>(),
                    ),
                    wgpu::BindingResource::TextureView(&tex.shape),
                    wgpu::BindingResource::TextureView(&tex.light),
                    ground.as_entire_binding(),
                    state.as_entire_binding(),
                ],
            );
            let workgroups = surface.heightfield_workgroups();
            self.bind_groups.push((group, linked(surface), workgroups));
        }
    }

    /// One dispatch per surface the frame can show, over its domain; a surface that `classify`
    /// left unshaded (`STATE_SHADED`) leaves at once. Direct dispatches rather than indirect
    /// ones sized by `classify`: each indirect dispatch costs the CPU a validation dispatch of
    /// wgpu's, with its barriers, in the encoder's `finish`.
    pub(super) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
    ) {
        let mut p = compute_pass(encoder, ts, slot);
        let mut bound = None;
        for (bg, linked, (x, z)) in &self.bind_groups {
            if bound != Some(*linked) {
                p.set_pipeline(&self.pipelines[usize::from(*linked)]);
                bound = Some(*linked);
            }
            p.set_bind_group(0, bg, &[]);
            p.dispatch_workgroups(*x, *z, 1);
        }
    }

    /// A surface's smoothed depression, displaced channel and bank heights as the latest frame's
    /// passes wrote them (over the heightmap's texels, without the border).
    pub(super) fn read_fields(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        surface: SurfaceId,
    ) -> RenderResult<SurfaceFields> {
        let tex = self
            .textures
            .get(&surface)
            .ok_or_else(|| RenderError::Readback("the surface has no heightfield yet".into()))?;
        let (w, h) = tex.size;
        let row = (w * 8).div_ceil(256) * 256;
        let mut channels = Vec::new();
        for (texture, channel, border) in [
            (&tex.textures[0], 0, BORDER),
            (&tex.textures[1], 1, BORDER),
            (&tex.textures[2], 0, BORDER),
        ] {
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("field readback"),
                size: (row * h) as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    origin: wgpu::Origin3d {
                        x: border,
                        y: border,
                        z: 0,
                    },
                    ..texture.as_image_copy()
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &staging,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
            queue.submit([encoder.finish()]);
            let data = map_staging(device, &staging)?;
            let mut values = Vec::with_capacity((w * h) as usize);
            for r in 0..h {
                for c in 0..w {
                    let o = (r * row + c * 8 + channel * 2) as usize;
                    values.push(f16_to_f32(u16::from_le_bytes([data[o], data[o + 1]])));
                }
            }
            channels.push(values);
        }
        let bank = channels.pop().unwrap_or_default();
        let displaced = channels.pop().unwrap_or_default();
        let depression = channels.pop().unwrap_or_default();
        Ok(SurfaceFields {
            width: w,
            height: h,
            depression,
            displaced,
            bank,
        })
    }
}
