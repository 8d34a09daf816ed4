//! `snowprint demo`: the built-in demo.

use std::path::{Path, PathBuf};

use snowprint::GpuOptions;
use snowprint::scene::Scene;

/// The scene the demo runs.
pub const DEMO_SCENE: &str = include_str!("../../../scenes/walker.toml");

/// Arguments of `snowprint demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Frames to run (default: the whole walk).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Which demo: `rooftops` or `city` (several hundred surfaces under the manager's budget).
    #[arg(long, default_value = "rooftops")]
    pub scene: String,
}

/// Run the built-in walker scene and write its heightmaps.
pub fn run(gpu: &GpuOptions, args: &Args) -> Result<(), String> {
    if args.scene == "city" {
        return crate::city::run(gpu, &args.out, args.frames);
    }
    let scene =
        Scene::parse(DEMO_SCENE, Path::new("scenes/walker.toml")).map_err(|e| e.to_string())?;
    let dt = 1.0 / 60.0;
    let frames = args
        .frames
        .unwrap_or(((scene.duration() / dt).ceil() as u32).max(1) + 30);
    crate::simulate::simulate(gpu, &scene, frames, dt, &args.out)?;
    eprintln!(
        "snowprint: wrote the heightmaps of {} surface(s) to {}",
        scene.surfaces.len(),
        args.out.display()
    );
    Ok(())
}
