//! The shell's `:view`: the latest live view opened in the default browser where a desktop has
//! one, else its address to open by hand.

use crate::script;
use std::process::{Command, Stdio};

/// Open the latest live view with `xdg-open` where a desktop has one; the line to show, or the
/// error when no view is served.
pub(super) fn open_latest() -> Result<String, String> {
    let Some(url) = script::view_api::live_views().pop() else {
        return Err("no live view is served; start one with s.view() (s being a scene)".into());
    };
    let desktop = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|x| !x.is_empty()));
    let opened = desktop
        && Command::new("xdg-open")
            .arg(&url)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .is_ok();
    Ok(if opened {
        format!("opened {url} in the default browser")
    } else {
        format!("{url}\n(no browser opens from here: open that address in one)")
    })
}
