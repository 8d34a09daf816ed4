//! CPU references of the kicked-up snow, written from what the passes promise rather than from
//! their WGSL: which texels spawn is read off the heights before and after an update (not
//! recomputed from the capture, as `spawn.wgsl` does), the ring's bookkeeping is counted by hand,
//! and a particle's step is the semi-implicit Euler step written out.

use super::{Particle, SprayRecord};

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

/// One simulation step of a particle: gravity, then its own drag, then the move; life runs down
/// to 0. A dead particle (life 0) stays as it is.
pub fn integrate(p: &Particle, dt: f32, gravity: f32) -> Particle {
    if p.life <= 0.0 {
        return *p;
    }
    let mut v = p.velocity;
    v[1] -= gravity * dt;
    for c in &mut v {
        *c /= 1.0 + p.drag * dt;
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

/// particle.wgsl's `spray_hash`: a number in [0, 1] from two words.
pub fn spray_hash(a: u32, b: u32) -> f32 {
    let mut v = a
        .wrapping_mul(747796405)
        .wrapping_add(b.wrapping_mul(2891336453))
        .wrapping_add(12345);
    v = ((v >> ((v >> 28) + 4)) ^ v).wrapping_mul(277803737);
    v ^= v >> 22;
    (v >> 8) as f32 * (1.0 / 16777215.0)
}

/// Whether the spawn in ring slot `slot` at world frame `frame` survives its material's amount.
pub fn kept(slot: u32, frame: u32, amount: f32) -> bool {
    amount >= 1.0 || spray_hash(slot, frame) < amount
}

/// A spawn's world particle after `place`, from its surface-local one (`age` still marking the
/// record), its slot, the world's frame and drag, and its surface's record; dead (life 0) when
/// thinned out.
pub fn place(local: &Particle, slot: u32, frame: u32, drag: f32, rec: &SprayRecord) -> Particle {
    let mut p = *local;
    p.age = 0.0;
    if !kept(slot, frame, rec.factors[0]) {
        p.life = 0.0;
        return p;
    }
    let m = glam::Mat4::from_cols_array(&rec.local_to_world);
    let v = glam::Vec3::from(local.velocity) * rec.factors[1];
    p.position = m.transform_point3(local.position.into()).into();
    p.velocity = m.transform_vector3(v).into();
    p.life = local.life * rec.factors[2];
    p.drag = drag * rec.factors[3];
    let unorm = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u32;
    let [r, g, b, radius] = rec.grain;
    p.albedo = unorm(r) | unorm(g) << 8 | unorm(b) << 16 | 255 << 24;
    p.radius = radius;
    p
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
            drag: 1.0,
            ..Particle::default()
        };
        let mut top: f32 = 0.0;
        for _ in 0..70 {
            p = integrate(&p, 1.0 / 60.0, 9.81);
            top = top.max(p.position[1]);
        }
        assert!(top > 0.2 && p.position[1] < top, "{top} {:?}", p.position);
        assert_eq!(p.life, 0.0);
        assert_eq!(integrate(&p, 0.1, 9.81), p);
    }
}
