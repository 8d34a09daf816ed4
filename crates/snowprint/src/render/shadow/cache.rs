//! What each shadow cascade does with its still casters' depth this frame (pure): the step
//! ([`cascade_step`]) and the rectangles of the map that moving casters and displaced snow cover
//! ([`sphere_rect`]), which the next frame restores.
//!
//! A cascade keeps its still casters' depth ([`Instance::still`](crate::render::Instance::still))
//! in a cache once they and the cascade have held still for a frame. While they hold, the
//! cascade's map keeps the frame before's depth: only the rectangles that the frame before's
//! moving casters and displaced snow drew into are copied back from the cache, then this frame's
//! are drawn. Clearing, copying or redrawing a whole depth map is fixed-function work, which GPUs
//! with graphics units in a small part of the chip (the H100) have little of
//! (`docs/PERFORMANCE.md`, "Shadows of what holds still").

use glam::{Mat4, Vec3};

/// A restore costs fragments, a copy of the whole map fixed-function writes: beyond this share of
/// the map's texels (one in `RESTORE_SHARE`; overlaps counted twice) the cascade is copied whole
/// instead. On the H100 restoring 86 % of a 3072^2 cascade cost less than copying it
/// (`docs/PERFORMANCE.md`, "Shadows of what holds still"), so only more than the whole copies.
pub(super) const RESTORE_SHARE: u64 = 1;

/// Most rectangles [`merged`] merges.
const MERGED_MAX: usize = 1024;

/// What a cascade does with its still casters' depth this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum CascadeStep {
    /// Clear the cascade and draw every caster into it.
    #[default]
    Draw,
    /// Draw the still casters into the cascade's cache, copy it in, draw the moving ones.
    Keep,
    /// Copy the cache in and draw the moving casters: the still ones are not drawn.
    CopyIn,
    /// Keep the map as the frame before left it, copy the cache back over what the frame before
    /// drew on top of the still casters, and draw the moving casters.
    Restore,
}

/// What a cascade's cache remembers between frames: the keys of its still casters' depth (equal
/// keys, the same depth; `MeshSet::still_keys`).
#[derive(Clone, Debug, Default)]
pub(super) struct CacheState {
    /// The frame before's key.
    pub last: Option<u64>,
    /// The key the cache holds.
    pub cached: Option<u64>,
    /// The key whose still depth the cascade's map holds under `dirty`.
    pub live: Option<u64>,
    /// Texel rectangles `[x0, y0, x1, y1)` the frame before drew into over the still depth.
    pub dirty: Vec<[u32; 4]>,
}

/// A cascade's step: `key` of its still casters this frame (`None`: it has none), `state` its
/// cache's memory, `map_texels` the texels of its map. A cache holding this frame's key is
/// restored (or copied whole, where the map does not hold it or the frame before drew over more
/// than a share of it); still casters that held still since the frame before are kept; any other
/// frame (the first of a new view, a still caster moved) draws everything and caches nothing, so
/// a cascade that moves every frame costs what it did without the cache.
pub(super) fn cascade_step(
    enabled: bool,
    key: Option<u64>,
    state: &CacheState,
    map_texels: u64,
) -> CascadeStep {
    let Some(key) = key.filter(|_| enabled) else {
        return CascadeStep::Draw;
    };
    if state.cached == Some(key) {
        let dirty: u64 = state.dirty.iter().map(|&r| area(r)).sum();
        if state.live == Some(key) && dirty * RESTORE_SHARE <= map_texels {
            CascadeStep::Restore
        } else {
            CascadeStep::CopyIn
        }
    } else if state.last == Some(key) {
        CascadeStep::Keep
    } else {
        CascadeStep::Draw
    }
}

impl CacheState {
    /// After the frame's `step` with `key`: what the map and the cache hold, and the rectangles
    /// `drawn` over the still depth this frame (the moving casters and the displaced snow),
    /// [`merged`] only where the next frame may restore them.
    pub(super) fn advance(&mut self, step: CascadeStep, key: Option<u64>, drawn: Vec<[u32; 4]>) {
        self.last = key;
        if step == CascadeStep::Keep {
            self.cached = key;
        }
        self.live = (step != CascadeStep::Draw).then_some(key).flatten();
        self.dirty = if self.live.is_some() {
            merged(drawn)
        } else {
            Vec::new()
        };
    }
}

