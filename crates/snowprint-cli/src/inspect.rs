//! `snowprint inspect FILE`: what a save holds, read and checked without a GPU.

use std::path::PathBuf;

use snowprint::manager::SaveFile;
use snowprint::manager::UNLIMITED;

/// Arguments of `snowprint inspect`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A save written by `snowprint simulate --save` or `SnowManager::save`.
    pub file: PathBuf,
}

/// Print the save's version, settings, clock, sections and surfaces.
pub fn run(args: &Args) -> Result<(), String> {
    let bytes = std::fs::read(&args.file)
        .map_err(|e| format!("{}: cannot be read: {e}", args.file.display()))?;
    let save =
        SaveFile::parse(&bytes).map_err(|e| format!("save file {}: {e}", args.file.display()))?;
    let c = &save.config;
    println!(
        "{}: snowprint save, format version {}",
        args.file.display(),
        save.version
    );
    println!(
        "  clock: {} frames, {:.4} s of snow time",
        save.frames(),
        save.time()
    );
    let budget = if c.updates_per_frame == UNLIMITED {
        "no budget".to_owned()
    } else {
        format!("{} updates a frame", c.updates_per_frame)
    };
    println!(
        "  manager: {budget}, pool {} bytes at {} bits{}, queue cap {}, active within {} m",
        c.pool_bytes,
        c.format.precision.bits(),
        if c.format.normals {
            " with normals"
        } else {
            ""
        },
        c.queue_cap,
        c.active_distance
    );
    println!("  sections ({} bytes in all):", bytes.len());
    for s in &save.sections {
        println!(
            "    {} {:>10} bytes stored, {:>10} bytes of data{}",
            String::from_utf8_lossy(&s.tag),
            s.stored,
            s.data.len(),
            if s.codec == 1 { " (LZ4)" } else { "" }
        );
    }
    println!(
        "  surfaces: {} registered, {} meshes",
        save.surface_count(),
        save.mesh_count()
    );
    let maps: std::collections::HashMap<u32, f64> = save
        .surfaces
        .iter()
        .filter_map(|s| Some((s.index, s.snapshot.heightmap().ok()?.pressed_volume())))
        .collect();
    for (i, (name, removed, queued, holds)) in save.surface_summary().into_iter().enumerate() {
        if removed {
            println!("    {name:<24} removed");
            continue;
        }
        let pressed = maps
            .get(&(i as u32))
            .map_or(String::new(), |v| format!(", {v:.1} texel-depths pressed"));
        println!("    {name:<24} {holds:<9} {queued} imprints queued{pressed}");
    }
    if !save.terrains.is_empty() {
        println!("  terrains: {}", save.terrains.len());
    }
    for t in &save.terrains {
        let windows: Vec<String> = t
            .origins()
            .iter()
            .zip(&t.desc.levels)
            .map(|(o, l)| {
                format!(
                    "{} x {} of {} m at texel ({}, {})",
                    l.texels[0], l.texels[1], l.texel_size, o[0], o[1]
                )
            })
            .collect();
        println!(
            "    {:<24} levels {}; {} chunks paged out",
            t.desc.name,
            windows.join(", "),
            t.chunks()
        );
    }
    Ok(())
}
