//! Gameplay probes over a manager's surfaces, whether they hold a heightmap or not.
//!
//! [`SnowManager::probe`] queues points and hands back a [`ManagedProbeTicket`]. At the next tick
//! each point is looked up among every registered surface (the topmost whose rectangle holds it
//! and whose ground is not above it, as [`crate::SnowWorld::probe`] does) and answered from where
//! that surface's snow is now:
//! - in the pool: by the world's probe pass, recorded first in the tick's encoder (so it reads
//!   the snow before the tick's evictions free any slot), read back without waiting;
//! - in the page store: on the CPU from the page, by the same rule as the GPU pass
//!   (`world/probe/cpu.rs`);
//! - never given a heightmap: untouched snow;
//! - a terrain window's level of the manager's (`terrain.rs`), when it is the topmost there:
//!   by the world's probe pass, as a resident surface (the finest level, outside the coarser
//!   levels' holes).
//!
//! A request with a point over a surface whose page is still on its way from the GPU waits for
//! the next tick. Imprints still queued for a surface are not in its samples yet (as with
//! [`SnowManager::read_heightmap`]).

use std::collections::HashMap;

use glam::Vec3;

use super::{ManagedId, SnowManager};
use crate::error::{Result, SnowError};
use crate::world::probe::cpu;
use crate::world::{
    MAX_PROBE_POINTS, MAX_UNCLAIMED_ANSWERS, ProbeSample, ProbeStatus, ProbeTicket,
};

/// A request for probe samples from a manager; ask [`SnowManager::probe_result`] for its answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ManagedProbeTicket(u64);

impl ManagedProbeTicket {
    /// The ticket's number (tickets of one manager count up from 0).
    pub fn number(self) -> u64 {
        self.0
    }
}

/// The snow under one point probed through a [`SnowManager`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManagedSample {
    /// The managed surface under the point, `None` when none is (a terrain window's level may
    /// be: [`ProbeSample::surface`] then names it).
    pub surface: Option<ManagedId>,
    /// The snow there. Its [`ProbeSample::surface`] is the world's handle when the sample was
    /// read from the pool, `None` when it came from a page or untouched snow.
    pub sample: ProbeSample,
}

/// The answer to a [`ManagedProbeTicket`].
#[derive(Clone, Debug, PartialEq)]
pub enum ManagedProbeStatus {
    /// Not answered yet: ask again after the next tick.
    Pending,
    /// The samples, one per point, in the order given. Handed over once.
    Ready(Vec<ManagedSample>),
}

/// Points of one request, each answered as soon as it can be.
#[derive(Debug)]
struct Request {
    ticket: u64,
    points: Vec<Vec3>,
    samples: Vec<Option<ManagedSample>>,
    /// For points read by the world's pass: (point, index in the world batch, surface; `None`
    /// over a terrain's level).
    from_world: Vec<(usize, usize, Option<ManagedId>)>,
    world: Option<ProbeTicket>,
}

/// The manager's probe state.
#[derive(Debug, Default)]
pub(super) struct ManagerProbes {
    next: u64,
    queued: Vec<Request>,
    queued_points: usize,
    /// Sent: waiting for the world's answer.
    sent: Vec<Request>,
    /// World answers taken and not yet used up by every request that shares them.
    world_answers: HashMap<ProbeTicket, Vec<ProbeSample>>,
    answers: HashMap<u64, Vec<ManagedSample>>,
    answer_order: std::collections::VecDeque<u64>,
}

