//! The demo world, built in code: procedural articulated people (and, later, the roofs they act
//! on).

pub mod anim;
pub mod skeleton;
