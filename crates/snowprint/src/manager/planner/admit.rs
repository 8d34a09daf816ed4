//! Residency: active surfaces without a slot get one, most useful first, evicting less useful ones.

use glam::Vec3;

use super::surface::{ByUse, Rank};
use super::{ARRIVING, ManagedId, PAGED, Planner, RESIDENT, ResidencyChange, WANTED};
use crate::pool::{Slot, SlotAllocator};

impl Planner {
    /// Give slots to active surfaces without one, most useful first, evicting less useful ones.
    pub(super) fn admit(&mut self, now: u64, focus: Option<Vec3>) {
        let mut victims: Vec<Rank> = self
            .resident
            .iter()
            .map(|&i| self.rank(i, now, focus))
            .collect();
        victims.sort_unstable_by(Rank::least_useful_first);
        let weakest = victims.first().copied();
        let largest_free = self.alloc.largest_free();
        let mut candidates: Vec<ByUse> = Vec::new();
        let mut best: Option<ByUse> = None;
        for &i in &self.active {
            let s = &self.status[i as usize];
            if s.has(RESIDENT) || s.has(ARRIVING) {
                continue;
            }
            let r = ByUse(self.rank(i, now, focus));
            // Cheap filter: it fits as things are, or it could evict the weakest resident.
            if s.bytes as u64 <= largest_free || weakest.is_some_and(|w| w.evictable_for(&r.0)) {
                best = best.max(Some(r));
                candidates.push(r);
            }
        }
        let Some(best) = best else { return };
        // The largest room any candidate can make: what the most useful one frees by evicting all
        // it may (eviction is monotone in usefulness). Larger candidates cannot get a slot now.
        let mut trial = self.alloc.clone();
        for v in victims.iter().take_while(|v| v.evictable_for(&best.0)) {
            if let Some(slot) = self.surfaces[v.index as usize].slot {
                trial.free(slot);
            }
        }
        let room = trial.largest_free();
        candidates.retain(|c| self.status[c.0.index as usize].bytes as u64 <= room);
        let smallest = candidates
            .iter()
            .map(|c| self.status[c.0.index as usize].bytes as u64)
            .min()
            .unwrap_or(u64::MAX);
        // Most useful first, popped only as far as needed (a heap builds in linear time; a city of
        // walkers can have hundreds of candidates for a handful of slots).
        let mut candidates = std::collections::BinaryHeap::from(candidates);
        let mut evicted = vec![false; victims.len()];
        let mut weakest_alive = 0;
        let mut chosen: Vec<usize> = Vec::new();
        // Evicting can only get less from here on: a candidate at least this large cannot fit.
        let mut hopeless = u64::MAX;
        while let Some(ByUse(cand)) = candidates.pop() {
            while weakest_alive < victims.len() && evicted[weakest_alive] {
                weakest_alive += 1;
            }
            let can_evict = victims
                .get(weakest_alive)
                .is_some_and(|v| v.evictable_for(&cand));
            // Eviction is monotone in usefulness: if this candidate cannot evict the weakest
            // resident, no later (less useful) one can; only free room is left for them.
            let free = self.alloc.largest_free();
            if (!can_evict || smallest >= hopeless) && free < smallest {
                break;
            }
            let bytes = self.status[cand.index as usize].bytes as u64;
            if bytes <= free
                && let Some(slot) = self.alloc.alloc(bytes)
            {
                self.give_slot(cand.index, slot);
                continue;
            }
            if !can_evict || bytes >= hopeless {
                continue;
            }
            // Try evicting the least useful residents, on a copy, until it fits.
            chosen.clear();
            let mut trial: Option<SlotAllocator> = None;
            let mut fits = false;
            // Every eviction pages a heightmap out: the page store must have room for it.
            let mut paged = self.paged_bound;
            for (v, rank) in victims.iter().enumerate().skip(weakest_alive) {
                if evicted[v] {
                    continue;
                }
                if !rank.evictable_for(&cand) {
                    break;
                }
                let Some(slot) = self.surfaces[rank.index as usize].slot else {
                    continue;
                };
                paged += self.status[rank.index as usize].bytes as u64;
                if paged > self.config.page_bytes {
                    break;
                }
                let t = trial.get_or_insert_with(|| self.alloc.clone());
                t.free(slot);
                chosen.push(v);
                if t.largest_free() >= bytes {
                    fits = true;
                    break;
                }
            }
            if !fits {
                // Later candidates can evict at most what this one could.
                hopeless = hopeless.min(bytes);
                continue;
            }
            for &v in &chosen {
                evicted[v] = true;
                self.release(victims[v].index, false, true);
            }
            if let Some(slot) = self.alloc.alloc(bytes) {
                self.give_slot(cand.index, slot);
            }
        }
    }

    fn give_slot(&mut self, index: u32, slot: Slot) {
        let s = &mut self.surfaces[index as usize];
        let st = &mut self.status[index as usize];
        s.slot = Some(slot);
        s.resident_pos = self.resident.len();
        if st.has(PAGED) {
            // Its heightmap comes back as it was: snowfall refills from its last update on.
            st.set(PAGED, false);
            self.paged_bound -= st.bytes as u64;
        } else {
            s.last_update_time = self.time;
            s.pressed_until = 0.0;
        }
        s.applied.clear();
        s.due_since = None;
        st.set(WANTED, false);
        st.set(RESIDENT, true);
        self.resident.push(index);
        self.plan
            .changes
            .push(ResidencyChange::Admit(ManagedId(index)));
    }
}
