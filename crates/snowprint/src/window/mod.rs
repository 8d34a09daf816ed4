//! A terrain-wide snow layer whose heightmap is a window that follows a focus (the player or the
//! camera): a clip map of nested levels, each one surface of a fixed texel size in the world's
//! pool, stored toroidally so that moving the window rewrites only the strips that enter it.
//!
//! Each frame the game gives [`Terrain::follow`] the focus; every level's window is centred on it,
//! snapped to whole texels of that level (`plan.rs`). When a level moves by `(dx, dz)` texels,
//! the strip that leaves is gathered from the pool (`strip.rs`, `strip.wgsl`) and paged out into
//! the terrain's store (`store.rs`), the strip that enters is written from the store (what was
//! paged out there before, else fresh snow) and the level's offsets and rectangle move: nothing
//! else in the pool is rewritten. Deformers are captured into every level as into any surface,
//! by the world's own update, under the same budget and pool; the far levels' coarse texels keep
//! the broad shape of trails that the near level has paged out.
//!
//! Every pass computes in logical texels (the capture's and the blur's space); only the pool's
//! texel functions map a logical texel to where it is stored (`pool/texel.wgsl`).

mod fold;
pub mod plan;
pub(crate) mod saved;
pub mod store;
pub mod strip;

use glam::{Vec2, Vec3};

use crate::error::{Result, SnowError};
use crate::ground::GroundField;
use crate::material::Material;
use crate::surface::{SurfaceDesc, SurfaceId, SurfaceLayout};
use crate::world::SnowWorld;
use strip::{Direction, StripGpu, StripParams};

/// How far inside a finer level's extent a coarser level's hole starts, in fine texels.
const HOLE_INSET: f32 = 0.25;

/// One level of a terrain's clip map: a window of `texels` at `texel_size` metres a texel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LevelDesc {
    /// Texels along world x and z.
    pub texels: [u32; 2],
    /// Texel side, metres.
    pub texel_size: f32,
}

/// The ground of a terrain that is not flat: heights over a world rectangle (metres above
/// [`TerrainDesc::ground_height`]), sampled at each level's texel centres (clamped at the
/// rectangle's edges), and how much snow its slopes hold.
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainGround {
    /// The heights, `columns x rows` samples across the rectangle (row 0 at its smallest z).
    pub grid: crate::ground::HeightGrid,
    /// World x and z of the rectangle's smallest corner, metres.
    pub origin: [f32; 2],
    /// Its sides along world x and z, metres.
    pub size: [f32; 2],
    /// How much snow its slopes hold.
    pub slope: crate::ground::SlopeRule,
}

/// A terrain-wide snow layer: its ground (flat at `ground_height`, or heights over the world
/// with `ground`), its snow and its levels, finest first (e.g. near 1024^2 at 5 cm, far 512^2 at
/// 40 cm).
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainDesc {
    /// Name; level `i`'s surface is named `"{name}.{i}"`.
    pub name: String,
    /// World height of the ground under the snow, metres (of the flat ground, or the height the
    /// `ground`'s heights are measured from).
    pub ground_height: f32,
    /// The ground when it is not flat. When a level moves, its ground field moves with it: only
    /// the entering strips are sampled and the slopes next to them and on its edges computed
    /// again (a jump larger than the window lays it whole).
    pub ground: Option<TerrainGround>,
    /// Depth of fresh snow, metres.
    pub snow_depth: f32,
    /// Fraction of the snow depth refilled per second while it snows.
    pub replenish_rate: f32,
    /// What it is made of.
    pub material: Material,
    /// The levels, finest first.
    pub levels: Vec<LevelDesc>,
}

/// What scrolling the window has cost, since the terrain was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ScrollStats {
    /// Scrolls that moved at least one level.
    pub scrolls: u64,
    /// Texels paged out of the pool.
    pub texels_out: u64,
    /// Texels written into the pool.
    pub texels_in: u64,
    /// Pool bytes written by the strips that entered, counted on the GPU as they were stored.
    pub bytes_written: u64,
    /// Of the entering texels, those paged back in (visited before) rather than fresh snow.
    pub texels_paged_in: u64,
    /// Compressed bytes the page store holds now.
    pub store_bytes: u64,
    /// Chunks of 64 x 64 world texels the page store holds now.
    pub store_chunks: u64,
    /// Pool bytes written folding finer levels' leaving strips into coarser levels.
    pub bytes_folded: u64,
}

