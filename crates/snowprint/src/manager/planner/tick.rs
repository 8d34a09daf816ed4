//! The tick: checks, touches, activity, then residency and budget (see the module docs).

use glam::Vec3;

use super::surface::plausible;
use super::{LISTED, REMOVED, RESIDENT, SNOWFALL, WANTED};
use super::{Plan, Planner, TOUCH_MARGIN, sweep_with};
use crate::deformer::Shape;
use crate::error::{Result, SnowError};
use crate::manager::quadtree::Aabb;
use crate::manager::queue;
use crate::manager::{CameraView, Frustum, ManagedDeformer, TickStats};

impl Planner {
    /// Run one frame: `dt` seconds passed, the camera (if any) looks at the world and the deformers
    /// are posed as at the end of the frame (with `previous` = last frame's pose for a sweep).
    /// Everything is checked before anything changes.
    pub fn tick(
        &mut self,
        dt: f32,
        camera: Option<&CameraView>,
        deformers: &[ManagedDeformer],
    ) -> Result<&Plan> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(SnowError::InvalidTimeStep { dt });
        }
        let frustum = camera.map(CameraView::frustum).transpose()?;
        let mut sweeps = std::mem::take(&mut self.sweeps);
        let checked = self.sweep_all(deformers, &mut sweeps);
        if let Err(e) = checked {
            self.sweeps = sweeps;
            return Err(e);
        }
        self.ensure_index();
        self.tick += 1;
        self.time += dt as f64;
        let now = self.tick;
        self.plan.changes.clear();
        self.plan.updates.clear();
        self.plan.stats = TickStats {
            frame: now - 1,
            evicted: std::mem::take(&mut self.evicted_between),
            ..TickStats::default()
        };
        let mut scratch = std::mem::take(&mut self.scratch);

        // 1. Touches.
        self.touch(now, deformers, &sweeps, &mut scratch);
        self.sweeps = sweeps;
        self.plan.stats.touched = self.touched.len();
        let focus = deformers
            .iter()
            .find(|d| d.player)
            .map(|d| d.deformer.pose.position)
            .or(camera.map(|c| c.eye));

        // 2. Activity.
        let seen = camera.zip(frustum.as_ref());
        self.update_activity(now, seen, &mut scratch);

        // 3. Residency.
        self.admit(now, focus);

        // 4. Budget.
        self.schedule(now, focus);

        // 5. The queues of surfaces still waiting are bounded, conservatively.
        self.bound_queues();

        self.scratch = scratch;
        self.count_waiting(now);
        Ok(&self.plan)
    }

    /// Check every deformer and fill `sweeps` with their swept bounds (see [`Self::sweep_of`]).
    fn sweep_all(
        &self,
        deformers: &[ManagedDeformer],
        sweeps: &mut Vec<(Vec3, Vec3, f32)>,
    ) -> Result<()> {
        sweeps.clear();
        for (i, d) in deformers.iter().enumerate() {
            if !plausible(&d.deformer) {
                d.deformer.validate_named(|| format!("#{i}"))?;
            }
            sweeps.push(self.sweep_of(&d.deformer)?);
        }
        Ok(())
    }

    /// Queue each deformer on the surfaces of loaded zones its sweep touches.
    fn touch(
        &mut self,
        now: u64,
        deformers: &[ManagedDeformer],
        sweeps: &[(Vec3, Vec3, f32)],
        scratch: &mut Vec<u32>,
    ) {
        self.touched.clear();
        // The deformers themselves are read only where they touch something.
        for (k, &(a, b, r)) in sweeps.iter().enumerate() {
            let m = Vec3::splat(r + TOUCH_MARGIN);
            self.lookup_into(&Aabb::new(a.min(b) - m, a.max(b) + m), scratch);
            for &i in scratch.iter() {
                let v = &self.volumes[i as usize];
                if !v.touched_by(a, b, r) || !self.zone_loaded[v.zone as usize] {
                    continue;
                }
                let d = &deformers[k];
                let st = &mut self.status[i as usize];
                if st.touched != now {
                    st.touched = now;
                    self.touched.push(i);
                }
                if d.player {
                    st.player = now;
                }
                let skip_applied = !st.has(SNOWFALL);
                let radii = &self.mesh_radius;
                let m = &mut self.surfaces[i as usize];
                let layout = m.desc.layout();
                let texel =
                    (m.desc.size.x / layout.width as f32).max(m.desc.size.y / layout.height as f32);
                let isolation = queue::Isolation {
                    tick: sweeps,
                    index: k,
                    sweep: &|d| sweep_with(radii, d),
                    // The blur's one texel, and one more for where a print's edge falls.
                    reach: 2.0 * texel,
                };
                queue::push(
                    &mut m.queue,
                    &m.applied,
                    skip_applied,
                    now,
                    d.deformer,
                    &isolation,
                );
                st.queue_len = m.queue.len() as u32;
                if st.queue_len > 0 && !st.has(LISTED) {
                    st.set(LISTED, true);
                    self.queued.push(i);
                }
            }
        }
    }

    /// Mark this tick's active surfaces: seen by the camera (`seen`) and near its eye, touched, or
    /// with imprints waiting; surfaces that stop being active are no longer due.
    fn update_activity(
        &mut self,
        now: u64,
        seen: Option<(&CameraView, &Frustum)>,
        scratch: &mut Vec<u32>,
    ) {
        self.active_next.clear();
        if let Some((cam, frustum)) = seen {
            let reach = Vec3::splat(self.config.active_distance);
            self.lookup_into(&Aabb::new(cam.eye - reach, cam.eye + reach), scratch);
            for &i in scratch.iter() {
                let s = &self.status[i as usize];
                // The bounding sphere of the surface's box.
                let (centre, radius) = (
                    (s.bounds.min + s.bounds.max) * 0.5,
                    (s.bounds.max - s.bounds.min).length() * 0.5,
                );
                if self.zone_loaded[s.zone as usize]
                    && s.bounds.distance_to(cam.eye) <= self.config.active_distance
                    && frustum.sees(centre, radius)
                {
                    self.activate(i, now);
                }
            }
        }
        for k in 0..self.touched.len() {
            self.activate(self.touched[k], now);
        }
        let mut k = 0;
        while k < self.queued.len() {
            let i = self.queued[k];
            let s = &mut self.status[i as usize];
            if (s.queue_len == 0 && !s.has(WANTED)) || s.has(REMOVED) {
                s.set(LISTED, false);
                self.queued.swap_remove(k);
                continue;
            }
            if self.zone_loaded[s.zone as usize] {
                self.activate(i, now);
            }
            k += 1;
        }
        let previous = std::mem::take(&mut self.active);
        // In index order, so that the plan does not depend on the order of lookups.
        let mut gone: Vec<u32> = previous
            .iter()
            .copied()
            .filter(|&i| {
                let s = &self.status[i as usize];
                s.active != now && !s.has(REMOVED)
            })
            .collect();
        gone.sort_unstable();
        // An inactive surface keeps its heightmap until the memory is wanted.
        for i in gone {
            self.surfaces[i as usize].due_since = None;
        }
        self.active = std::mem::take(&mut self.active_next);
        self.active_next = previous;
        self.plan.stats.active = self.active.len();
    }

    /// The plan's closing statistics: the pool, the queues, and who waits for memory.
    fn count_waiting(&mut self, now: u64) {
        let st = &mut self.plan.stats;
        st.resident = self.resident.len();
        st.pool_bytes_used = self.alloc.used();
        st.pool_bytes_budget = self.alloc.budget();
        let mut waiting_for_memory = 0;
        let mut queued = 0;
        for &i in &self.queued {
            let s = &self.status[i as usize];
            queued += s.queue_len as usize;
            if !s.has(RESIDENT) && s.queue_len > 0 && s.active == now {
                waiting_for_memory += 1;
            }
        }
        st.queued_imprints = queued;
        st.waiting_for_memory = waiting_for_memory;
    }

    /// Bound the queue of every surface left waiting this tick (see [`queue::bound`]).
    fn bound_queues(&mut self) {
        let cap = self.config.queue_cap;
        let mut merged = 0;
        for k in 0..self.queued.len() {
            let i = self.queued[k] as usize;
            if (self.status[i].queue_len as usize) <= cap {
                continue;
            }
            let radii = &self.mesh_radius;
            let radius = |shape: &Shape| match shape {
                Shape::Mesh(id) => radii.get(id.0 as usize).copied().flatten().unwrap_or(0.0),
                s => s.bounding_radius().unwrap_or(0.0),
            };
            let q = &mut self.surfaces[i].queue;
            merged += queue::bound(q, cap, radius) as u64;
            self.status[i].queue_len = q.len() as u32;
        }
        self.plan.stats.imprints_merged = merged;
        self.merged_total += merged;
    }

    fn activate(&mut self, i: u32, now: u64) {
        let s = &mut self.status[i as usize];
        if s.active != now {
            s.active = now;
            self.active_next.push(i);
        }
    }
}
