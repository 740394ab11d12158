//! One help entry (`Doc`, written with `doc_entry!`) and the examples several entries share. Each
//! binding file keeps the entries of its own names beside them; [`super::docs`] gathers them.

/// One documented name.
#[derive(Debug, Clone, Copy)]
pub struct Doc {
    /// The name as typed (a function, a method, or a property).
    pub name: &'static str,
    /// Group shown by `:help`.
    pub group: &'static str,
    /// Call forms.
    pub signature: &'static str,
    /// What it does.
    pub about: &'static str,
    /// A runnable example.
    pub example: &'static str,
}

macro_rules! doc_entry {
    ($name:literal, $group:literal, $sig:literal, $about:literal, $ex:expr) => {
        Doc {
            name: $name,
            group: $group,
            signature: $sig,
            about: $about,
            example: $ex,
        }
    };
}
pub(super) use doc_entry;

pub(super) const PAIR_PHASES: &str = "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [25e-6, 0, 0] })); s.phases = [0.0, phase_deg(90)]; print(s.phases);";
pub(super) const PAIR_VELOCITY: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0] })); s.model = \"averaged\"; print(s.velocity(0));";
pub(super) const PAIR_DELTA_Q: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0], dir: [0, 1, 0] })); print(s.observe(delta_q(0, 1)));";
pub(super) const PAIR_RECORD: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0] })); let rec = s.record([pair_mean(0, 1), pair_separation(0, 1)], 1); s.run_periods(2); print(rec);";
pub(super) const PAIR_ROWS: &str = "let s = scene(); s.add(dumbbell()); let rec = s.record([R_H(0)], 1); s.run_periods(1); print(rec.rows[1].time);";
pub(super) const PAIR_COLUMNS: &str = "let s = scene(); s.add(dumbbell()); let rec = s.record([q(0, 0)], at_end()); s.run_periods(1); print(rec.columns); print(rec.header); print(rec.column(\"q[0,0]\"));";
