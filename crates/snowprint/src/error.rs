//! Typed errors of the library: one variant per cause, each carrying the value that was wrong.

use std::path::PathBuf;

/// Everything the library can report instead of panicking.
///
/// Variants that come from wgpu, I/O or an encoder keep that error as their
/// [`source`](std::error::Error::source); new variants may be added in any release, so a `match`
/// needs a `_` arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SnowError {
    /// No GPU adapter could be found at all.
    #[error(
        "no GPU adapter was found: install a Vulkan driver (on Debian or Ubuntu: `apt-get install mesa-vulkan-drivers` for the software one)"
    )]
    NoAdapter,
    /// An adapter was requested by name and none matched.
    #[error("no GPU adapter matches {requested:?}; the adapters found are: {available}")]
    AdapterNotFound {
        /// The name asked for (by `--adapter` or `SNOWPRINT_ADAPTER`).
        requested: String,
        /// Names of the adapters that exist, comma separated.
        available: String,
    },
    /// The adapter lacks a capability the passes need.
    #[error(
        "GPU adapter {adapter} lacks {missing}, which snowprint's capture and compute passes need; pick another adapter with --adapter, or install a Vulkan driver (on Debian or Ubuntu: `apt-get install mesa-vulkan-drivers`)"
    )]
    AdapterUnsupported {
        /// The adapter, described.
        adapter: String,
        /// The missing capabilities.
        missing: String,
    },
    /// The device could not be created.
    #[error("the GPU device could not be created on {adapter}: {source}")]
    RequestDevice {
        /// The adapter's name.
        adapter: String,
        /// The underlying wgpu error.
        source: wgpu::RequestDeviceError,
    },
    /// A caller's device was created with a limit below what snowprint's passes need.
    #[error(
        "the GPU device's limit {limit} is {available}, but snowprint needs {required}: create the device with `snowprint::required_limits()` (or limits at least as good, e.g. `required_limits().using_resolution(adapter.limits())`)"
    )]
    DeviceLimit {
        /// The `wgpu::Limits` field.
        limit: &'static str,
        /// What snowprint needs ([`crate::required_limits`]).
        required: u64,
        /// What the device was created with.
        available: u64,
    },
    /// A caller's device was created without a feature snowprint's passes need.
    #[error(
        "the GPU device lacks the features {missing}: create it with `snowprint::required_features()` among its required features"
    )]
    DeviceFeature {
        /// The missing `wgpu::Features`, printed.
        missing: String,
    },
    /// A frame was encoded and not yet reported submitted: the per-frame tables it uploaded are
    /// still in use.
    #[error(
        "a snow frame was encoded and not reported submitted: call SnowWorld::submitted with its PendingFrame after queue.submit (or SnowWorld::abandon_pending if its encoder was dropped) before encoding another"
    )]
    FramePending,
    /// The frame's update needs a per-frame buffer larger than the device can bind.
    #[error(
        "this frame's update needs {bytes} bytes of {buffer} ({surfaces} surfaces updated), but this device binds at most {max} bytes: update fewer or smaller surfaces a frame (SnowWorld::encode_update with part of them, or a SnowManager's update budget)"
    )]
    FrameTooLarge {
        /// Which per-frame buffer.
        buffer: &'static str,
        /// Bytes it would need.
        bytes: u64,
        /// The device's largest storage binding, bytes.
        max: u64,
        /// Surfaces in the update.
        surfaces: usize,
    },
    /// A surface description is not usable.
    #[error("surface {name:?}: {what} is {value}, but it must be {expected}")]
    InvalidSurface {
        /// Name of the surface.
        name: String,
        /// Which field.
        what: &'static str,
        /// The offending value, printed.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A terrain window's description or focus is not usable (`crate::Terrain`).
    #[error("terrain {name:?}: {what} is {value}, but it must be {expected}")]
    InvalidTerrain {
        /// Name of the terrain.
        name: String,
        /// Which field (a level's names its index).
        what: String,
        /// The offending value, printed.
        value: String,
        /// What would be accepted.
        expected: String,
    },
    /// A window level was moved while a frame was encoded and not yet reported submitted.
    #[error(
        "terrain {name:?} cannot scroll while a snow frame is encoded and not reported submitted: call SnowWorld::submitted first"
    )]
    WindowBusy {
        /// Name of the terrain.
        name: String,
    },
    /// A deformer description is not usable.
    #[error("deformer {name:?}: {what} is {value}, but it must be {expected}")]
    InvalidDeformer {
        /// Name of the deformer.
        name: String,
        /// Which field.
        what: &'static str,
        /// The offending value, printed.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A mesh is not usable as a deformer.
    #[error("mesh {name:?}: {reason}")]
    InvalidMesh {
        /// Name or path of the mesh.
        name: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A surface's ground (heights, mesh or slope rule) is not usable.
    #[error("surface {name:?}: {reason}")]
    InvalidGround {
        /// Name of the surface.
        name: String,
        /// What is wrong, with the value and what to do.
        reason: String,
    },
    /// A mesh file could not be read.
    #[error("mesh file {}: {reason}", path.display())]
    MeshFile {
        /// The file.
        path: PathBuf,
        /// Why it could not be used.
        reason: String,
        /// The I/O error, when the file or its folder could not be opened or read.
        #[source]
        source: Option<std::io::Error>,
    },
    /// A mesh file names a buffer or image it may not read: outside the folder it may read from,
    /// an absolute path, a URI with a scheme other than `data:`, or a malformed `data:` URI.
    #[error("mesh file {}: {what} has uri {uri:?}, which {problem}; {fix}", path.display())]
    MeshUri {
        /// The mesh file.
        path: PathBuf,
        /// Which reference (`buffer 0`, `image 2`).
        what: String,
        /// The URI as written (shortened when long).
        uri: String,
        /// What is wrong with it.
        problem: String,
        /// What to do.
        fix: String,
    },
    /// A handle does not name a live object of this world.
    #[error(
        "{what} handle {index} does not belong to this world (it was removed or never existed)"
    )]
    StaleHandle {
        /// Kind of handle.
        what: &'static str,
        /// Its index.
        index: u32,
    },
    /// The heightmap pool has no room for a surface. A normal state: free or evict a surface, or give
    /// the pool more bytes.
    #[error(
        "the heightmap pool has no room for surface {name:?}: it needs {needed} bytes, {free} of {budget} bytes are free in one piece"
    )]
    PoolExhausted {
        /// The surface that did not fit.
        name: String,
        /// Bytes the surface needs.
        needed: u64,
        /// Largest free block.
        free: u64,
        /// The pool's budget.
        budget: u64,
    },
    /// The GPU did not finish or a readback failed, for a reason other than those below.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// Waiting for the GPU failed (the device was lost, or the wait timed out).
    #[error("GPU readback failed: {0}")]
    Poll(#[from] wgpu::PollError),
    /// A buffer could not be mapped for reading.
    #[error("GPU readback failed: {0}")]
    BufferMap(#[from] wgpu::BufferAsyncError),
    /// A mapped buffer's range could not be viewed.
    #[error("GPU readback failed: {0}")]
    MapRange(#[from] wgpu::MapRangeError),
    /// Writing an output file failed for a reason of the library's (the I/O errors are
    /// [`SnowError::WriteFile`]).
    #[error("could not write {}: {reason}", path.display())]
    Output {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Writing a file failed.
    #[error("could not write {}: {source}", path.display())]
    WriteFile {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Reading a file failed.
    #[error("could not read {}: {source}", path.display())]
    ReadFile {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A PNG file could not be decoded.
    #[error("could not read {}: {source}", path.display())]
    PngDecode {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: png::DecodingError,
    },
    /// A PNG that decodes but is not what was asked for (a heightmap is 16-bit greyscale).
    #[error("could not read {}: {reason}", path.display())]
    PngFormat {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// Encoding a PNG failed.
    #[error("PNG encoding failed: {0}")]
    PngEncode(#[from] png::EncodingError),
    /// A setting of a configuration ([`WorldConfig`](crate::WorldConfig)'s capture, a
    /// [`ManagerConfig`](crate::ManagerConfig), a [`CameraView`](crate::CameraView)) is not usable.
    #[error("{config} {what} is {value}, but it must be {expected}")]
    Config {
        /// Which configuration: `capture`, `manager setting` or `camera`.
        config: &'static str,
        /// Which field.
        what: &'static str,
        /// The offending value, printed.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A time step is not usable.
    #[error("time step {dt} s is not usable: it must be a finite number of seconds, 0 or more")]
    InvalidTimeStep {
        /// The step given.
        dt: f32,
    },
    /// A posed vertex buffer does not match its mesh.
    #[error("posed vertices for mesh {mesh}: got {got} vertices, the mesh has {expected}")]
    PoseMismatch {
        /// Mesh index.
        mesh: u32,
        /// Vertices given.
        got: usize,
        /// Vertices of the mesh.
        expected: usize,
    },
    /// Joint matrices given for a skinned mesh do not match its joints.
    #[error(
        "joint matrices for skinned mesh {mesh}: got {got}, the mesh has {expected} joints; give one matrix a joint, as SkinnedMesh::pose computes them"
    )]
    JointCount {
        /// Mesh index.
        mesh: u32,
        /// Matrices given.
        got: usize,
        /// Joints of the mesh.
        expected: usize,
    },
    /// A surface was listed twice in one update.
    #[error("surface {index} is listed twice in one update; list each surface once")]
    DuplicateUpdate {
        /// The surface's index.
        index: u32,
    },
    /// A scene file is not valid: one sentence `<file>:<line>: <what is wrong>; <what to do>`.
    #[error("{0}")]
    Scene(String),
    /// The contents of a save do not fit together (a planner state, a heightmap section, a pool
    /// larger than this device allows); the file itself read well.
    #[error("{0}")]
    SaveContent(String),
    /// A save's text sections could not be encoded.
    #[error("save: {0}")]
    SaveEncode(#[source] serde_json::Error),
    /// A surface snapshot that does not fit the world it is restored into.
    #[error("the snapshot of surface {name:?} cannot be restored: {reason}")]
    Snapshot {
        /// The surface.
        name: String,
        /// What does not match.
        reason: String,
    },
    /// A save file that cannot be read (corrupt, truncated, foreign or from a newer version).
    #[error("save file {}: {reason}", path.display())]
    SaveFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong, and what to do.
        reason: String,
        /// The error underneath, where there is one (the I/O error of a file that cannot be read,
        /// the library's error of a save whose parts do not fit together).
        #[source]
        source: Option<Box<dyn std::error::Error + Send + Sync>>,
    },
    /// Heights given to [`crate::PoolFormat::encode`] or `decode` do not match the heightmap's
    /// size.
    #[error(
        "a {width} x {height} heightmap at {bits}-bit precision needs {expected} {what}, but {got} were given"
    )]
    HeightsLength {
        /// Texels along x.
        width: u32,
        /// Texels along z.
        height: u32,
        /// The pool's precision, bits a channel (8, 16 or 32).
        bits: u32,
        /// What was counted (texels a channel, or words).
        what: &'static str,
        /// How many it needs.
        expected: usize,
        /// How many were given.
        got: usize,
    },
    /// Every staging buffer of the probe ring holds a batch not yet read back; nothing asked
    /// before was dropped.
    #[error(
        "all {ring} probe batches are in flight ({in_flight} not yet read back): probe again after the next update or SnowWorld::poll_probes"
    )]
    ProbeRingFull {
        /// Batches in flight.
        in_flight: usize,
        /// Batches the ring holds.
        ring: usize,
    },
    /// More points were probed between two updates than one batch holds.
    #[error(
        "{asked} more probe points would exceed the {max} one batch holds ({queued} already queued): probe fewer, or call SnowWorld::poll_probes to send the queued ones"
    )]
    TooManyProbePoints {
        /// Points in the refused request.
        asked: usize,
        /// Points already queued for the next batch.
        queued: usize,
        /// Most points a batch holds.
        max: usize,
    },
    /// A probed point is not finite.
    #[error("probe point #{index} is {value}, but it must be finite")]
    InvalidProbePoint {
        /// Its index in the slice given.
        index: usize,
        /// The point, printed.
        value: String,
    },
    /// A probe ticket that this world does not know.
    #[error(
        "probe ticket {ticket} is unknown: never given by this world, already answered, or forgotten after more newer answers were left unread than the world keeps"
    )]
    UnknownProbe {
        /// The ticket's number.
        ticket: u64,
    },
}

