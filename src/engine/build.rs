//! Scene builders: random suspensions and lattices, seeded and reproducible.

use super::cells::CellMap;
use super::error::{invalid, require_positive, Result};
use super::model::Model;
use super::periodic::separation;
use super::scene::Scene;
use super::swimmer::{unit_direction, Dumbbell};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// SplitMix64: a small, fast, well-mixed generator; the same seed gives the same scene on every
/// platform.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniformly distributed unit vector.
    pub fn unit_vector(&mut self) -> Vector3<f64> {
        let z = 2.0 * self.uniform() - 1.0;
        let phi = 2.0 * PI * self.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Orientations of a built suspension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientations {
    /// Uniform on the sphere.
    Random,
    /// All along this unit vector.
    Aligned(Vector3<f64>),
}

/// Phases of a built suspension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phases {
    /// Uniform in [0, 2π).
    Random,
    /// All equal to this value (rad).
    Equal(f64),
}

/// Most swimmers one random placement may place: a scene of 2e6 averaged swimmers holds ~0.3 GB
/// and takes seconds a right-hand side; more is a memory exhaustion sooner than a simulation.
pub const MAX_RANDOM_SWIMMERS: usize = 2_000_000;

/// The side (m) of the cube holding `n` copies of `d` at sphere volume fraction `phi`.
pub fn box_side(n: usize, d: &Dumbbell, phi: f64) -> Result<f64> {
    require_positive("volume fraction", phi, "dimensionless")?;
    if phi >= 0.3 {
        return Err(invalid!(
            "volume fraction {phi} is too dense for random placement of dumbbells (use < 0.3)"
        ));
    }
    let v = 4.0 / 3.0 * PI * (d.a1.powi(3) + d.a2.powi(3));
    Ok((n as f64 * v / phi).cbrt())
}

/// `n` copies of `d` placed uniformly at random in a box of sides `sides` (m) centred on the
/// origin (the scene's periodic box, or a region of open space), every sphere gap wider than the
/// strokes can close (by minimum images in a periodic box), with the given orientations and
/// phases: random sequential addition from the generator seeded with `seed`.
pub fn random_suspension(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    sides: [f64; 3],
    orientations: Orientations,
    phases: Phases,
    seed: u64,
) -> Result<()> {
    random_suspension_apart(scene, n, d, sides, orientations, phases, seed, None)
}

/// [`random_suspension`] with every sphere gap above `gap` (m) if given, instead of the default
/// 4λ·max(w1, w2) the strokes can close. Each candidate is tested against the spheres in the cells
/// around its own (cells as wide as the widest conflict, 2·largest radius + gap): O(1) per
/// candidate, so placement is O(n).
#[allow(clippy::too_many_arguments)]
pub fn random_suspension_apart(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    sides: [f64; 3],
    orientations: Orientations,
    phases: Phases,
    seed: u64,
    gap: Option<f64>,
) -> Result<()> {
    for side in sides {
        require_positive("box side", side, "m")?;
    }
    place_apart(scene, n, d, seed, gap, |rng| {
        let u = Vector3::new(rng.uniform(), rng.uniform(), rng.uniform()).add_scalar(-0.5);
        let c = u.component_mul(&Vector3::from(sides));
        let dir = match orientations {
            Orientations::Random => rng.unit_vector(),
            Orientations::Aligned(v) => v,
        };
        let phase = match phases {
            Phases::Random => 2.0 * PI * rng.uniform(),
            Phases::Equal(p) => p,
        };
        (c, dir, phase)
    })
}

