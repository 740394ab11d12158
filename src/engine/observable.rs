//! Named quantities that can be measured on a scene now ([`Observable::evaluate`]) or recorded on a
//! trigger ([`super::recorder`]). Each knows its name, its components and their unit.

use super::advance::Probe;
use super::error::Result;
use super::fields::{Field, FieldKind, FieldSpec, FieldStat};
use super::pair_correlation::{self, PairPart};
use super::scene::Scene;
use super::stepping::{RunControl, Workspace};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// A quantity of one swimmer, a pair, or the whole scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Observable {
    /// Hydrodynamic centre R_H of swimmer i (m).
    CenterH(usize),
    /// Geometric centre R_G = (X1 + X2)/2 of swimmer i (m).
    CenterG(usize),
    /// Unit orientation N of swimmer i.
    Dir(usize),
    /// Length |X2 − X1| of swimmer i (m).
    Length(usize),
    /// Spring tension k0 (d − L) of swimmer i (N), microscopic model.
    Tension(usize),
    /// Mean position (R_H^i + R_H^j)/2 projected on `axis` (m).
    PairMean(usize, usize, Vector3<f64>),
    /// Separation R_H^j − R_H^i projected on `axis` (m).
    PairSeparation(usize, usize, Vector3<f64>),
    /// q = N^i · N^j.
    Q(usize, usize),
    /// D_H = |R_H^i − R_H^j| (m), by minimum image in a box.
    DistanceH(usize, usize),
    /// Δq(T) = q(0) − q(T) over the next period (a probe run on a copy of the scene).
    DeltaQ(usize, usize),
    /// ΔD_H(T) = [D_H(0) − D_H(T)]/ℓ over the next period (probe run on a copy), in ℓ of swimmer i.
    DeltaDistanceH(usize, usize),
    /// Polarization |⟨N⟩|.
    Polarization,
    /// Nematic order: largest eigenvalue of Q = ⟨3NN − I⟩/2.
    Nematic,
    /// The smallest gap between the surfaces of any two spheres of the scene (m).
    MinGap,
    /// The smallest gap between a sphere's surface and the wall (m).
    WallGap,
    /// Height of swimmer i's hydrodynamic centre R_H above the wall (m).
    Height(usize),
    /// Angle of swimmer i's orientation N to the wall's plane (rad; positive pointing away from
    /// the wall, in [−π/2, π/2]).
    WallAngle(usize),
    /// Mean swimming speed ⟨|V|⟩ over the swimmers (m/s): V = dR_H/dt in the averaged model, the
    /// displacement of R_H over the next period / T in the sphere models (a probe run on a copy).
    MeanSpeed,
    /// Mean squared displacement ⟨|R_H(t) − R_H(t0)|²⟩ over the swimmers, t0 each one's origin:
    /// its placement or the last [`Scene::reset_origins`] (m²).
    Msd,
    /// Orientation autocorrelation of order l (1 or 2) over the swimmers since each one's origin
    /// (as [`Observable::Msd`]): C1 = ⟨N(t)·N(t0)⟩, C2 = ⟨P2(N(t)·N(t0))⟩; free rotational
    /// diffusion gives e^{−l(l+1) D_r t}.
    OrientationAutocorrelation(u8),
    /// The pair correlation of the centres in the box, one part of it ([`pair_correlation`]):
    /// `bins` shells of equal width up to r_max.
    PairCorrelation {
        /// Number of shells.
        bins: usize,
        /// Upper end of the last shell (m), at most half the box's shortest side.
        r_max: f64,
        /// g, g1 or g2.
        part: PairPart,
    },
    /// Péclet number of the pair (i, j): the deterministic drift of its mean position over one
    /// period against the rms diffusion of that mean along one axis in the same time,
    /// |V| T / √(2 D T), with D = (D_t^i + D_t^j)/4 the mean's coefficient as rigid dumbbells.
    Peclet(usize, usize),
    /// Histogram of the centre distances D_H of all pairs: `bins` counts, bin k covering
    /// [k, k+1) · r_max/bins (m); pairs at r_max or beyond are not counted.
    PairDistances {
        /// Number of bins.
        bins: usize,
        /// Upper end of the last bin (m).
        r_max: f64,
    },
    /// A scalar summary of a field's cells ([`super::fields`]): of ρ (1/m³), |Π| or Q's largest
    /// eigenvalue.
    Field {
        /// Which field.
        kind: FieldKind,
        /// Which summary.
        stat: FieldStat,
        /// Its grid and smoothing.
        spec: FieldSpec,
    },
}