/// Result alias of the library.
pub type Result<T, E = SnowError> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::SnowError;
    use crate::{Heightmap, ManagerConfig};

    #[test]
    fn errors_cross_threads() {
        fn send_sync<T: Send + Sync + 'static>() {}
        send_sync::<SnowError>();
        send_sync::<crate::render::RenderError>();
    }

    #[test]
    fn a_bad_setting_is_matchable_without_parsing_text() {
        let bad = ManagerConfig {
            updates_per_frame: 0,
            ..ManagerConfig::default()
        };
        let e = bad.validate().unwrap_err();
        assert!(
            matches!(
                e,
                SnowError::Config {
                    config: "manager setting",
                    what: "updates_per_frame",
                    ..
                }
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "manager setting updates_per_frame is 0, but it must be 1 or more"
        );
    }

    #[test]
    fn loading_a_heightmap_that_is_not_a_png_says_it_could_not_read_it() {
        let dir = std::env::temp_dir().join(format!("snowprint-error-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("not.png");
        std::fs::write(&path, b"this is text, not a PNG").unwrap();
        let e = Heightmap::load_png(&path).unwrap_err();
        assert!(matches!(e, SnowError::PngDecode { .. }), "{e:?}");
        assert!(e.to_string().starts_with("could not read "), "{e}");
        assert!(std::error::Error::source(&e).is_some());
        let missing = Heightmap::load_png(&dir.join("missing.png")).unwrap_err();
        assert!(matches!(missing, SnowError::ReadFile { .. }), "{missing:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