/// One level as the terrain keeps it.
#[derive(Clone, Copy, Debug)]
struct Level {
    surface: SurfaceId,
    desc: LevelDesc,
    /// World texel of its logical texel (0, 0).
    origin: [i64; 2],
}

/// A terrain-wide snow layer in a [`SnowWorld`]: its levels are surfaces of the world (drawn by
/// the renderer, probed, captured and updated as any surface); [`Terrain::follow`] moves them.
pub struct Terrain {
    desc: TerrainDesc,
    levels: Vec<Level>,
    store: store::StripStore,
    strips: StripGpu,
    stats: ScrollStats,
    /// Pool bytes the last scroll whose readback arrived wrote.
    last_written: u64,
    /// Scrolls and folds submitted whose readbacks have not been landed, oldest first.
    in_flight: std::collections::VecDeque<InFlight>,
}

/// A submitted scroll (its leaving strips, in the order read back) or fold.
struct InFlight {
    read: strip::StripRead,
    leaving: Vec<(usize, plan::Strip)>,
    fold: bool,
}

impl Terrain {
    /// Add the terrain's levels to `world`, centred on `focus`. Refused, in one sentence naming
    /// the value, when a level has no texels, a texel side not above 0 or is larger than the
    /// capture atlas, when the levels do not fit the pool, or when the focus is not finite;
    /// nothing is added then.
    pub fn new(world: &mut SnowWorld, desc: TerrainDesc, focus: Vec3) -> Result<Self> {
        validate(&desc, world)?;
        check_focus(&desc.name, focus)?;
        let mut levels: Vec<Level> = Vec::new();
        for (i, l) in desc.levels.iter().enumerate() {
            let origin = plan::origin_for(
                [focus.x as f64, focus.z as f64],
                l.texel_size as f64,
                l.texels,
                world.pool_format().precision.unit_texels(),
            );
            let (surface, layout) = level_surface(&desc, i, origin);
            let added = world.add_level(surface, layout).and_then(|id| {
                world.move_level(
                    id,
                    center_of(&desc, l, origin),
                    plan::wrap_for(origin, l.texels),
                )?;
                Ok(id)
            });
            match added {
                Ok(id) => levels.push(Level {
                    surface: id,
                    desc: *l,
                    origin,
                }),
                Err(e) => {
                    for l in &levels {
                        let _ = world.remove_surface(l.surface);
                    }
                    return Err(e);
                }
            }
        }
        Self::finish(world, desc, levels, Default::default())
    }

    /// The terrain of `levels` (added to `world`) with its store and statistics: the levels'
    /// holes set and their grounds laid.
    fn finish(
        world: &mut SnowWorld,
        desc: TerrainDesc,
        levels: Vec<Level>,
        kept: saved::Kept,
    ) -> Result<Self> {
        let terrain = Self {
            strips: StripGpu::new(world.device(), world.pool_format().precision),
            desc,
            levels,
            store: kept.store,
            stats: kept.stats,
            last_written: kept.last_written,
            in_flight: Default::default(),
        };
        terrain.set_holes(world)?;
        for i in 0..terrain.levels.len() {
            terrain.lay_ground(world, i)?;
        }
        Ok(terrain)
    }

    /// Lay level `i` on the terrain's ground where its window stands, whole (nothing on flat
    /// ground): the ground's heights sampled once at the level's texel centres
    /// ([`ground_height`]), its field built as a surface's ([`GroundField::build`]), in logical
    /// order, which the capture reads.
    fn lay_ground(&self, world: &mut SnowWorld, i: usize) -> Result<()> {
        let Some(g) = &self.desc.ground else {
            return Ok(());
        };
        let l = &self.levels[i];
        let [w, h] = l.desc.texels;
        let heights = (0..h as i64)
            .flat_map(|r| (0..w as i64).map(move |c| (c, r)))
            .map(|(c, r)| ground_height(g, &l.desc, [l.origin[0] + c, l.origin[1] + r]))
            .collect();
        let desc = world.surface(l.surface)?;
        let layout = SurfaceLayout {
            width: w,
            height: h,
        };
        let field = GroundField::build(layout, desc.size, heights, desc.snow_depth, g.slope);
        world.set_ground_field(l.surface, Some(field))
    }