/// Most bins a pair-distance histogram may have (a recorder row holds one column per bin).
pub const MAX_BINS: usize = 10_000;

/// `name [unit]`, e.g. `R_H[0] [m]`.
impl std::fmt::Display for Observable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} [{}]", self.name(), self.unit())
    }
}

impl Observable {
    /// Short name, e.g. `R_H[0]`, `q[0,1]`.
    pub fn name(&self) -> String {
        match self {
            Observable::CenterH(i) => format!("R_H[{i}]"),
            Observable::CenterG(i) => format!("R_G[{i}]"),
            Observable::Dir(i) => format!("N[{i}]"),
            Observable::Length(i) => format!("length[{i}]"),
            Observable::Tension(i) => format!("tension[{i}]"),
            Observable::PairMean(i, j, _) => format!("mean[{i},{j}]"),
            Observable::PairSeparation(i, j, _) => format!("separation[{i},{j}]"),
            Observable::Q(i, j) => format!("q[{i},{j}]"),
            Observable::DistanceH(i, j) => format!("D_H[{i},{j}]"),
            Observable::DeltaQ(i, j) => format!("dq_T[{i},{j}]"),
            Observable::DeltaDistanceH(i, j) => format!("dD_H_T[{i},{j}]"),
            Observable::Polarization => "polarization".into(),
            Observable::Nematic => "nematic".into(),
            Observable::MinGap => "min_gap".into(),
            Observable::WallGap => "wall_gap".into(),
            Observable::Height(i) => format!("height[{i}]"),
            Observable::WallAngle(i) => format!("wall_angle[{i}]"),
            Observable::MeanSpeed => "mean_speed".into(),
            Observable::Msd => "msd".into(),
            Observable::OrientationAutocorrelation(l) => format!("C{l}"),
            Observable::PairCorrelation { part, .. } => part.name().into(),
            Observable::Peclet(i, j) => format!("Pe[{i},{j}]"),
            Observable::PairDistances { .. } => "D_H_hist".into(),
            Observable::Field { kind, stat, .. } => format!("{}_{}", kind.name(), stat.name()),
        }
    }

