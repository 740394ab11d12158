//! The spheres as structure of arrays, the layout every pair kernel reads.

use crate::engine::periodic::PeriodicBox;
use nalgebra::Vector3;

/// Sphere data as structure of arrays.
#[derive(Debug, Clone, Default)]
pub struct SoaSpheres {
    /// Positions (m).
    pub x: Vec<f64>,
    /// y (m).
    pub y: Vec<f64>,
    /// z (m).
    pub z: Vec<f64>,
    /// Radii (m).
    pub a: Vec<f64>,
    /// Radii squared (m²).
    pub a2: Vec<f64>,
    /// Forces (N).
    pub fx: Vec<f64>,
    /// y force.
    pub fy: Vec<f64>,
    /// z force.
    pub fz: Vec<f64>,
    /// The periodic box the spheres sit in, if any: the gap passes measure minimum images (the
    /// RPY kernel here is open space's; a box's mobility is [`crate::engine::ewald`]'s).
    pub periodic: Option<PeriodicBox>,
}

impl SoaSpheres {
    /// Resize to `n` spheres.
    pub fn resize(&mut self, n: usize) {
        for v in [
            &mut self.x,
            &mut self.y,
            &mut self.z,
            &mut self.a,
            &mut self.a2,
            &mut self.fx,
            &mut self.fy,
            &mut self.fz,
        ] {
            v.resize(n, 0.0);
        }
    }

    /// Set sphere `i`'s radius (m) and its square.
    pub fn set_radius(&mut self, i: usize, a: f64) {
        self.a[i] = a;
        self.a2[i] = a * a;
    }

    /// Fill with spheres at `pos` of radii `radii`, and their `forces` when given (the gap
    /// passes need none).
    pub fn fill(&mut self, pos: &[Vector3<f64>], radii: &[f64], forces: Option<&[Vector3<f64>]>) {
        self.resize(pos.len());
        for (i, (p, a)) in pos.iter().zip(radii).enumerate() {
            self.x[i] = p.x;
            self.y[i] = p.y;
            self.z[i] = p.z;
            self.set_radius(i, *a);
        }
        for (i, f) in forces.unwrap_or_default().iter().enumerate() {
            self.fx[i] = f.x;
            self.fy[i] = f.y;
            self.fz[i] = f.z;
        }
    }

    /// Number of spheres.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// x_i − x_j as (x, y, z), its minimum image in a box.
    #[inline]
    pub(crate) fn delta(&self, i: usize, j: usize) -> (f64, f64, f64) {
        let (rx, ry, rz) = (
            self.x[i] - self.x[j],
            self.y[i] - self.y[j],
            self.z[i] - self.z[j],
        );
        match &self.periodic {
            None => (rx, ry, rz),
            Some(b) => (b.image(rx, 0), b.image(ry, 1), b.image(rz, 2)),
        }
    }
}
