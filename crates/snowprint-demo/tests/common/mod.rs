//! Shared set-up of the GPU tests: one device for the whole test binary.

#![allow(dead_code)]

use std::sync::OnceLock;

use snowprint::{GpuContext, GpuOptions};

/// The test device (software Vulkan in CI). A missing adapter fails the tests with the library's
/// own sentence about what to install.
pub fn gpu() -> &'static GpuContext {
    static GPU: OnceLock<GpuContext> = OnceLock::new();
    GPU.get_or_init(|| match GpuContext::new(&GpuOptions::default()) {
        Ok(g) => g,
        Err(e) => panic!("GPU tests need an adapter: {e}"),
    })
}
