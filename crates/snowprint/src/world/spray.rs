//! The world's side of the kicked-up snow (`crate::spray`): each update layer's settings and
//! surface placements written, the spray's pass recorded between the capture and the accumulation,
//! and the ring read back.

use super::{FramePlan, SnowWorld};
use crate::error::Result;
use crate::spray::{Particle, SpawnInputs, SprayCounters, SprayRecord};

impl SnowWorld {
    /// Record layer `layer`'s spray (when the world has it): simulate the ring by `dt`, then spawn
    /// from `plan`'s captured surfaces. Called after the capture and before the accumulation
    /// (the spawn reads the heights the accumulation then overwrites); `plan` may be empty, and
    /// the particles still move.
    pub(super) fn record_spray(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        plan: &FramePlan,
        layer: usize,
        dt: f32,
        queries: &mut crate::gpu::timestamps::StageQueries<'_>,
    ) {
        let Some(spray) = self.spray.as_mut() else {
            return;
        };
        let (device, queue) = (&self.device, &self.queue);
        let params = spray.params(self.config.format.precision, self.frames, dt);
        let surfaces = &self.surfaces;
        let records: Vec<SprayRecord> = plan
            .surfaces
            .iter()
            .map(|p| {
                surfaces[p.index]
                    .as_ref()
                    .map(|s| {
                        SprayRecord::new(
                            s.desc.local_to_world().to_cols_array(),
                            &s.desc.material.spray,
                        )
                    })
                    .unwrap_or_default()
            })
            .collect();
        spray.records.ensure(
            device,
            (records.len() * std::mem::size_of::<SprayRecord>()) as u64,
        );
        // The first layer's tables land with the submission; a later layer's in the encoder's
        // order, after the earlier layer's passes read theirs.
        let mut write = |buffer: &wgpu::Buffer, bytes: &[u8]| {
            if bytes.is_empty() {
                return;
            }
            if layer == 0 {
                queue.write_buffer(buffer, 0, bytes);
            } else {
                crate::gpu::resources::write_in_order(device, enc, buffer, 0, bytes);
            }
        };
        write(spray.params_buffer(), bytemuck::bytes_of(&params));
        write(&spray.records.buffer, bytemuck::cast_slice(&records));
        let captured = plan.surfaces.iter().any(|s| s.captured);
        let acc = &plan.accumulate;
        let inputs = SpawnInputs {
            records: &self.records.buffer,
            capture: &self.capture.buffer,
            pool: &self.pool,
            winding: &self.winding.buffer,
            tiles: &self.tiles.buffer,
            count: if captured {
                acc.records.len() as u32
            } else {
                0
            },
            max_width: acc.max_width,
            max_height: acc.max_height,
        };
        spray.encode(device, enc, &inputs, queries);
    }

    /// The kicked-up snow's ring, for an engine's own drawing: [`crate::SPRAY_RING_HEADER`] bytes
    /// of counters, then `capacity` [`Particle`]s (dead ones with `life` 0), in world space after
    /// each update. `None` when the world has no spray ([`crate::WorldConfig::spray`]).
    pub fn spray_particles(&self) -> Option<&wgpu::Buffer> {
        self.spray.as_ref().map(|s| &s.ring)
    }

    /// Read the spray's counters and every particle back (waits for the GPU; for tests and tools).
    /// `None` when the world has no spray.
    pub fn read_spray(&self) -> Result<Option<(SprayCounters, Vec<Particle>)>> {
        self.spray
            .as_ref()
            .map(|s| s.read(&self.device, &self.queue))
            .transpose()
    }
}
