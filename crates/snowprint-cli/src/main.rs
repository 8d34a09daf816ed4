//! The `snowprint` command: run scenes, the demo and the benchmarks.
//!
//! Each subcommand lives in its own module with its own arguments; this file only dispatches and
//! turns errors into one sentence and a non-zero exit.

mod args;
mod bench;
mod city;
mod demo;
mod inspect;
mod managed;
mod output;
mod play;
mod progress;
mod report;
mod simulate;
mod terrain;

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
    Simulate(simulate::Args),
    /// Run the built-in demo and write its outputs.
    Demo(demo::Args),
    /// Measure the deformation update per stage on the GPU, against a copy of the same bytes.
    Bench(bench::Args),
    /// Open a window and walk a person through snow (WASD, Shift run, C slide, F fall, Space
    /// throw, T tier, V debug view, drag to orbit).
    Play(play::Args),
    /// Print what a save file holds (settings, clock, sections, surfaces), checking it whole.
    Inspect(inspect::Args),
}

fn main() -> ExitCode {
    quiet_device_select_probe();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("SNOWPRINT_LOG")
                // winit's warnings about a display without a size or settings (Xvfb) are no one's.
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,winit=error")),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let cli = Cli::parse();
    let gpu = snowprint::GpuOptions {
        adapter: cli.adapter.clone(),
    };
    let result = match cli.command {
        Command::Simulate(args) => simulate::run(&gpu, &args),
        Command::Demo(args) => demo::run(&gpu, &args),
        Command::Bench(args) => bench::run(&gpu, &args),
        Command::Inspect(args) => inspect::run(&args),
        Command::Play(args) => play::run(&gpu, args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("snowprint: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Mesa's Vulkan layer `VK_LAYER_MESA_device_select` asks the Wayland compositor for the default
/// GPU while wgpu enumerates adapters; with no session (a server, CI) libwayland prints
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment." twice, an error that is no
/// one's. With no Wayland session the probe can learn nothing, so in that case (and only when the
/// user has not chosen a device through the layer) the command runs itself again with the layer's
/// documented switch `NODEVICE_SELECT=1`: the same process (exec), nothing else changed.
/// snowprint picks its adapter itself (`--adapter`), so the layer's ordering does not matter.
fn quiet_device_select_probe() {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::process::CommandExt as _;
        let set = |k: &str| std::env::var_os(k).is_some();
        let runtime_dir_ok =
            std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
        if runtime_dir_ok
            || set("NODEVICE_SELECT")
            || set("MESA_VK_DEVICE_SELECT")
            || set("DRI_PRIME")
            || set("WAYLAND_DISPLAY")
        {
            return;
        }
        let Ok(exe) = std::env::current_exe() else {
            return;
        };
        let mut args = std::env::args_os();
        let argv0 = args.next().unwrap_or_else(|| exe.clone().into_os_string());
        // exec returns only when it failed; then run on as we are.
        let _ = std::process::Command::new(exe)
            .arg0(argv0)
            .args(args)
            .env("NODEVICE_SELECT", "1")
            .exec();
    }
}

/// Resident memory every 10,000 frames (or `SNOWPRINT_MEMORY_EVERY`), at `info` level (`SNOWPRINT_LOG=info`): how the soak in
/// docs/RELIABILITY.md samples a long run.
pub fn log_memory(frame: u64) {
    // SNOWPRINT_MEMORY_EVERY changes the interval (the tests sample short runs).
    static EVERY: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    let every = *EVERY.get_or_init(|| {
        std::env::var("SNOWPRINT_MEMORY_EVERY")
            .ok()
            .and_then(|s| s.parse().ok())
            .filter(|&n| n > 0)
            .unwrap_or(10_000)
    });
    if frame.is_multiple_of(every)
        && let Some(kib) = resident_kib()
    {
        tracing::info!("frame {frame}: resident memory {kib} KiB");
    }
}

/// This process's resident memory, KiB (Linux; `None` elsewhere).
fn resident_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
