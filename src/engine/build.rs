//! Scene builders: random suspensions and lattices, seeded and reproducible.

use super::cells::CellMap;
use super::error::{invalid, require_positive, short, Result};
use super::model::Model;
use super::periodic::separation;
pub use super::rng::Rng;
use super::scene::Scene;
use super::swimmer::{unit_direction, Dumbbell};
use nalgebra::Vector3;
use std::f64::consts::PI;

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

/// The side (m) of the cube holding `n` copies of `d` at sphere volume fraction `phi`. Whether
/// that many fit is [`place_apart`]'s estimate ([`rsa_fill`]), which every random placement
/// shares.
pub fn box_side(n: usize, d: &Dumbbell, phi: f64) -> Result<f64> {
    require_positive("volume fraction", phi, "dimensionless")?;
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
    let draw = Draw {
        orientations,
        phases,
        seed,
        gap: None,
    };
    random_suspension_apart(scene, n, d, sides, draw)
}

/// How a random suspension is drawn: its orientations and phases, the generator's seed, and the
/// smallest sphere gap at placement (m; `None`: the 4λ·max(w1, w2) the strokes can close).
#[derive(Debug, Clone, Copy)]
pub struct Draw {
    /// The swimmers' orientations.
    pub orientations: Orientations,
    /// Their stroke phases.
    pub phases: Phases,
    /// The generator's seed.
    pub seed: u64,
    /// The smallest sphere gap, if not the default.
    pub gap: Option<f64>,
}

