//! Philox4x32-10 (Salmon, Moraes, Dror & Shaw, "Parallel random numbers: as easy as 1, 2, 3",
//! SC'11): a counter-based generator. A draw is a pure function of (seed, counter), so the noise of
//! step k, component i is the same whatever the thread count, the order of evaluation, or a save
//! and load between steps; and it is the generator a GPU kernel would use.

use std::f64::consts::PI;

const M0: u64 = 0xD251_1F53;
const M1: u64 = 0xCD9E_8D57;
const W0: u32 = 0x9E37_79B9;
const W1: u32 = 0xBB67_AE85;

fn round(c: [u32; 4], k: [u32; 2]) -> [u32; 4] {
    let p0 = M0 * c[0] as u64;
    let p1 = M1 * c[2] as u64;
    [
        (p1 >> 32) as u32 ^ c[1] ^ k[0],
        p1 as u32,
        (p0 >> 32) as u32 ^ c[3] ^ k[1],
        p0 as u32,
    ]
}

/// The 128 random bits of counter `c` under key `k`.
pub fn philox4x32(mut c: [u32; 4], mut k: [u32; 2]) -> [u32; 4] {
    c = round(c, k);
    for _ in 0..9 {
        k = [k[0].wrapping_add(W0), k[1].wrapping_add(W1)];
        c = round(c, k);
    }
    c
}

/// Which quantity of a step a draw belongs to (the counter's second word), so that the Wiener
/// increments and a scheme's auxiliary variables never share bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Stream {
    /// Standard normal Wiener increments.
    Wiener = 0,
    /// Two-point variables (±1) of the weak second-order scheme.
    Signs = 1,
}

/// Draws of step `step` of the generator seeded with `seed`.
#[derive(Debug, Clone, Copy)]
pub struct StepDraws {
    key: [u32; 2],
    step: u64,
}

impl StepDraws {
    /// The draws of step `step` under `seed`.
    pub fn new(seed: u64, step: u64) -> Self {
        StepDraws {
            key: [seed as u32, (seed >> 32) as u32],
            step,
        }
    }

    fn bits(&self, stream: Stream, block: u64) -> [u32; 4] {
        // Counter: (block, stream | high bits of block, step).
        let c = [
            block as u32,
            (stream as u32) | (((block >> 32) as u32) << 2),
            self.step as u32,
            (self.step >> 32) as u32,
        ];
        philox4x32(c, self.key)
    }

    /// Fill `out` with independent standard normal numbers (Box-Muller on 53-bit uniforms in
    /// (0, 1]; one block of 128 bits gives two).
    pub fn normals(&self, out: &mut [f64]) {
        for (block, pair) in out.chunks_mut(2).enumerate() {
            let r = self.bits(Stream::Wiener, block as u64);
            let u1 = uniform(r[0], r[1]);
            let u2 = uniform(r[2], r[3]);
            let rad = (-2.0 * u1.ln()).sqrt();
            let (s, c) = (2.0 * PI * u2).sin_cos();
            pair[0] = rad * c;
            if let Some(second) = pair.get_mut(1) {
                *second = rad * s;
            }
        }
    }

    /// Sign number `i` (±1, each with probability 1/2).
    pub fn sign(&self, i: u64) -> f64 {
        let r = self.bits(Stream::Signs, i / 128);
        let bit = (r[((i % 128) / 32) as usize] >> (i % 32)) & 1;
        if bit == 1 {
            1.0
        } else {
            -1.0
        }
    }
}

/// A uniform number in (0, 1] from 53 of the 64 bits (hi, lo): never 0, so its logarithm is finite.
fn uniform(hi: u32, lo: u32) -> f64 {
    let x = ((hi as u64) << 32 | lo as u64) >> 11;
    (x as f64 + 1.0) * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The known-answer vectors of the Random123 distribution (kat_vectors, philox4x32 10 rounds).
    #[test]
    fn philox_matches_the_reference_vectors() {
        assert_eq!(
            philox4x32([0; 4], [0; 2]),
            [0x6627_e8d5, 0xe169_c58d, 0xbc57_ac4c, 0x9b00_dbd8]
        );
        assert_eq!(
            philox4x32([u32::MAX; 4], [u32::MAX; 2]),
            [0x408f_276d, 0x41c8_3b0e, 0xa20b_c7c6, 0x6d54_51fd]
        );
        assert_eq!(
            philox4x32(
                [0x243f_6a88, 0x85a3_08d3, 0x1319_8a2e, 0x0370_7344],
                [0xa409_3822, 0x299f_31d0]
            ),
            [0xd16c_fe09, 0x94fd_cceb, 0x5001_e420, 0x2412_6ea1]
        );
    }

    /// Mean 0 and variance 1 within 5 standard errors of their estimators (2e5 numbers: the
    /// mean's standard error is 2.2e-3, the variance's 3.2e-3; false-failure probability ~6e-7).
    #[test]
    fn normals_have_unit_variance() {
        let mut x = vec![0.0; 200_000];
        StepDraws::new(7, 3).normals(&mut x);
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
        assert!(mean.abs() < 5.0 * (1.0 / n).sqrt(), "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * (2.0 / n).sqrt(), "variance {var}");
        let signs: f64 = (0..100_000).map(|i| StepDraws::new(7, 3).sign(i)).sum();
        assert!(signs.abs() < 5.0 * (1e5f64).sqrt(), "sign sum {signs}");
    }
}
