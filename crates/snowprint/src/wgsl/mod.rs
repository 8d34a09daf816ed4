//! The shader registry: every WGSL module a pipeline compiles, composed, validated and reflected
//! at build time from one table (`src/wgsl/table.rs`).
//!
//! A WGSL file imports another module by name with a line `// import name`; `build.rs` puts each
//! entry module's imports (once each, recursively) before its own text, validates the result with
//! naga (a broken shader fails `cargo build` with the module and the file and line of the error),
//! and reflects its bindings: group, binding, the stages of the entry points that use it, and the
//! binding's type. [`ShaderModule::layout_entries`] turns them into bind-group layout entries, from
//! which every pipeline's layouts are made (a binding is declared once, in WGSL); what naga cannot
//! know (whether a float texture or a sampler filters, dynamic offsets) comes from
//! [`OVERRIDES`]. The constants that Rust and WGSL share are defined once, in
//! `src/wgsl/constants.wgsl`, and reflected into [`consts`]. An engine's own shaders import the
//! pool and the material through [`engine_module`] and [`material_module`] (prefixed names, the
//! pool at a binding of the importer's choice).
//!
//! The resolver is a few lines of `build.rs`, not the `wesl` crate (what Bevy's `bevy_shader`
//! uses): `wesl` 0.4.0 (the last release that builds with rustc 1.95; 0.4.4 needs 1.97.1) adds about
//! four CPU-minutes to a clean build here, against half a minute for the naga that validation needs
//! anyway, and WESL scopes each module: `pool/texel.wgsl` and `accumulate/capture_read.wgsl` read
//! buffers that their importer declares (`pool` read-only in the renderer, read-write in the update,
//! at different bindings), which WESL does not allow (0.4.0 left `pool` unresolved and dropped a
//! transitive `channel_max` without an error). Moving to WESL later means turning each `// import a`
//! into `import package::a::{...};` and passing those buffers as pointers.

/// How a binding is bound, as reflected from the module.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// A uniform buffer.
    Uniform,
    /// A storage buffer.
    Storage {
        /// Bound `read` (else `read_write`).
        read_only: bool,
    },
    /// A sampled texture.
    Texture {
        /// What the texture's texels are.
        sample: TextureSample,
        /// The view's dimension.
        dimension: wgpu::TextureViewDimension,
        /// Multisampled.
        multisampled: bool,
    },
    /// A storage texture.
    StorageTexture {
        /// Read, write or both.
        access: wgpu::StorageTextureAccess,
        /// Texel format.
        format: wgpu::TextureFormat,
        /// The view's dimension.
        dimension: wgpu::TextureViewDimension,
    },
    /// A sampler.
    Sampler {
        /// A comparison sampler.
        comparison: bool,
    },
}

/// The texels of a sampled texture, as WGSL declares them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureSample {
    /// `texture_*<f32>` (filterable unless [`OVERRIDES`] says not).
    Float,
    /// `texture_depth_*`.
    Depth,
    /// `texture_*<i32>`.
    Sint,
    /// `texture_*<u32>`.
    Uint,
}

/// One binding of a module, reflected by build.rs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    /// `@group`.
    pub group: u32,
    /// `@binding`.
    pub binding: u32,
    /// The variable's name in WGSL.
    pub name: &'static str,
    /// Bits of the stages whose entry points use it: 1 vertex, 2 fragment, 4 compute (as
    /// [`wgpu::ShaderStages`]).
    pub stages: u32,
    /// Bit `i` set when entry point `i` of the module ([`ShaderModule::entry_points`]) uses it.
    pub entry_points: u64,
    /// How it is bound.
    pub kind: BindingKind,
}

/// An entry point of a module.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EntryPoint {
    /// Its WGSL name.
    pub name: &'static str,
    /// Its stage, as [`wgpu::ShaderStages`] bits.
    pub stages: u32,
}

/// What reflection cannot tell about a binding, by (module, variable name).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Override {
    /// A float texture that is not filterable, or a sampler that does not filter.
    NotFiltering,
    /// A float texture or sampler that filters where the device can filter `Rgba16Float` (the
    /// heightfield textures), else not.
    FilterableIfSupported,
    /// A buffer bound with a dynamic offset.
    DynamicOffset,
    /// Visible to these stages (bits as [`wgpu::ShaderStages`]) instead of the reflected ones,
    /// where a layout is shared by modules whose entry points use different stages.
    Stages(u32),
}