    /// Move level `i`'s ground field with its window, which was at world texel `from`: the field
    /// shifted, the entering strips sampled, the columns computed again only where they can
    /// change and only that level's part of the ground buffers written (bit for bit the field
    /// [`Terrain::lay_ground`] gives at the new origin); a jump larger than the window lays it
    /// whole.
    fn scroll_ground(&self, world: &mut SnowWorld, i: usize, from: [i64; 2]) -> Result<()> {
        let Some(g) = &self.desc.ground else {
            return Ok(());
        };
        let l = &self.levels[i];
        let by = [l.origin[0] - from[0], l.origin[1] - from[1]];
        let at = |c: u32, r: u32| {
            ground_height(g, &l.desc, [l.origin[0] + c as i64, l.origin[1] + r as i64])
        };
        if !world.scroll_ground(l.surface, by, g.slope, at)? {
            self.lay_ground(world, i)?;
        }
        Ok(())
    }

    /// Leave each level's finer neighbour's extent to it: level `i > 0` does not draw the
    /// rectangle of level `i - 1` (in its own local frame), so the two never draw over each other.
    fn set_holes(&self, world: &mut SnowWorld) -> Result<()> {
        for pair in self.levels.windows(2) {
            let (fine, coarse) = (&pair[0], &pair[1]);
            let c = center_of(&self.desc, &coarse.desc, coarse.origin);
            let (lo, hi) = extent_of(&fine.desc, fine.origin);
            // Inset by a quarter of a fine texel: the two overlap by that much, so that no pixel
            // on the edge is left to neither (the tessellated tier's meshes meet there).
            let inset = fine.desc.texel_size * HOLE_INSET;
            let hole = [
                lo.x - c.x + inset,
                lo.y - c.z + inset,
                hi.x - c.x - inset,
                hi.y - c.z - inset,
            ];
            world.set_level_hole(coarse.surface, Some(hole))?;
        }
        Ok(())
    }

    /// The description.
    pub fn desc(&self) -> &TerrainDesc {
        &self.desc
    }

    /// Each level's surface, finest first.
    pub fn surfaces(&self) -> Vec<SurfaceId> {
        self.levels.iter().map(|l| l.surface).collect()
    }

    /// World texel of level `level`'s logical texel (0, 0) (`None` past the last level).
    pub fn origin(&self, level: usize) -> Option<[i64; 2]> {
        self.levels.get(level).map(|l| l.origin)
    }

    /// What scrolling has cost so far.
    pub fn stats(&self) -> ScrollStats {
        ScrollStats {
            store_bytes: self.store.bytes(),
            store_chunks: self.store.chunks() as u64,
            ..self.stats
        }
    }

    /// Pool bytes written by the last scroll whose readback has arrived (all have after
    /// [`Terrain::flush`]).
    pub fn last_bytes_written(&self) -> u64 {
        self.last_written
    }

