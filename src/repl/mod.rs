//! The interactive shell over [`crate::script`]: session logic ([`Session`]) apart from the
//! terminal ([`terminal`]), so the logic is tested without one.

mod completion;
mod helper;
pub mod kernel;
pub mod reference;
mod session;
pub mod terminal;
mod view_command;

pub use helper::ReplHelper;
pub use session::{Reply, Session};
pub use terminal::{piped, run, PROMPT};

use std::path::PathBuf;

/// The path in the environment variable `name`: `None` when it is unset or empty (an empty value
/// counts as unset, as the XDG base directory specification has it) and, with `absolute`, when
/// it is relative (the specification ignores relative paths in its variables).
pub fn env_path(name: &str, absolute: bool) -> Option<PathBuf> {
    let p = PathBuf::from(std::env::var_os(name)?);
    if p.as_os_str().is_empty() || (absolute && p.is_relative()) {
        None
    } else {
        Some(p)
    }
}
