//! Gameplay probes: the snow under chosen world points, answered a frame or two later without
//! waiting for the GPU.
//!
//! [`SnowWorld::probe`] queues points and hands back a [`ProbeTicket`]. When the batch is sent,
//! every queued point is looked up on the CPU (the surface whose rectangle holds it), and one
//! small compute pass (`probe.wgsl`) reads each point's texel and its neighbours from the pool into
//! a results buffer, copied into a staging buffer of a ring and mapped with `map_async`. The batch
//! is sent:
//! - by [`SnowWorld::encode_update`] and [`SnowWorld::encode_step`], recorded first in the
//!   caller's encoder (mapped when the caller reports it submitted, so the answer comes once the
//!   caller's frame has run on the GPU);
//! - by [`SnowWorld::step`] and [`SnowWorld::update`], and by [`SnowWorld::send_probes`], as a
//!   small submission of its own, ahead of the update.
//!
//! Every update and every [`SnowWorld::poll_probes`] polls the device with
//! [`wgpu::PollType::Poll`] only, never a blocking wait; a batch whose mapping has completed is
//! read and its buffer returned to the ring. The samples show the snow as the updates submitted
//! before the batch left it. An abandoned frame ([`SnowWorld::abandon_pending`]) queues its
//! batch's requests again.
//!
//! The ring holds [`PROBE_RING`] batches in flight. When every one is in flight and no batch is
//! being gathered, a new probe is refused with [`SnowError::ProbeRingFull`] (nothing already asked
//! is dropped): poll, or probe again next frame.

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use glam::{Quat, Vec3};

mod batch;
pub(crate) mod cpu;

use super::SnowWorld;
use super::footstep::Footstep;
use crate::error::{Result, SnowError};
use crate::gpu::resources::Growable;
use crate::surface::SurfaceId;

/// Batches of probes that can be in flight at once (staging buffers in the ring).
pub const PROBE_RING: usize = 4;
/// Most points one batch (everything probed between two updates) can hold.
pub const MAX_PROBE_POINTS: usize = 4096;
/// Answered tickets kept until asked for; beyond this the oldest answer is forgotten (asking
/// for it then is [`SnowError::UnknownProbe`]).
pub const MAX_UNCLAIMED_ANSWERS: usize = 1024;
/// How far below a surface's ground a point may lie and still be over that surface, metres.
pub(crate) const GROUND_SLACK: f32 = 0.01;

/// A request for probe samples; ask [`SnowWorld::probe_result`] for its answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ProbeTicket(u64);

impl ProbeTicket {
    /// The ticket's number (tickets of one world count up from 0).
    pub fn number(self) -> u64 {
        self.0
    }
}

/// The snow under one probed point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The point asked about, world metres.
    pub point: Vec3,
    /// The surface under it: the topmost whose rectangle holds the point and whose ground is not
    /// above it (1 cm of slack); `None` when no surface is under it (every other field is then 0,
    /// the normal `+Y`).
    pub surface: Option<SurfaceId>,
    /// Snow remaining above the ground at the point's texel, metres.
    pub snow_depth_m: f32,
    /// How far the snow top is pressed below the fresh snow there, metres.
    pub depression_m: f32,
    /// Snow pushed out of that texel by deformers (kept for banks), metres.
    pub displaced_m: f32,
    /// Normal of the snow top (depression only, banks not included), world space, unit length.
    pub normal: Vec3,
}

impl ProbeSample {
    fn outside(point: Vec3) -> Self {
        Self {
            point,
            surface: None,
            snow_depth_m: 0.0,
            depression_m: 0.0,
            displaced_m: 0.0,
            normal: Vec3::Y,
        }
    }
}

/// The answer to a [`ProbeTicket`].
#[derive(Clone, Debug, PartialEq)]
pub enum ProbeStatus {
    /// Not read back yet: ask again after the next update.
    Pending,
    /// The samples, one per point, in the order given. Handed over once: the ticket is then
    /// forgotten.
    Ready(Vec<ProbeSample>),
}

/// One point's query, as `ProbeQuery` in probe.wgsl (36 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeQuery {
    base: u32,
    width: u32,
    height: u32,
    texel: u32,
    bits: u32,
    texel_x: f32,
    texel_z: f32,
    snow_depth: f32,
    wrap: u32,
}