/// Add `n` copies of `d` drawn by `draw` (centre, orientation, phase from the seeded generator)
/// by random sequential addition: a draw whose spheres would come within `gap` (at least what
/// the strokes can close) of a placed sphere, or into a wall, is drawn again.
pub fn place_apart(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    seed: u64,
    gap: Option<f64>,
    mut draw: impl FnMut(&mut Rng) -> (Vector3<f64>, Vector3<f64>, f64),
) -> Result<()> {
    if n > MAX_RANDOM_SWIMMERS {
        return Err(invalid!(
            "cannot place {n} swimmers at random in one call: one call places at most {MAX_RANDOM_SWIMMERS} (a scene that size holds ~0.3 GB and takes seconds a step); place fewer"
        ));
    }
    scene.check_placeable(&d)?;
    // Over a stroke a sphere moves by w·2λ along its axis (w = a_other/(a1+a2)): two spheres
    // placed further apart than 4λ·max(w1, w2) cannot be brought into contact by the strokes.
    let stroke = 4.0 * d.lambda * d.w1().max(d.w2());
    let margin = match gap {
        Some(g) => {
            require_positive("gap", g, "m")?;
            g.max(stroke)
        }
        None => stroke,
    };
    let a_max = scene
        .swimmers()
        .iter()
        .flat_map(|o| [o.a1, o.a2])
        .fold(d.a1.max(d.a2), f64::max);
    // The spheres placed so far: radii, binned by centre.
    let mut spheres = Spheres {
        cells: CellMap::new(2.0 * a_max + margin, scene.periodic()),
        radii: Vec::new(),
    };
    for i in 0..scene.count() {
        let (x1, x2) = scene.spheres(i);
        let o = &scene.swimmers()[i];
        spheres.insert(x1, o.a1);
        spheres.insert(x2, o.a2);
    }
    let periodic = scene.periodic().copied();
    let mut rng = Rng::new(seed);
    let max_tries = 1000 * (n + 1);
    let mut tries = 0;
    let mut placed = 0;
    while placed < n {
        tries += 1;
        if tries > max_tries {
            return Err(invalid!(
                "placed only {placed} of {n} swimmers without overlaps after {max_tries} tries; use a larger box or a lower volume fraction"
            ));
        }
        let (c, dir, phase) = draw(&mut rng);
        let dir = unit_direction(dir)?;
        let new = Dumbbell { phase, ..d };
        let (x1, x2) = new.sphere_positions(c, dir, scene.contact_length(&new));
        // Above a wall only places clear of it count (one sphere's stroke closes half the
        // margin of a pair).
        let above = scene
            .check_clear_of_wall(&new, &x1, &x2, 0.5 * margin)
            .is_ok();
        let clear = above
            && [(x1, d.a1), (x2, d.a2)].iter().all(|&(x, a)| {
                spheres.cells.near(x.x, x.y, x.z, |k, at| {
                    let k = k as usize;
                    let gap = separation(periodic.as_ref(), x - Vector3::from(at)).norm()
                        - a
                        - spheres.radii[k];
                    gap > margin
                })
            });
        if clear {
            scene.push(new, c, dir);
            spheres.insert(x1, d.a1);
            spheres.insert(x2, d.a2);
            placed += 1;
        }
    }
    Ok(())
}

/// Placed spheres for [`random_suspension_apart`]: binned by centre (the cells keep the
/// centres), with their radii.
struct Spheres {
    cells: CellMap,
    radii: Vec<f64>,
}

impl Spheres {
    fn insert(&mut self, x: Vector3<f64>, a: f64) {
        self.cells.insert(x.x, x.y, x.z, self.radii.len() as u32);
        self.radii.push(a);
    }
}

/// A cubic lattice of `swimmers` Fig-1 swimmers (symmetric, spacing 3ℓ, along x, phases spread
/// over the period) for timings: every pair interacts.
pub fn lattice_scene(swimmers: usize, model: Model) -> Result<Scene> {
    lattice_scene_of(swimmers, model, Dumbbell::default())
}

/// [`lattice_scene`] of swimmers `d` (their phases spread over the period).
pub fn lattice_scene_of(swimmers: usize, model: Model, d: Dumbbell) -> Result<Scene> {
    let mut s = Scene::new();
    s.set_model(model);
    let side = (swimmers as f64).cbrt().ceil() as usize;
    let spacing = 3.0 * d.ell;
    for i in 0..swimmers {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let phase = (i as f64 * 0.7) % (2.0 * std::f64::consts::PI);
        let c = Vector3::new(x as f64, y as f64, z as f64) * spacing;
        s.add(Dumbbell { phase, ..d }, c, Vector3::x())?;
    }
    Ok(s)
}