    /// Centre every level on `focus` (world metres; y is ignored), scrolling those that move:
    /// their leaving strips gathered and read back to the page store, their entering strips
    /// written, their offsets moved, in a submission of their own ahead of the world's next frame.
    /// Nothing waits for the GPU unless a strip that enters was paged out by a scroll whose
    /// readback has not arrived yet (the window turned back within a frame or two): pages and
    /// statistics land as their readbacks arrive, at a later call or at [`Terrain::flush`]. Call
    /// it between frames, not between `encode_step` and `submitted`.
    pub fn follow(&mut self, world: &mut SnowWorld, focus: Vec3) -> Result<()> {
        check_focus(&self.desc.name, focus)?;
        // Refused before anything is recorded, so that a refusal leaves the window as it was.
        if world.frame_pending() {
            return Err(SnowError::WindowBusy {
                name: self.desc.name.clone(),
            });
        }
        self.drain(world, false)?;
        let unit = world.pool_format().precision.unit_texels();
        let moves: Vec<(usize, [i64; 2], Vec<plan::ScrollStep>)> = self
            .levels
            .iter()
            .enumerate()
            .filter_map(|(i, level)| {
                let l = level.desc;
                let focus = [focus.x as f64, focus.z as f64];
                let to = plan::origin_for(focus, l.texel_size as f64, l.texels, unit);
                (to != level.origin).then(|| (i, to, plan::scroll(level.origin, to, l.texels)))
            })
            .collect();
        if moves.is_empty() {
            return Ok(());
        }
        let returning = moves.iter().any(|(i, _, steps)| {
            steps
                .iter()
                .any(|s| self.in_flight_overlaps(*i, &s.entering))
        });
        if returning {
            self.flush(world)?;
        }
        let mut dispatches = Vec::new();
        let (mut incoming, mut leaving) = (Vec::new(), Vec::new());
        let (mut out_texels, mut in_texels) = (0u32, 0u32);
        for (i, _, steps) in &moves {
            let level = &self.levels[*i];
            let (heights, layout, _) = world.level_slot(level.surface)?;
            let mut wrap = plan::wrap_for(level.origin, level.desc.texels);
            for step in steps {
                let params = |s: &plan::Strip, wrap: u32, first: u32| StripParams {
                    heights,
                    width: layout.width,
                    height: layout.height,
                    wrap,
                    x0: s.x0,
                    y0: s.y0,
                    columns: s.columns,
                    rows: s.rows,
                    first,
                    unit_bytes: self.strips.unit_bytes(),
                    _pad: [0; 2],
                };
                dispatches.push((Direction::Out, params(&step.leaving, wrap, out_texels)));
                leaving.push((*i, step.leaving));
                out_texels += step.leaving.texels() as u32;
                let e = step.entering;
                let texels = self.store.get(*i, e.world, e.columns, e.rows);
                self.stats.texels_paged_in +=
                    texels.chunks_exact(2).filter(|p| p != &[0, 0]).count() as u64;
                incoming.extend(texels);
                dispatches.push((Direction::In, params(&e, step.wrap, in_texels)));
                in_texels += e.texels() as u32;
                wrap = step.wrap;
            }
        }
        self.submit_strips(world, &dispatches, &incoming, leaving, false);
        let mut from = Vec::new();
        for (i, to, steps) in &moves {
            let l = &mut self.levels[*i];
            from.push(l.origin);
            l.origin = *to;
            let wrap = steps.last().map_or(0, |s| s.wrap);
            world.move_level(l.surface, center_of(&self.desc, &l.desc, *to), wrap)?;
        }
        self.set_holes(world)?;
        for ((i, _, _), from) in moves.iter().zip(from) {
            self.scroll_ground(world, *i, from)?;
        }
        self.stats.scrolls += 1;
        self.stats.texels_out += out_texels as u64;
        self.stats.texels_in += in_texels as u64;
        Ok(())
    }

    /// Wait for every scroll's readback and fold, and land them in the page store and the
    /// statistics (the texels paged out are then all in the store).
    pub fn flush(&mut self, world: &mut SnowWorld) -> Result<()> {
        while !self.in_flight.is_empty() {
            self.drain(world, true)?;
        }
        Ok(())
    }

    /// Scrolls whose readbacks are still on their way.
    pub fn scrolls_in_flight(&self) -> usize {
        self.in_flight.iter().filter(|f| !f.fold).count()
    }

    /// Whether a strip of level `level` still on its way overlaps world texels of `strip`.
    /// Record `dispatches` of the strips' pass (with `incoming`, the words that enter) in a
    /// submission of their own and keep its readback in flight: a scroll's (`leaving` the strips
    /// read back, in order) or a fold's.
    fn submit_strips(
        &mut self,
        world: &SnowWorld,
        dispatches: &[(Direction, StripParams)],
        incoming: &[u32],
        leaving: Vec<(usize, plan::Strip)>,
        fold: bool,
    ) {
        let mut enc = world.device().create_command_encoder(&Default::default());
        let read = self.strips.encode(
            world.device(),
            world.queue(),
            &mut enc,
            world.pool_buffer(),
            dispatches,
            incoming,
        );
        world.queue().submit([enc.finish()]);
        read.submitted();
        self.in_flight.push_back(InFlight {
            read,
            leaving,
            fold,
        });
    }

