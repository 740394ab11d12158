//! swimlab: low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai.
//!
//! Layers, arrows one way: [`repl`] → [`script`] → [`plot`] → [`engine`]. [`script`] binds the
//! engine and the pictures to Rhai; [`plot`] draws what the engine measures; [`repl`] is the
//! interactive shell; the binary is a thin CLI over them.
#![warn(missing_docs)]
// Numerical kernels index several arrays in lockstep; an index loop says that most plainly.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod engine;
pub mod plot;
pub mod repl;
pub mod script;
pub mod sweep;
