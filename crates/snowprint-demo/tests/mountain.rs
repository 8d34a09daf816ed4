//! The mountain on the GPU: the hiker's first steps print the near level of the valley's sliding
//! window, measured from the local snow top on the valley's slopes, while the window follows it.

mod common;

use snowprint::render::{RenderConfig, Renderer, Tier};
use snowprint::{SnowWorld, WorldConfig};
use snowprint_demo::scene::DemoScene;
use snowprint_demo::scene::mountain::Mountain;

#[test]
fn the_hiker_prints_the_near_level_as_the_window_follows() {
    let gpu = common::gpu();
    let mut world = SnowWorld::new(gpu, WorldConfig::default()).expect("world");
    let mut renderer =
        Renderer::new(gpu, RenderConfig::new(64, 36, Tier::Relief)).expect("renderer");
    let mut m = Mountain::new(&mut world, &mut renderer).expect("mountain");
    // Three seconds at 10 Hz: about 4 m of the loop, five or six boot prints.
    let hz = 10.0;
    for k in 0..(3.0 * hz) as u32 {
        m.advance(&mut world, k as f32 / hz, (k + 1) as f32 / hz)
            .expect("advance");
    }
    let levels = m.valley().surfaces();
    let near = world.read_heightmap(levels[0]).expect("near level");
    let pressed = near.depression.iter().filter(|&&d| d > 65535 / 4).count();
    let deepest = near.depression.iter().copied().max().unwrap_or(0) as f32 / 65535.0;
    eprintln!("near level: {pressed} texels past a quarter, deepest {deepest:.3}");
    // A boot's sole comes down 0.16 m into 0.3 m of snow, from the local top on the slope: 0.53
    // of the depth by hand; the blur over 5 cm texels takes a little off the deepest texel.
    assert!(pressed >= 40, "only {pressed} texels pressed");
    assert!(
        (0.35..=0.56).contains(&deepest),
        "deepest print {deepest}, 0.53 by hand"
    );
    // The window moved with the hiker: strips left and entered, and nothing else was written.
    let s = m.valley().stats();
    assert!(s.scrolls > 0 && s.texels_in > 0, "{s:?}");
    assert!(s.bytes_written <= s.texels_in * 4, "{s:?}");
}
