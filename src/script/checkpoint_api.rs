//! Runs that survive a kill in scripts: `s.checkpoint(path, every)` and `s.checksum`.

use super::console;
use super::convert::{script_error, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::observable_api::trigger_of;
use super::scene_api::SceneHandle;
use rhai::{Dynamic, Engine};

/// `s.checkpoint(path, every)`: checkpoints from now on; whether the run went on from one.
fn checkpoint(s: &mut SceneHandle, path: &str, every: Dynamic) -> ScriptResult<bool> {
    let trigger = trigger_of(&every)
        .map_err(|_| script_error(format!("checkpoint(path, every): every must be a number of periods, every_periods(n) or every_seconds(t), got {}", super::convert::describe(&every))))?;
    let resumed = s.with_sim(|sim| sim.checkpoint(std::path::Path::new(path), &trigger))?;
    if let Some(t) = resumed {
        let periods = s
            .borrow()
            .period()
            .map(|p| format!(" ({:.6} periods)", t / p))
            .unwrap_or_default();
        console::note(&format!(
            "going on from the checkpoint {path} at t = {t:e} s{periods}"
        ));
    }
    Ok(resumed.is_some())
}

pub(super) fn register(engine: &mut Engine) {
    engine
        .register_fn("checkpoint", checkpoint)
        .register_get("checksum", |s: &mut SceneHandle| {
            format!("{:016x}", s.borrow().checksum())
        });
}

/// The help text of this file's script names (`:help NAME`), gathered by [`super::docs`].
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("checkpoint", "running", "s.checkpoint(path, every) -> bool", "Make the runs from here on survive a kill: every n periods (a number, every_periods(n)) or every_seconds(t) of scene time from now, the runs write the scene and every recorder's rows to path (JSON, atomically: a kill leaves the last whole checkpoint). If path already holds a checkpoint of this setup (the scene as it is now, the same every, the same recorders, created before this call), the scene and the recorders go on from it, a CSV stream written anew with the checkpoint's rows, and true is returned (a note says where); a checkpoint of another setup is refused, naming what differs. Run with s.run_to(t) or s.run_to_periods(n), which run nothing where the scene already is: the same script started again then ends as an uninterrupted run would, the same final state bit for bit and the same rows. Trajectories cannot be taken back after a kill and are refused. Delete the file to start afresh.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 0.5); s.checkpoint(\"out/help/checkpoint.json\", 1); s.run_to_periods(2); print(r.len);"),
    doc_entry!("checksum", "reading", "s.checksum -> string", "A 64-bit checksum (FNV-1a, 16 hex digits) of the scene's time and state, bit by bit: two runs that print the same checksum ended alike to the last bit.", "let s = scene(); s.add(dumbbell()); print(s.checksum);"),
];