/// `rects` with every pair whose bounding rectangle has no more texels than the two together
/// replaced by that rectangle, until no pair is (a person's limbs overlap: their union is
/// restored once). Past [`MERGED_MAX`] rectangles they are left as they are (the pairs' test
/// would cost more CPU than the overlaps cost the GPU).
pub(super) fn merged(mut rects: Vec<[u32; 4]>) -> Vec<[u32; 4]> {
    if rects.len() > MERGED_MAX {
        return rects;
    }
    let union = |a: [u32; 4], b: [u32; 4]| {
        [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ]
    };
    let mut merging = true;
    while merging {
        merging = false;
        let mut i = 0;
        while i < rects.len() {
            let mut j = i + 1;
            while j < rects.len() {
                let u = union(rects[i], rects[j]);
                if area(u) <= area(rects[i]) + area(rects[j]) {
                    rects[i] = u;
                    rects.swap_remove(j);
                    merging = true;
                } else {
                    j += 1;
                }
            }
            i += 1;
        }
    }
    rects
}

/// Texels of a rectangle.
pub(super) fn area(r: [u32; 4]) -> u64 {
    u64::from(r[2].saturating_sub(r[0])) * u64::from(r[3].saturating_sub(r[1]))
}

/// The texels `[x0, y0, x1, y1)` of a `size` map, from its top left corner, that a sphere at
/// `center` of `radius` metres can cover under a cascade's orthographic `to_clip`, a texel wider
/// on every side; `None` where it covers none.
pub(in crate::render) fn sphere_rect(
    to_clip: Mat4,
    center: Vec3,
    radius: f32,
    size: u32,
) -> Option<[u32; 4]> {
    let c = to_clip * center.extend(1.0);
    let rx = radius * to_clip.row(0).truncate().length();
    let ry = radius * to_clip.row(1).truncate().length();
    let s = size as f32;
    let clamp = |v: f32| v.clamp(0.0, s) as u32;
    let x0 = clamp(((c.x - rx) * 0.5 + 0.5) * s - 1.0);
    let x1 = clamp((((c.x + rx) * 0.5 + 0.5) * s + 1.0).ceil());
    let y0 = clamp((0.5 - (c.y + ry) * 0.5) * s - 1.0);
    let y1 = clamp(((0.5 - (c.y - ry) * 0.5) * s + 1.0).ceil());
    (x0 < x1 && y0 < y1).then_some([x0, y0, x1, y1])
}

/// A texel rectangle of a `size` map in clip space, `(x0, y0, x1, y1)` (y up).
pub(super) fn clip_rect(r: [u32; 4], size: u32) -> [f32; 4] {
    let s = size as f32;
    let x = |t: u32| t as f32 / s * 2.0 - 1.0;
    let y = |t: u32| 1.0 - t as f32 / s * 2.0;
    [x(r[0]), y(r[3]), x(r[2]), y(r[1])]
}

#[cfg(test)]
mod tests {
    use super::*;
    use CascadeStep::{CopyIn, Draw, Keep, Restore};

    /// Frame by frame, a cascade whose still casters hold still from the second frame: the first
    /// draws, the second keeps (drawing the still casters into the cache and copying it in), the
    /// rest restore; a moved caster draws, then keeps again.
    #[test]
    fn a_cascade_keeps_its_still_casters_once_they_hold_still() {
        let keys = [1, 1, 1, 1, 2, 2, 2, 1];
        let mut state = CacheState::default();
        let mut steps = Vec::new();
        for k in keys {
            let step = cascade_step(true, Some(k), &state, 100);
            state.advance(step, Some(k), vec![[0, 0, 5, 5]]);
            steps.push(step);
        }
        // Back at key 1 after key 2 was cached: 1 is no longer in the cache, and 2 was last.
        assert_eq!(
            steps,
            [Draw, Keep, Restore, Restore, Draw, Keep, Restore, Draw]
        );
    }