/// [`random_suspension`] as `draw` says, every sphere gap above its `gap` (m) if given, instead of
/// the default 4λ·max(w1, w2) the strokes can close. Each candidate is tested against the spheres
/// in the cells around its own (cells as wide as the widest conflict, 2·largest radius + gap):
/// O(1) per candidate, so placement is O(n).
pub fn random_suspension_apart(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    sides: [f64; 3],
    draw: Draw,
) -> Result<()> {
    // No swimmers need no room (a volume fraction gives them a cube of side 0).
    if n == 0 {
        return Ok(());
    }
    for side in sides {
        require_positive("box side", side, "m")?;
    }
    scene.check_region_reach(&d, sides)?;
    let Draw {
        orientations,
        phases,
        seed,
        gap,
    } = draw;
    place_in(scene, n, d, seed, gap, Some(sides), |rng| {
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
/// the strokes can close) of a placed sphere, or into a wall, is drawn again. In a periodic box
/// the draws are taken to cover the box: a count that cannot fit there ([`rsa_fill`]) is refused
/// before the first draw, and the draws stop at [`DRAWS_PER_BODY`] for every body the box holds.
pub fn place_apart(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    seed: u64,
    gap: Option<f64>,
    draw: impl FnMut(&mut Rng) -> (Vector3<f64>, Vector3<f64>, f64),
) -> Result<()> {
    let region = scene.periodic().map(|b| b.sides());
    place_in(scene, n, d, seed, gap, region, draw)
}

/// [`place_apart`] with the centres drawn in `region` (sides, m, of a cuboid centred on the
/// origin), if known: a count that cannot fit there is refused before the first draw, and the
/// draws are bounded by the room there.
fn place_in(
    scene: &mut Scene,
    n: usize,
    d: Dumbbell,
    seed: u64,
    gap: Option<f64>,
    region: Option<[f64; 3]>,
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
    // The most draws: 1000 per swimmer, and no more than the room in the region calls for.
    let mut max_tries = 1000 * (n as u64 + 1);
    let mut fits = None;
    if let Some(sides) = region {
        let room = Room::new(scene, d, margin, sides)?;
        room.check(n, gap.filter(|g| *g > stroke))?;
        max_tries = max_tries.min(room.draws());
        fits = Some(room.fits());
    }
    let a_max = scene
        .swimmers()
        .iter()
        .flat_map(|o| [o.a1, o.a2])
        .fold(d.a1.max(d.a2), f64::max);
    // The spheres placed so far: radii, binned by centre.
    let mut spheres = Spheres {
        cells: CellMap::for_points(
            2.0 * a_max + margin,
            scene.periodic(),
            2 * (scene.count() + n),
        ),
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
    let mut tries = 0;
    let mut placed = 0;
    while placed < n {
        tries += 1;
        if tries > max_tries {
            let why = match fits {
                Some(k) => format!(
                    " (random sequential addition slows as the space fills: it makes {DRAWS_PER_BODY} draws for every body the space holds, where about {k} fit)"
                ),
                None => String::new(),
            };
            let wall = if scene.wall().is_some() {
                ", a lower wall"
            } else {
                ""
            };
            return Err(invalid!(
                "placed only {placed} of {n} swimmers without overlaps after {max_tries} draws{why}; place fewer, or give them more room (a larger box, a lower volume fraction{wall} or a smaller gap)"
            ));
        }
        let (c, dir, phase) = draw(&mut rng);
        let dir = unit_direction(dir)?;
        let new = Dumbbell { phase, ..d };
        let (x1, x2) = new.sphere_positions(c, dir, scene.contact_length(&new));
        // Above a wall only places clear of it count (one sphere's stroke closes half the
        // margin of a pair).
        let above = scene.clear_of_boundary(&new, &x1, &x2, 0.5 * margin);
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

/// Draws random sequential addition makes at most for every body (see [`Room`]) its space holds,
/// the budget at which [`rsa_fill`] is measured: placing near that fill takes as long as giving
/// up does, a few seconds for a 100 µm box of the paper's swimmers.
pub const DRAWS_PER_BODY: f64 = 100.0;

/// The fraction of space random sequential addition fills in [`DRAWS_PER_BODY`] draws per body the
/// space holds, with bodies of two balls of radii `b1`, `b2` whose centres are `dist` apart, drawn
/// with uniform orientations (the union's volume over the space's).
///
/// Balls alone fill 0.341 in that budget (0.3841 at jamming, the limit that random sequential
/// addition of spheres approaches as t^(-1/3)). Two balls kept apart need two free places at
/// once, which the filling space offers less often: far apart (`dist` ≥ 1.5 (b1 + b2)) equal
/// balls fill 0.26, unequal ones more, as the smaller one matters less (ρ = b_small/b_big:
/// 0.341 − 0.079 (1 − (1 − ρ)^2.5)); overlapping balls fill as one ball, and between the fill
/// falls linearly over 0.5 ≤ dist/(b1 + b2) ≤ 1.5. This fits runs of 5,000 to 10,000 bodies in
/// periodic boxes (ρ from 0.2 to 1, dist/(b1 + b2) from 0 to 5) within −6% and +2.3%; the
/// factor 1.023 puts it above every run's fill: a count it refuses did not fit in any of them.
pub fn rsa_fill(b1: f64, b2: f64, dist: f64) -> f64 {
    const BALLS: f64 = 0.341 * 1.023;
    const FAR_DROP: f64 = 0.079 * 1.023;
    let rho = b1.min(b2) / b1.max(b2);
    let far = BALLS - FAR_DROP * (1.0 - (1.0 - rho).powf(2.5));
    let ramp = (dist / (b1 + b2) - 0.5).clamp(0.0, 1.0);
    BALLS - (BALLS - far) * ramp
}

/// The volume of the union of two balls of radii `r1`, `r2` whose centres are `dist` apart (m³).
fn two_balls(r1: f64, r2: f64, dist: f64) -> f64 {
    let ball = |r: f64| 4.0 / 3.0 * PI * r.powi(3);
    if dist >= r1 + r2 {
        ball(r1) + ball(r2)
    } else if dist <= (r1 - r2).abs() {
        ball(r1.max(r2))
    } else {
        // Less the lens both hold.
        let lens = PI
            * (r1 + r2 - dist).powi(2)
            * (dist * dist + 2.0 * dist * (r1 + r2) - 3.0 * (r1 - r2).powi(2))
            / (12.0 * dist);
        ball(r1) + ball(r2) - lens
    }
}

/// The room random sequential addition has for swimmers `d` whose centres are drawn in a cuboid of
/// `sides` centred on the origin, every sphere gap kept above `margin`.
///
/// A gap above `margin` between spheres of radii a, a' is a contact-free distance above
/// (a + margin/2) + (a' + margin/2): each swimmer keeps clear a body of two balls of radii
/// a1 + margin/2, a2 + margin/2 (the wall keeps its gap above margin/2, so the bodies lie above
/// it). Their space is the region widened by a swimmer's reach from its centre (in a periodic box
/// at most the box; above a wall only what lies above it); the swimmers already there take their
/// bodies' volume of it.
struct Room<'a> {
    scene: &'a Scene,
    d: Dumbbell,
    margin: f64,
    sides: [f64; 3],
    /// The volume of one body (m³).
    body: f64,
    /// The fraction of the space the bodies fill ([`rsa_fill`]).
    fill: f64,
    /// The farthest a body reaches from its centre (m), over the stroke.
    reach: f64,
    /// The space's volume (m³).
    volume: f64,
    /// The swimmers already in the space, and their bodies' volume (m³).
    present: usize,
    occupied: f64,
}

impl<'a> Room<'a> {
    fn new(scene: &'a Scene, d: Dumbbell, margin: f64, sides: [f64; 3]) -> Result<Self> {
        let (b1, b2) = (d.a1 + 0.5 * margin, d.a2 + 0.5 * margin);
        let longest = d.ell + d.lambda;
        let mut room = Room {
            scene,
            d,
            margin,
            sides,
            body: two_balls(b1, b2, d.ell),
            fill: rsa_fill(b1, b2, d.ell),
            reach: (d.w2() * longest + b1).max(d.w1() * longest + b2),
            volume: 0.0,
            present: 0,
            occupied: 0.0,
        };
        let (lo, hi) = room.bounds(1.0)?;
        room.volume = (0..3).map(|k| hi[k] - lo[k]).product();
        let periodic = scene.periodic();
        for (i, o) in scene.swimmers().iter().enumerate() {
            let (x1, x2) = scene.spheres(i);
            let c = separation(periodic, 0.5 * (x1 + x2));
            if (0..3).all(|k| lo[k] <= c[k] && c[k] <= hi[k]) {
                room.present += 1;
                room.occupied +=
                    two_balls(o.a1 + 0.5 * margin, o.a2 + 0.5 * margin, (x2 - x1).norm());
            }
        }
        Ok(room)
    }

    /// The corners of the space for centres drawn in the region, with it (and a periodic box)
    /// scaled by `scale`; or the error of a wall above the region.
    fn bounds(&self, scale: f64) -> Result<([f64; 3], [f64; 3])> {
        let sides = self.sides.map(|s| s * scale);
        let box_sides = self.scene.periodic().map(|b| b.sides().map(|s| s * scale));
        let half: [f64; 3] = std::array::from_fn(|k| {
            let h = 0.5 * sides[k] + self.reach;
            box_sides.map_or(h, |l| h.min(0.5 * l[k]))
        });
        let mut lo = half.map(|h| -h);
        if let Some(w) = self.scene.wall() {
            // R_H = w1 X1 + w2 X2: with each sphere above the wall by its radius and half the
            // margin, the centre is above it by w1 a1 + w2 a2 + margin/2, however it turns.
            let need = self.d.w1() * self.d.a1 + self.d.w2() * self.d.a2 + 0.5 * self.margin;
            let top = 0.5 * sides[2];
            if w.z + need >= top {
                return Err(invalid!(
                    "no swimmer can be placed at random clear of the wall at z = {:e} m: the centres are drawn in {}, whose top, z = {} m, lies below z = {} m, the lowest a centre can be ({} m above the wall: its spheres' radii, and half the {} m gap kept from the wall); lower the wall below z = {} m to fill the whole region, or add the swimmers at chosen centres above it",
                    w.z,
                    self.describe(),
                    short(top),
                    short(w.z + need),
                    short(need),
                    short(self.margin),
                    short(-top - self.reach)
                ));
            }
            lo[2] = lo[2].max(w.z);
        }
        Ok((lo, half))
    }

    /// The region, as a reader takes it in: "the periodic box of ...", "a cube of side ...".
    fn describe(&self) -> String {
        let [x, y, z] = self.sides.map(short);
        let whole_box = self
            .scene
            .periodic()
            .is_some_and(|b| (0..3).all(|k| self.sides[k] >= b.sides()[k]));
        if whole_box {
            format!("the periodic box of {x} x {y} x {z} m")
        } else if x == y && y == z {
            format!("a cube of side {x} m centred on the origin")
        } else {
            format!("a region of {x} x {y} x {z} m centred on the origin")
        }
    }

    /// How many swimmers `d` fit besides those present.
    fn fits(&self) -> usize {
        self.fits_in(self.volume)
    }

    fn fits_in(&self, volume: f64) -> usize {
        ((self.fill * volume - self.occupied) / self.body).max(0.0) as usize
    }

    /// The most draws the space calls for ([`DRAWS_PER_BODY`]).
    fn draws(&self) -> u64 {
        (DRAWS_PER_BODY * self.volume / self.body).ceil() as u64
    }

    /// Refuse `n` more swimmers if they do not fit, naming the space, the estimate and the room
    /// that would do: sides scaled up, or a smaller gap than `gap` (one above the strokes' need).
    fn check(&self, n: usize, gap: Option<f64>) -> Result<()> {
        let fits = self.fits();
        if n <= fits {
            return Ok(());
        }
        let fits_at = |f: f64| {
            self.bounds(f).map_or(0, |(lo, hi)| {
                self.fits_in((0..3).map(|k| hi[k] - lo[k]).product())
            })
        };
        // The scale of the sides at which n fit: doubled until it is enough, then bisected.
        let (mut low, mut high) = (1.0, 2.0);
        while fits_at(high) < n && high < 1e6 {
            (low, high) = (high, 2.0 * high);
        }
        for _ in 0..40 {
            let mid = 0.5 * (low + high);
            if fits_at(mid) >= n {
                high = mid;
            } else {
                low = mid;
            }
        }
        let [x, y, z] = self.sides;
        let mut space = format!("in {}", self.describe());
        if let Some(w) = self.scene.wall() {
            space += &format!(" above the wall at z = {:e} m", w.z);
        }
        let besides = match self.present {
            0 => String::new(),
            k => format!(" besides the {k} swimmers already there"),
        };
        let spheres = 4.0 / 3.0 * PI * (self.d.a1.powi(3) + self.d.a2.powi(3));
        let phi = n as f64 * spheres / (x * y * z);
        let smaller_gap = match gap {
            Some(g) => format!(
                ", or a smaller gap than {} m (the strokes need {} m)",
                short(g),
                short(4.0 * self.d.lambda * self.d.w1().max(self.d.w2()))
            ),
            None => String::new(),
        };
        Err(invalid!(
            "{n} swimmers do not fit at random {space}{besides}: each keeps clear a body of {} m^3 (its two spheres widened by half the {} m gap kept between spheres, {} m apart), and random sequential addition fills about {:.0}% of the space with such bodies ({DRAWS_PER_BODY} draws for every body it holds), so about {fits} fit; place at most {fits}, or give them more room: sides {}x as long (a sphere volume fraction of at most {} instead of {}){smaller_gap}",
            short(self.body),
            short(self.margin),
            short(self.d.ell),
            100.0 * self.fill,
            short(high),
            short(phi / high.powi(3)),
            short(phi)
        ))
    }
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
