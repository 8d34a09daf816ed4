//! Kicked-up snow (issue 17, part 3): GPU particles spawned where an update deepens a print fast,
//! read from the update's own data, so no deformer is tracked on the CPU. Off unless
//! [`crate::WorldConfig::spray`] is set; then each update layer records, between the capture and
//! the accumulation:
//!
//! 1. `simulate.wgsl`: every slot of the ring advances by the layer's time
//!    (gravity, drag); cost: the ring's capacity;
//! 2. `spawn.wgsl` `spawn`: a texel of a captured tile whose depression this update
//!    grows by more than [`SprayConfig::threshold`] spawns one particle on the new snow top,
//!    thrown up and out down the print's slope, into a fixed-capacity ring (an atomic counter);
//!    cost: the captured tiles, as the accumulation's;
//! 3. `fold`: the ring's head moves past the spawns kept; spawns past the capacity in one frame are
//!    dropped and counted ([`SprayCounters`]), a defined answer rather than an overwrite of the
//!    frame's own particles;
//! 4. `place` (`simulate.wgsl`): this frame's spawns, written in their surface's frame, move to the
//!    world (the spawn already binds six storage buffers); cost: the ring's
//!    capacity.
//!
//! The spawn reads the heights before the accumulation overwrites them and writes nothing the
//! accumulation reads, so the update is bit-identical with spray on or off. CPU reference:
//! [`cpu`]. Each material throws its own grains ([`SprayLook`], `Material::spray`): `place`
//! thins a surface's spawns by its amount, scales their speed, life and drag, and gives them its
//! albedo and radius, which the renderer's `spray` pass draws.

pub(crate) mod cpu;
mod look;

pub use look::SprayLook;

use crate::error::{Result, SnowError};
use crate::gpu::resources::{Growable, bind_group};
use crate::pool::Precision;

/// Largest ring, particles (48 bytes each: 96 MiB, under WebGPU's least storage binding of
/// 128 MiB).
pub const MAX_SPRAY_CAPACITY: u32 = 1 << 21;

/// Settings of the kicked-up snow ([`crate::WorldConfig::spray`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SprayConfig {
    /// Particles in the ring (at most [`MAX_SPRAY_CAPACITY`]): a bound on what lives at once and
    /// on what one frame spawns; the simulation costs one invocation a slot every frame.
    pub capacity: u32,
    /// A texel spawns when an update deepens it by more than this fraction of the snow depth
    /// (after the update's replenishment). Keep it above a frame's replenishment, or a deformer
    /// resting in snow that refills spawns every frame.
    pub threshold: f32,
    /// Launch speed, metres per second (scaled per particle by 0.3 to 1.5 with the growth).
    pub speed: f32,
    /// Seconds a particle lives (0.7 to 1 times this).
    pub lifetime: f32,
    /// Velocity lost per second, as a rate (`v /= 1 + drag * dt` each step).
    pub drag: f32,
    /// Downward acceleration, metres per second squared.
    pub gravity: f32,
}

impl Default for SprayConfig {
    fn default() -> Self {
        Self {
            capacity: 16384,
            threshold: 0.05,
            speed: 1.2,
            lifetime: 1.2,
            drag: 1.5,
            gravity: 9.81,
        }
    }
}

impl SprayConfig {
    /// Refuse a setting out of range, naming it.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &'static str, value: String, expected: &'static str| {
            Err(SnowError::Config {
                config: "spray",
                what,
                value,
                expected,
            })
        };
        if self.capacity == 0 || self.capacity > MAX_SPRAY_CAPACITY {
            return bad(
                "capacity",
                self.capacity.to_string(),
                "1 to 2097152 particles",
            );
        }
        if !(self.threshold.is_finite() && (0.0..1.0).contains(&self.threshold)) {
            return bad(
                "threshold",
                self.threshold.to_string(),
                "a fraction of the snow depth in [0, 1)",
            );
        }
        for (what, v) in [
            ("speed", self.speed),
            ("lifetime", self.lifetime),
            ("drag", self.drag),
            ("gravity", self.gravity),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(what, v.to_string(), "a finite number of 0 or more");
            }
        }
        Ok(())
    }

    /// The threshold in channel units at `precision` (what the GPU compares a growth against).
    pub fn threshold_units(&self, precision: Precision) -> u32 {
        (self.threshold * precision.channel_max() as f32).floor() as u32
    }
}