    /// Unit of every component.
    pub fn unit(&self) -> &'static str {
        match self {
            Observable::CenterH(_)
            | Observable::CenterG(_)
            | Observable::Length(_)
            | Observable::PairMean(..)
            | Observable::PairSeparation(..)
            | Observable::DistanceH(..)
            | Observable::MinGap
            | Observable::WallGap
            | Observable::Height(_) => "m",
            Observable::WallAngle(_) => "rad",
            Observable::Tension(_) => "N",
            Observable::MeanSpeed => "m/s",
            Observable::Msd => "m^2",
            Observable::PairDistances { .. } => "pairs",
            Observable::Field {
                kind: FieldKind::Density,
                stat: FieldStat::Variance,
                ..
            } => "1/m^6",
            Observable::Field {
                kind: FieldKind::Density,
                ..
            } => "1/m^3",
            Observable::DeltaDistanceH(..) => "ell",
            // Dimensionless: unit vectors, phase measures, order parameters, correlations, the
            // Péclet number, and the fields other than density.
            Observable::Dir(_)
            | Observable::Q(..)
            | Observable::DeltaQ(..)
            | Observable::Polarization
            | Observable::Nematic
            | Observable::OrientationAutocorrelation(_)
            | Observable::PairCorrelation { .. }
            | Observable::Peclet(..)
            | Observable::Field { .. } => "1",
        }
    }

    /// Column names of the components (`R_H[0].x`, … for vectors; the name for scalars).
    pub fn columns(&self) -> Vec<String> {
        let n = self.name();
        if let Observable::PairDistances { bins, .. } | Observable::PairCorrelation { bins, .. } =
            self
        {
            (0..*bins).map(|k| format!("{n}[{k}]")).collect()
        } else if self.is_vector() {
            ["x", "y", "z"].iter().map(|c| format!("{n}.{c}")).collect()
        } else {
            vec![n]
        }
    }

    /// Whether the value has three components.
    pub fn is_vector(&self) -> bool {
        matches!(
            self,
            Observable::CenterH(_) | Observable::CenterG(_) | Observable::Dir(_)
        )
    }

    /// The swimmer indices this observable refers to.
    fn indices(&self) -> Vec<usize> {
        match *self {
            Observable::CenterH(i)
            | Observable::CenterG(i)
            | Observable::Dir(i)
            | Observable::Length(i)
            | Observable::Tension(i)
            | Observable::Height(i)
            | Observable::WallAngle(i) => vec![i],
            Observable::PairMean(i, j, _)
            | Observable::PairSeparation(i, j, _)
            | Observable::Q(i, j)
            | Observable::DistanceH(i, j)
            | Observable::DeltaQ(i, j)
            | Observable::DeltaDistanceH(i, j)
            | Observable::Peclet(i, j) => vec![i, j],
            Observable::Polarization
            | Observable::Msd
            | Observable::Nematic
            | Observable::MinGap
            | Observable::WallGap
            | Observable::MeanSpeed
            | Observable::PairDistances { .. }
            | Observable::OrientationAutocorrelation(_)
            | Observable::PairCorrelation { .. }
            | Observable::Field { .. } => vec![],
        }
    }

    /// Check that the indices exist in `scene` and the parameters make sense.
    pub fn check(&self, scene: &Scene) -> Result<()> {
        if let Observable::Field { spec, .. } = self {
            spec.check()?;
        }
        if let Observable::PairDistances { bins, r_max } = *self {
            if bins == 0 || bins > MAX_BINS || !(r_max.is_finite() && r_max > 0.0) {
                return Err(super::error::invalid!(
                    "pair_distances(bins, r_max) needs 1 to {MAX_BINS} bins and a positive r_max in m, got {bins} and {r_max}; e.g. pair_distances(50, 100e-6)"
                ));
            }
        }
        if let Observable::PairCorrelation { bins, r_max, .. } = *self {
            if bins == 0 || bins > MAX_BINS || !(r_max.is_finite() && r_max > 0.0) {
                return Err(super::error::invalid!(
                    "pair_correlation(bins, r_max) needs 1 to {MAX_BINS} shells and a positive r_max in m, got {bins} and {r_max}; e.g. pair_correlation(50, 50e-6)"
                ));
            }
        }
        if let Observable::OrientationAutocorrelation(l) = *self {
            if !(1..=2).contains(&l) {
                return Err(super::error::invalid!(
                    "the orientation autocorrelation has order 1 (<N(t).N(t0)>) or 2 (<P2(N(t).N(t0))>), got {l}"
                ));
            }
        }
        for i in self.indices() {
            scene.swimmer(i)?;
        }
        if matches!(
            self,
            Observable::WallGap | Observable::Height(_) | Observable::WallAngle(_)
        ) && scene.geometry().floor().is_none()
        {
            return Err(super::error::invalid!(
                "{} is measured from the wall, and this scene has none; give the scene a wall first (a plane at height z, m)",
                self.name()
            ));
        }
        Ok(())
    }

    /// What a scene-wide observable that has no value without swimmers measures, or `None`
    /// (the one-swimmer and pair observables name their swimmers; a histogram of no pairs is
    /// all zeros; a field refuses an empty scene itself).
    fn over_the_swimmers(&self) -> Option<&'static str> {
        match self {
            Observable::Polarization | Observable::Nematic => {
                Some("an order of the swimmers' orientations")
            }
            Observable::MeanSpeed | Observable::Msd | Observable::OrientationAutocorrelation(_) => {
                Some("an average over the swimmers")
            }
            Observable::MinGap => Some("the smallest gap between two spheres of the swimmers"),
            Observable::WallGap => Some("the smallest gap between the wall and a swimmer's sphere"),
            _ => None,
        }
    }

    /// The value now (1 or 3 components).
    pub fn evaluate(&self, s: &Scene) -> Result<Vec<f64>> {
        let mut ws = Workspace::default();
        self.measure(s, &mut Probe::new(&mut ws, &RunControl::default()))
    }

    /// The value now; the observables that compare with one period later (`delta_q`,
    /// `delta_D_H`, `mean_speed` in the sphere models) run a copy there with `probe`, which stops
    /// at a step boundary on its control's interrupt, reporting the scene's own time (the scene
    /// itself is never changed).
    pub fn measure(&self, s: &Scene, probe: &mut Probe) -> Result<Vec<f64>> {
        self.check(s)?;
        // Checked here and not in `check`: a recorder may be set up before the swimmers come.
        if s.count() == 0 {
            if let Some(what) = self.over_the_swimmers() {
                return Err(super::error::invalid!(
                    "{} is {what}, and this scene has no swimmers, so it has no value; add swimmers first",
                    self.name()
                ));
            }
        }
        let v3 = |v: Vector3<f64>| vec![v.x, v.y, v.z];
        Ok(match *self {
            Observable::CenterH(i) => v3(s.center(i)?),
            Observable::CenterG(i) => {
                let (a, b) = s.spheres(i);
                v3((a + b) / 2.0)
            }
            Observable::Dir(i) => v3(s.dir(i)?),
            Observable::Length(i) => vec![s.length(i)?],
            Observable::Tension(i) => vec![s.tension(i)?],
            Observable::PairMean(i, j, axis) => {
                // Displacements first: the mean of two large positions would round the drift.
                let base =
                    (s.center(i)? - s.displacement(i)? + s.center(j)? - s.displacement(j)?) / 2.0;
                let disp = (s.displacement(i)? + s.displacement(j)?) / 2.0;
                vec![base.dot(&axis) + disp.dot(&axis)]
            }
            Observable::PairSeparation(i, j, axis) => {
                vec![(s.center(j)? - s.center(i)?).dot(&axis)]
            }
            Observable::Q(i, j) => vec![s.dir(i)?.dot(&s.dir(j)?)],
            Observable::DistanceH(i, j) => {
                vec![s.geometry().separation(s.center(i)? - s.center(j)?).norm()]
            }
            Observable::DeltaQ(i, j) => {
                let q = Observable::Q(i, j);
                let (before, after) = Self::over_a_period(s, &q, probe)?;
                vec![before[0] - after[0]]
            }
            Observable::DeltaDistanceH(i, j) => {
                let d = Observable::DistanceH(i, j);
                let (before, after) = Self::over_a_period(s, &d, probe)?;
                vec![(before[0] - after[0]) / s.swimmer(i)?.ell]
            }
            Observable::Polarization => {
                let mut sum = Vector3::zeros();
                for i in 0..s.count() {
                    sum += s.dir(i)?;
                }
                vec![sum.norm() / s.count().max(1) as f64]
            }
            Observable::Nematic => {
                if s.count() == 0 {
                    return Ok(vec![0.0]);
                }
                let mut q = Matrix3::zeros();
                for i in 0..s.count() {
                    let n = s.dir(i)?;
                    q += 1.5 * n * n.transpose() - 0.5 * Matrix3::identity();
                }
                q /= s.count() as f64;
                vec![SymmetricEigen::new(q).eigenvalues.max()]
            }
            Observable::MinGap => vec![Self::min_gap(s)],
            Observable::WallGap => vec![Self::wall_gap(s)],
            Observable::Height(i) => vec![s.center(i)?.z - Self::wall_z(s)],
            Observable::WallAngle(i) => vec![s.dir(i)?.z.clamp(-1.0, 1.0).asin()],
            Observable::MeanSpeed => {
                let v = probe.center_velocities(s)?;
                vec![v.iter().map(|v| v.norm()).sum::<f64>() / v.len().max(1) as f64]
            }
            Observable::PairDistances { bins, r_max } => Self::histogram(s, bins, r_max)?,
            Observable::Field { kind, stat, spec } => vec![Field::of(s, kind, &spec)?.stat(stat)],
            Observable::Msd => {
                let mut sum = 0.0;
                for i in 0..s.count() {
                    sum += s.displacement_since_origin(i)?.norm_squared();
                }
                vec![sum / s.count().max(1) as f64]
            }
            Observable::OrientationAutocorrelation(l) => {
                let mut sum = 0.0;
                for i in 0..s.count() {
                    let c = s.dir(i)?.dot(&s.origin(i)?.dir);
                    sum += if l == 1 { c } else { 1.5 * c * c - 0.5 };
                }
                vec![sum / s.count().max(1) as f64]
            }
            Observable::PairCorrelation { bins, r_max, part } => {
                pair_correlation::of_scene(s, bins, r_max)?
                    .part(part)
                    .to_vec()
            }
            Observable::Peclet(i, j) => vec![Self::peclet(s, i, j, probe)?],
        })
    }

    /// The Péclet number of pair (i, j) ([`Observable::Peclet`]): the drift from a probe on a
    /// noise-free copy with the model's default integrator, the diffusion at the scene's
    /// temperature.
    fn peclet(s: &Scene, i: usize, j: usize, probe: &mut Probe) -> Result<f64> {
        if !s.thermal().is_on() {
            return Err(super::error::invalid!(
                "the Peclet number compares drift with diffusion, and at temperature 0 nothing diffuses; set a temperature above 0 K"
            ));
        }
        let mut quiet = s.clone();
        quiet.set_temperature(0.0)?;
        quiet.set_integrator(None);
        if !quiet.swimmer_model().stroke_averaged() {
            // A noisy state lies off the stroke's cycle by the thermal spring fluctuation, whose
            // relaxation moves R_H (the dumbbell's own spheres interact) by far more than a
            // period's drift: relax for one period first.
            quiet = probe.one_period_later(&quiet)?;
        }
        let v = probe.center_velocities(&quiet)?;
        let drift = (v[i] + v[j]) / 2.0;
        let t = s.period()?;
        let d = (s.rigid_diffusion(i)?.translation() + s.rigid_diffusion(j)?.translation()) / 4.0;
        let pe = drift.norm() * t / (2.0 * d * t).sqrt();
        if !pe.is_finite() {
            return Err(super::error::invalid!(
                "the Peclet number at {:e} K is beyond what f64 holds: the diffusion coefficient, {d:e} m^2/s, is too small to divide the drift by; give a temperature nearer room temperature (e.g. 300 K)",
                s.thermal().temperature
            ));
        }
        Ok(pe)
    }

    /// Counts of pair distances D_H in `bins` bins on [0, r_max); rows in parallel for large scenes.
    fn histogram(s: &Scene, bins: usize, r_max: f64) -> Result<Vec<f64>> {
        use rayon::prelude::*;
        let c = (0..s.count())
            .map(|i| s.center(i))
            .collect::<Result<Vec<_>>>()?;
        let width = r_max / bins as f64;
        let g = s.geometry();
        let row = |i: usize| {
            let mut h = vec![0.0; bins];
            for cj in &c[i + 1..] {
                let k = (g.separation(c[i] - cj).norm() / width) as usize;
                if k < bins {
                    h[k] += 1.0;
                }
            }
            h
        };
        let add = |mut a: Vec<f64>, b: Vec<f64>| {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
            a
        };
        // Counts are integers in f64: the sum is exact in any order.
        Ok(if c.len() >= 256 {
            (0..c.len())
                .into_par_iter()
                .map(row)
                .reduce(|| vec![0.0; bins], add)
        } else {
            (0..c.len()).map(row).fold(vec![0.0; bins], add)
        })
    }

    /// The wall's height (checked to exist by [`Observable::check`]).
    fn wall_z(s: &Scene) -> f64 {
        s.geometry().floor().unwrap_or(0.0)
    }

    /// The smallest gap between a sphere and the wall (m); [`Observable::check`] makes sure there
    /// are both.
    fn wall_gap(s: &Scene) -> f64 {
        let g = s.geometry();
        (0..s.count())
            .flat_map(|i| {
                let (x1, x2) = s.spheres(i);
                let d = s.swimmers()[i];
                [g.gap(&x1, d.a1), g.gap(&x2, d.a2)]
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The smallest sphere gap of the scene (m); [`Observable::check`] makes sure there is a
    /// swimmer, whose two spheres make a pair.
    fn min_gap(s: &Scene) -> f64 {
        s.closest_spheres().map_or(f64::INFINITY, |g| g.0)
    }

    /// Value of `obs` now and one period later, on a copy of the scene (the scene is not changed).
    fn over_a_period(
        s: &Scene,
        obs: &Observable,
        probe: &mut Probe,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        let before = obs.evaluate(s)?;
        let later = probe.one_period_later(s)?;
        Ok((before, obs.evaluate(&later)?))
    }
}
