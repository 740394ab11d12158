//! swimlab: low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai.
//!
//! Layers, arrows one way: [`repl`] → [`script`] → [`engine`]. [`script`] binds the engine to
//! Rhai; [`repl`] is the interactive shell; the binary is a thin CLI over both.
#![warn(missing_docs)]
// Numerical kernels index several arrays in lockstep; an index loop says that most plainly.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod engine;
pub mod repl;
pub mod script;