/// One frame's settings, as `SprayParams` in particle.wgsl (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SprayParams {
    /// Particles in the ring.
    pub capacity: u32,
    /// Growth, channel units, above which a texel spawns.
    pub threshold_units: u32,
    /// The world's frame number (seeds the jitter).
    pub frame: u32,
    /// Padding.
    pub _pad0: u32,
    /// Seconds simulated.
    pub dt: f32,
    /// See [`SprayConfig::speed`].
    pub speed: f32,
    /// See [`SprayConfig::lifetime`].
    pub lifetime: f32,
    /// See [`SprayConfig::drag`].
    pub drag: f32,
    /// See [`SprayConfig::gravity`].
    pub gravity: f32,
    /// Padding to 48 bytes.
    pub _pad1: [u32; 3],
}

/// Where an updated surface lies and what its material throws, as `SprayRecord` in
/// particle.wgsl: one per [`crate::pool::SurfaceRecord`] of the update, same order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SprayRecord {
    /// Column-major surface-local to world transform.
    pub local_to_world: [f32; 16],
    /// The material's [`SprayLook`] factors: amount, speed, lifetime, drag.
    pub factors: [f32; 4],
    /// The material's grain: albedo (linear RGB) and radius (metres).
    pub grain: [f32; 4],
}

impl SprayRecord {
    /// A surface's record: its placement and its material's spray.
    pub fn new(local_to_world: [f32; 16], look: &SprayLook) -> Self {
        let [r, g, b] = look.albedo;
        Self {
            local_to_world,
            factors: [look.amount, look.speed, look.lifetime, look.drag],
            grain: [r, g, b, look.radius],
        }
    }
}

/// One particle, as `Particle` in particle.wgsl (32 bytes, world space).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Particle {
    /// Metres.
    pub position: [f32; 3],
    /// Seconds left; dead at 0.
    pub life: f32,
    /// Metres per second.
    pub velocity: [f32; 3],
    /// Seconds since it was spawned.
    pub age: f32,
    /// Albedo, RGBA8 unorm (alpha 255): its material's [`SprayLook::albedo`].
    pub albedo: u32,
    /// Radius as drawn, metres.
    pub radius: f32,
    /// Velocity lost per second, as a rate: the world's drag times its material's factor.
    pub drag: f32,
    /// Padding to 48 bytes.
    pub _pad: u32,
}

/// The ring's counters as the GPU left them (u32 words, see particle.wgsl).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SprayCounters {
    /// Slot where the next frame's spawns start.
    pub head: u32,
    /// Texels that asked to spawn in the last update layer.
    pub last_requested: u32,
    /// Of those, spawns dropped because the ring's capacity was reached.
    pub last_dropped: u32,
    /// Spawns dropped since the world was made.
    pub dropped_total: u32,
    /// Spawns kept since the world was made.
    pub spawned_total: u32,
}

/// Bytes of counters at the start of the ring buffer, before the particles (`RING_HEADER` words in
/// particle.wgsl).
pub const SPRAY_RING_HEADER: u64 = 32;

