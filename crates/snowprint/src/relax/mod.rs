//! The relaxation pass: surfaces of a material with an angle of repose slump back toward it after
//! the accumulation (`relax.wgsl`; CPU reference [`cpu`]; the rule in [`crate::Material`]).
//!
//! The world's frame plan lists the surfaces that relax this update ([`RelaxPlan`]); the pass runs
//! after the fused (or merge) pass and before the normals, so that kept normals see the slumped
//! top. A dispatch takes up to [`RELAX_HALO`](crate::wgsl::consts::RELAX_HALO) steps over every
//! listed surface (`z` is the record) in workgroup memory, each workgroup a tile and a halo as
//! wide as its steps; dispatches alternate between the pool and a scratch buffer, and a copy ends
//! an odd number of them in the pool ([`RelaxPlan::schedule`]).
//!
//! Why: one dispatch a step read five texels from the pool a texel a step, and on the talk's frame
//! each step's dispatch and barrier cost more than its texels. A tile's steps in workgroup memory
//! read the pool once, a tile where a step moves nothing stops stepping, and a tile that stood
//! still with its neighbours in the dispatch from the pool is skipped by the one back to it (tile
//! flags, `RelaxBuffers::tiles`): a settled surface costs one dispatch, not two.

pub(crate) mod cpu;

use crate::gpu::resources::bind_group;
use crate::gpu::timestamps::StageQueries;
use crate::pool::Precision;

/// One relaxing surface, as `RelaxRecord` in relax.wgsl (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RelaxRecord {
    /// Word offset of the heights region in the pool.
    pub heights: u32,
    /// Heightmap texels along local x and z.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// First u32 of the surface's depressions in the scratch buffer.
    pub scratch: u32,
    /// Largest top difference between x neighbours that stands, channel units.
    pub threshold_x: u32,
    /// The same between z neighbours.
    pub threshold_z: u32,
    /// The rectangle that relaxes (`relax::Rect`): first column, first row, columns, rows.
    pub rect: [u32; 4],
    /// Steps each relaxing dispatch takes ([`RelaxPlan::schedule`]).
    pub dispatch_steps: u32,
    /// First word of the surface's tile flags ([`RelaxPlan::tile_words`]).
    pub tiles: u32,
    /// Toroidal storage offsets (`pool::wrapped`).
    pub wrap: u32,
}

/// Where a surface of a slumping material may still move, kept by the world between updates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Settle {
    /// Updates it still relaxes for after the last that pressed it.
    pub updates: u32,
    /// Texels that may be unsettled (empty once it has settled).
    pub rect: Rect,
}

/// A rectangle of texels: first column and row, one past the last column and row.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Rect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Rect {
    /// Whether it holds no texel.
    pub fn is_empty(&self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    /// The smallest rectangle holding both (an empty one holds nothing).
    pub fn union(self, other: Rect) -> Rect {
        match (self.is_empty(), other.is_empty()) {
            (true, _) => other,
            (_, true) => self,
            _ => Rect {
                x0: self.x0.min(other.x0),
                y0: self.y0.min(other.y0),
                x1: self.x1.max(other.x1),
                y1: self.y1.max(other.y1),
            },
        }
    }

    /// Grown by `n` texels on every side, within a `width` x `height` heightmap.
    pub fn grown(self, n: u32, width: u32, height: u32) -> Rect {
        if self.is_empty() {
            return self;
        }
        Rect {
            x0: self.x0.saturating_sub(n),
            y0: self.y0.saturating_sub(n),
            x1: self.x1.saturating_add(n).min(width),
            y1: self.y1.saturating_add(n).min(height),
        }
    }

    /// Columns and rows.
    pub fn size(&self) -> (u32, u32) {
        if self.is_empty() {
            (0, 0)
        } else {
            (self.x1 - self.x0, self.y1 - self.y0)
        }
    }
}

