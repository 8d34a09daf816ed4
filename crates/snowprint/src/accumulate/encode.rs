//! Recording a frame's accumulation chain: the records of the surfaces updated
//! ([`AccumulatePlan`], built on the CPU by the world's frame plan) into one dispatch per stage.

use super::{AccumulatePipelines, FUSED_WORKGROUP, REFILL_CHUNK, WORKGROUP};
use crate::gpu::resources::{bind_group, dispatch_rows};
use crate::gpu::timestamps::StageQueries;
use crate::pool::SurfaceRecord;

/// What a frame's accumulation runs over and how.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AccumulatePlan {
    /// One record per updated surface, those that refill snow first.
    pub records: Vec<SurfaceRecord>,
    /// Blur and merge fused in one pass (else separate passes through the scratch buffer).
    pub fused: bool,
    /// Whether the pool keeps normals (a normals pass follows).
    pub normals: bool,
    /// With `fused`: the first `refill` records (those that refill snow, marked
    /// [`MODE_REFILLED`](crate::pool::MODE_REFILLED)) are replenished over their whole heights
    /// regions by one streaming dispatch before the fused pass (0: the fused pass refills).
    pub refill: u32,
    /// Largest heights region of the `refill` records, words.
    pub refill_words: u32,
    /// With `fused`: records after the first `grid` are updated only over the tiles the capture
    /// listed (a seal dispatch, then an indirect one).
    pub listed: bool,
    /// Records the fused pass's grid covers: all of them when not `listed`, else those it refills
    /// (none when the refill pass streams). The records it ray-casts itself
    /// ([`MODE_CAST`](crate::pool::MODE_CAST)) are not its.
    pub grid: u32,
    /// Entries at the head of the tile list that the plan wrote, the tiles of the records the
    /// fused pass ray-casts itself: one workgroup each of its dispatch over them.
    pub cast_tiles: u32,
    /// Whether they are many ([`crate::WorldConfig::cast_many_from`]): then each workgroup has
    /// 128 invocations rather than 256.
    pub cast_many: bool,
    /// Widest record, texels.
    pub max_width: u32,
    /// Tallest record, texels.
    pub max_height: u32,
    /// Texels the merge writes per invocation (two at 8 bits).
    pub unit_texels: u32,
}

impl AccumulatePlan {
    /// Empty it, keeping its memory.
    pub fn clear(&mut self) {
        self.records.clear();
        self.refill = 0;
        self.refill_words = 0;
        self.listed = false;
        self.grid = 0;
        self.cast_tiles = 0;
        self.cast_many = false;
        self.max_width = 0;
        self.max_height = 0;
    }
}

/// The buffers the accumulation binds, each in the layouts' binding order.
#[derive(Clone, Copy, Debug)]
pub struct AccumulateBuffers<'a> {
    /// [`SurfaceRecord`]s.
    pub records: &'a wgpu::Buffer,
    /// The capture (encoded depth per texel).
    pub capture: &'a wgpu::Buffer,
    /// Mesh winding per texel.
    pub winding: &'a wgpu::Buffer,
    /// Blurred captures (separate passes only).
    pub scratch: &'a wgpu::Buffer,
    /// The heightmap pool (updated in place).
    pub pool: &'a wgpu::Buffer,
    /// Tile flags written by the capture.
    pub tiles: &'a wgpu::Buffer,
    /// The capture's tile list with its indirect dispatch.
    pub tile_list: &'a wgpu::Buffer,
    /// The capture's analytic primitives, which the fused pass ray-casts for the records marked
    /// [`MODE_CAST`](crate::pool::MODE_CAST).
    pub prims: &'a wgpu::Buffer,
    /// The surfaces' ground fields (the capture's), read by that ray cast.
    pub ground: &'a wgpu::Buffer,
}

/// Record a frame's accumulation: fused (or blur then merge), then normals when kept; each a
/// compute pass with one dispatch over every record (`z` is the record).
pub fn encode(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &AccumulatePipelines,
    plan: &AccumulatePlan,
    b: &AccumulateBuffers<'_>,
    queries: &mut StageQueries<'_>,
) {
    encode_update(device, enc, pipes, plan, b, queries);
    encode_normals(device, enc, pipes, plan, b, queries);
}