/// What the CPU keeps of a point to turn its raw result into a sample.
#[derive(Clone, Copy)]
struct PointInfo {
    point: Vec3,
    surface: Option<SurfaceId>,
    snow_depth: f32,
    rotation: Quat,
    /// The value of a channel pressed to the ground at the pool's precision.
    channel_max: f64,
    /// On ground that is not flat: the texel's bare depth (rock under the snow column's top, of a
    /// slope that holds less snow), metres, and the slope of the column's base (local
    /// `d/dx`, `d/dz`), which the snow top's slope rides on. Zero on flat ground.
    bare: f32,
    base_slope: glam::Vec2,
}

/// Points asked for by one ticket (or one keyed probe).
struct Request {
    ticket: u64,
    key: Option<u64>,
    points: Vec<Vec3>,
}

/// A ticket's share of a batch.
struct Share {
    ticket: u64,
    key: Option<u64>,
    start: usize,
    len: usize,
}

const MAP_PENDING: u8 = 0;
const MAP_DONE: u8 = 1;
const MAP_FAILED: u8 = 2;

/// One staging buffer of the ring and the batch it carries.
struct RingSlot {
    staging: Option<wgpu::Buffer>,
    /// Set by the `map_async` callback.
    mapped: Arc<AtomicU8>,
    in_flight: bool,
    /// Recorded into a caller's encoder not yet reported submitted (mapped once it is).
    awaiting_submit: bool,
    /// Bytes of results the batch copies into the staging buffer.
    points_bytes: u64,
    shares: Vec<Share>,
    points: Vec<PointInfo>,
    /// The world's frame when the batch was recorded.
    frame: u64,
}

/// The world's probe state: queued requests, the ring, answers and the keyed cache.
pub(super) struct Probes {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    queries: Growable,
    results: Growable,
    ring: Vec<RingSlot>,
    queued: Vec<Request>,
    queued_points: usize,
    next_ticket: u64,
    answers: HashMap<u64, Result<Vec<ProbeSample>, String>>,
    answer_order: VecDeque<u64>,
    cache: HashMap<u64, (ProbeSample, u64, u64)>,
    /// Updates run so far.
    pub(super) frame: u64,
    /// The footsteps of the last update.
    pub(super) footsteps: Vec<Footstep>,
    /// A CPU copy of each mesh deformer's vertices (as last posed), by mesh index: footsteps
    /// find a mesh's lowest point from them.
    pub(super) mesh_vertices: Vec<Option<Vec<Vec3>>>,
}

