//! swimlab: low-Reynolds-number dumbbell swimmers (Putz & Dunkel 2010), scriptable with Rhai.
//!
//! Layers, arrows one way: [`repl`] → [`script`] → [`plot`] → [`engine`], and [`view`] (the live
//! view in the browser) beside [`plot`]. [`script`] binds the engine, the pictures and the view to
//! Rhai; [`plot`] draws what the engine measures; [`view`] serves a scene's frames while it runs;
//! [`repl`] is the interactive shell; the binary is a thin CLI over them.
#![warn(missing_docs)]
// Numerical kernels index several arrays in lockstep; an index loop says that most plainly.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod engine;
pub mod plot;
pub mod repl;
pub mod script;
pub mod sweep;
pub mod view;
