//! The `banks` pass (compute, `banks.wgsl`): a share of the snow each diced surface's captures
//! pushed down rises in banks beside the trails, on it and on the surfaces beside it. Two
//! dispatches per surface seen over its texels and a band around it
//! (`FrameSurface::bank_domain`), which leave at once where `classify` left the surface unshaded:
//! `bank_norm` spreads each texel's share into the scratch texture, `bank_gather` collects it
//! into the bank heights.

use super::BankParams;
use crate::gpu::resources::{Growable, KeptGroups, uniform_block};
use crate::render::frame::FrameSurface;
use crate::render::gpu::UNIFORM_STRIDE;
use crate::render::heightfield::{HeightfieldPass, linked, linked_pipelines};
use crate::render::pipeline;
use crate::render::readback::{Timestamps, compute_pass};

/// A surface's dispatches of both bank passes.
struct SurfaceBanks {
    /// The groups of `bank_norm` and `bank_gather`.
    groups: [wgpu::BindGroup; 2],
    /// Whether a surface lies beside a side (the linked pipelines).
    linked: bool,
    /// Workgroups over its domain (`FrameSurface::bank_workgroups`).
    workgroups: (u32, u32),
}

pub(in crate::render) struct BanksPass {
    layout: wgpu::BindGroupLayout,
    /// `bank_norm` and `bank_gather`, each for surfaces with nothing beside them and with a
    /// surface beside a side.
    pipelines: [[wgpu::ComputePipeline; 2]; 2],
    /// Per surface: `BankParams` in a uniform block.
    params: Growable,
    /// This frame's bind groups (norm, gather) per surface, whether it is linked, and its
    /// workgroups; `None` where it draws no banks or nothing of the frame shows it.
    bind_groups: Vec<Option<SurfaceBanks>>,
    /// The groups by surface slot (norm at `2 s`, gather at `2 s + 1`), kept while what they
    /// bind stays.
    kept: KeptGroups,
}

impl BanksPass {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let layout = crate::wgsl::BANKS.bind_group_layout(device, "banks", 0);
        let module = pipeline::shader(device, "banks.wgsl", crate::wgsl::BANKS.wgsl());
        let pipelines = [("bank norm", "bank_norm"), ("bank gather", "bank_gather")]
            .map(|(label, entry)| linked_pipelines(device, label, (&module, entry), &layout));
        Self {
            params: Growable::new(
                device,
                "bank params",
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                256 * 8,
            ),
            layout,
            pipelines,
            bind_groups: Vec::new(),
            kept: KeptGroups::default(),
        }
    }

    /// Upload the bank parameters of each surface that draws banks and bind its heightfield
    /// textures: in the tessellated tier (`active`) every diced surface, in the others the
    /// surfaces whose material throws rims (`Material::compressibility`), which the relief and
    /// POM searches raise above the snow top.
    pub(crate) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        active: bool,
        (pool, state, surfaces): (&wgpu::Buffer, &wgpu::Buffer, &[FrameSurface<'_>]),
        heightfields: &HeightfieldPass,
    ) {
        self.bind_groups.clear();
        let banked = |surface: &FrameSurface<'_>| {
            if active {
                surface.tessellated
            } else {
                surface.rims()
            }
        };
        if !surfaces.iter().any(banked) {
            return;
        }
        let stride = UNIFORM_STRIDE as usize;
        let mut bytes = vec![0u8; surfaces.len().max(1) * stride];
        for (s, surface) in surfaces.iter().enumerate() {
            if !banked(surface) {
                continue;
            }
            let (desc, layout) = (surface.view.desc, surface.view.layout);
            let bank = BankParams {
                domain: surface.bank_domain(),
                ..BankParams::new(
                    layout.width,
                    layout.height,
                    surface.texel(),
                    desc.snow_depth,
                    surface.banks(),
                )
            };
            bytes[s * stride..s * stride + std::mem::size_of::<BankParams>()]
                .copy_from_slice(bytemuck::bytes_of(&bank));
        }
        self.params.write_whole(device, queue, &bytes);
        let tv = wgpu::BindingResource::TextureView;
        self.kept.truncate(2 * surfaces.len());
        let (kept, layout) = (&mut self.kept, &self.layout);
        self.bind_groups = surfaces
            .iter()
            .enumerate()
            .map(|(s, surface)| {
                if !banked(surface) || !surface.seen {
                    return None;
                }
                let tex = heightfields.texture(surface.view.id)?;
                let params =
                    uniform_block(&self.params.buffer, s, std::mem::size_of::<BankParams>());
                let texels = [pool.as_entire_binding(), heightfields.params(s)];
                let norm = kept.get(
                    device,
                    "bank norm",
                    layout,
                    2 * s,
                    &[
                        params.clone(),
                        tv(&tex.shape),
                        tv(&tex.light),
                        tv(&tex.bank),
                        tv(&tex.bank_scratch),
                        texels[0].clone(),
                        texels[1].clone(),
                        state.as_entire_binding(),
                    ],
                );
                let gather = kept.get(
                    device,
                    "bank gather",
                    layout,
                    2 * s + 1,
                    &[
                        params,
                        tv(&tex.shape),
                        tv(&tex.light),
                        tv(&tex.bank_scratch),
                        tv(&tex.bank),
                        texels[0].clone(),
                        texels[1].clone(),
                        state.as_entire_binding(),
                    ],
                );
                Some(SurfaceBanks {
                    groups: [norm, gather],
                    linked: linked(surface),
                    workgroups: surface.bank_workgroups(),
                })
            })
            .collect();
    }

    /// Both bank passes over the surfaces seen that draw banks (direct dispatches, as the
    /// heightfield pass's: the deformed ones among them do the work).
    pub(crate) fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        ts: Option<&Timestamps>,
        slot: usize,
    ) {
        let mut p = compute_pass(encoder, ts, slot);
        for (step, pipelines) in self.pipelines.iter().enumerate() {
            let mut bound = None;
            for s in self.bind_groups.iter().flatten() {
                if bound != Some(s.linked) {
                    p.set_pipeline(&pipelines[usize::from(s.linked)]);
                    bound = Some(s.linked);
                }
                p.set_bind_group(0, &s.groups[step], &[]);
                p.dispatch_workgroups(s.workgroups.0, s.workgroups.1, 1);
            }
        }
    }
}
