//! Managed surfaces on ground that is not flat: the manager resolves a surface's ground once (a
//! mesh rasterised on the GPU then), keeps the field while the surface waits, is paged out or is
//! saved, and lays it again at every admission, so a print on a slope is the same whether the
//! surface stayed resident or came back from its page.

use super::{ManagedId, SnowManager};
use crate::error::Result;
use crate::ground::{Ground, GroundField, SlopeRule};

/// A managed surface's ground: the field the world is given at each admission, and the rule that
/// built it (kept by saves, which store the heights and rebuild the field).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ManagedGround {
    pub(crate) field: GroundField,
    pub(crate) slope: SlopeRule,
}

impl SnowManager {
    /// Lay a managed surface on `ground`, bared where it is steeper than `slope` allows (see
    /// [`crate::SnowWorld::set_ground`], whose checks and refusals it shares). The field is built
    /// now, a mesh rasterised on the GPU and waited for, and kept: the surface takes it into the
    /// world at each admission, its touch volume and bounds widen to the ground's range, probes
    /// over it when paged read it, and saves keep it. [`Ground::Flat`] gives the flat ground
    /// back. Refused with [`crate::SnowError::FramePending`] while a tick is recorded and not
    /// submitted.
    pub fn set_ground(&mut self, id: ManagedId, ground: &Ground, slope: SlopeRule) -> Result<()> {
        self.not_pending()?;
        let desc = self.planner.surface(id)?.clone();
        let field = self
            .world
            .resolve_ground(&desc, desc.layout(), ground, slope)?;
        self.lay_ground(id, field.map(|field| ManagedGround { field, slope }))
    }

    /// Keep `ground` for surface `id`, widen its volume, and give it to the world now when the
    /// surface is resident.
    pub(crate) fn lay_ground(
        &mut self,
        id: ManagedId,
        ground: Option<ManagedGround>,
    ) -> Result<()> {
        // Over the capture region, the apron's ground included, as the world's plan culls.
        let range = ground
            .as_ref()
            .map_or((0.0, 0.0), |g| g.field.region_range());
        self.planner.set_ground_range(id, range)?;
        if let Some(w) = self.world_ids[id.0 as usize] {
            self.world
                .set_ground_field(w, ground.as_ref().map(|g| g.field.clone()))?;
        }
        let i = id.0 as usize;
        if self.grounds.len() <= i {
            self.grounds.resize(i + 1, None);
        }
        self.grounds[i] = ground;
        Ok(())
    }

    /// A managed surface's ground field (`None` on flat ground).
    pub fn ground(&self, id: ManagedId) -> Result<Option<&GroundField>> {
        self.planner.surface(id)?;
        Ok(self.ground_field(id))
    }

    /// The field of a surface the caller knows is registered.
    pub(crate) fn ground_field(&self, id: ManagedId) -> Option<&GroundField> {
        self.grounds
            .get(id.0 as usize)
            .and_then(Option::as_ref)
            .map(|g| &g.field)
    }
}
