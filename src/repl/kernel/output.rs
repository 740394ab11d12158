//! A cell's output on IOPub: prints, `display(value)`, text that functions write themselves,
//! notes and the progress display; a value's MIME bundle (pictures as PNG and SVG).

use super::shared::Shared;
use super::wire;
use crate::repl::session::Session;
use crate::script::{console, progress, show, view_api, Picture};
use base64::Engine as _;
use serde_json::{json, Value};
use std::sync::{Arc, Mutex};

/// Everything a cell writes goes to IOPub as the cell's output: prints, display(value),
/// text functions write themselves, notes and the progress display.
pub(super) fn route_output(session: &mut Session, shared: &Arc<Shared>) {
    let sh = shared.clone();
    session.on_print(move |s| {
        sh.publish_current(
            "stream",
            json!({"name": "stdout", "text": format!("{s}\n")}),
        );
    });
    // display(value) mid-cell: a display_data now, pictures inline.
    let sh = shared.clone();
    console::set_display_sink(Some(Arc::new(move |v: &rhai::Dynamic| {
        let (data, _) = mime_bundle(v);
        sh.publish_current("display_data", json!({"data": data, "metadata": {}}));
    })));
    // Text that functions write themselves (tplot) goes to the same stream.
    let sh = shared.clone();
    console::set_sink(Some(Arc::new(move |s: &str| {
        sh.publish_current("stream", json!({"name": "stdout", "text": s}));
    })));
    // Notes a run gives (a cost far beyond its length, and why) go to the cell's stderr.
    let sh = shared.clone();
    console::set_note_sink(Some(Arc::new(move |s: &str| {
        sh.publish_current("stream", json!({"name": "stderr", "text": s}));
    })));
    // A view started in a cell shows its page inline, below the address it prints.
    let sh = shared.clone();
    view_api::set_sink(Some(Arc::new(move |url: &str| {
        let src = url
            .replace('&', "&amp;")
            .replace('"', "&quot;")
            .replace('<', "&lt;");
        let html = format!(
            "<iframe src=\"{src}\" width=\"100%\" height=\"480\" style=\"border: 1px solid #ccc\"></iframe>"
        );
        sh.publish_current(
            "display_data",
            json!({"data": {"text/html": html, "text/plain": url}, "metadata": {}}),
        );
    })));
    let sh = shared.clone();
    // One display per run: shown at its first line, updated in place, cleared at its end.
    let open: Mutex<Option<String>> = Mutex::new(None);
    let progress_sink: progress::ProgressSink = Arc::new(move |line: Option<&str>| {
        let Ok(mut open) = open.lock() else { return };
        let (msg_type, id) = match (line, open.as_ref()) {
            (Some(_), None) => ("display_data", open.insert(wire::uuid()).clone()),
            (Some(_), Some(id)) => ("update_display_data", id.clone()),
            (None, _) => match open.take() {
                Some(id) => ("update_display_data", id),
                None => return,
            },
        };
        sh.publish_current(
            msg_type,
            json!({
                "data": {"text/plain": line.unwrap_or("")},
                "metadata": {},
                "transient": {"display_id": id},
            }),
        );
    });
    progress::set_sink(Some(progress_sink));
}

/// Data of a value for Jupyter: text, and for a picture PNG and SVG.
pub(super) fn mime_bundle(v: &rhai::Dynamic) -> (Value, bool) {
    let text = show(v);
    if let Some(p) = v.read_lock::<Picture>() {
        let img = p.image();
        let png = base64::engine::general_purpose::STANDARD.encode(&img.png);
        return (
            json!({"text/plain": text, "image/png": png, "image/svg+xml": img.svg}),
            true,
        );
    }
    (json!({"text/plain": text}), false)
}
