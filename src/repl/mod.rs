//! The interactive shell over [`crate::script`]: session logic ([`Session`]) apart from the
//! terminal ([`terminal`]), so the logic is tested without one.

mod helper;
pub mod kernel;
mod session;
pub mod terminal;

pub use helper::ReplHelper;
pub use session::{Reply, Session};
pub use terminal::{piped, run, PROMPT};
