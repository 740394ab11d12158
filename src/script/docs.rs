//! The help text of every script-visible name: what `:help NAME` shows. Each entry has a runnable
//! example (tests run them all, and check that every registered function has an entry).

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

macro_rules! doc {
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

/// Every documented name.
pub const DOCS: &[Doc] = &[
    doc!("scene", "building", "scene() -> Scene", "An empty scene: no swimmers, mu = 1e-3 Pa s, model \"micro\", mobility \"rpy\", default integrator.", "let s = scene(); print(s);"),
    doc!("dumbbell", "building", "dumbbell() -> Dumbbell\ndumbbell(#{ a1, a2, ell, lambda, omega, k0, phase, center, dir }) -> Dumbbell", "A swimmer description (SI units). Every key is optional; defaults are the paper's symmetric Fig-1 swimmer (a1 = a2 = 0.15 ell, ell = 5e-6 m, lambda = 0.1 ell, omega = 500 1/s, k0 = 1e-3 kg/s^2, phase 0, at the origin, along +x). Unknown keys are errors.", "let d = dumbbell(#{ a1: 1.125e-6, a2: 0.5625e-6, phase: 0.5 }); print(d.a2);"),
    doc!("add", "building", "s.add(d: Dumbbell) -> int", "Add a swimmer at length L(t) of the scene's time, its hydrodynamic centre at d.center, pointing along d.dir; returns its 0-based index. Refuses overlapping swimmers.", "let s = scene(); let i = s.add(dumbbell()); print(i);"),
    doc!("copy", "building", "s.copy() -> Scene", "An independent copy of the scene (same state, no recorders). `let t = s;` would name the same scene.", "let s = scene(); let t = s.copy(); t.add(dumbbell()); print(s.count);"),
    doc!("phase", "phases", "phase(x) -> float\ns.phase(i) -> float", "phase(x): x radians wrapped to [0, 2 pi). s.phase(i): the stroke phase of swimmer i.", "print(phase(7.0)); let s = scene(); s.add(dumbbell(#{ phase: 1.0 })); print(s.phase(0));"),
    doc!("phase_deg", "phases", "phase_deg(x) -> float", "x degrees as radians in [0, 2 pi).", "print(phase_deg(90));"),
    doc!("phases", "phases", "s.phases -> array\ns.phases = [..]", "All stroke phases (rad) in swimmer order; assign one per swimmer.", PAIR_PHASES),
    doc!("set_phase", "phases", "s.set_phase(i, phi)", "Set the stroke phase of swimmer i (rad).", "let s = scene(); s.add(dumbbell()); s.set_phase(0, pi()); print(s.phases);"),
    doc!("model", "numerics", "s.model -> string\ns.model = \"micro\" | \"rigid\" | \"averaged\"", "The model: \"micro\" (spheres, springs, mobility), \"rigid\" (the same with lengths following L(t) exactly: k0 -> infinity, not stiff) or \"averaged\" (stroke-averaged R_H and N). Switching converts the state.", "let s = scene(); s.add(dumbbell()); s.model = \"averaged\"; print(s.model);"),
    doc!("add_random", "scene", "s.add_random(d, n, volume_fraction, seed) -> int\ns.add_random(d, n, volume_fraction, seed, #{ aligned: [x, y, z], phase: p }) -> int", "Add n copies of dumbbell d at random places in a cube centred on the origin, sized so that all spheres fill the given volume fraction, without overlaps (random sequential addition, seeded: the same seed gives the same scene). Orientations and phases are random unless fixed by the options. Returns the new swimmer count; on failure the scene is unchanged.", "let s = scene(); s.add_random(dumbbell(#{}), 20, 0.01, 1); print(s.count);"),
    doc!("add_at", "scene", "s.add_at(d, centres: array) -> int", "Add a copy of dumbbell d (its orientation and phase) at every centre [x, y, z] (m) of the array, e.g. a lattice from the stdlib module \"lattice\". All or nothing: if one does not fit, the scene is unchanged. Returns the new swimmer count.", "import \"lattice\" as lattice; let s = scene(); s.add_at(dumbbell(), lattice::cubic(2, 2, 2, 20e-6)); print(s.count);"),
    doc!("sweep", "scene", "sweep(params: array, f) -> array\nsweep(params: array, f, threads: int) -> array", "Call f(p) for every p of params on all cores (or on `threads` threads) and return the results in the order of params. Each call should build its own scene; results may be numbers, strings, arrays or maps. The first failing call is the error, naming its parameter. For clusters, run one process per parameter instead: swimlab run script.rhai --set D=10 (README, Sweeps).", "let r = sweep([1, 2, 3], |p| p * p); print(r);"),
    doc!("plot", "pictures", "plot(path, series)\nplot(path, series, #{ title, x_label, y_label, log_x, log_y, width, height })\nrec.plot(path, x_column, y_columns)\nrec.plot(path, x_column, y_columns, options)", "Draw series to an SVG or PNG file (by the extension; folders are created). A series is #{ x: [..], y: [..], label: \"..\", style: \"line\" | \"points\" }; give one map or an array of them. rec.plot draws recorded columns against one column, with their units as labels. Text uses an embedded font: no system fonts needed.", "plot(\"out/help/p.svg\", [#{ x: [1, 2, 3], y: [1, 4, 9], label: \"x^2\" }, #{ x: [1, 2, 3], y: [1, 8, 27], label: \"x^3\", style: \"points\" }], #{ title: \"powers\", x_label: \"x\", y_label: \"y\", log_y: true });"),
    doc!("tplot", "pictures", "tplot(series)\ntplot(series, options)\nrec.tplot(x_column, y_columns)\nrec.tplot(x_column, y_columns, options)", "A quick plot as text in the terminal: series and options as for plot, plus cols and rows (the plot area in characters, default 72 x 18).", "tplot(#{ x: [0, 1, 2, 3], y: [0, 1, 4, 9], label: \"x^2\" }, #{ cols: 40, rows: 8 });"),
    doc!("snapshot", "pictures", "s.snapshot(path)\ns.snapshot(path, #{ plane: \"xy\" | \"xz\" | \"yz\", title, width, height })", "A picture of the scene (SVG or PNG): every swimmer's spheres at their radii and its rod, projected on a plane, coloured by the in-plane direction of N (aligned swimmers share a colour; out-of-plane ones fade to grey). Call it in a loop for the frames of an animation.", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [12e-6, 3e-6, 0], dir: [0, 1, 0] })); s.snapshot(\"out/help/scene.png\", #{ title: \"two swimmers\" });"),
    doc!("backend", "numerics", "s.backend -> string\ns.backend = \"cpu\" | \"gpu\" | \"auto\"", "Where the dynamics run: the CPU (default), a GPU through wgpu (Vulkan, Metal, DX12; f64 shaders required; fixed-step euler/rk4, micro and averaged models), or \"auto\": the GPU when one is present and the scene is at least as large as the crossover measured on this machine. Results agree to round-off (tested to 1e-12 per step).", "let s = scene(); s.backend = \"auto\"; print(s.backend);"),
    doc!("backend_info", "numerics", "s.backend_info -> string", "Which backend the next run uses and why (for \"auto\": the measured crossover).", "let s = scene(); print(s.backend_info);"),
    doc!("mobility", "numerics", "s.mobility -> string\ns.mobility = \"rpy\" | \"oseen\"", "Pair mobility of the microscopic model: Rotne-Prager-Yamakawa (default) or Oseen.", "let s = scene(); s.mobility = \"oseen\"; print(s.mobility);"),
    doc!("overlaps", "numerics", "s.overlaps -> string\ns.overlaps = \"stop\" | \"allow\"", "What happens when spheres of different swimmers touch: \"stop\" (default) ends the run with an error naming them; \"allow\" lets them overlap, moved by the RPY tensor for overlapping spheres (Zuk et al. 2014, positive definite; the averaged model, a far-field model, then runs on with its D^-5 terms). A swimmer's own spheres touching always stops the run. CPU only.", "let s = scene(); s.overlaps = \"allow\"; print(s.overlaps);"),
    doc!("steric", "numerics", "s.steric -> map or ()\ns.steric = #{ range, stiffness } | ()", "A soft repulsion between spheres of different swimmers: force stiffness * (range - gap) (N) along the line of centres when their surface gap is below range (m). Off by default (). Microscopic model: the forces join the spring forces in the mobility. Averaged model: each swimmer moves as a free-draining rigid dumbbell of length ell under them. Not in the rigid-stroke model; CPU only; costs one O(N^2) pass per right-hand side.", "let s = scene(); s.steric = #{ range: 1e-7, stiffness: 1e-3 }; print(s.steric.range);"),
    doc!("cutoff", "numerics", "s.cutoff -> float or ()\ns.cutoff = distance | ()", "Far-field cutoff of the averaged model (m): pairs further apart are left out. Off by default (). Each left-out pair's contribution is bounded by 9/64 v0 (28|A_R|(Lambda/ell) xi^3 + 84 c_J xi^4) with xi = ell/cutoff (README, Suspensions).", "let s = scene(); s.cutoff = 100e-6; print(s.cutoff);"),
    doc!("coefficients", "numerics", "s.coefficients -> string\ns.coefficients = \"paper\" | \"leading_order\"", "Coefficients of the averaged model's I and J terms: as published, or the leading-order ones.", "let s = scene(); s.coefficients = \"leading_order\"; print(s.coefficients);"),
    doc!("integrator", "numerics", "s.integrator -> Integrator\ns.integrator = euler(dt) | rk4(dt) | dopri5(rtol) | rosw(rtol) | \"default\"", "The time integrator. The default depends on the model and the scene's stiffness.", "let s = scene(); s.add(dumbbell()); print(s.integrator); s.integrator = rk4(5e-6); print(s.integrator);"),
    doc!("euler", "numerics", "euler(dt) -> Integrator", "Forward Euler with steps of at most dt seconds.", "let i = euler(1e-6); print(i);"),
    doc!("rk4", "numerics", "rk4(dt) -> Integrator", "Classic Runge-Kutta 4 with steps of at most dt seconds.", "let i = rk4(5e-6); print(i);"),
    doc!("dopri5", "numerics", "dopri5(rtol) -> Integrator", "Adaptive Dormand-Prince 5(4); rtol is relative to the stroke and drift scales, not to positions.", "let i = dopri5(1e-8); print(i);"),
    doc!("rosw", "numerics", "rosw(rtol) -> Integrator", "Adaptive Rosenbrock-W ROS34PW2 (order 3, L-stable): implicit in each dumbbell's own spring and hydrodynamics, explicit between dumbbells; not held by the spring's stability limit.", "let i = rosw(1e-6); print(i);"),
    doc!("mu", "numerics", "s.mu -> float\ns.mu = x", "Viscosity (Pa s).", "let s = scene(); s.mu = 2e-3; print(s.mu);"),
    doc!("stiff_rate", "numerics", "s.stiff_rate -> float", "The largest spring relaxation rate k0 (1/gamma1 + 1/gamma2) (1/s); explicit steps need dt below ~2.8/rate.", "let s = scene(); s.add(dumbbell()); print(s.stiff_rate);"),
    doc!("run", "running", "s.run(seconds)", "Advance the scene; Ctrl-C stops at a clean step boundary and keeps the state.", "let s = scene(); s.add(dumbbell()); s.run(1e-3); print(s.time);"),
    doc!("run_periods", "running", "s.run_periods(n)", "Advance n stroke periods 2 pi/omega (the swimmers' omega must agree).", "let s = scene(); s.add(dumbbell()); s.run_periods(1); print(s.time);"),
    doc!("time", "running", "s.time -> float", "Current time (s).", "let s = scene(); print(s.time);"),
    doc!("period", "running", "s.period -> float", "The common stroke period (s).", "let s = scene(); s.add(dumbbell()); print(s.period);"),
    doc!("count", "running", "s.count -> int", "Number of swimmers.", "let s = scene(); print(s.count);"),
    doc!("stats", "running", "s.stats -> map", "Work counters: steps, rejected steps, right-hand-side evaluations.", "let s = scene(); s.add(dumbbell()); s.run_periods(1); print(s.stats);"),
    doc!("center", "reading", "s.center(i) -> [x, y, z]", "Hydrodynamic centre R_H of swimmer i (m).", "let s = scene(); s.add(dumbbell()); print(s.center(0));"),
    doc!("dir", "reading", "s.dir(i) -> [x, y, z]", "Unit orientation N of swimmer i (from the a1 sphere to the a2 sphere).", "let s = scene(); s.add(dumbbell(#{ dir: [0, 1, 0] })); print(s.dir(0));"),
    doc!("velocity", "reading", "s.velocity(i) -> [x, y, z]", "dR_H/dt of swimmer i now (m/s).", PAIR_VELOCITY),
    doc!("spin", "reading", "s.spin(i) -> [x, y, z]", "dN/dt of swimmer i now (1/s).", "let s = scene(); s.add(dumbbell()); print(s.spin(0));"),
    doc!("length", "reading", "s.length(i) -> float\nlength(i) -> Observable", "Length |X2 - X1| of swimmer i (m); as a global function, the observable.", "let s = scene(); s.add(dumbbell()); print(s.length(0)); print(length(0));"),
    doc!("swimmer", "reading", "s.swimmer(i) -> Dumbbell", "Parameters and current pose of swimmer i.", "let s = scene(); s.add(dumbbell()); print(s.swimmer(0));"),
    doc!("observe", "observables", "s.observe(obs) -> float | array", "Evaluate an observable now.", "let s = scene(); s.add(dumbbell()); print(s.observe(R_H(0)));"),
    doc!("R_H", "observables", "R_H(i) -> Observable", "Hydrodynamic centre of swimmer i (m).", "print(R_H(0));"),
    doc!("R_G", "observables", "R_G(i) -> Observable", "Geometric centre (X1 + X2)/2 of swimmer i (m).", "print(R_G(0));"),
    doc!("N", "observables", "N(i) -> Observable", "Unit orientation of swimmer i.", "print(N(0));"),
    doc!("tension", "observables", "tension(i) -> Observable", "Spring tension k0 (d - L) of swimmer i (N), microscopic model.", "print(tension(0));"),
    doc!("pair_mean", "observables", "pair_mean(i, j) -> Observable\npair_mean(i, j, axis) -> Observable", "(R_H^i + R_H^j)/2 along axis (default x) (m).", "print(pair_mean(0, 1, [0, 0, 1]));"),
    doc!("pair_separation", "observables", "pair_separation(i, j) -> Observable\npair_separation(i, j, axis) -> Observable", "R_H^j - R_H^i along axis (default x) (m).", "print(pair_separation(0, 1));"),
    doc!("q", "observables", "q(i, j) -> Observable", "q = N^i . N^j.", "print(q(0, 1));"),
    doc!("D_H", "observables", "D_H(i, j) -> Observable", "Distance |R_H^i - R_H^j| (m).", "print(D_H(0, 1));"),
    doc!("delta_q", "observables", "delta_q(i, j) -> Observable", "q(0) - q(T) over the next period, measured on a copy (the scene is not advanced).", PAIR_DELTA_Q),
    doc!("delta_D_H", "observables", "delta_D_H(i, j) -> Observable", "[D_H(0) - D_H(T)]/ell over the next period, on a copy; > 0: approaching.", "print(delta_D_H(0, 1));"),
    doc!("mean_speed", "observables", "mean_speed() -> Observable", "Mean swimming speed <|V|> over the swimmers (m/s). Averaged model: V = dR_H/dt. Sphere models: the displacement of R_H over the next period divided by T, measured on a copy of the scene (costs one period per evaluation).", "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [20e-6, 0, 0], phase: 1.0 })); s.model = \"averaged\"; print(s.observe(mean_speed()));"),
    doc!("pair_distances", "observables", "pair_distances(bins, r_max) -> Observable", "Histogram of the hydrodynamic-centre distances D_H of all pairs: an array of bins counts, bin k covering [k, k+1) * r_max / bins (m); pairs at r_max or beyond are not counted. Recorded as columns D_H_hist[0], D_H_hist[1], ...", "let s = scene(); s.add_random(dumbbell(#{}), 30, 0.01, 2); print(s.observe(pair_distances(10, 100e-6)));"),
    doc!("polarization", "observables", "polarization() -> Observable", "|<N>| over all swimmers.", "let s = scene(); s.add(dumbbell()); print(s.observe(polarization()));"),
    doc!("min_gap", "observables", "min_gap() -> Observable", "The smallest gap between the surfaces of any two spheres of the scene (m): how close the closest approach is. O(N²), parallel for large scenes.", "let s = scene(); s.add(dumbbell(#{})); s.add(dumbbell(#{ center: [2e-5, 0.0, 0.0] })); print(s.observe(min_gap()));"),
    doc!("nematic", "observables", "nematic() -> Observable", "Largest eigenvalue of Q = <3NN - I>/2.", "let s = scene(); s.add(dumbbell()); print(s.observe(nematic()));"),
    doc!("record", "recording", "s.record([obs, ...], every) -> Recorder", "Record observables on a trigger: a number (every n periods), every_periods(n), every_seconds(t), at_times([..]) or at_end(). Periodic recorders take a row at once. Only the recorded observables are evaluated, only at their times.", PAIR_RECORD),
    doc!("every_periods", "recording", "every_periods(n) -> Trigger", "Every n periods from now.", "print(every_periods(2));"),
    doc!("every_seconds", "recording", "every_seconds(t) -> Trigger", "Every t seconds from now.", "print(every_seconds(1e-3));"),
    doc!("at_times", "recording", "at_times([t1, t2, ...]) -> Trigger", "At the given absolute times (s).", "print(at_times([0.01, 0.02]));"),
    doc!("at_end", "recording", "at_end() -> Trigger", "At the end of every run.", "print(at_end());"),
    doc!("rows", "recording", "rec.rows -> array of maps", "The recorded rows, keyed by column name (time, R_H[0].x, ...).", PAIR_ROWS),
    doc!("columns", "recording", "rec.columns -> array\nrec.header -> array\nrec.column(name) -> array", "Column names (without / with units) and one column's values.", PAIR_COLUMNS),
    doc!("stream_csv", "recording", "rec.stream_csv(path)", "From now on append every row to path as CSV the moment it is recorded (one whole line per row, unbuffered; the file starts with the header and the rows so far). A kill or Ctrl-C loses no row already recorded.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); r.stream_csv(\"out/help/stream.csv\"); s.run_periods(2);"),
    doc!("param", "running", "param(name, default) -> value", "The value given by swimlab run --set name=VALUE, or default without one: let D = param(\"D\", 10.0); lets a cluster job choose D. A --set name the script never reads, or hides with its own let, is an error.", "let D = param(\"D\", 10.0); print(D);"),
    doc!("to_csv", "recording", "rec.to_csv(path)", "Write the rows as CSV; the header carries names and units. Folders are created; the file is written whole to a temporary file and renamed, so a crash keeps the old one.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); s.run_periods(1); r.to_csv(\"out/help/r.csv\");"),
    doc!("save", "files", "s.save(path)", "Save the whole scene (swimmers, phases, model, integrator, time, state) as JSON; load_scene reads it back exactly. Recorders are not saved; an adaptive integrator restarts its step-size control after loading.", "let s = scene(); s.add(dumbbell()); s.save(\"out/help/scene.json\"); let t = load_scene(\"out/help/scene.json\"); print(t.count);"),
    doc!("load_scene", "files", "load_scene(path) -> Scene", "A scene saved with s.save(path).", "let s = scene(); s.save(\"out/help/empty.json\"); print(load_scene(\"out/help/empty.json\"));"),
    doc!("write_csv", "files", "write_csv(path, rows)\nwrite_csv(path, columns, rows)", "Write an array of maps as CSV (columns in the given order, or sorted).", "write_csv(\"out/help/t.csv\", [\"D\", \"v\"], [#{ D: 10.0, v: 1e-6 }]);"),
    doc!("sci", "formatting", "sci(x) -> string\nsci(x, digits) -> string", "Scientific notation.", "print(sci(1.23456e-7, 2));"),
    doc!("fixed", "formatting", "fixed(x, digits) -> string", "Fixed-point notation.", "print(fixed(3.14159, 2));"),
    doc!("lpad", "formatting", "lpad(x, width) -> string", "Right-align x in width characters.", "print(lpad(42, 6));"),
    doc!("rpad", "formatting", "rpad(x, width) -> string", "Left-align x in width characters.", "print(rpad(\"D\", 6) + \"|\");"),
    doc!("pi", "formatting", "pi() -> float", "The number pi.", "print(pi());"),
    doc!("quick", "formatting", "quick() -> bool", "True under `swimlab run --quick` (or SWIMLAB_QUICK=1): long scripts run a short variant.", "let n = if quick() { 1 } else { 100 }; print(n);"),
    doc!("is_number", "formatting", "is_number(x) -> bool", "Whether x is an integer or a float.", "print(is_number(1e-6));"),
    doc!("uniform_randoms", "formatting", "uniform_randoms(n, seed) -> array", "n reproducible uniform numbers in [0, 1) (splitmix64).", "print(uniform_randoms(3, 42));"),
    doc!("a1", "swimmer properties", "d.a1 -> float", "Radius of sphere 1 (m); N points from it to sphere 2.", "print(dumbbell().a1);"),
    doc!("a2", "swimmer properties", "d.a2 -> float", "Radius of sphere 2 (m).", "print(dumbbell(#{ a2: 1e-6 }).a2);"),
    doc!("ell", "swimmer properties", "d.ell -> float", "Mean length (m).", "print(dumbbell().ell);"),
    doc!("lambda", "swimmer properties", "d.lambda -> float", "Stroke amplitude (m).", "print(dumbbell().lambda);"),
    doc!("omega", "swimmer properties", "d.omega -> float", "Angular frequency (1/s).", "print(dumbbell().omega);"),
    doc!("k0", "swimmer properties", "d.k0 -> float", "Spring constant (kg/s^2).", "print(dumbbell().k0);"),
    doc!("name", "observables", "obs.name -> string\nobs.unit -> string", "An observable's name (its column prefix) and unit.", "print(q(0, 1).name); print(R_H(0).unit);"),
    doc!("unit", "observables", "obs.unit -> string", "An observable's unit (m, N, ell, or 1).", "print(D_H(0, 1).unit);"),
    doc!("len", "recording", "rec.len -> int", "Number of rows recorded.", "let s = scene(); s.add(dumbbell()); let r = s.record([R_H(0)], 1); s.run_periods(2); print(r.len);"),
    doc!("header", "recording", "rec.header -> array", "Column names with units, as written to CSV.", PAIR_COLUMNS),
    doc!("column", "recording", "rec.column(name) -> array", "One column's values.", PAIR_COLUMNS),
];

