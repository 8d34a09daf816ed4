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
//! On GPUs, [`fused.wgsl`](FUSED_SHADER) does stages 1 and 2 in one pass. Every pass reads and
//! writes heights through `pool/texel.wgsl`, at the pool's [`Precision`] (an override constant).
//!
//! CPU reference: [`cpu`].

pub(crate) mod cpu;
mod encode;

pub use encode::{AccumulateBuffers, AccumulatePlan, encode};

use crate::gpu::resources::compute_storage;
use crate::pool::Precision;

/// Record layout shared by every pass.
pub const SHARED: &str = include_str!("../shared.wgsl");
/// Stage 1 (without the shared prelude).
pub const BLUR_SHADER: &str = include_str!("blur.wgsl");
/// Stage 2 (without the shared prelude).
pub const MERGE_SHADER: &str = include_str!("merge.wgsl");
/// Normals (without the shared prelude).
pub const NORMALS_SHADER: &str = include_str!("normals.wgsl");
/// Blur and merge in one pass (without the shared prelude).
pub const FUSED_SHADER: &str = include_str!("fused.wgsl");
/// The indirect arguments of the listed fused pass (without the shared prelude).
pub const SEAL_SHADER: &str = include_str!("seal.wgsl");
pub use crate::pool::TILE_LIST_HEADER;
/// The arithmetic shared by every stage.
pub const MATHS: &str = include_str!("maths.wgsl");
/// Reading the capture buffer (for the passes that bind it).
pub const CAPTURE_READ: &str = include_str!("capture_read.wgsl");
/// Reading heights from the pool at any precision.
pub const TEXEL_READ: &str = include_str!("../pool/texel.wgsl");
/// Writing heights to the pool at any precision.
pub const TEXEL_WRITE: &str = include_str!("../pool/texel_write.wgsl");

/// Workgroup side of the separate accumulation passes.
pub const WORKGROUP: u32 = 8;
/// Workgroup side of the fused pass: one of the pool's update tiles ([`crate::pool::TILE_SIDE`]).
pub const FUSED_WORKGROUP: u32 = crate::pool::TILE_SIDE;

/// The shader source of a stage with the shared prelude, as compiled.
pub fn with_prelude(stage: &str) -> String {
    let capture = if stage.contains("var<storage, read> capture") {
        CAPTURE_READ
    } else {
        ""
    };
    let pool = if stage.contains("var<storage, read_write> pool") {
        format!("{TEXEL_READ}\n{TEXEL_WRITE}")
    } else {
        String::new()
    };
    let channels = crate::pool::CHANNELS_WGSL;
    format!("{SHARED}\n{channels}\n{MATHS}\n{capture}\n{pool}\n{stage}")
}

/// The three compute pipelines and their layouts.
pub struct AccumulatePipelines {
    /// Stage 1.
    pub blur: wgpu::ComputePipeline,
    /// Stage 2.
    pub merge: wgpu::ComputePipeline,
    /// Normals.
    pub normals: wgpu::ComputePipeline,
    /// Blur and merge fused, over every tile of the records that refill snow.
    pub fused: wgpu::ComputePipeline,
    /// Blur and merge fused, over the capture's listed tiles of the records that do not.
    pub fused_listed: wgpu::ComputePipeline,
    /// Writes the listed pass's indirect dispatch.
    pub seal: wgpu::ComputePipeline,
    /// Layout of the seal's group 0: the tile list.
    pub seal_layout: wgpu::BindGroupLayout,
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
        let blur_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blur"),
            entries: &[
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, true),
                compute_storage(3, false),
            ],
        });
        let merge_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("merge"),
            entries: &[
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
            ],
        });
        let fused_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fused"),
            entries: &[
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, false),
                compute_storage(3, true),
                compute_storage(4, true),
                compute_storage(5, true),
            ],
        });
        let seal_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("seal"),
            entries: &[compute_storage(0, false)],
        });
        let normals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("normals"),
            entries: &[compute_storage(0, true), compute_storage(1, false)],
        });
        let constants = [("PRECISION", precision.bits() as f64)];
        let make = |name: &str, src: &str, layout: &wgpu::BindGroupLayout| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(with_prelude(src).into()),
            });
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(name),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(&pl),
                module: &module,
                entry_point: Some(name),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    // Every pass writes its workgroup arrays before reading them.
                    zero_initialize_workgroup_memory: false,
                },
                cache: None,
            })
        };
        Self {
            blur: make("blur", BLUR_SHADER, &blur_layout),
            merge: make("merge", MERGE_SHADER, &merge_layout),
            normals: make("normals", NORMALS_SHADER, &normals_layout),
            fused: make("fused", FUSED_SHADER, &fused_layout),
            fused_listed: make("fused_listed", FUSED_SHADER, &fused_layout),
            seal: make("seal_tiles", SEAL_SHADER, &seal_layout),
            seal_layout,
            blur_layout,
            merge_layout,
            normals_layout,
            fused_layout,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shader parses and validates with naga, so a broken shader fails `cargo test`.
    #[test]
    fn shaders_validate() {
        for (name, src) in [
            ("blur", with_prelude(BLUR_SHADER)),
            ("merge", with_prelude(MERGE_SHADER)),
            ("normals", with_prelude(NORMALS_SHADER)),
            ("fused", with_prelude(FUSED_SHADER)),
            ("seal", with_prelude(SEAL_SHADER)),
            ("capture", crate::capture::SHADER.to_owned()),
        ] {
            let module = naga::front::wgsl::parse_str(&src)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
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
        let src = with_prelude(MERGE_SHADER);
        let module = naga::front::wgsl::parse_str(&src).unwrap();
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
        ];
        for (i, (name, offset)) in names.iter().enumerate() {
            assert_eq!(name, expect[i]);
            assert_eq!(*offset as usize, i * 4);
        }
    }
}
