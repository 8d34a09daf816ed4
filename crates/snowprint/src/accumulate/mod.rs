//! The accumulation chain of the talk, one WGSL pass per stage, each dispatched once per frame over
//! every surface updated in it (`z` of the dispatch is the surface's record):
//!
//! 1. [`blur.wgsl`](BLUR_SHADER): capture to depression, 4-tap bilinear Poisson blur
//!    (reads the capture buffer, writes the scratch buffer);
//! 2. [`merge.wgsl`](MERGE_SHADER): replenish each heightmap, then deepen it by the blurred
//!    capture, in place (reads the scratch and each slot's heights, writes the heights);
//! 3. [`normals.wgsl`](NORMALS_SHADER), only when the pool keeps normals: normals of the new snow
//!    top (reads the heights, writes the normals region).
//!
//! On GPUs, [`fused.wgsl`](FUSED_SHADER) does stages 1 and 2 in one pass; when many words of
//! heights refill snow, [`refill.wgsl`](REFILL_SHADER) streams their replenishment first and the
//! fused pass visits only the tiles the capture reached. Every pass reads and
//! writes heights through `pool/texel.wgsl`, at the pool's [`Precision`] (an override constant).
//!
//! CPU reference: [`cpu`].

pub(crate) mod cpu;
mod encode;

pub use encode::{AccumulateBuffers, AccumulatePlan, encode, encode_normals, encode_update};

use std::sync::OnceLock;

use crate::pool::Precision;

use crate::wgsl::ShaderModule;

pub use crate::pool::TILE_LIST_HEADER;

/// Workgroup side of the separate accumulation passes.
pub const WORKGROUP: u32 = crate::wgsl::consts::WORKGROUP;
/// Workgroup side of the fused pass: one of the pool's update tiles ([`crate::pool::TILE_SIDE`]).
pub const FUSED_WORKGROUP: u32 = crate::pool::TILE_SIDE;

/// Words of a heights region one workgroup of the refill takes (refill.wgsl).
pub const REFILL_CHUNK: u32 =
    crate::wgsl::consts::REFILL_GROUP * crate::wgsl::consts::REFILL_VECTORS * 4;

// The refill reads and writes 16-byte vectors from each slot's start to the end of its last one.
const _: () = assert!(crate::pool::SLOT_ALIGN.is_multiple_of(16));

/// The three compute pipelines and their layouts.
pub struct AccumulatePipelines {
    /// Stage 1.
    pub blur: wgpu::ComputePipeline,
    /// Stage 2.
    pub merge: wgpu::ComputePipeline,
    /// Normals.
    pub normals: wgpu::ComputePipeline,
    /// Replenishment of whole heights regions, before the fused pass.
    pub refill: wgpu::ComputePipeline,
    /// Blur and merge fused, over every tile of the first records (tiles with nothing to deepen or
    /// refill leave at once).
    pub fused: wgpu::ComputePipeline,
    /// Blur and merge fused, over the capture's listed tiles of the records the grid leaves.
    pub fused_listed: wgpu::ComputePipeline,
    /// The fused pass over the tiles of the records it ray-casts itself (`MODE_CAST`), which the
    /// plan lists at the head of the tile list, a workgroup of 256 invocations a tile, and the same
    /// over many tiles ([`AccumulatePlan::cast_many`]), 128 a tile: compiled when first wanted
    /// ([`Self::fused_cast`], [`Self::compile_casts`]), as a world on another capture path never
    /// casts.
    fused_cast: [OnceLock<wgpu::ComputePipeline>; 2],
    /// The heights' precision the passes were compiled for.
    precision: Precision,
    /// Writes the listed pass's indirect dispatch.
    pub seal: wgpu::ComputePipeline,
    /// Layout of the seal's group 0: the tile list.
    pub seal_layout: wgpu::BindGroupLayout,
    /// Layout of the refill's group 0: records, pool.
    pub refill_layout: wgpu::BindGroupLayout,
    /// Layout of the blur's group 0.
    pub blur_layout: wgpu::BindGroupLayout,
    /// Layout of the merge's group 0.
    pub merge_layout: wgpu::BindGroupLayout,
    /// Layout of the normals' group 0.
    pub normals_layout: wgpu::BindGroupLayout,
    /// Layout of the fused passes' group 0: records, capture, pool, winding, tile flags, tile list.
    pub fused_layout: wgpu::BindGroupLayout,
}

