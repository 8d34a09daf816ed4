// hud.wgsl: the play window's line of text (frame time, tier, view), drawn over the finished frame
// in the window's own format: a box of character cells on a half-dark background, each cell a 5 x 7
// glyph (packed by font.rs) scaled by whole pixels, so every pixel is either glyph or background.
// CPU reference: font.rs `mask`.
// Reads: the HUD uniform. Writes: the window's texture (blended, premultiplied alpha).

const GLYPH_W: u32 = 5u;
const GLYPH_H: u32 = 7u;
const CELL_W: u32 = 6u;
const CELL_H: u32 = 9u;
// Background around and behind the text, premultiplied: black at this alpha.
const SHADE: f32 = 0.55;

struct Hud {
    rect: vec4<u32>,              // text origin x, y (pixels from the top left), scale, characters
    size: vec4<f32>,              // target width and height, pixels
    glyphs: array<vec4<u32>, 16>, // two words a character (font.rs `glyph`), 32 characters
}

@group(0) @binding(0) var<uniform> hud: Hud;

fn margin() -> f32 {
    return f32(hud.rect.z * 2u);
}

@vertex
fn vs_hud(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    )[i];
    let scale = hud.rect.z;
    let size = vec2<f32>(f32(hud.rect.w * CELL_W * scale), f32(CELL_H * scale)) + 2.0 * margin();
    let px = vec2<f32>(hud.rect.xy) - margin() + corner * size;
    let ndc = px / hud.size.xy * 2.0 - 1.0;
    return vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0);
}

fn glyph_word(character: u32, word: u32) -> u32 {
    let k = character * 2u + word;
    return hud.glyphs[k / 4u][k % 4u];
}

fn lit(character: u32, x: u32, y: u32) -> bool {
    var bit: u32;
    var word: u32;
    if y < 6u {
        word = glyph_word(character, 0u);
        bit = (5u - y) * GLYPH_W + (GLYPH_W - 1u - x);
    } else {
        word = glyph_word(character, 1u);
        bit = GLYPH_W - 1u - x;
    }
    return ((word >> bit) & 1u) == 1u;
}

@fragment
fn fs_hud(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let background = vec4<f32>(0.0, 0.0, 0.0, SHADE);
    let p = vec2<i32>(floor(pos.xy)) - vec2<i32>(hud.rect.xy);
    if p.x < 0 || p.y < 0 {
        return background;
    }
    let f = vec2<u32>(p) / hud.rect.z;
    let character = f.x / CELL_W;
    let x = f.x % CELL_W;
    if character >= hud.rect.w || x >= GLYPH_W || f.y >= GLYPH_H || !lit(character, x, f.y) {
        return background;
    }
    return vec4<f32>(1.0);
}
