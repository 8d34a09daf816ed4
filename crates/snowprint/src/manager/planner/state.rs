//! The planner's state for saves, and a planner rebuilt from one (every part checked).

use std::collections::HashMap;

use super::{LISTED, PAGED, Planner, REMOVED, RESIDENT, WANTED};
use crate::deformer::Deformer;
use crate::error::{Result, SnowError};
use crate::manager::queue::Imprint;
use crate::manager::{ManagerConfig, ZoneId};
use crate::mesh::MeshId;
use crate::surface::SurfaceDesc;

/// One surface of a [`PlannerState`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct SurfaceState {
    pub(crate) desc: SurfaceDesc,
    pub(crate) zone: ZoneId,
    pub(crate) removed: bool,
    pub(crate) paged: bool,
    pub(crate) wanted: bool,
    /// Tick stamps: last touched, by the player, last active.
    pub(crate) stamps: [u64; 3],
    /// `(offset, bytes)` of its slot while resident.
    pub(crate) slot: Option<(u64, u64)>,
    pub(crate) queue: Vec<Imprint>,
    pub(crate) applied: Vec<Deformer>,
    pub(crate) due_since: Option<u64>,
    pub(crate) last_update_time: f64,
    pub(crate) pressed_until: f64,
}

/// Everything a [`Planner`] decides from, for saves: a planner rebuilt from it plans exactly as
/// the one it was taken from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct PlannerState {
    pub(crate) tick: u64,
    pub(crate) time: f64,
    pub(crate) merged_total: u64,
    /// Zones in the order the planner met them, with whether they are loaded.
    pub(crate) zones: Vec<(ZoneId, bool)>,
    /// Bounding radius of each world mesh, by its index.
    pub(crate) mesh_radius: Vec<Option<f32>>,
    pub(crate) surfaces: Vec<SurfaceState>,
    pub(crate) active: Vec<u32>,
    pub(crate) resident: Vec<u32>,
    pub(crate) queued: Vec<u32>,
    pub(crate) evicted_between: Vec<String>,
}

impl Planner {
    /// The planner's state (see [`PlannerState`]).
    pub(crate) fn state(&self) -> PlannerState {
        let mut zones = vec![(ZoneId(0), true); self.zone_loaded.len()];
        for (&id, &z) in &self.zones {
            zones[z] = (id, self.zone_loaded[z]);
        }
        PlannerState {
            tick: self.tick,
            time: self.time,
            merged_total: self.merged_total,
            zones,
            mesh_radius: self.mesh_radius.clone(),
            surfaces: self
                .surfaces
                .iter()
                .zip(&self.status)
                .map(|(m, st)| SurfaceState {
                    desc: m.desc.clone(),
                    zone: zones_id(&self.zones, st.zone),
                    removed: st.has(REMOVED),
                    paged: st.has(PAGED),
                    wanted: st.has(WANTED),
                    stamps: [st.touched, st.player, st.active],
                    slot: m.slot.map(|s| (s.offset, s.bytes)),
                    queue: m.queue.iter().copied().collect(),
                    applied: m.applied.clone(),
                    due_since: m.due_since,
                    last_update_time: m.last_update_time,
                    pressed_until: m.pressed_until,
                })
                .collect(),
            active: self.active.clone(),
            resident: self.resident.clone(),
            queued: self.queued.clone(),
            evicted_between: self.evicted_between.clone(),
        }
    }

