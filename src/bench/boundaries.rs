//! One right-hand side of a suspension in each boundary against the same swimmers in open space:
//! the microscopic (spring) and rigid-stroke models, side by side in one process.
//!
//! Each size is `S` asymmetric Fig-1 swimmers (a2 = a1/2) placed at random at sphere volume
//! fraction φ = 1% in a cube ([`crate::engine::build::box_side`]); the same state is then
//! evaluated in open space, in the periodic box of that side, and above a wall just below the
//! cube. The times are medians of right-hand sides repeated until each series has run ~0.3 s or
//! 1,000 times (at least 3), the system built once (as a run builds it once) and the time
//! advanced by a fortieth of a period between them (as a run's stages advance; the rigid model's
//! iteration starts from the earlier tensions). The box's sums keep the tolerance the scene's
//! default integrator gives them (`Scene::ewald_tol`) unless another is given; the table says
//! which. Above the wall the divergence ∇·M, which a thermal run adds as the drift kT ∇·M once a
//! right-hand side, is timed at the same state.

use super::table::Table;
use crate::engine::build::{box_side, random_suspension, Orientations, Phases};
use crate::engine::mobility::MobilityOperator;
use crate::engine::wall::{Wall, WallMobility};
use crate::engine::{Dumbbell, Model, Scene};
use std::time::Instant;

/// The sphere volume fraction of every scene.
pub const PHI: f64 = 0.01;

/// One model at one size.
#[derive(Debug, Clone)]
pub struct Row {
    /// The model.
    pub model: Model,
    /// Swimmers.
    pub swimmers: usize,
    /// Seconds per right-hand side in open space.
    pub open: f64,
    /// In the periodic box.
    pub periodic: f64,
    /// Above the wall.
    pub wall: f64,
    /// The wall's divergence ∇·M (a thermal run's drift kT ∇·M, once a right-hand side).
    pub wall_divergence: f64,
    /// The box's Ewald tolerance.
    pub ewald_tol: f64,
}

/// Median seconds of `f`, repeated until the series has run ~0.3 s or 1,000 times (at least 3).
fn median_time(mut f: impl FnMut()) -> f64 {
    let mut times = Vec::new();
    let start = Instant::now();
    while times.len() < 3 || (start.elapsed().as_secs_f64() < 0.3 && times.len() < 1000) {
        let s = Instant::now();
        f();
        times.push(s.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Median seconds of the wall's divergence ∇·M at the spheres of `scene` (above `wall`).
fn divergence_time(scene: &Scene, wall: Wall) -> f64 {
    let mut pos = Vec::new();
    let mut radii = Vec::new();
    for (i, d) in scene.swimmers().iter().enumerate() {
        let (x1, x2) = scene.spheres(i);
        pos.extend([x1, x2]);
        radii.extend([d.a1, d.a2]);
    }
    let op = WallMobility::new(scene.mu(), scene.mobility(), wall);
    let mut div = vec![nalgebra::Vector3::zeros(); pos.len()];
    median_time(|| {
        op.divergence(&pos, &radii, &mut div);
    })
}

/// Median seconds of one right-hand side of `scene` as it is.
fn rhs_time(scene: &Scene) -> Result<f64, String> {
    let mut sys = scene.system().map_err(|e| e.to_string())?;
    let (y, _) = scene.raw_state();
    let y = y.to_vec();
    let mut dy = vec![0.0; y.len()];
    let h = scene.period().map_err(|e| e.to_string())? / 40.0;
    let mut t = scene.time();
    let time = median_time(|| {
        t += h;
        sys.rhs(t, &y, &mut dy);
    });
    if dy.iter().any(|v| !v.is_finite()) {
        return Err("a right-hand side was not finite".into());
    }
    Ok(time)
}

/// The paper's asymmetric swimmer: a2 = a1/2, a1 = 1.5 Λ with Λ = 0.15 ℓ.
pub fn asymmetric_swimmer() -> Dumbbell {
    let mut d = Dumbbell::default();
    (d.a1, d.a2) = (0.225 * d.ell, 0.1125 * d.ell);
    d
}

/// `swimmers` random Fig-1 swimmers at φ = 1% under `model`, in open space, a box (its sums to
/// `ewald_tol`, else the one the default integrator gives them) and above a wall.
pub fn measure(
    model: Model,
    swimmers: usize,
    seed: u64,
    ewald_tol: Option<f64>,
) -> Result<Row, String> {
    let err = |e: crate::engine::EngineError| e.to_string();
    let d = asymmetric_swimmer();
    let side = box_side(swimmers, &d, PHI).map_err(err)?;
    let mut scene = Scene::new();
    scene.set_model(model);
    if let Some(tol) = ewald_tol {
        scene.set_ewald_tol(Some(tol)).map_err(err)?;
    }
    scene.set_box(Some([side; 3])).map_err(err)?;
    random_suspension(
        &mut scene,
        swimmers,
        d,
        [side; 3],
        Orientations::Random,
        Phases::Random,
        seed,
    )
    .map_err(err)?;
    let periodic = rhs_time(&scene)?;
    let ewald_tol = scene.ewald_tol();
    scene.set_box(None).map_err(err)?;
    let open = rhs_time(&scene)?;
    let reach = d.ell + d.lambda + d.a1.max(d.a2);
    let plane = Wall::at(-0.5 * side - reach).map_err(err)?;
    scene.set_wall(Some(plane)).map_err(err)?;
    let wall = rhs_time(&scene)?;
    let wall_divergence = divergence_time(&scene, plane);
    Ok(Row {
        model,
        swimmers,
        open,
        periodic,
        wall,
        wall_divergence,
        ewald_tol,
    })
}

/// The microscopic and rigid-stroke models at every size in `sizes`, the box's sums to
/// `ewald_tol` (else the one the default integrator gives them).
pub fn run(sizes: &[usize], ewald_tol: Option<f64>) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    for &s in sizes {
        for model in [Model::Micro, Model::Rigid] {
            rows.push(measure(model, s, 0x5eed + s as u64, ewald_tol)?);
        }
    }
    Ok(rows)
}

/// The table: seconds per right-hand side in each boundary, the ratios to open space, the wall's
/// divergence over the spring model's right-hand side in open space, and the rigid model's
/// open-space time over the spring model's at the same size.
pub fn table(rows: &[Row]) -> Table {
    let mut t = Table::new(&[
        "model",
        "swimmers",
        "ewald_tol",
        "open_s",
        "box_s",
        "wall_s",
        "box_over_open",
        "wall_over_open",
        "wall_div_over_micro_open",
        "open_over_micro_open",
    ]);
    for r in rows {
        let micro = rows
            .iter()
            .find(|m| m.model == Model::Micro && m.swimmers == r.swimmers)
            .map_or(f64::NAN, |m| m.open);
        t.rows.push(vec![
            r.model.name().to_string(),
            r.swimmers.to_string(),
            format!("{:.1e}", r.ewald_tol),
            format!("{:.3e}", r.open),
            format!("{:.3e}", r.periodic),
            format!("{:.3e}", r.wall),
            format!("{:.2}", r.periodic / r.open),
            format!("{:.2}", r.wall / r.open),
            format!("{:.2}", r.wall_divergence / micro),
            format!("{:.2}", r.open / micro),
        ]);
    }
    t
}
