//! The budget: which due surfaces are updated this frame.

use glam::Vec3;

use super::{ManagedId, PlannedUpdate, Planner, SNOWFALL};
use crate::deformer::Deformer;

impl Planner {
    /// Pick at most K due surfaces and hand them their queued imprints.
    pub(super) fn schedule(&mut self, now: u64, focus: Option<Vec3>) {
        let slack_max = self.config.distance_slack_frames as u64;
        let reach = self.config.active_distance.max(f32::MIN_POSITIVE);
        // (deadline, due since, index, player)
        let mut due: Vec<(u64, u64, u32, bool)> = Vec::new();
        for &i in &self.resident {
            let st = &self.status[i as usize];
            if st.active != now {
                continue;
            }
            let s = &mut self.surfaces[i as usize];
            if s.due_since.is_none() {
                let replenish = st.has(SNOWFALL)
                    && s.pressed_until > s.last_update_time
                    && self.time - s.last_update_time >= self.config.replenish_interval as f64;
                if st.queue_len > 0 || replenish {
                    s.due_since = Some(now);
                }
            }
            let Some(since) = s.due_since else { continue };
            let player = st.player == now;
            let slack = if player {
                0
            } else if st.queue_len == 0 {
                slack_max
            } else {
                let d = focus.map_or(0.0, |f| st.bounds.distance_to(f));
                (slack_max as f32 * (d / reach).min(1.0)).round() as u64
            };
            due.push((since + slack, since, i, player));
        }
        self.plan.stats.due = due.len();
        let k = self.budget();
        due.sort_unstable();
        let mut pick: Vec<u32> = Vec::with_capacity(k.min(due.len()));
        let mut max_wait = 0;
        if due.len() <= k {
            // Everything due fits: player's first, then by deadline.
            pick.extend(due.iter().filter(|d| d.3).map(|d| d.2));
            pick.extend(due.iter().filter(|d| !d.3).map(|d| d.2));
        } else {
            // The player's surfaces take up to the reserved slots, then earliest deadline first.
            let reserved = k - self.non_player_slots();
            let mut taken = vec![false; due.len()];
            for (n, d) in due.iter().enumerate() {
                if pick.len() >= reserved {
                    break;
                }
                if d.3 {
                    pick.push(d.2);
                    taken[n] = true;
                }
            }
            for (n, d) in due.iter().enumerate() {
                if pick.len() >= k {
                    break;
                }
                if !taken[n] {
                    pick.push(d.2);
                    taken[n] = true;
                }
            }
            for (n, &(_, since, _, _)) in due.iter().enumerate() {
                if !taken[n] {
                    max_wait = max_wait.max(now - since);
                }
            }
        }
        for i in pick {
            let time = self.time;
            let s = &mut self.surfaces[i as usize];
            let since = s.due_since.take().unwrap_or(now);
            let queued = std::mem::take(&mut s.queue);
            let frames: Vec<u64> = queued.iter().map(|e| e.frame).collect();
            let imprints: Vec<Deformer> = queued.into_iter().map(|e| e.deformer).collect();
            self.status[i as usize].queue_len = 0;
            let elapsed = (time - s.last_update_time) as f32;
            s.last_update_time = time;
            if !imprints.is_empty() && s.desc.replenish_rate > 0.0 {
                s.pressed_until = time + 1.0 / s.desc.replenish_rate as f64;
            }
            s.applied.clear();
            s.applied.extend_from_slice(&imprints);
            max_wait = max_wait.max(now - since);
            self.plan.stats.updated.push(s.desc.name.clone());
            self.plan.updates.push(PlannedUpdate {
                surface: ManagedId(i),
                elapsed,
                wait_frames: now - since,
                imprints,
                frames,
            });
        }
        self.plan.stats.max_wait_frames = max_wait;
    }
}
