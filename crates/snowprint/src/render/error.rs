//! What the renderer can report instead of panicking.

use crate::error::SnowError;

/// What the renderer can report instead of panicking.
///
/// Variants that come from wgpu or the world keep that error as their
/// [`source`](std::error::Error::source); new variants may be added in any release, so a `match`
/// needs a `_` arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// A setting of [`RenderConfig`](super::RenderConfig) is not usable.
    #[error("render setting {what} is {value}, but it must be {expected}")]
    InvalidConfig {
        /// Which setting.
        what: &'static str,
        /// The value given.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// Something in a [`RenderFrame`](super::RenderFrame) is not usable.
    #[error("render frame: {what} is {value}, but it must be {expected}")]
    InvalidFrame {
        /// Which part of the frame.
        what: String,
        /// The value given.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// A mesh handle that this renderer did not give out.
    #[error("render mesh handle {index} does not belong to this renderer")]
    StaleMesh {
        /// The handle's index.
        index: u32,
    },
    /// The registered meshes would not fit in one buffer of the device (they share one vertex
    /// and one index buffer).
    #[error(
        "the registered meshes' {what} would take {bytes} bytes, but this device's buffers hold at most {max}: register fewer or smaller meshes"
    )]
    MeshesTooLarge {
        /// `vertices` or `indices`.
        what: &'static str,
        /// Bytes they would take with the mesh given.
        bytes: u64,
        /// The device's `max_buffer_size`.
        max: u64,
    },
    /// The target view given to [`Renderer::render_to_view`](super::Renderer::render_to_view) does not have the configured size.
    #[error(
        "the target is {got:?} pixels but the renderer is configured for {expected:?}; call Renderer::resize first"
    )]
    TargetSize {
        /// The target's size.
        got: (u32, u32),
        /// The configured size.
        expected: (u32, u32),
    },
    /// The world refused a request (a stale surface handle, an invalid mesh).
    #[error(transparent)]
    World(#[from] SnowError),
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
    /// The GPU refused a pipeline or a frame (a driver that cannot compile a shader, a limit
    /// exceeded); wgpu's error is kept as the source.
    #[error("the GPU refused the renderer's work: {0}")]
    Gpu(#[from] wgpu::Error),
}

/// Result of the renderer.
pub type RenderResult<T> = Result<T, RenderError>;
