//! swimlab: low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai.
//!
//! Layers, arrows one way: [`script`] binds [`engine`] to Rhai; the binary's CLI drives [`script`].
#![warn(missing_docs)]
// Numerical kernels index several arrays in lockstep; an index loop says that most plainly.
#![allow(clippy::needless_range_loop)]

pub mod engine;
pub mod script;