/// The spray's pipelines, ring and per-frame tables, kept by a world that has spray.
pub(crate) struct SprayGpu {
    pub(crate) config: SprayConfig,
    spawn: wgpu::ComputePipeline,
    fold: wgpu::ComputePipeline,
    simulate: wgpu::ComputePipeline,
    place: wgpu::ComputePipeline,
    spawn_layout: wgpu::BindGroupLayout,
    simulate_layout: wgpu::BindGroupLayout,
    /// The ring: [`SPRAY_RING_HEADER`] bytes of counters, then `capacity` [`Particle`]s (zeroed
    /// at first: the ring empty, every particle dead).
    pub(crate) ring: wgpu::Buffer,
    params: wgpu::Buffer,
    /// [`SprayRecord`]s of the layer being recorded.
    pub(crate) records: Growable,
}

/// The update's buffers the spawn pass reads.
pub(crate) struct SpawnInputs<'a> {
    pub(crate) records: &'a wgpu::Buffer,
    pub(crate) capture: &'a wgpu::Buffer,
    pub(crate) pool: &'a wgpu::Buffer,
    pub(crate) winding: &'a wgpu::Buffer,
    pub(crate) tiles: &'a wgpu::Buffer,
    /// Records of the layer (the dispatch's `z`), 0 for a layer that captured nothing.
    pub(crate) count: u32,
    /// Widest and tallest record, texels.
    pub(crate) max_width: u32,
    pub(crate) max_height: u32,
}

impl SprayGpu {
    pub(crate) fn new(device: &wgpu::Device, precision: Precision, config: SprayConfig) -> Self {
        use crate::wgsl::{SPRAY_SIMULATE, SPRAY_SPAWN};
        use wgpu::BufferUsages as U;
        let spawn_layout = SPRAY_SPAWN.bind_group_layout(device, "spray spawn", 0);
        let simulate_layout = SPRAY_SIMULATE.bind_group_layout(device, "spray simulate", 0);
        let constants = [("PRECISION", precision.bits() as f64)];
        let make = |shader: &crate::wgsl::ShaderModule,
                    layout: &wgpu::BindGroupLayout,
                    entry: &str,
                    constants: &[(&str, f64)]| {
            let [p] = shader.compute_pipelines(device, [entry], layout, constants);
            p
        };
        let buffer = |label: &str, size: u64, usage: U| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            spawn: make(&SPRAY_SPAWN, &spawn_layout, "spawn", &constants),
            fold: make(&SPRAY_SPAWN, &spawn_layout, "fold", &constants),
            simulate: make(&SPRAY_SIMULATE, &simulate_layout, "simulate", &[]),
            place: make(&SPRAY_SIMULATE, &simulate_layout, "place", &[]),
            spawn_layout,
            simulate_layout,
            // Buffers are created zeroed: every particle dead, the ring empty.
            ring: buffer(
                "spray ring",
                SPRAY_RING_HEADER + config.capacity as u64 * std::mem::size_of::<Particle>() as u64,
                U::STORAGE | U::VERTEX | U::COPY_SRC,
            ),
            params: buffer("spray params", 48, U::UNIFORM | U::COPY_DST),
            records: Growable::new(device, "spray records", U::STORAGE | U::COPY_DST, 96 * 16),
            config,
        }
    }

    /// The layer's settings, for [`SprayGpu::encode`].
    pub(crate) fn params(&self, precision: Precision, frame: u64, dt: f32) -> SprayParams {
        let c = &self.config;
        SprayParams {
            capacity: c.capacity,
            threshold_units: c.threshold_units(precision),
            frame: frame as u32,
            dt,
            speed: c.speed,
            lifetime: c.lifetime,
            drag: c.drag,
            gravity: c.gravity,
            ..SprayParams::default()
        }
    }

    /// The buffer the layer's [`SprayParams`] are written to before it is recorded.
    pub(crate) fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// Record one layer: simulate every slot, then (when the layer captured anything) spawn, fold
    /// and place, in one compute pass.
    pub(crate) fn encode(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        inputs: &SpawnInputs<'_>,
        queries: &mut crate::gpu::timestamps::StageQueries<'_>,
    ) {
        let sim_bg = bind_group(
            device,
            "spray simulate",
            &self.simulate_layout,
            &[
                self.params.as_entire_binding(),
                self.ring.as_entire_binding(),
                self.records.buffer.as_entire_binding(),
            ],
        );
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("spray"),
            timestamp_writes: queries.compute("spray"),
        });
        pass.set_pipeline(&self.simulate);
        pass.set_bind_group(0, &sim_bg, &[]);
        let grid = crate::gpu::resources::dispatch_rows(self.config.capacity.div_ceil(64));
        pass.dispatch_workgroups(grid.0, grid.1, 1);
        if inputs.count == 0 {
            return;
        }
        let spawn_bg = bind_group(
            device,
            "spray spawn",
            &self.spawn_layout,
            &[
                inputs.records.as_entire_binding(),
                inputs.capture.as_entire_binding(),
                inputs.pool.as_entire_binding(),
                inputs.winding.as_entire_binding(),
                inputs.tiles.as_entire_binding(),
                self.params.as_entire_binding(),
                self.ring.as_entire_binding(),
            ],
        );
        let tile = crate::pool::TILE_SIDE;
        pass.set_pipeline(&self.spawn);
        pass.set_bind_group(0, &spawn_bg, &[]);
        pass.dispatch_workgroups(
            inputs.max_width.div_ceil(tile),
            inputs.max_height.div_ceil(tile),
            inputs.count,
        );
        pass.set_pipeline(&self.fold);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.place);
        pass.set_bind_group(0, &sim_bg, &[]);
        pass.dispatch_workgroups(grid.0, grid.1, 1);
    }

    /// Read the counters and every particle back (waits for the GPU; for tests and tools).
    pub(crate) fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<(SprayCounters, Vec<Particle>)> {
        let bytes = crate::gpu::readback::download(device, queue, &self.ring, 0, self.ring.size())?;
        let (header, particles) = bytes.split_at(SPRAY_RING_HEADER as usize);
        let w: &[u32] = bytemuck::cast_slice(header);
        let counters = SprayCounters {
            head: w[0],
            last_requested: w[2],
            last_dropped: w[3],
            dropped_total: w[4],
            spawned_total: w[5],
        };
        Ok((counters, bytemuck::cast_slice(particles).to_vec()))
    }
}

