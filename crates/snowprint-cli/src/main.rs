//! The `snowprint` command: run scenes, the demo and the benchmarks.

mod simulate;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Real-time deformable snow: heightmaps captured from below and accumulated on the GPU.
#[derive(Parser, Debug)]
#[command(name = "snowprint", version, about)]
struct Cli {
    /// GPU adapter to use: part of its name, case-insensitive (default: the best one found).
    #[arg(long, global = true, env = "SNOWPRINT_ADAPTER")]
    adapter: Option<String>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene file for a number of frames and dump every surface's heightmap.
    Simulate {
        /// Scene file (TOML, see docs/SCENES.md).
        #[arg(long)]
        scene: PathBuf,
        /// Frames to run.
        #[arg(long)]
        frames: u32,
        /// Seconds per frame.
        #[arg(long, default_value_t = 1.0 / 60.0)]
        dt: f32,
        /// Folder for `<surface>.png` (16-bit depression) and `<surface>.json`.
        #[arg(long)]
        dump: PathBuf,
    },
    /// Run the built-in demo scene and write its heightmaps to `--out`.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Frames to run (default: the whole walk).
        #[arg(long)]
        frames: Option<u32>,
    },
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("SNOWPRINT_LOG")
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let gpu = snowprint::GpuOptions {
        adapter: cli.adapter.clone(),
    };
    let result = match cli.command {
        Command::Simulate {
            scene,
            frames,
            dt,
            dump,
        } => simulate::run(&gpu, &scene, frames, dt, &dump),
        Command::Demo { out, frames } => simulate::demo(&gpu, &out, frames),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("snowprint: {e}");
            ExitCode::FAILURE
        }
    }
}
