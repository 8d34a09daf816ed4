//! The HUD's font: 5 x 7 pixel glyphs of the characters the HUD writes (digits, a few signs and
//! the lowercase letters of its words), each packed as 35 bits, row by row from the top, the
//! leftmost pixel of a row in its highest bit. What `hud.wgsl` draws and what [`mask`], the CPU
//! reference, says it draws.

/// Glyph columns and rows (as in hud.wgsl).
pub const GLYPH_W: u32 = 5;
#[cfg(test)]
pub const GLYPH_H: u32 = 7;
/// A character cell: the glyph and one pixel of space right, two below (before scaling).
#[cfg(test)]
pub const CELL_W: u32 = GLYPH_W + 1;
#[cfg(test)]
pub const CELL_H: u32 = GLYPH_H + 2;

const GLYPHS: &[(char, [&str; 7])] = &[
    (
        '0',
        [
            "01110", "10001", "10011", "10101", "11001", "10001", "01110",
        ],
    ),
    (
        '1',
        [
            "00100", "01100", "00100", "00100", "00100", "00100", "01110",
        ],
    ),
    (
        '2',
        [
            "01110", "10001", "00001", "00010", "00100", "01000", "11111",
        ],
    ),
    (
        '3',
        [
            "11110", "00001", "00001", "01110", "00001", "00001", "11110",
        ],
    ),
    (
        '4',
        [
            "00010", "00110", "01010", "10010", "11111", "00010", "00010",
        ],
    ),
    (
        '5',
        [
            "11111", "10000", "11110", "00001", "00001", "10001", "01110",
        ],
    ),
    (
        '6',
        [
            "00110", "01000", "10000", "11110", "10001", "10001", "01110",
        ],
    ),
    (
        '7',
        [
            "11111", "00001", "00010", "00100", "01000", "01000", "01000",
        ],
    ),
    (
        '8',
        [
            "01110", "10001", "10001", "01110", "10001", "10001", "01110",
        ],
    ),
    (
        '9',
        [
            "01110", "10001", "10001", "01111", "00001", "00010", "01100",
        ],
    ),
    (
        '.',
        [
            "00000", "00000", "00000", "00000", "00000", "01100", "01100",
        ],
    ),
    (
        ':',
        [
            "00000", "01100", "01100", "00000", "01100", "01100", "00000",
        ],
    ),
    (
        '|',
        [
            "00100", "00100", "00100", "00100", "00100", "00100", "00100",
        ],
    ),
    (
        '-',
        [
            "00000", "00000", "00000", "11111", "00000", "00000", "00000",
        ],
    ),
    (
        '/',
        [
            "00001", "00010", "00010", "00100", "01000", "01000", "10000",
        ],
    ),
    (
        ' ',
        [
            "00000", "00000", "00000", "00000", "00000", "00000", "00000",
        ],
    ),
    (
        'a',
        [
            "00000", "00000", "01110", "00001", "01111", "10001", "01111",
        ],
    ),
    (
        'c',
        [
            "00000", "00000", "01110", "10000", "10000", "10001", "01110",
        ],
    ),
    (
        'd',
        [
            "00001", "00001", "01101", "10011", "10001", "10001", "01111",
        ],
    ),
    (
        'e',
        [
            "00000", "00000", "01110", "10001", "11111", "10000", "01110",
        ],
    ),
    (
        'f',
        [
            "00110", "01001", "01000", "11100", "01000", "01000", "01000",
        ],
    ),
    (
        'h',
        [
            "10000", "10000", "10110", "11001", "10001", "10001", "10001",
        ],
    ),
    (
        'i',
        [
            "00100", "00000", "01100", "00100", "00100", "00100", "01110",
        ],
    ),
    (
        'l',
        [
            "01100", "00100", "00100", "00100", "00100", "00100", "01110",
        ],
    ),
    (
        'm',
        [
            "00000", "00000", "11010", "10101", "10101", "10001", "10001",
        ],
    ),
    (
        'n',
        [
            "00000", "00000", "10110", "11001", "10001", "10001", "10001",
        ],
    ),
    (
        'o',
        [
            "00000", "00000", "01110", "10001", "10001", "10001", "01110",
        ],
    ),
    (
        'p',
        [
            "00000", "00000", "11110", "10001", "11110", "10000", "10000",
        ],
    ),
    (
        'r',
        [
            "00000", "00000", "10110", "11001", "10000", "10000", "10000",
        ],
    ),
    (
        's',
        [
            "00000", "00000", "01111", "10000", "01110", "00001", "11110",
        ],
    ),
    (
        't',
        [
            "01000", "01000", "11100", "01000", "01000", "01001", "00110",
        ],
    ),
    (
        'u',
        [
            "00000", "00000", "10001", "10001", "10001", "10011", "01101",
        ],
    ),
    (
        'v',
        [
            "00000", "00000", "10001", "10001", "10001", "01010", "00100",
        ],
    ),
    (
        'w',
        [
            "00000", "00000", "10001", "10001", "10101", "10101", "01010",
        ],
    ),
    (
        'x',
        [
            "00000", "00000", "10001", "01010", "00100", "01010", "10001",
        ],
    ),
];