/// The heights' part of [`encode`]: fused, or blur then merge.
pub fn encode_update(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &AccumulatePipelines,
    plan: &AccumulatePlan,
    b: &AccumulateBuffers<'_>,
    queries: &mut StageQueries<'_>,
) {
    let (max_w, max_h) = (plan.max_width, plan.max_height);
    let records = plan.records.len() as u32;
    if plan.fused {
        let fused_bg = bind_group(
            device,
            "fused",
            &pipes.fused_layout,
            &[
                b.records.as_entire_binding(),
                b.capture.as_entire_binding(),
                b.pool.as_entire_binding(),
                b.winding.as_entire_binding(),
                b.tiles.as_entire_binding(),
                b.tile_list.as_entire_binding(),
                b.prims.as_entire_binding(),
                b.ground.as_entire_binding(),
            ],
        );
        // The snow that fell, over whole regions, in a pass of its own (timed apart); then the
        // captures, over the tiles they reached.
        if plan.refill > 0 {
            let refill_bg = bind_group(
                device,
                "refill",
                &pipes.refill_layout,
                &[b.records.as_entire_binding(), b.pool.as_entire_binding()],
            );
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("refill"),
                timestamp_writes: queries.compute("refill"),
            });
            let (x, y) = refill_groups(plan.refill_words);
            pass.set_pipeline(&pipes.refill);
            pass.set_bind_group(0, &refill_bg, &[]);
            pass.dispatch_workgroups(x, y, plan.refill);
        }
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("fused"),
            timestamp_writes: queries.compute("fused"),
        });
        pass.set_bind_group(0, &fused_bg, &[]);
        if plan.grid > 0 {
            pass.set_pipeline(&pipes.fused);
            pass.dispatch_workgroups(
                max_w.div_ceil(FUSED_WORKGROUP),
                max_h.div_ceil(FUSED_WORKGROUP),
                plan.grid,
            );
        }
        if plan.cast_tiles > 0 {
            let (x, y) = dispatch_rows(plan.cast_tiles);
            pass.set_pipeline(pipes.fused_cast(device, plan.cast_many));
            pass.dispatch_workgroups(x, y, 1);
        }
        if plan.listed {
            let seal_bg = bind_group(
                device,
                "seal",
                &pipes.seal_layout,
                &[b.tile_list.as_entire_binding()],
            );
            pass.set_pipeline(&pipes.seal);
            pass.set_bind_group(0, &seal_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&pipes.fused_listed);
            pass.set_bind_group(0, &fused_bg, &[]);
            pass.dispatch_workgroups_indirect(b.tile_list, 0);
        }
    } else {
        let blur_bg = bind_group(
            device,
            "blur",
            &pipes.blur_layout,
            &[
                b.records.as_entire_binding(),
                b.capture.as_entire_binding(),
                b.winding.as_entire_binding(),
                b.scratch.as_entire_binding(),
            ],
        );
        let merge_bg = bind_group(
            device,
            "merge",
            &pipes.merge_layout,
            &[
                b.records.as_entire_binding(),
                b.scratch.as_entire_binding(),
                b.pool.as_entire_binding(),
            ],
        );
        let units_w = max_w.div_ceil(plan.unit_texels);
        for (stage, pipeline, bg, width) in [
            ("blur", &pipes.blur, &blur_bg, max_w),
            ("merge", &pipes.merge, &merge_bg, units_w),
        ] {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(stage),
                timestamp_writes: queries.compute(stage),
            });
            pass.set_bind_group(0, bg, &[]);
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(
                width.div_ceil(WORKGROUP),
                max_h.div_ceil(WORKGROUP),
                records,
            );
        }
    }
}

/// Workgroups of the refill over a region of `words`: [`REFILL_CHUNK`] words each (refill.wgsl),
/// in rows ([`dispatch_rows`]).
fn refill_groups(words: u32) -> (u32, u32) {
    dispatch_rows(words.div_ceil(REFILL_CHUNK).max(1))
}

/// The normals' part of [`encode`], when the pool keeps them: normals of every record's new top.
pub fn encode_normals(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &AccumulatePipelines,
    plan: &AccumulatePlan,
    b: &AccumulateBuffers<'_>,
    queries: &mut StageQueries<'_>,
) {
    let (max_w, max_h) = (plan.max_width, plan.max_height);
    let records = plan.records.len() as u32;
    if plan.normals {
        let normals_bg = bind_group(
            device,
            "normals",
            &pipes.normals_layout,
            &[b.records.as_entire_binding(), b.pool.as_entire_binding()],
        );
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("normals"),
            timestamp_writes: queries.compute("normals"),
        });
        pass.set_bind_group(0, &normals_bg, &[]);
        pass.set_pipeline(&pipes.normals);
        pass.dispatch_workgroups(
            max_w.div_ceil(WORKGROUP),
            max_h.div_ceil(WORKGROUP),
            records,
        );
    }
}