/// What the relaxation runs over in one update.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RelaxPlan {
    /// The relaxing surfaces.
    pub records: Vec<RelaxRecord>,
    /// Steps this update (even; the most any listed material asks for).
    pub steps: u32,
    /// u32 words of scratch (every listed surface's texels).
    pub scratch_words: u32,
    /// u32 words of tile flags: a word for each `RELAX_TILE`-square tile of every listed
    /// surface's rectangle (whether the tile stood still in the last dispatch from the pool).
    pub tile_words: u32,
    /// Largest width and height of the listed surfaces (the dispatch grid).
    pub max_width: u32,
    /// See `max_width`.
    pub max_height: u32,
    /// Relaxing dispatches ([`RelaxPlan::schedule`]), each of `dispatch_steps` steps.
    pub dispatches: u32,
    /// See `dispatches`.
    pub dispatch_steps: u32,
}

/// How `steps` relaxation steps split into dispatches: `(dispatches, steps each)`, the fewest
/// dispatches of at most `halo` steps that take exactly `steps` in all (equal shares, so that one
/// number a record says how many).
pub fn split_steps(steps: u32, halo: u32) -> (u32, u32) {
    if steps == 0 {
        return (0, 0);
    }
    let fewest = steps.div_ceil(halo.max(1));
    let n = (fewest..=steps)
        .find(|n| steps.is_multiple_of(*n))
        .unwrap_or(steps);
    (n, steps / n)
}

impl RelaxPlan {
    /// List no surface.
    pub fn clear(&mut self) {
        *self = Self {
            records: std::mem::take(&mut self.records),
            ..Self::default()
        };
        self.records.clear();
    }

    /// List a surface that relaxes `steps` steps this update over its record's rectangle, in a
    /// pool of `unit`-texel units.
    pub fn push(&mut self, mut record: RelaxRecord, steps: u32, unit: u32) {
        let [x0, _, w, h] = record.rect;
        record.scratch = self.scratch_words;
        self.scratch_words += w * h;
        // Tiles start on a unit, as `tile_grid` in relax.wgsl counts them.
        let tile = crate::wgsl::consts::RELAX_TILE;
        record.tiles = self.tile_words;
        self.tile_words += (x0 % unit.max(1) + w).div_ceil(tile) * h.div_ceil(tile);
        // The grid covers the rectangle's texels, and at 8 bits one unit more.
        self.max_width = self.max_width.max(w + 1);
        self.max_height = self.max_height.max(h);
        self.steps = self.steps.max(steps);
        self.records.push(record);
    }

    /// Split the plan's steps into dispatches (`split_steps`) and tell every record (call once
    /// every surface is listed).
    pub fn schedule(&mut self) {
        let (n, k) = split_steps(self.steps, crate::wgsl::consts::RELAX_HALO);
        self.dispatches = n;
        self.dispatch_steps = k;
        for r in &mut self.records {
            r.dispatch_steps = k;
        }
    }

    /// Whether nothing relaxes.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty() || self.steps == 0
    }
}

/// The three entry points and their layout.
pub struct RelaxPipelines {
    from_pool: wgpu::ComputePipeline,
    to_pool: wgpu::ComputePipeline,
    copy: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl RelaxPipelines {
    /// Compile the pass for heightmaps of `precision`.
    pub fn new(device: &wgpu::Device, precision: Precision) -> Self {
        let shader = &crate::wgsl::RELAX;
        let layout = shader.bind_group_layout(device, "relax", 0);
        let constants = [("PRECISION", precision.bits() as f64)];
        let [from_pool, to_pool, copy] = shader.compute_pipelines(
            device,
            ["relax_from_pool", "relax_to_pool", "relax_copy"],
            &layout,
            &constants,
        );
        Self {
            from_pool,
            to_pool,
            copy,
            layout,
        }
    }
}

/// What a world keeps for the pass: its pipelines, and the records and scratch it grows.
pub(crate) struct RelaxGpu {
    pub(crate) pipes: RelaxPipelines,
    pub(crate) records: crate::gpu::resources::Growable,
    pub(crate) scratch: crate::gpu::resources::Growable,
    pub(crate) tiles: crate::gpu::resources::Growable,
}

impl RelaxGpu {
    pub(crate) fn new(device: &wgpu::Device, precision: Precision) -> Self {
        use crate::gpu::resources::Growable;
        use wgpu::BufferUsages as U;
        Self {
            pipes: RelaxPipelines::new(device, precision),
            records: Growable::new(device, "relax records", U::STORAGE | U::COPY_DST, 32 * 16),
            scratch: Growable::new(device, "relax scratch", U::STORAGE, 4 * 4096),
            tiles: Growable::new(device, "relax tiles", U::STORAGE, 4 * 256),
        }
    }
}

/// The buffers the pass binds.
pub struct RelaxBuffers<'a> {
    /// The plan's records.
    pub records: &'a wgpu::Buffer,
    /// The heightmap pool.
    pub pool: &'a wgpu::Buffer,
    /// At least `plan.scratch_words` u32.
    pub scratch: &'a wgpu::Buffer,
    /// At least `plan.tile_words` u32 (written before they are read: no clearing).
    pub tiles: &'a wgpu::Buffer,
}