impl Probes {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let shader = &crate::wgsl::PROBE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe"),
            entries: &shader.layout_entries(0),
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe"),
            source: wgpu::ShaderSource::Wgsl(shader.source.into()),
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("probe"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("probe_points"),
            compilation_options: Default::default(),
            cache: None,
        });
        use wgpu::BufferUsages as U;
        Self {
            pipeline,
            layout,
            queries: Growable::new(device, "probe queries", U::STORAGE | U::COPY_DST, 36 * 64),
            results: Growable::new(device, "probe results", U::STORAGE | U::COPY_SRC, 16 * 64),
            ring: (0..PROBE_RING)
                .map(|_| RingSlot {
                    staging: None,
                    mapped: Arc::new(AtomicU8::new(MAP_PENDING)),
                    in_flight: false,
                    awaiting_submit: false,
                    points_bytes: 0,
                    shares: Vec::new(),
                    points: Vec::new(),
                    frame: 0,
                })
                .collect(),
            queued: Vec::new(),
            queued_points: 0,
            next_ticket: 0,
            answers: HashMap::new(),
            answer_order: VecDeque::new(),
            cache: HashMap::new(),
            frame: 0,
            footsteps: Vec::new(),
            mesh_vertices: Vec::new(),
        }
    }

    /// Keep a copy of mesh `index`'s vertices (registered or posed).
    pub(super) fn keep_mesh(&mut self, index: usize, vertices: &[Vec3]) {
        if self.mesh_vertices.len() <= index {
            self.mesh_vertices.resize(index + 1, None);
        }
        let kept = self.mesh_vertices[index].get_or_insert_with(Vec::new);
        kept.clear();
        kept.extend_from_slice(vertices);
    }

    /// Drop the copy of a removed mesh's vertices.
    pub(super) fn forget_mesh(&mut self, index: usize) {
        if let Some(kept) = self.mesh_vertices.get_mut(index) {
            *kept = None;
        }
    }

    fn in_flight(&self) -> usize {
        self.ring.iter().filter(|s| s.in_flight).count()
    }

    /// Queue a request, or refuse it with a defined error.
    fn enqueue(&mut self, key: Option<u64>, points: &[Vec3]) -> Result<u64> {
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(SnowError::InvalidProbePoint {
                index,
                value: format!("{:?}", points[index].to_array()),
            });
        }
        if self.queued_points + points.len() > MAX_PROBE_POINTS {
            return Err(SnowError::TooManyProbePoints {
                asked: points.len(),
                queued: self.queued_points,
                max: MAX_PROBE_POINTS,
            });
        }
        // A new batch needs a free slot; joining the batch being gathered does not.
        let in_flight = self.in_flight();
        if self.queued.is_empty() && in_flight == PROBE_RING {
            return Err(SnowError::ProbeRingFull {
                in_flight,
                ring: PROBE_RING,
            });
        }
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        self.queued_points += points.len();
        self.queued.push(Request {
            ticket,
            key,
            points: points.to_vec(),
        });
        Ok(ticket)
    }

    fn remember_answer(&mut self, ticket: u64, answer: Result<Vec<ProbeSample>, String>) {
        self.answers.insert(ticket, answer);
        self.answer_order.push_back(ticket);
        while self.answers.len() > MAX_UNCLAIMED_ANSWERS {
            match self.answer_order.pop_front() {
                Some(old) => {
                    self.answers.remove(&old);
                }
                None => break,
            }
        }
    }

    /// Read every batch whose mapping completed, and free its slot.
    fn harvest(&mut self) {
        for s in 0..self.ring.len() {
            let slot = &mut self.ring[s];
            if !slot.in_flight || slot.awaiting_submit {
                continue;
            }
            let state = slot.mapped.load(Ordering::Acquire);
            if state == MAP_PENDING {
                continue;
            }
            let Some(staging) = slot.staging.as_ref() else {
                continue;
            };
            let samples: Result<Vec<ProbeSample>, String> = if state == MAP_DONE {
                let range = staging.slice(..slot.points.len().max(1) as u64 * 16);
                let out = match range.get_mapped_range() {
                    Ok(bytes) => {
                        let words: &[[u32; 4]] = bytemuck::cast_slice(&bytes);
                        Ok(slot
                            .points
                            .iter()
                            .zip(words)
                            .map(|(info, raw)| decode(info, *raw))
                            .collect())
                    }
                    Err(e) => Err(format!("the probe staging buffer could not be read: {e}")),
                };
                staging.unmap();
                out
            } else {
                Err("the probe staging buffer could not be mapped".to_owned())
            };
            slot.in_flight = false;
            let frame = slot.frame;
            let shares = std::mem::take(&mut slot.shares);
            for share in &shares {
                let answer = samples
                    .as_ref()
                    .map(|all| all[share.start..share.start + share.len].to_vec())
                    .map_err(Clone::clone);
                match share.key {
                    Some(key) => {
                        if let Ok(Some(&sample)) = answer.as_ref().map(|a| a.first()) {
                            let newer = self.cache.get(&key).is_none_or(|c| c.2 < share.ticket);
                            if newer {
                                self.cache.insert(key, (sample, frame, share.ticket));
                            }
                        }
                    }
                    None => self.remember_answer(share.ticket, answer),
                }
            }
            let mut shares = shares;
            shares.clear();
            self.ring[s].shares = shares;
        }
    }
}

/// A sample from a point's raw result: channels as stored, then the slope of the top (f32 bits).
fn decode(info: &PointInfo, raw: [u32; 4]) -> ProbeSample {
    if info.surface.is_none() {
        return ProbeSample::outside(info.point);
    }
    decode_over(info, raw)
}

/// A sample from a point's raw result over a surface (`info.surface` is only named).
fn decode_over(info: &PointInfo, raw: [u32; 4]) -> ProbeSample {
    let metres = |v: u32| (v as f64 / info.channel_max * info.snow_depth as f64) as f32;
    let depression_m = metres(raw[0]).min(info.snow_depth);
    let (dx, dz) = (
        f32::from_bits(raw[2]) + info.base_slope.x,
        f32::from_bits(raw[3]) + info.base_slope.y,
    );
    let local = Vec3::new(-dx, 1.0, -dz).normalize_or(Vec3::Y);
    ProbeSample {
        point: info.point,
        surface: info.surface,
        snow_depth_m: (info.snow_depth - info.bare - depression_m).max(0.0),
        depression_m,
        displaced_m: metres(raw[1]),
        normal: info.rotation * local,
    }
}