/// The one table of what reflection cannot know, by module (`"*"`: every module that has the
/// binding) and binding name.
pub const OVERRIDES: &[(&str, &str, Override)] = &[
    // One capture view and one mesh draw per surface, in uniform blocks.
    ("capture", "view", Override::DynamicOffset),
    ("capture", "draw", Override::DynamicOffset),
    // frame.wgsl's group 0 is one layout shared by every pass of the renderer.
    // (Compute too: the tonemap and the visibility buffer's shading are compute passes.)
    ("*", "frame", Override::Stages(ALL_STAGES)),
    ("*", "shadow_map", Override::Stages(FRAGMENT_COMPUTE)),
    ("*", "shadow_sampler", Override::Stages(FRAGMENT_COMPUTE)),
    ("*", "linear_sampler", Override::Stages(FRAGMENT_COMPUTE)),
    ("*", "linear_sampler", Override::FilterableIfSupported),
    // The snow passes' heightfield textures (Rgba16Float), filtered where the device can.
    ("surface", "heightfield", Override::FilterableIfSupported),
    // (Compute too: the visibility path shades the deformable material in `shade_deformable`.)
    ("surface", "heightfield", Override::Stages(FRAGMENT_COMPUTE)),
    (
        "surface",
        "heightfield_light",
        Override::FilterableIfSupported,
    ),
    ("surface", "heightfield_light", Override::Stages(FRAGMENT)),
    // Bank heights, read with textureLoad (bilinear by hand, as in the tessellated tier).
    ("surface", "bank_texture", Override::NotFiltering),
    // The tessellated tier shares the snow pass's bindings with both stages, and with compute
    // (its `shade_tess`, and `surface.wgsl`'s `shade_deformable`, which comes with the import).
    ("tess_surface", "surface", Override::Stages(ALL_STAGES)),
    (
        "tess_surface",
        "heightfield",
        Override::FilterableIfSupported,
    ),
    ("tess_surface", "heightfield", Override::Stages(ALL_STAGES)),
    (
        "tess_surface",
        "heightfield_light",
        Override::FilterableIfSupported,
    ),
    (
        "tess_surface",
        "heightfield_light",
        Override::Stages(VERTEX_FRAGMENT),
    ),
    ("tess_surface", "bank_texture", Override::NotFiltering),
    ("tess_surface", "bank_texture", Override::Stages(ALL_STAGES)),
    (
        "tess_surface",
        "surface_state",
        Override::Stages(ALL_STAGES),
    ),
    // Read with textureLoad only.
    ("tonemap", "scene_color", Override::NotFiltering),
    ("tonemap_compute", "scene_color", Override::NotFiltering),
    ("banks", "shape", Override::NotFiltering),
    ("banks", "light", Override::NotFiltering),
    ("banks", "scratch_in", Override::NotFiltering),
    ("dice", "shape", Override::NotFiltering),
    ("dice", "banks", Override::NotFiltering),
];

const FRAGMENT: u32 = wgpu::ShaderStages::FRAGMENT.bits();
const VERTEX_FRAGMENT: u32 = wgpu::ShaderStages::VERTEX_FRAGMENT.bits();
const ALL_STAGES: u32 = wgpu::ShaderStages::VERTEX_FRAGMENT
    .union(wgpu::ShaderStages::COMPUTE)
    .bits();
const FRAGMENT_COMPUTE: u32 = wgpu::ShaderStages::FRAGMENT
    .union(wgpu::ShaderStages::COMPUTE)
    .bits();

/// An entry module of the registry.
#[derive(Clone, Copy, Debug)]
pub struct ShaderModule {
    /// Its name in `src/wgsl/table.rs`.
    pub name: &'static str,
    /// The composed WGSL, as validated.
    pub source: &'static str,
    /// Its entry points, in declaration order.
    pub entry_points: &'static [EntryPoint],
    /// Its bindings, by group then binding.
    pub bindings: &'static [Binding],
}

impl ShaderModule {
    /// The composed source, for `wgpu::ShaderSource::Wgsl` (owned, as the render code takes it).
    pub fn wgsl(&self) -> String {
        self.source.to_owned()
    }

    /// The overrides of binding `name`.
    fn overrides(&self, name: &str) -> Vec<Override> {
        OVERRIDES
            .iter()
            .filter(|(m, n, _)| (*m == self.name || *m == "*") && *n == name)
            .map(|(_, _, o)| *o)
            .collect()
    }

    /// Bind-group layout entries of group `group`, from the reflected bindings and [`OVERRIDES`],
    /// on a device that filters `Rgba16Float`.
    pub fn layout_entries(&self, group: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
        self.layout_entries_for(group, true)
    }

    /// [`Self::layout_entries`] on a device that filters `Rgba16Float` or not
    /// (`GpuCaps::filterable_rgba16f`).
    pub fn layout_entries_for(
        &self,
        group: u32,
        filterable_rgba16f: bool,
    ) -> Vec<wgpu::BindGroupLayoutEntry> {
        self.bindings
            .iter()
            .filter(|b| b.group == group)
            .map(|b| {
                let stages = self
                    .overrides(b.name)
                    .iter()
                    .find_map(|o| match o {
                        Override::Stages(s) => Some(*s),
                        _ => None,
                    })
                    .unwrap_or(b.stages);
                self.layout_entry(b, stages, filterable_rgba16f)
            })
            .collect()
    }