    /// A frame before that drew over more texels than the map has is copied whole; so is a map
    /// that holds another key's depth (the cache does, from before).
    #[test]
    fn a_large_restore_or_a_map_of_another_key_copies_the_cache_whole() {
        let state = |live, dirty| CacheState {
            last: Some(1),
            cached: Some(1),
            live,
            dirty,
        };
        // 100 of 100 texels: restored; 101: copied.
        let all = vec![[0, 0, 10, 10]];
        assert_eq!(
            cascade_step(true, Some(1), &state(Some(1), all), 100),
            Restore
        );
        let two = vec![[0, 0, 10, 10], [10, 10, 11, 11]];
        assert_eq!(
            cascade_step(true, Some(1), &state(Some(1), two), 100),
            CopyIn
        );
        assert_eq!(
            cascade_step(true, Some(1), &state(None, vec![]), 100),
            CopyIn
        );
        assert_eq!(
            cascade_step(true, Some(1), &state(Some(2), vec![]), 100),
            CopyIn
        );
    }

    /// A cascade that moves every frame never caches; nothing still, or the cache off, draws.
    #[test]
    fn a_moving_cascade_or_no_still_caster_draws() {
        let mut state = CacheState::default();
        for k in 0..5 {
            let step = cascade_step(true, Some(k), &state, 100);
            assert_eq!(step, Draw);
            state.advance(step, Some(k), vec![]);
        }
        let held = CacheState {
            last: Some(1),
            cached: Some(1),
            live: Some(1),
            dirty: vec![],
        };
        assert_eq!(cascade_step(true, None, &held, 100), Draw);
        assert_eq!(cascade_step(false, Some(1), &held, 100), Draw);
        // A draw leaves nothing for the next frame to restore.
        state.advance(Draw, Some(9), vec![[0, 0, 1, 1]]);
        assert!(state.live.is_none() && state.dirty.is_empty());
    }

    /// By hand: two overlapping squares become their bounding rectangle (no more texels than
    /// both: 10 x 6 = 60 against 36 + 36), which then takes in a third it touches; two apart stay.
    #[test]
    fn overlapping_rectangles_merge_and_apart_ones_stay() {
        let m = merged(vec![[0, 0, 6, 6], [4, 0, 10, 6], [10, 0, 12, 6]]);
        assert_eq!(m, [[0, 0, 12, 6]]);
        let apart = vec![[0, 0, 2, 2], [10, 10, 12, 12]];
        assert_eq!(merged(apart.clone()), apart);
    }

    /// By hand: a cascade 16 m wide (clip x = p.x / 8, y = -p.z / 8) on a 64-texel map, a
    /// sphere of 1 m at (2, 0, 3): clip x from 0.125 to 0.375, texels 36 to 44, and y from
    /// -0.5 to -0.25, texels 40 to 48 from the top; a texel wider on every side.
    #[test]
    fn a_sphere_covers_the_texels_of_its_square() {
        let to_clip = Mat4::from_cols(
            glam::Vec4::new(0.125, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 0.5, 0.0),
            glam::Vec4::new(0.0, -0.125, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 0.5, 1.0),
        );
        let r = sphere_rect(to_clip, Vec3::new(2.0, 0.0, 3.0), 1.0, 64);
        assert_eq!(r, Some([35, 39, 45, 49]));
        // Half off the map: clamped; wholly off: none.
        let edge = sphere_rect(to_clip, Vec3::new(8.0, 0.0, 0.0), 1.0, 64);
        assert_eq!(edge, Some([59, 27, 64, 37]));
        assert_eq!(
            sphere_rect(to_clip, Vec3::new(16.0, 0.0, 0.0), 1.0, 64),
            None
        );
        // Back to clip space: x from 35/32 - 1, y from 1 - 49/32 (y up).
        assert_eq!(
            clip_rect([35, 39, 45, 49], 64),
            [0.09375, -0.53125, 0.40625, -0.21875]
        );
    }
}