impl AccumulatePipelines {
    /// Compile the passes for heightmaps of `precision`.
    pub fn new(device: &wgpu::Device, precision: Precision) -> Self {
        use crate::wgsl::{BLUR, FUSED, MERGE, NORMALS, REFILL, SEAL};
        let blur_layout = BLUR.bind_group_layout(device, "blur", 0);
        let merge_layout = MERGE.bind_group_layout(device, "merge", 0);
        // One layout for the four fused entry points: the module's group 0 covers what either reads.
        let fused_layout = FUSED.bind_group_layout(device, "fused", 0);
        let seal_layout = SEAL.bind_group_layout(device, "seal", 0);
        let refill_layout = REFILL.bind_group_layout(device, "refill", 0);
        let normals_layout = NORMALS.bind_group_layout(device, "normals", 0);
        let make = |name: &str, shader: &ShaderModule, layout: &wgpu::BindGroupLayout| {
            pipeline(device, name, shader, layout, precision)
        };
        Self {
            blur: make("blur", &BLUR, &blur_layout),
            merge: make("merge", &MERGE, &merge_layout),
            normals: make("normals", &NORMALS, &normals_layout),
            refill: make("refill", &REFILL, &refill_layout),
            fused: make("fused", &FUSED, &fused_layout),
            fused_listed: make("fused_listed", &FUSED, &fused_layout),
            fused_cast: [OnceLock::new(), OnceLock::new()],
            precision,
            seal: make("seal_tiles", &SEAL, &seal_layout),
            seal_layout,
            refill_layout,
            blur_layout,
            merge_layout,
            normals_layout,
            fused_layout,
        }
    }

    /// The fused pass's entry point over the tiles it ray-casts, for many tiles or a few
    /// ([`AccumulatePlan::cast_many`]), compiled at its first call.
    pub fn fused_cast(&self, device: &wgpu::Device, many: bool) -> &wgpu::ComputePipeline {
        let name = if many {
            "fused_cast_many"
        } else {
            "fused_cast"
        };
        self.fused_cast[usize::from(many)].get_or_init(|| {
            pipeline(
                device,
                name,
                &crate::wgsl::FUSED,
                &self.fused_layout,
                self.precision,
            )
        })
    }

    /// Compile both of the fused pass's cast entry points now, rather than at the first frame
    /// that casts: for a world whose capture path casts ([`crate::CapturePath::Update`]).
    pub fn compile_casts(&self, device: &wgpu::Device) {
        for many in [false, true] {
            self.fused_cast(device, many);
        }
    }
}

/// The compute pipeline of entry point `name` of `shader`, its group 0 laid out as `layout`, for
/// heights of `precision`.
fn pipeline(
    device: &wgpu::Device,
    name: &str,
    shader: &ShaderModule,
    layout: &wgpu::BindGroupLayout,
    precision: Precision,
) -> wgpu::ComputePipeline {
    let [p] = shader.compute_pipelines(
        device,
        [name],
        layout,
        &[("PRECISION", precision.bits() as f64)],
    );
    p
}

#[cfg(test)]
mod tests {
    /// Every shader parses and validates with naga, so a broken shader fails `cargo test` (build.rs
    /// already fails the build on one: see `crate::wgsl`).
    #[test]
    fn shaders_validate() {
        for (name, shader) in [
            ("blur", &crate::wgsl::BLUR),
            ("merge", &crate::wgsl::MERGE),
            ("normals", &crate::wgsl::NORMALS),
            ("refill", &crate::wgsl::REFILL),
            ("fused", &crate::wgsl::FUSED),
            ("seal", &crate::wgsl::SEAL),
            ("capture", &crate::wgsl::CAPTURE),
        ] {
            let src = shader.source;
            let module = naga::front::wgsl::parse_str(src)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        }
    }

    /// The Rust record and the WGSL record have the same size and field offsets.
    #[test]
    fn record_layout_matches_wgsl() {
        let module = naga::front::wgsl::parse_str(crate::wgsl::MERGE.source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("SurfaceRecord"))
            .unwrap();
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!()
        };
        assert_eq!(
            layouter[handle].size as usize,
            std::mem::size_of::<crate::pool::SurfaceRecord>()
        );
        let names: Vec<_> = members
            .iter()
            .map(|m| (m.name.clone().unwrap(), m.offset))
            .collect();
        let expect = [
            "heights",
            "normals",
            "scratch",
            "width",
            "height",
            "atlas_x",
            "atlas_y",
            "mode",
            "replenish_units",
            "batch",
            "mask_fraction",
            "snow_depth",
            "frustum_height",
            "texel_x",
            "texel_z",
            "tiles",
            "wrap",
            "half_x",
            "half_z",
            "prims",
            "prim_count",
            "ground",
        ];
        assert_eq!(names.len(), expect.len());
        for (i, (name, offset)) in names.iter().enumerate() {
            assert_eq!(name, expect[i]);
            assert_eq!(*offset as usize, i * 4);
        }
    }
}
