//! Probe batches on the GPU: the queued points looked up on the CPU, one compute pass reading
//! their texels, and the copy into a ring slot's staging buffer, mapped once submitted.

use std::sync::atomic::Ordering;

use glam::{Quat, Vec3};

use super::{
    MAP_DONE, MAP_FAILED, MAP_PENDING, PointInfo, ProbeQuery, Probes, Request, Share, cpu,
};
use crate::surface::SurfaceId;
use crate::world::SnowWorld;

/// Bytes of one `ProbeQuery`.
const QUERY_BYTES: u64 = std::mem::size_of::<ProbeQuery>() as u64;

impl SnowWorld {
    /// The surface under a point (see [`super::ProbeSample::surface`]): the topmost whose
    /// rectangle holds it (outside its hole, where a finer terrain window level answers) and whose
    /// ground is not above it; its query and what decodes it.
    fn surface_under(&self, point: Vec3) -> Option<(ProbeQuery, PointInfo)> {
        let precision = self.config.format.precision;
        let mut best: Option<(f32, usize)> = None;
        for (i, s) in self.surfaces.iter().enumerate() {
            let Some(s) = s else { continue };
            let field = s.ground.as_ref().map(|g| &g.field);
            match cpu::over_outside_hole(&s.desc, field, s.hole, point) {
                Some(ground) if best.is_none_or(|b| b.0 < ground) => best = Some((ground, i)),
                _ => {}
            }
        }
        let i = best?.1;
        let s = self.surfaces[i].as_ref()?;
        let id = SurfaceId(i as u32, self.generations[i]);
        let (mut query, info) = cpu::query(
            &s.desc,
            &s.layout,
            precision,
            s.slot.heights_word(),
            Some(id),
            s.ground.as_ref().map(|g| &g.field),
            point,
        );
        query.wrap = s.wrap;
        Some((query, info))
    }

