//! CPU references of the kicked-up snow, written from what the passes promise rather than from
//! their WGSL: which texels spawn is read off the heights before and after an update (not
//! recomputed from the capture, as `spawn.wgsl` does), the ring's bookkeeping is counted by hand,
//! and a particle's step is the semi-implicit Euler step written out.

use super::Particle;

/// Texels (row-major indices) that spawn in an update, from the depression channel before and after
/// it, the update's replenishment (units) and the threshold (units): a texel spawns when the update
/// deepened it by more than the threshold beyond what it refilled, i.e. when
/// `after - (before - replenish)` exceeds it (`before - replenish` saturating at 0). Holds for
/// materials that do not slump (a slump moves the heights again after the update).
pub fn spawning_texels(
    before: &[u32],
    after: &[u32],
    replenish_units: u32,
    threshold_units: u32,
) -> Vec<usize> {
    assert_eq!(before.len(), after.len(), "before and after differ in size");
    before
        .iter()
        .zip(after)
        .enumerate()
        .filter(|(_, (b, a))| {
            let refilled = b.saturating_sub(replenish_units);
            a.saturating_sub(refilled) > threshold_units
        })
        .map(|(i, _)| i)
        .collect()
}

/// What the ring keeps of a frame's `requested` spawns at `capacity`: `(kept, dropped)`.
pub fn ring_fold(requested: u32, capacity: u32) -> (u32, u32) {
    let kept = requested.min(capacity);
    (kept, requested - kept)
}

/// One simulation step of a particle: gravity, then drag, then the move; life runs down to 0.
/// A dead particle (life 0) stays as it is.
pub fn integrate(p: &Particle, dt: f32, gravity: f32, drag: f32) -> Particle {
    if p.life <= 0.0 {
        return *p;
    }
    let mut v = p.velocity;
    v[1] -= gravity * dt;
    for c in &mut v {
        *c /= 1.0 + drag * dt;
    }
    let mut out = *p;
    out.velocity = v;
    for (x, dx) in out.position.iter_mut().zip(v) {
        *x += dx * dt;
    }
    out.life = (p.life - dt).max(0.0);
    out.age = p.age + dt;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn still_heights_spawn_nothing() {
        let h = vec![0, 10, 400, 65535];
        assert!(spawning_texels(&h, &h, 0, 0).is_empty());
        // A refill of 5 units that the capture pressed back: growth 5, under a threshold of 5.
        let after: Vec<u32> = h.clone();
        assert!(spawning_texels(&h, &after, 5, 5).is_empty());
        assert_eq!(spawning_texels(&h, &after, 5, 4), vec![1, 2, 3]);
    }

    #[test]
    fn ring_counts_what_it_drops() {
        assert_eq!(ring_fold(10, 16), (10, 0));
        assert_eq!(ring_fold(40, 16), (16, 24));
    }

    #[test]
    fn a_thrown_particle_rises_then_falls() {
        let mut p = Particle {
            position: [0.0; 3],
            life: 1.0,
            velocity: [1.0, 3.0, 0.0],
            age: 0.0,
        };
        let mut top: f32 = 0.0;
        for _ in 0..70 {
            p = integrate(&p, 1.0 / 60.0, 9.81, 1.0);
            top = top.max(p.position[1]);
        }
        assert!(top > 0.2 && p.position[1] < top, "{top} {:?}", p.position);
        assert_eq!(p.life, 0.0);
        assert_eq!(integrate(&p, 0.1, 9.81, 1.0), p);
    }
}