#[cfg(test)]
mod tests {
    /// Every struct of particle.wgsl has the Rust side's size, field by field.
    #[test]
    fn layouts_match_wgsl() {
        let module = naga::front::wgsl::parse_str(crate::wgsl::SPRAY_SIMULATE.source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        for (name, size, fields) in [
            (
                "SprayParams",
                std::mem::size_of::<super::SprayParams>(),
                12usize,
            ),
            ("SprayRecord", std::mem::size_of::<super::SprayRecord>(), 3),
            ("Particle", std::mem::size_of::<super::Particle>(), 8),
        ] {
            let (handle, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("{name} not in particle.wgsl"));
            let naga::TypeInner::Struct { members, .. } = &ty.inner else {
                panic!("{name} is not a struct")
            };
            assert_eq!(layouter[handle].size as usize, size, "{name}");
            assert_eq!(members.len(), fields, "{name}");
        }
        // Particle: position at 0, life at 12, velocity at 16, age at 28, then albedo, radius,
        // drag and padding.
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("Particle"))
            .unwrap();
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!()
        };
        let offsets: Vec<u32> = members.iter().map(|m| m.offset).collect();
        assert_eq!(offsets, [0, 12, 16, 28, 32, 36, 40, 44]);
    }

    #[test]
    fn config_refuses_bad_values() {
        let ok = super::SprayConfig::default();
        assert!(ok.validate().is_ok());
        for bad in [
            super::SprayConfig { capacity: 0, ..ok },
            super::SprayConfig {
                threshold: f32::NAN,
                ..ok
            },
            super::SprayConfig { drag: -1.0, ..ok },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