/// Record the plan's steps: one compute pass, [`RelaxPlan::dispatches`] dispatches alternating
/// from the pool to the scratch and back, and a copy back to the pool after an odd number.
pub fn encode(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipes: &RelaxPipelines,
    plan: &RelaxPlan,
    b: &RelaxBuffers<'_>,
    queries: &mut StageQueries<'_>,
) {
    if plan.is_empty() {
        return;
    }
    let bg = bind_group(
        device,
        "relax",
        &pipes.layout,
        &[
            b.records.as_entire_binding(),
            b.pool.as_entire_binding(),
            b.scratch.as_entire_binding(),
            b.tiles.as_entire_binding(),
        ],
    );
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("relax"),
        timestamp_writes: queries.compute("relax"),
    });
    pass.set_bind_group(0, &bg, &[]);
    let tile = crate::wgsl::consts::RELAX_TILE;
    // A tile's columns start on a unit (two texels at 8 bits): the grid covers one more column.
    let (gx, gy, gz) = (
        plan.max_width.div_ceil(tile),
        plan.max_height.div_ceil(tile),
        plan.records.len() as u32,
    );
    for k in 0..plan.dispatches {
        pass.set_pipeline(if k % 2 == 0 {
            &pipes.from_pool
        } else {
            &pipes.to_pool
        });
        pass.dispatch_workgroups(gx, gy, gz);
    }
    if plan.dispatches % 2 == 1 {
        pass.set_pipeline(&pipes.copy);
        pass.dispatch_workgroups(gx, gy, gz);
    }
}

#[cfg(test)]
mod tests {
    use super::split_steps;

    /// Steps split into the fewest dispatches of at most the halo, equal shares, all taken.
    #[test]
    fn steps_split_into_equal_dispatches() {
        assert_eq!(split_steps(0, 4), (0, 0));
        assert_eq!(split_steps(2, 4), (1, 2));
        assert_eq!(split_steps(8, 4), (2, 4));
        assert_eq!(split_steps(6, 4), (2, 3));
        assert_eq!(split_steps(10, 4), (5, 2));
        assert_eq!(split_steps(64, 4), (16, 4));
        for steps in (2..=64).step_by(2) {
            let (n, k) = split_steps(steps, 4);
            assert_eq!(
                n,
                (1..=steps)
                    .find(|n| steps % n == 0 && steps / n <= 4)
                    .unwrap()
            );
            assert_eq!(n * k, steps);
            // Even steps always split into twos at worst.
            assert!((2..=4).contains(&k), "{steps}: {k} a dispatch");
        }
    }

    /// `RelaxRecord` here and in relax.wgsl: same fields in order, 4 bytes each, 48 bytes.
    #[test]
    fn record_layout_matches_wgsl() {
        let module = naga::front::wgsl::parse_str(crate::wgsl::RELAX.source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("RelaxRecord"))
            .unwrap();
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("RelaxRecord is not a struct")
        };
        assert_eq!(
            layouter[handle].size as usize,
            std::mem::size_of::<super::RelaxRecord>()
        );
        for (i, m) in members.iter().enumerate() {
            assert_eq!(m.offset as usize, i * 4, "{:?}", m.name);
        }
    }
}