impl SnowManager {
    /// Ask for the snow under `points` (world metres) over every registered surface, resident or
    /// not. The answer comes from [`SnowManager::probe_result`] after the next tick or two;
    /// nothing waits for the GPU. Fails with [`SnowError::InvalidProbePoint`] for a point that is
    /// not finite, [`SnowError::TooManyProbePoints`] past [`MAX_PROBE_POINTS`] points between two
    /// ticks (nothing is queued then).
    pub fn probe(&mut self, points: &[Vec3]) -> Result<ManagedProbeTicket> {
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(SnowError::InvalidProbePoint {
                index,
                value: format!("{:?}", points[index].to_array()),
            });
        }
        let p = &mut self.probes;
        if p.queued_points + points.len() > MAX_PROBE_POINTS {
            return Err(SnowError::TooManyProbePoints {
                asked: points.len(),
                queued: p.queued_points,
                max: MAX_PROBE_POINTS,
            });
        }
        let ticket = p.next;
        p.next += 1;
        p.queued_points += points.len();
        p.queued.push(Request {
            ticket,
            points: points.to_vec(),
            samples: vec![None; points.len()],
            from_world: Vec::new(),
            world: None,
        });
        Ok(ManagedProbeTicket(ticket))
    }

    /// The answer to a ticket (polling the device without waiting). A ticket answered once is
    /// forgotten; asking again, or for a ticket this manager never gave, fails with
    /// [`SnowError::UnknownProbe`].
    pub fn probe_result(&mut self, ticket: ManagedProbeTicket) -> Result<ManagedProbeStatus> {
        self.collect_world_answers()?;
        if let Some(samples) = self.probes.answers.remove(&ticket.0) {
            return Ok(ManagedProbeStatus::Ready(samples));
        }
        let p = &self.probes;
        let known = p.queued.iter().chain(&p.sent).any(|r| r.ticket == ticket.0);
        if known {
            Ok(ManagedProbeStatus::Pending)
        } else {
            Err(SnowError::UnknownProbe { ticket: ticket.0 })
        }
    }

    /// Answer the queued requests that can be answered now, and record the world's probe pass
    /// for their points over resident surfaces into `enc` (the tick's encoder, before its
    /// residency changes).
    pub(super) fn send_probes(&mut self, enc: &mut wgpu::CommandEncoder) -> Result<()> {
        if self.probes.queued.is_empty() {
            return Ok(());
        }
        let mut world_points = Vec::new();
        let mut waiting = Vec::new();
        let mut pages = HashMap::new();
        for mut r in std::mem::take(&mut self.probes.queued) {
            if !self.resolve(&mut r, &mut world_points, &mut pages)? {
                waiting.push(r);
                continue;
            }
            self.probes.queued_points -= r.points.len();
            if r.from_world.is_empty() {
                self.finish(r);
            } else {
                self.probes.sent.push(r);
            }
        }
        self.probes.queued = waiting;
        if world_points.is_empty() {
            return Ok(());
        }
        let ticket = match self.world.probe(&world_points) {
            Ok(t) => t,
            Err(SnowError::ProbeRingFull { .. }) => {
                // Every batch is in flight: the requests go back to the queue for the next tick.
                let sent: Vec<Request> = self
                    .probes
                    .sent
                    .extract_if(.., |r| r.world.is_none())
                    .collect();
                for mut r in sent {
                    self.probes.queued_points += r.points.len();
                    r.samples.iter_mut().for_each(|s| *s = None);
                    r.from_world.clear();
                    self.probes.queued.push(r);
                }
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        for r in self.probes.sent.iter_mut().filter(|r| r.world.is_none()) {
            r.world = Some(ticket);
        }
        self.world.encode_probes(enc);
        Ok(())
    }

    /// Answer what the CPU can of a request, and list its points over resident surfaces in
    /// `world_points`. Returns `false` (nothing changed) when a point lies over a surface whose
    /// page is still on its way.
    fn resolve(
        &self,
        r: &mut Request,
        world_points: &mut Vec<Vec3>,
        pages: &mut HashMap<u32, PageChannels>,
    ) -> Result<bool> {
        let under: Vec<Option<ManagedId>> =
            r.points.iter().map(|&p| self.managed_under(p)).collect();
        // Points where a terrain level is the topmost: the world's pass answers them (it picks
        // the level, or a resident surface above it).
        let on_level: Vec<bool> = r
            .points
            .iter()
            .zip(&under)
            .map(|(&p, id)| self.level_is_topmost(p, *id))
            .collect();
        if under
            .iter()
            .flatten()
            .any(|id| self.arriving.iter().any(|a| a.ids.contains(id)))
        {
            return Ok(false);
        }
        for (k, (&point, id)) in r.points.iter().zip(under).enumerate() {
            if on_level[k] {
                r.from_world.push((k, world_points.len(), None));
                world_points.push(point);
                continue;
            }
            let Some(id) = id else {
                r.samples[k] = Some(ManagedSample {
                    surface: None,
                    sample: cpu::outside(point),
                });
                continue;
            };
            if self.world_id(id).is_some() {
                r.from_world.push((k, world_points.len(), Some(id)));
                world_points.push(point);
                continue;
            }
            let desc = self.planner.surface(id)?;
            let sample = match self.pages.get(id.0) {
                Some(page) => {
                    let c = match pages.entry(id.0) {
                        std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                        std::collections::hash_map::Entry::Vacant(e) => {
                            e.insert(PageChannels::of(page)?)
                        }
                    };
                    cpu::sample(
                        desc,
                        &c.layout,
                        c.precision,
                        (&c.depression, &c.displaced),
                        (None, self.ground_field(id)),
                        point,
                    )
                }
                None => cpu::untouched_on(desc, self.ground_field(id), point),
            };
            r.samples[k] = Some(ManagedSample {
                surface: Some(id),
                sample,
            });
        }
        Ok(true)
    }

    /// Whether a terrain level of the manager's lies over `point` (outside its hole) with its
    /// ground not below that of `managed`, the topmost managed surface there.
    fn level_is_topmost(&self, point: Vec3, managed: Option<ManagedId>) -> bool {
        let top = |id: crate::SurfaceId| -> Option<f32> {
            let desc = self.world.surface(id).ok()?;
            let field = self.world.ground(id).ok()?;
            let hole = self.world.hole(id).ok()?;
            cpu::over_outside_hole(desc, field, hole, point)
        };
        let Some(level) = self.level_ids().filter_map(top).reduce(f32::max) else {
            return false;
        };
        let managed = managed.and_then(|id| {
            let desc = self.planner.surface(id).ok()?;
            cpu::over_on(desc, self.ground_field(id), point)
        });
        managed.is_none_or(|m| level >= m)
    }

    /// The topmost registered surface over a point (see [`crate::ProbeSample::surface`]).
    fn managed_under(&self, point: Vec3) -> Option<ManagedId> {
        let mut best: Option<(f32, ManagedId)> = None;
        for (id, _) in self.surface_names() {
            let Ok(desc) = self.planner.surface(id) else {
                continue;
            };
            match cpu::over_on(desc, self.ground_field(id), point) {
                Some(ground) if best.is_none_or(|b| b.0 < ground) => best = Some((ground, id)),
                _ => {}
            }
        }
        best.map(|b| b.1)
    }

    /// Move the requests whose world samples have arrived to the answers.
    fn collect_world_answers(&mut self) -> Result<()> {
        let tickets: Vec<ProbeTicket> = {
            let mut t: Vec<ProbeTicket> = self.probes.sent.iter().filter_map(|r| r.world).collect();
            t.dedup();
            t
        };
        for t in tickets {
            if self.probes.world_answers.contains_key(&t) {
                continue;
            }
            if let ProbeStatus::Ready(samples) = self.world.probe_result(t)? {
                self.probes.world_answers.insert(t, samples);
            }
        }
        let ready: Vec<Request> = self
            .probes
            .sent
            .extract_if(.., |r| {
                r.world
                    .is_some_and(|t| self.probes.world_answers.contains_key(&t))
            })
            .collect();
        for mut r in ready {
            let t = r.world.expect("filtered above");
            let answer = &self.probes.world_answers[&t];
            for &(k, at, id) in &r.from_world {
                let sample = answer[at];
                // Over a level, the world may have answered from a resident surface above it.
                let surface = id.or_else(|| {
                    let w = sample.surface?;
                    let i = self.world_ids.iter().position(|&x| x == Some(w))?;
                    Some(ManagedId(i as u32))
                });
                r.samples[k] = Some(ManagedSample { surface, sample });
            }
            if !self.probes.sent.iter().any(|s| s.world == Some(t)) {
                self.probes.world_answers.remove(&t);
            }
            self.finish(r);
        }
        Ok(())
    }

    fn finish(&mut self, r: Request) {
        let samples = r.samples.into_iter().flatten().collect();
        let p = &mut self.probes;
        p.answers.insert(r.ticket, samples);
        p.answer_order.push_back(r.ticket);
        // Answers nobody asks for are forgotten, oldest first.
        while p.answers.len() > MAX_UNCLAIMED_ANSWERS {
            match p.answer_order.pop_front() {
                Some(old) => {
                    p.answers.remove(&old);
                }
                None => break,
            }
        }
    }
}

/// A page's channels, decompressed once per tick for the points over it.
struct PageChannels {
    layout: crate::surface::SurfaceLayout,
    precision: crate::pool::Precision,
    depression: Vec<u32>,
    displaced: Vec<u32>,
}

impl PageChannels {
    fn of(page: &super::pages::Page) -> Result<Self> {
        let snap = page.decompress()?;
        let heights = snap.format.heights_bytes(snap.width, snap.height) as usize / 4;
        let words = snap
            .words
            .get(..heights)
            .ok_or_else(|| SnowError::Snapshot {
                name: snap.desc.name.clone(),
                reason: format!(
                    "its page holds {} words, its heights need {heights}",
                    snap.words.len()
                ),
            })?;
        let (depression, displaced) = snap.format.decode(snap.width, snap.height, words)?;
        Ok(Self {
            layout: crate::surface::SurfaceLayout {
                width: snap.width,
                height: snap.height,
            },
            precision: snap.format.precision,
            depression,
            displaced,
        })
    }
}