const PAIR_PHASES: &str = "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ center: [25e-6, 0, 0] })); s.phases = [0.0, phase_deg(90)]; print(s.phases);";
const PAIR_VELOCITY: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0] })); s.model = \"averaged\"; print(s.velocity(0));";
const PAIR_DELTA_Q: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0], dir: [0, 1, 0] })); print(s.observe(delta_q(0, 1)));";
const PAIR_RECORD: &str = "let s = scene(); s.add(dumbbell(#{ center: [-25e-6, 0, 0] })); s.add(dumbbell(#{ phase: pi() / 2.0, center: [25e-6, 0, 0] })); let rec = s.record([pair_mean(0, 1), pair_separation(0, 1)], 1); s.run_periods(2); print(rec);";
const PAIR_ROWS: &str = "let s = scene(); s.add(dumbbell()); let rec = s.record([R_H(0)], 1); s.run_periods(1); print(rec.rows[1].time);";
const PAIR_COLUMNS: &str = "let s = scene(); s.add(dumbbell()); let rec = s.record([q(0, 0)], at_end()); s.run_periods(1); print(rec.columns); print(rec.header); print(rec.column(\"q[0,0]\"));";

/// The entry for `name`.
pub fn lookup(name: &str) -> Option<&'static Doc> {
    DOCS.iter().find(|d| d.name == name)
}