/// The packed glyph of `c`: rows 0 to 5 in the first word (bits 29 down to 0), row 6 in the
/// second (bits 4 down to 0); `None` for a character the font has not.
pub fn glyph(c: char) -> Option<[u32; 2]> {
    let rows = GLYPHS.iter().find(|g| g.0 == c)?.1;
    let bits = |row: &str| {
        debug_assert_eq!(row.len() as u32, GLYPH_W);
        row.bytes()
            .fold(0u32, |acc, b| (acc << 1) | u32::from(b == b'1'))
    };
    let first = rows[..6].iter().fold(0u32, |acc, r| (acc << 5) | bits(r));
    Some([first, bits(rows[6])])
}

/// Whether the glyph bit at column `x` (0 = left) and row `y` (0 = top) is set.
#[cfg(test)]
pub fn lit(g: [u32; 2], x: u32, y: u32) -> bool {
    let (word, shift) = if y < 6 {
        (g[0], (5 - y) * GLYPH_W + (GLYPH_W - 1 - x))
    } else {
        (g[1], GLYPH_W - 1 - x)
    };
    (word >> shift) & 1 == 1
}

/// CPU reference of the HUD's text: for a box of `text.len()` cells at `scale` pixels a font
/// pixel, whether each pixel (row-major, `cols * CELL_W * scale` wide) is a lit glyph pixel.
#[cfg(test)]
pub fn mask(text: &str, scale: u32) -> Vec<bool> {
    let glyphs: Vec<[u32; 2]> = text.chars().map(|c| glyph(c).unwrap_or([0, 0])).collect();
    let (w, h) = (glyphs.len() as u32 * CELL_W * scale, CELL_H * scale);
    (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let (fx, fy) = (px / scale, py / scale);
            let (cell, x) = ((fx / CELL_W) as usize, fx % CELL_W);
            x < GLYPH_W && fy < GLYPH_H && lit(glyphs[cell], x, fy)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_word_the_hud_writes_is_in_the_font() {
        let words = "0123456789.:|-/ ms fps relief pom tessellated shaded materials depression occlusion normals taps";
        for c in words.chars() {
            assert!(glyph(c).is_some(), "{c:?} is not in the font");
        }
        // '1' has its foot (row 6, columns 1 to 3) and its flag (row 1, columns 1 and 2).
        let one = glyph('1').unwrap();
        assert!(lit(one, 1, 6) && lit(one, 2, 6) && lit(one, 3, 6) && !lit(one, 0, 6));
        assert!(lit(one, 1, 1) && lit(one, 2, 1) && !lit(one, 3, 1));
        assert_eq!(glyph('é'), None);
    }

    #[test]
    fn the_mask_places_cells_side_by_side() {
        let m = mask("1 1", 2);
        let w = 3 * CELL_W * 2;
        assert_eq!(m.len() as u32, w * CELL_H * 2);
        // Row 6 of the font (pixel rows 12, 13): the foot of each '1', nothing in the blank.
        let row = |y: u32| -> Vec<bool> { (0..w).map(|x| m[(y * w + x) as usize]).collect() };
        let foot = row(12);
        let lit_px: Vec<u32> = (0..w).filter(|&x| foot[x as usize]).collect();
        let first: Vec<u32> = (2..8).collect();
        let third: Vec<u32> = (26..32).collect();
        assert_eq!(lit_px, [first, third].concat());
    }
}