    /// Record the queued probes as one batch into a free ring slot (the slot was kept free when
    /// the batch's first request was queued): into `enc` when given, mapped once the caller
    /// reports it submitted, else into an encoder of its own, submitted and mapped at once.
    pub(in crate::world) fn flush_probes(&mut self, enc: Option<&mut wgpu::CommandEncoder>) {
        if self.probes.queued.is_empty() {
            return;
        }
        let Some(s) = self.probes.ring.iter().position(|s| !s.in_flight) else {
            // Unreachable by `enqueue`'s check; the requests wait for a slot.
            return;
        };
        let requests = std::mem::take(&mut self.probes.queued);
        self.probes.queued_points = 0;
        let mut queries = Vec::new();
        let mut points = std::mem::take(&mut self.probes.ring[s].points);
        let mut shares = std::mem::take(&mut self.probes.ring[s].shares);
        points.clear();
        shares.clear();
        for r in &requests {
            shares.push(Share {
                ticket: r.ticket,
                key: r.key,
                start: points.len(),
                len: r.points.len(),
            });
            for &p in &r.points {
                let (query, info) = self.surface_under(p).unwrap_or((
                    ProbeQuery::default(),
                    PointInfo {
                        point: p,
                        surface: None,
                        snow_depth: 0.0,
                        rotation: Quat::IDENTITY,
                        channel_max: 1.0,
                        bare: 0.0,
                        base_slope: glam::Vec2::ZERO,
                    },
                ));
                queries.push(query);
                points.push(info);
            }
        }
        let frame = self.probes.frame;
        let slot = &mut self.probes.ring[s];
        slot.points = points;
        slot.shares = shares;
        slot.frame = frame;
        match enc {
            Some(enc) => {
                self.record_probe_batch(s, &queries, enc);
                self.probes.ring[s].awaiting_submit = true;
            }
            None => {
                let mut enc = self
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("snow probes"),
                    });
                self.record_probe_batch(s, &queries, &mut enc);
                self.queue.submit([enc.finish()]);
                self.probes.map_slot(s);
            }
        }
    }

    /// Upload a batch's queries, dispatch the probe pass and copy the results into ring slot
    /// `s`'s staging buffer, in `enc`.
    fn record_probe_batch(
        &mut self,
        s: usize,
        queries: &[ProbeQuery],
        enc: &mut wgpu::CommandEncoder,
    ) {
        let n = queries.len().max(1) as u64;
        let (device, queue) = (&self.device, &self.queue);
        let p = &mut self.probes;
        p.queries.ensure(device, n * QUERY_BYTES);
        p.results.ensure(device, n * 16);
        if queries.is_empty() {
            queue.write_buffer(&p.queries.buffer, 0, &[0; QUERY_BYTES as usize]);
        } else {
            queue.write_buffer(&p.queries.buffer, 0, bytemuck::cast_slice(queries));
        }
        let slot = &mut p.ring[s];
        if slot.staging.as_ref().is_none_or(|b| b.size() < n * 16) {
            slot.staging = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("probe staging"),
                size: (n * 16).next_power_of_two().max(256),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &p.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.pool.as_entire_binding(),
                },
                sized(1, &p.queries.buffer, n * QUERY_BYTES),
                sized(2, &p.results.buffer, n * 16),
            ],
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("probe"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&p.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(n.div_ceil(64) as u32, 1, 1);
        }
        let staging = slot.staging.as_ref().expect("made above");
        enc.copy_buffer_to_buffer(&p.results.buffer, 0, staging, 0, n * 16);
        slot.points_bytes = n * 16;
        slot.in_flight = true;
    }

    /// Before an update: record the queued probes into the update's encoder (they read the snow
    /// as the updates before it left it) and read what came back.
    pub(in crate::world) fn probes_before_update(&mut self, enc: &mut wgpu::CommandEncoder) {
        self.flush_probes(Some(enc));
        self.poll_probes_only();
    }

    /// After an update is encoded (its footsteps noted as its layers were planned): count the
    /// frame, read what came back.
    pub(in crate::world) fn probes_after_update(&mut self) {
        self.probes.frame += 1;

        self.poll_probes_only();
    }

    /// The update's encoder was submitted: map the batch recorded into it.
    pub(in crate::world) fn probes_submitted(&mut self) {
        for s in 0..self.probes.ring.len() {
            if self.probes.ring[s].awaiting_submit {
                self.probes.map_slot(s);
            }
        }
    }

    /// The update's encoder will never be submitted: its batch's requests are queued again
    /// (nothing asked is dropped) and its slot is free.
    pub(in crate::world) fn probes_abandoned(&mut self) {
        let p = &mut self.probes;
        for s in 0..p.ring.len() {
            let slot = &mut p.ring[s];
            if !slot.awaiting_submit {
                continue;
            }
            slot.awaiting_submit = false;
            slot.in_flight = false;
            let mut again: Vec<Request> = slot
                .shares
                .drain(..)
                .map(|share| Request {
                    ticket: share.ticket,
                    key: share.key,
                    points: slot.points[share.start..share.start + share.len]
                        .iter()
                        .map(|i| i.point)
                        .collect(),
                })
                .collect();
            p.queued_points += again.iter().map(|r| r.points.len()).sum::<usize>();
            again.append(&mut p.queued);
            p.queued = again;
        }
    }
}

impl Probes {
    /// Start mapping ring slot `s`'s staging buffer (its commands were submitted).
    fn map_slot(&mut self, s: usize) {
        let slot = &mut self.ring[s];
        slot.awaiting_submit = false;
        let Some(staging) = slot.staging.as_ref() else {
            return;
        };
        slot.mapped.store(MAP_PENDING, Ordering::Release);
        let flag = slot.mapped.clone();
        staging
            .slice(..slot.points_bytes)
            .map_async(wgpu::MapMode::Read, move |r| {
                flag.store(
                    if r.is_ok() { MAP_DONE } else { MAP_FAILED },
                    Ordering::Release,
                );
            });
    }
}

/// A storage binding of the first `size` bytes of a buffer.
fn sized(binding: u32, buffer: &wgpu::Buffer, size: u64) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: wgpu::BufferSize::new(size),
        }),
    }
}