impl SnowWorld {
    /// Ask for the snow under `points` (world metres). The answer comes a frame or two later from
    /// [`SnowWorld::probe_result`]; nothing here or there waits for the GPU. Fails with
    /// [`SnowError::ProbeRingFull`] when every staging buffer is in flight and no batch is being
    /// gathered, [`SnowError::TooManyProbePoints`] past [`MAX_PROBE_POINTS`] points between two
    /// updates, and [`SnowError::InvalidProbePoint`] for a point that is not finite.
    pub fn probe(&mut self, points: &[Vec3]) -> Result<ProbeTicket> {
        self.probes.enqueue(None, points).map(ProbeTicket)
    }

    /// Probe one point for a caller's `key` (a foot, a wheel): when answered, the sample replaces
    /// the key's entry in the cache that [`SnowWorld::under`] reads. Fails as [`SnowWorld::probe`].
    pub fn probe_keyed(&mut self, key: u64, point: Vec3) -> Result<()> {
        self.probes.enqueue(Some(key), &[point]).map(|_| ())
    }

    /// The latest answered sample for `key` and its age in updates (0: read after the last
    /// update's snow, 1: a frame older...); `None` before the key's first answer.
    pub fn under(&self, key: u64) -> Option<(ProbeSample, u64)> {
        self.probes
            .cache
            .get(&key)
            .map(|&(sample, frame, _)| (sample, self.probes.frame.saturating_sub(frame)))
    }

    /// Forget a key's cached sample (a character that left).
    pub fn forget_key(&mut self, key: u64) {
        self.probes.cache.remove(&key);
    }

    /// The answer to a ticket, after polling the device without waiting. A ticket answered once
    /// is forgotten; asking again, or for a ticket this world never gave, or for one left unasked
    /// past [`MAX_UNCLAIMED_ANSWERS`] newer answers, fails with [`SnowError::UnknownProbe`].
    pub fn probe_result(&mut self, ticket: ProbeTicket) -> Result<ProbeStatus> {
        self.poll_probes_only();
        if let Some(answer) = self.probes.answers.remove(&ticket.0) {
            return answer.map(ProbeStatus::Ready).map_err(SnowError::Readback);
        }
        let t = ticket.0;
        let queued = self.probes.queued.iter().any(|r| r.ticket == t);
        let in_flight = self
            .probes
            .ring
            .iter()
            .any(|s| s.in_flight && s.shares.iter().any(|x| x.ticket == t));
        if queued || in_flight {
            Ok(ProbeStatus::Pending)
        } else {
            Err(SnowError::UnknownProbe { ticket: t })
        }
    }

    /// Send the probes queued since the last update to the GPU now (rather than at the start of
    /// the next update) and read every batch that is back. Never waits.
    pub fn poll_probes(&mut self) {
        self.send_probes();
        self.poll_probes_only();
    }

    /// Send the probes queued since the last update to the GPU now, without polling (so batches
    /// already back stay in flight until the next poll). Does nothing when none are queued.
    pub fn send_probes(&mut self) {
        self.flush_probes(None);
    }

    /// Record the probes queued so far into `enc` (the manager's tick, before its residency
    /// changes); they are mapped once [`SnowWorld::submitted`] or [`SnowWorld::probes_sent`] says
    /// the encoder was submitted.
    pub(crate) fn encode_probes(&mut self, enc: &mut wgpu::CommandEncoder) {
        self.flush_probes(Some(enc));
    }

    /// The encoder that [`SnowWorld::encode_probes`] recorded into was submitted (without a
    /// world frame in it).
    pub(crate) fn probes_sent(&mut self) {
        self.probes_submitted();
    }

    /// Probe batches in flight (at most [`PROBE_RING`]).
    pub fn probes_in_flight(&self) -> usize {
        self.probes.in_flight()
    }

    /// The footsteps of the last update: deformers that landed on a surface during it.
    pub fn footsteps(&self) -> &[Footstep] {
        &self.probes.footsteps
    }

    /// Poll the device without waiting and read what came back.
    pub(super) fn poll_probes_only(&mut self) {
        if self.probes.in_flight() == 0 {
            return;
        }
        // A failed poll (a lost device) leaves the batches in flight; the update reports the loss.
        let _ = self.device.poll(wgpu::PollType::Poll);
        self.probes.harvest();
    }
}

#[cfg(test)]
mod tests;