    /// The bind-group layout of group `group` ([`Self::layout_entries`]), labelled `label`.
    pub(crate) fn bind_group_layout(
        &self,
        device: &wgpu::Device,
        label: &str,
        group: u32,
    ) -> wgpu::BindGroupLayout {
        self.bind_group_layout_for(device, label, group, true)
    }

    /// The compute pipelines of entry points `entries`, of one module, their one bind group laid
    /// out as `layout`, with the override `constants`, each labelled by its entry point; workgroup
    /// memory is not zeroed (each pass writes its workgroup arrays before reading them).
    pub(crate) fn compute_pipelines<const N: usize>(
        &self,
        device: &wgpu::Device,
        entries: [&str; N],
        layout: &wgpu::BindGroupLayout,
        constants: &[(&str, f64)],
    ) -> [wgpu::ComputePipeline; N] {
        let label = entries.first().copied();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label,
            source: wgpu::ShaderSource::Wgsl(self.source.into()),
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label,
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
        entries.map(|entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pl),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    zero_initialize_workgroup_memory: false,
                },
                cache: None,
            })
        })
    }

    /// The bind-group layout of group `group` on a device that filters `Rgba16Float` or not
    /// ([`Self::layout_entries_for`]), labelled `label`.
    pub(crate) fn bind_group_layout_for(
        &self,
        device: &wgpu::Device,
        label: &str,
        group: u32,
        filterable_rgba16f: bool,
    ) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &self.layout_entries_for(group, filterable_rgba16f),
        })
    }

    /// The layout entries of group `group` that only the named entry points need, visible to their
    /// stages (e.g. the shadow pass's group 0, which `vs_shadow` reads alone). [`OVERRIDES`]
    /// apply, except their stages.
    pub fn layout_entries_of(
        &self,
        entry_points: &[&str],
        group: u32,
        filterable_rgba16f: bool,
    ) -> Vec<wgpu::BindGroupLayoutEntry> {
        let chosen: Vec<_> = self
            .entry_points
            .iter()
            .enumerate()
            .filter(|(_, ep)| entry_points.contains(&ep.name))
            .collect();
        self.bindings
            .iter()
            .filter(|b| b.group == group)
            .filter_map(|b| {
                let stages = chosen
                    .iter()
                    .filter(|(i, _)| b.entry_points & (1 << i) != 0)
                    .fold(0, |s, (_, ep)| s | ep.stages);
                (stages != 0).then(|| self.layout_entry(b, stages, filterable_rgba16f))
            })
            .collect()
    }

    /// The layout entry of binding `b`, visible to `stages`.
    fn layout_entry(
        &self,
        b: &Binding,
        stages: u32,
        filterable_rgba16f: bool,
    ) -> wgpu::BindGroupLayoutEntry {
        let overrides = self.overrides(b.name);
        let filtering = !overrides.contains(&Override::NotFiltering)
            && (filterable_rgba16f || !overrides.contains(&Override::FilterableIfSupported));
        let dynamic = overrides.contains(&Override::DynamicOffset);
        let ty = match b.kind {
            BindingKind::Uniform => wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            BindingKind::Storage { read_only } => wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            BindingKind::Texture {
                sample,
                dimension,
                multisampled,
            } => wgpu::BindingType::Texture {
                sample_type: match sample {
                    TextureSample::Float => wgpu::TextureSampleType::Float {
                        filterable: filtering,
                    },
                    TextureSample::Depth => wgpu::TextureSampleType::Depth,
                    TextureSample::Sint => wgpu::TextureSampleType::Sint,
                    TextureSample::Uint => wgpu::TextureSampleType::Uint,
                },
                view_dimension: dimension,
                multisampled,
            },
            BindingKind::StorageTexture {
                access,
                format,
                dimension,
            } => wgpu::BindingType::StorageTexture {
                access,
                format,
                view_dimension: dimension,
            },
            BindingKind::Sampler { comparison: true } => {
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison)
            }
            BindingKind::Sampler { comparison: false } if filtering => {
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)
            }
            BindingKind::Sampler { comparison: false } => {
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering)
            }
        };
        wgpu::BindGroupLayoutEntry {
            binding: b.binding,
            visibility: wgpu::ShaderStages::from_bits_truncate(stages),
            ty,
            count: None,
        }
    }
}

include!(concat!(env!("OUT_DIR"), "/wgsl_registry.rs"));

mod engine;
pub use engine::{ImportOptions, engine_module, material_module};

/// Every entry module, by name (for tests and tools).
pub fn all() -> &'static [&'static ShaderModule] {
    ALL
}

/// The entry module called `name`.
pub fn get(name: &str) -> Option<&'static ShaderModule> {
    ALL.iter().copied().find(|m| m.name == name)
}

#[cfg(test)]
mod tests;
