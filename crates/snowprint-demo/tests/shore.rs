//! The shore scene on the GPU: the people's walk crosses all four strips and leaves prints in
//! each as deep as its material gives (the walk plane lies 5, 8, 11 and 20 cm below the strips'
//! tops): shallow ones in wet sand, deeper in dry sand, mud prints deeper than mud's water depth
//! (so they hold water), the deepest in the powder of the bank.

mod common;

use snowprint::render::{RenderConfig, Renderer, Tier};
use snowprint::{SnowWorld, WorldConfig};
use snowprint_demo::scene::DemoScene;
use snowprint_demo::scene::shore::Shore;

#[test]
fn people_leave_prints_in_every_strip_as_deep_as_its_material_gives() {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(gpu, WorldConfig::default()).expect("world");
    let mut renderer =
        Renderer::new(gpu, RenderConfig::new(64, 36, Tier::Relief)).expect("renderer");
    let mut shore = Shore::new(&mut world, &mut renderer).expect("shore");
    // Eight seconds at 10 Hz: the runner crosses every strip, the walkers two or three each.
    let hz = 10.0;
    for k in 0..(8.0 * hz) as u32 {
        shore
            .advance(&mut world, k as f32 / hz, (k + 1) as f32 / hz)
            .expect("advance");
    }
    // Deepest print (fraction of each strip's depth) and texels pressed past a quarter of it.
    let mut deepest = Vec::new();
    for &(id, _) in shore.surfaces() {
        let desc = world.surface(id).expect("surface").clone();
        let h = world.read_heightmap(id).expect("heightmap");
        let max = h.depression.iter().copied().max().unwrap_or(0) as f32 / 65535.0;
        let pressed = h.depression.iter().filter(|&&d| d > 65535 / 4).count();
        eprintln!(
            "{}: deepest print {:.1} cm of {:.0} cm, {pressed} texels past a quarter",
            desc.name,
            max * desc.snow_depth * 100.0,
            desc.snow_depth * 100.0
        );
        assert!(pressed > 50, "{}: only {pressed} texels pressed", desc.name);
        deepest.push((desc, max));
    }
    let metres = |k: usize| deepest[k].1 * deepest[k].0.snow_depth;
    let (wet, dry, mud, bank) = (metres(0), metres(1), metres(2), metres(3));
    assert!(
        wet < dry && dry < mud && mud < bank,
        "{wet} {dry} {mud} {bank}"
    );
    let water = deepest[2]
        .0
        .material
        .look
        .water_depth
        .expect("mud has water");
    assert!(
        mud > water + 0.02,
        "mud prints {mud} m against water depth {water} m"
    );
}