    /// A planner with `config` that continues from `state`, every part of it checked (a state
    /// read from a file may be anything): one sentence for the first thing that is wrong.
    pub(crate) fn from_state(config: &ManagerConfig, state: PlannerState) -> Result<Self> {
        let bad = |what: String| {
            Err(SnowError::SaveContent(format!(
                "saved planner state: {what}"
            )))
        };
        let mut p = Planner::new(config)?;
        if !(state.time.is_finite() && state.time >= 0.0) {
            return bad(format!(
                "time {} is not a finite number of seconds",
                state.time
            ));
        }
        for &(zone, loaded) in &state.zones {
            if p.zones.contains_key(&zone) {
                return bad(format!("zone {} is listed twice", zone.0));
            }
            let z = p.zone_index(zone);
            p.zone_loaded[z] = loaded;
        }
        for (i, r) in state.mesh_radius.iter().enumerate() {
            if let Some(r) = *r {
                p.set_mesh_radius(MeshId(i as u32), r)?;
            }
        }
        let n = state.surfaces.len();
        let index_ok = |list: &[u32], what: &str| -> Result<()> {
            let mut seen = vec![false; n];
            for &i in list {
                if i as usize >= n || std::mem::replace(&mut seen[i as usize], true) {
                    return Err(SnowError::SaveContent(format!(
                        "saved planner state: {what} names surface {i} of {n}, or twice"
                    )));
                }
            }
            Ok(())
        };
        index_ok(&state.active, "the active list")?;
        index_ok(&state.resident, "the resident list")?;
        index_ok(&state.queued, "the queued list")?;
        for (i, s) in state.surfaces.into_iter().enumerate() {
            let id = p.add_surface(&s.desc, s.zone)?;
            let stamps_ok = s.stamps.iter().all(|&t| t <= state.tick);
            let times_ok = [s.last_update_time, s.pressed_until]
                .iter()
                .all(|t| t.is_finite() && *t >= 0.0);
            if !stamps_ok || !times_ok || s.due_since.is_some_and(|d| d > state.tick) {
                return bad(format!(
                    "surface {:?} has stamps past the clock",
                    s.desc.name
                ));
            }
            if s.queue.iter().any(|e| e.frame > state.tick)
                || s.queue
                    .iter()
                    .zip(s.queue.iter().skip(1))
                    .any(|(a, b)| a.frame > b.frame)
            {
                return bad(format!(
                    "surface {:?}'s queue is out of frame order",
                    s.desc.name
                ));
            }
            for (k, d) in s
                .queue
                .iter()
                .map(|e| &e.deformer)
                .chain(&s.applied)
                .enumerate()
            {
                d.validate_named(|| format!("{} imprint #{k}", s.desc.name))?;
                p.sweep_of(d)?;
            }
            let st = &mut p.status[i];
            st.touched = s.stamps[0];
            st.player = s.stamps[1];
            st.active = s.stamps[2];
            st.set(REMOVED, s.removed);
            st.set(WANTED, s.wanted);
            if s.paged {
                st.set(PAGED, true);
                p.paged_bound += st.bytes as u64;
            }
            st.queue_len = s.queue.len() as u32;
            let m = &mut p.surfaces[id.0 as usize];
            m.queue = s.queue.into();
            m.applied = s.applied;
            m.due_since = s.due_since;
            m.last_update_time = s.last_update_time;
            m.pressed_until = s.pressed_until;
            if let Some((offset, bytes)) = s.slot {
                if bytes != p.status[i].bytes as u64 || s.paged || s.removed {
                    return bad(format!(
                        "surface {:?} holds a slot of {bytes} bytes that does not fit its state",
                        p.surfaces[i].desc.name
                    ));
                }
                let Some(slot) = p.alloc.alloc_at(offset, bytes) else {
                    return bad(format!(
                        "surface {:?}'s slot at {offset} overlaps another or leaves the pool",
                        p.surfaces[i].desc.name
                    ));
                };
                p.surfaces[i].slot = Some(slot);
                p.status[i].set(RESIDENT, true);
            }
        }
        let resident: Vec<u32> = (0..n as u32)
            .filter(|&i| p.status[i as usize].has(RESIDENT))
            .collect();
        if resident.len() != state.resident.len()
            || state
                .resident
                .iter()
                .any(|&i| !p.status[i as usize].has(RESIDENT))
        {
            return bad("the resident list does not match the surfaces' slots".into());
        }
        for (pos, &i) in state.resident.iter().enumerate() {
            p.surfaces[i as usize].resident_pos = pos;
        }
        p.resident = state.resident;
        for &i in &state.queued {
            p.status[i as usize].set(LISTED, true);
        }
        if (0..n).any(|i| {
            let st = &p.status[i];
            st.queue_len > 0 && !st.has(REMOVED) && !st.has(LISTED)
        }) {
            return bad("a surface with queued imprints is missing from the queued list".into());
        }
        p.queued = state.queued;
        p.active = state.active;
        p.tick = state.tick;
        p.time = state.time;
        p.merged_total = state.merged_total;
        p.evicted_between = state.evicted_between;
        Ok(p)
    }
}

/// The caller's id of the zone with index `z`.
fn zones_id(zones: &HashMap<ZoneId, usize>, z: u32) -> ZoneId {
    zones
        .iter()
        .find(|&(_, &i)| i == z as usize)
        .map_or(ZoneId(0), |(&id, _)| id)
}
