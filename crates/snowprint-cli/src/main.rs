//! The `snowprint` command: run scenes, the demo and the benchmarks.
//!
//! Each subcommand lives in its own module with its own arguments; this file only dispatches and
//! turns errors into one sentence and a non-zero exit.

mod bench;
mod city;
mod demo;
mod managed;
mod simulate;

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
        Command::Simulate(args) => simulate::run(&gpu, &args),
        Command::Demo(args) => demo::run(&gpu, &args),
        Command::Bench(args) => bench::run(&gpu, &args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("snowprint: {e}");
            ExitCode::FAILURE
        }
    }
}