    fn in_flight_overlaps(&self, level: usize, strip: &plan::Strip) -> bool {
        let span = |s: &plan::Strip| {
            let (x0, z0) = (s.world[0], s.world[1]);
            (x0, z0, x0 + s.columns as i64, z0 + s.rows as i64)
        };
        let (ax0, az0, ax1, az1) = span(strip);
        self.in_flight
            .iter()
            .flat_map(|f| &f.leaving)
            .any(|(l, s)| {
                let (bx0, bz0, bx1, bz1) = span(s);
                *l == level && ax0 < bx1 && bx0 < ax1 && az0 < bz1 && bz0 < az1
            })
    }

    /// Land the readbacks that have arrived, in order (all of them, waiting, when `wait`): the
    /// leaving strips into the page store and folded into coarser levels, the bytes into the
    /// statistics.
    fn drain(&mut self, world: &mut SnowWorld, wait: bool) -> Result<()> {
        if !wait {
            world.device().poll(wgpu::PollType::Poll)?;
        }
        let mut folds = Vec::new();
        while let Some(f) = self.in_flight.front() {
            if !wait && !f.read.is_ready() {
                break;
            }
            let Some(f) = self.in_flight.pop_front() else {
                break;
            };
            let (pairs, written) = f.read.wait(world.device())?;
            if f.fold {
                self.stats.bytes_folded += written;
                continue;
            }
            self.stats.bytes_written += written;
            self.last_written = written;
            let mut at = 0usize;
            for (i, s) in f.leaving {
                let n = 2 * s.texels() as usize;
                let texels = &pairs[at..at + n];
                self.store.put(i, s.world, s.columns, s.rows, texels);
                if i + 1 < self.levels.len() {
                    folds.push((i, s, texels.to_vec()));
                }
                at += n;
            }
        }
        self.fold(world, &folds)
    }
}

/// The height of `g` at the centre of world texel `t` of a level of `l`'s texel side (clamped at
/// the ground's rectangle): a pure function of the world texel, so that a field laid whole and
/// one moved strip by strip agree bit for bit.
fn ground_height(g: &TerrainGround, l: &LevelDesc, t: [i64; 2]) -> f32 {
    let s = l.texel_size as f64;
    let uv = |k: usize| {
        (((t[k] as f64 + 0.5) * s - g.origin[k] as f64) / g.size[k] as f64).clamp(0.0, 1.0) as f32
    };
    g.grid.sample(uv(0), uv(1))
}

/// Level `i` of `desc` as a surface of the world, its window's first world texel at `origin`.
pub(crate) fn level_surface(
    desc: &TerrainDesc,
    i: usize,
    origin: [i64; 2],
) -> (SurfaceDesc, SurfaceLayout) {
    let l = &desc.levels[i];
    let surface = SurfaceDesc {
        name: format!("{}.{i}", desc.name),
        center: center_of(desc, l, origin),
        size: Vec2::new(l.texels[0] as f32, l.texels[1] as f32) * l.texel_size,
        yaw_degrees: 0.0,
        snow_depth: desc.snow_depth,
        replenish_rate: desc.replenish_rate,
        material: desc.material,
    };
    let layout = SurfaceLayout {
        width: l.texels[0],
        height: l.texels[1],
    };
    (surface, layout)
}

/// The world centre of a level's rectangle whose first world texel is `origin`, on the ground.
fn center_of(desc: &TerrainDesc, l: &LevelDesc, origin: [i64; 2]) -> Vec3 {
    let s = l.texel_size as f64;
    Vec3::new(
        ((origin[0] as f64 + l.texels[0] as f64 / 2.0) * s) as f32,
        desc.ground_height,
        ((origin[1] as f64 + l.texels[1] as f64 / 2.0) * s) as f32,
    )
}

