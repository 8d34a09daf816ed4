//! `snowprint play`: a window you can walk in. A person in a yard of fresh snow, steered with the
//! keys, followed by an orbiting camera, drawn by the library's renderer into the window's surface
//! texture (`Renderer::encode_to_view`) after the world's update recorded into the same encoder
//! (`SnowWorld::encode_step`), one submit a frame.
//!
//! Controls: W A S D walk (relative to the camera), Shift runs, C slides, F falls, Space throws a
//! snowball, T switches the snow tier (relief, POM, tessellated), V the debug view, a left-button
//! drag or the arrow keys orbit the camera, the wheel zooms, Esc quits. The frame time, tier and
//! view are drawn in the top left corner (`hud/`, the window's own pass: the renderer draws no
//! text) and written in the window's title.
//!
//! For tests and recordings, `--script` replays keys over time (`script.rs`), `--frames` and
//! `--seconds` end the run, `--dt` fixes the step of each frame, `--screenshot` writes the last
//! frame as PNG and `--gif` the run as an animation.

mod game;
mod hud;
mod player;
mod script;
mod window;
mod yard;

use std::path::{Path, PathBuf};

use snowprint::render::{DebugView, Tier};

pub use script::Script;

/// Arguments of `snowprint play`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Window size, WIDTHxHEIGHT (default: 960x540 on a GPU, 640x360 on a software adapter).
    #[arg(long, value_parser = crate::demo::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Snow tier to start in: relief, pom or tessellated (T switches).
    #[arg(long, default_value = "relief")]
    pub tier: Tier,
    /// Debug view to start in: shaded, materials, depression, occlusion, normals or taps (V
    /// switches).
    #[arg(long, default_value = "shaded")]
    pub debug_view: DebugView,
    /// Samples per pixel along each axis, 1 to 4 (default: 2 on a GPU, 1 on a software adapter).
    #[arg(long, allow_negative_numbers = true)]
    pub supersample: Option<u32>,
    /// No falling snow.
    #[arg(long)]
    pub no_snowfall: bool,
    /// Keys replayed over time: a file, or the script itself, such as "w:2s,a:0.5s,space"; the
    /// run ends with the script unless --frames or --seconds say when.
    #[arg(long)]
    pub script: Option<String>,
    /// Quit after this many frames.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::frames)]
    pub frames: Option<u32>,
    /// Quit after this many seconds of play.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seconds)]
    pub seconds: Option<f32>,
    /// Seconds of play each frame advances, whatever the frame took (default: the frame's own
    /// time, at most 0.1 s): makes a scripted run the same on every machine.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seconds)]
    pub dt: Option<f32>,
    /// Write the last frame shown to this PNG file.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Write a JSON report at the end: the adapter, the frames and their median time, the last
    /// frame's camera, and the path the person's pelvis took (x, z a frame), so that a test can
    /// find the trail in the screenshot.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write the frames shown to this GIF file (every third frame, at most 480 pixels wide).
    #[arg(long)]
    pub gif: Option<PathBuf>,
}

/// An output file: its folder must exist and its name end in `ext`, checked before the window
/// opens.
fn check_output(flag: &str, path: &Path, ext: &str) -> Result<(), String> {
    let ok_ext = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if !ok_ext {
        return Err(format!(
            "{flag} {}: give a file name ending in .{ext}",
            path.display()
        ));
    }
    if path.is_dir() {
        return Err(format!(
            "{flag} {}: that is a folder; give a file name ending in .{ext}",
            path.display()
        ));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent
        && !dir.is_dir()
    {
        return Err(format!(
            "{flag} {}: the folder {} does not exist; create it or write elsewhere",
            path.display(),
            dir.display()
        ));
    }
    Ok(())
}

/// The arguments, checked: everything a user can get wrong is refused here, before a window opens.
pub struct Checked {
    args: Args,
    script: Option<Script>,
}

impl Checked {
    fn new(args: Args) -> Result<Self, String> {
        if let Some(s) = args.supersample
            && !(1..=4).contains(&s)
        {
            return Err(format!("--supersample {s}: give 1 to 4"));
        }
        if let Some(p) = &args.screenshot {
            check_output("--screenshot", p, "png")?;
        }
        if let Some(p) = &args.report {
            check_output("--report", p, "json")?;
        }
        if let Some(p) = &args.gif {
            check_output("--gif", p, "gif")?;
        }
        let script = args
            .script
            .as_deref()
            .map(Script::from_arg)
            .transpose()
            .map_err(|e| format!("--script: {e}"))?;
        Ok(Self { args, script })
    }
}

/// Open the window and play until it is closed (or the run's end given by `--frames` or
/// `--seconds`).
pub fn run(gpu: &snowprint::GpuOptions, args: Args) -> Result<(), String> {
    let checked = Checked::new(args)?;
    game::run(gpu, checked)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_checked_before_the_window_opens() {
        let e = check_output("--screenshot", Path::new("shot.jpg"), "png").unwrap_err();
        assert!(e.contains("ending in .png"), "{e}");
        let e = check_output("--gif", Path::new("/no/such/folder/a.gif"), "gif").unwrap_err();
        assert!(e.contains("/no/such/folder does not exist"), "{e}");
        assert!(check_output("--gif", Path::new("a.GIF"), "gif").is_ok());
        let dir = std::env::temp_dir().join("snowprint-play-check.png");
        std::fs::create_dir_all(&dir).unwrap();
        let e = check_output("--screenshot", &dir, "png").unwrap_err();
        assert!(e.contains("is a folder") || e.contains("folder"), "{e}");
        let _ = std::fs::remove_dir(&dir);
    }
}
