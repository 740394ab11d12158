//! What the suspension stepper keeps while it refines a step: the scratch of a refinement (one
//! per thread), the refined paths, and what the rounds of one coarse step keep for the next.

/// The coarse step a round of refinement works on: from `t` by `h`, its start state `y`, the
/// states it reached (`end`, before any refinement), and the motion floors of the error measure.
#[derive(Clone, Copy)]
pub(super) struct Coarse<'a> {
    pub(super) t: f64,
    pub(super) h: f64,
    pub(super) y: &'a [f64],
    pub(super) end: &'a [f64],
    pub(super) floor: &'a [f64],
}

/// A step of a subset of the swimmers: from `t0` by `h` at tolerance `tol`, the swimmers
/// `bodies` stepped, those of `changed` changed since the system last read them, and the motion
/// floors of the error measure.
#[derive(Clone, Copy)]
pub(super) struct SubsetStep<'a> {
    pub(super) t0: f64,
    pub(super) h: f64,
    pub(super) tol: f64,
    pub(super) bodies: &'a [usize],
    pub(super) changed: &'a [usize],
    pub(super) floor: &'a [f64],
}

/// A refined group's path across a coarse step: (time from its start, the group's states).
pub(super) type Path = Vec<(f64, Vec<f64>)>;

/// What the rounds of refining one coarse step keep for the next round.
#[derive(Default)]
pub(super) struct Rounds {
    /// Each group refined so far, by its swimmers.
    pub(super) groups: std::collections::HashMap<Vec<usize>, Refined>,
    /// The swimmers of the groups refined since the read errors were last found.
    pub(super) changed: Vec<usize>,
    /// The neighbours' largest read errors so far (see
    /// [`Suspension::ring_of`](super::stepper::Suspension::ring_of)).
    pub(super) worst: std::collections::HashMap<usize, f64>,
    /// Scratch of the read errors, by swimmer.
    pub(super) read: Vec<f64>,
    /// The swimmers of the groups refined since the ring was last stepped again.
    pub(super) redo_changed: Vec<usize>,
    /// Each part of the ring stepped again so far, by its swimmers: their new states (by
    /// component) and errors.
    pub(super) ring: std::collections::HashMap<Vec<usize>, RingPart>,
}

/// A part of the ring stepped again: its swimmers' new states (by component) and errors.
pub(super) type RingPart = (Vec<f64>, Vec<f64>);

/// Scratch of a refinement: the working state (the refined swimmers at their sub-step, the others
/// interpolated), stages and rates.
#[derive(Debug, Clone, Default)]
pub(super) struct Refinement {
    pub(super) yw: Vec<f64>,
    pub(super) y0: Vec<f64>,
    pub(super) k: [Vec<f64>; 4],
    pub(super) f: Vec<f64>,
    pub(super) f0: Vec<f64>,
    pub(super) acc: Vec<f64>,
    pub(super) y1: Vec<f64>,
    pub(super) err: Vec<f64>,
    pub(super) errors: Vec<f64>,
}

impl Refinement {
    /// Sized to a state of `n` components (and at least `bodies` bodies). Entries are not
    /// reset: a refinement on shared access writes every entry it reads (its bodies' and the
    /// states they read).
    pub(super) fn fit(&mut self, n: usize, bodies: usize) {
        let [k1, k2, k3, k4] = &mut self.k;
        for v in [
            k1,
            k2,
            k3,
            k4,
            &mut self.yw,
            &mut self.y0,
            &mut self.f,
            &mut self.f0,
            &mut self.acc,
            &mut self.y1,
            &mut self.err,
        ] {
            v.resize(n, 0.0);
        }
        if self.errors.len() < bodies {
            self.errors.resize(bodies, 0.0);
        }
    }
}

/// Scratch for refinements on several threads (a clone starts empty).
#[derive(Debug, Default)]
pub(super) struct Pool(pub(super) std::sync::Mutex<Vec<Refinement>>);

impl Pool {
    /// Run `f` with scratch from the pool, given back after (a thread working on two groups at
    /// once, as rayon may nest, takes a second).
    pub(super) fn with<T>(&self, f: impl FnOnce(&mut Refinement) -> T) -> T {
        let mut sub = self
            .0
            .lock()
            .ok()
            .and_then(|mut v| v.pop())
            .unwrap_or_default();
        let r = f(&mut sub);
        if let Ok(mut v) = self.0.lock() {
            v.push(sub);
        }
        r
    }
}

impl Clone for Pool {
    fn clone(&self) -> Self {
        Pool::default()
    }
}

/// A refined group's outcome: its state components, its path across the coarse step and the
/// steps it took.
pub(super) struct Refined {
    pub(super) comps: Vec<usize>,
    pub(super) path: Path,
    pub(super) steps: u64,
}