/// The world xz rectangle `(min, max)` of a level whose first world texel is `origin`.
fn extent_of(l: &LevelDesc, origin: [i64; 2]) -> (Vec2, Vec2) {
    let s = l.texel_size as f64;
    let at = |i: i64| (i as f64 * s) as f32;
    (
        Vec2::new(at(origin[0]), at(origin[1])),
        Vec2::new(
            at(origin[0] + l.texels[0] as i64),
            at(origin[1] + l.texels[1] as i64),
        ),
    )
}

fn check_focus(name: &str, focus: Vec3) -> Result<()> {
    if focus.is_finite() && focus.x.abs() < 1.0e7 && focus.z.abs() < 1.0e7 {
        return Ok(());
    }
    Err(SnowError::InvalidTerrain {
        name: name.to_owned(),
        what: "the focus".into(),
        value: format!("{:?}", focus.to_array()),
        expected: "a finite point within 10000 km of the origin".into(),
    })
}

/// Check a terrain against the world it goes into, naming the first thing that is wrong.
fn validate(desc: &TerrainDesc, world: &SnowWorld) -> Result<()> {
    validate_for(
        desc,
        world.pool_format(),
        world.config().atlas_side,
        world.memory().pool_budget,
    )
}

/// [`validate`] against a world's pool format, capture atlas side and pool budget (a save's
/// terrains are checked against its settings before any world is made).
pub(crate) fn validate_for(
    desc: &TerrainDesc,
    format: crate::pool::PoolFormat,
    atlas_side: u32,
    budget: u64,
) -> Result<()> {
    let bad = |what: String, value: String, expected: String| {
        Err(SnowError::InvalidTerrain {
            name: desc.name.clone(),
            what,
            value,
            expected,
        })
    };
    if desc.levels.is_empty() {
        return bad("levels".into(), "empty".into(), "at least one level".into());
    }
    if !(desc.ground_height.is_finite()) {
        return bad(
            "ground_height".into(),
            desc.ground_height.to_string(),
            "finite".into(),
        );
    }
    if let Some(g) = &desc.ground {
        g.grid.validate(&desc.name)?;
        g.slope.validate(&desc.name)?;
        let ok = |v: [f32; 2], positive: bool| {
            v.iter().all(|x| x.is_finite() && (!positive || *x > 0.0))
        };
        if !ok(g.origin, false) || !ok(g.size, true) {
            return bad(
                "the ground's rectangle".into(),
                format!("origin {:?}, size {:?}", g.origin, g.size),
                "a finite origin and sides above 0 metres".into(),
            );
        }
    }
    // A level's capture region (its texels and the apron) must fit the atlas.
    let side = atlas_side.saturating_sub(2 * crate::capture::APRON);
    let mut bytes = 0u64;
    for (i, l) in desc.levels.iter().enumerate() {
        let [w, h] = l.texels;
        if w == 0 || h == 0 || w > side || h > side || w > 0xffff || h > 0xffff {
            return bad(
                format!("level {i}'s texels"),
                format!("[{w}, {h}]"),
                format!(
                    "between 1 and {side} a side (the capture atlas's side, WorldConfig.atlas_side, less the capture's apron of a texel on each side)"
                ),
            );
        }
        if format.precision.unit_texels() == 2 && w % 2 == 1 {
            return bad(
                format!("level {i}'s texels"),
                format!("[{w}, {h}]"),
                "an even number of texels along x in an 8-bit pool".into(),
            );
        }
        if !(l.texel_size.is_finite()
            && l.texel_size >= crate::MIN_TEXEL_SIZE
            && l.texel_size <= 100.0)
        {
            return bad(
                format!("level {i}'s texel_size"),
                l.texel_size.to_string(),
                format!("a number of metres from {} to 100", crate::MIN_TEXEL_SIZE),
            );
        }
        bytes += format.slot_bytes(w, h);
    }
    if bytes > budget {
        return bad(
            "the levels' heightmaps".into(),
            format!("{bytes} bytes"),
            format!(
                "at most the pool's {budget} bytes (WorldConfig.pool_bytes, or fewer or smaller levels)"
            ),
        );
    }
    Ok(())
}
