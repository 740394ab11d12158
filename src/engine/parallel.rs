//! From how many spheres a pair sum runs on rayon's threads, and from how many points a grid's
//! passes do; [`for_chunks_mut`] and [`map_indices`] run a loop on those threads or on the
//! caller's. One product must be long enough that rayon's dispatch (a few µs) is a negligible
//! share of it; how many spheres that takes follows from the cost of one pair, so the threshold
//! differs by the kind of pair sum (the timings are in the book's design notes, "When the pair
//! kernels take over, and when rows go parallel").

/// Pairs in open space (the RPY or Oseen rows, steric forces, gaps): a pair costs a few dozen
/// flops, and a product of 256 spheres about 0.3 ms.
pub const PARALLEL_SPHERES: usize = 256;

/// Pairs summed with their images (the wall's Blake image terms; the box's Ewald sums over
/// images and waves): a pair costs several open-space pairs, so a product is long enough from
/// fewer spheres. Above a wall, open space's pairs and the wall's run side by side from here.
pub const PARALLEL_IMAGE_SPHERES: usize = 64;

/// Points of a grid from which an FFT's passes (rows along an axis, transposes) run on rayon's
/// threads. Each pass is one parallel call; on a smaller grid a pass takes a few µs, about what
/// handing it to the pool and waking its threads costs, and the woken threads spin on the other
/// cores while the caller goes on.
pub const PARALLEL_GRID_POINTS: usize = 4096;

/// `f(state, k, chunk)` for every chunk `k` of `chunk` items of `data`, on rayon's threads where
/// `parallel` (each job's `state` from `init`), else in order on the caller's thread.
pub fn for_chunks_mut<T, S, I, F>(data: &mut [T], chunk: usize, parallel: bool, init: I, f: F)
where
    T: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, usize, &mut [T]) + Sync + Send,
{
    use rayon::prelude::*;
    if parallel {
        data.par_chunks_mut(chunk)
            .enumerate()
            .for_each_init(init, |s, (k, c)| f(s, k, c));
    } else {
        let mut s = init();
        for (k, c) in data.chunks_mut(chunk).enumerate() {
            f(&mut s, k, c);
        }
    }
}

/// `f(state, i)` for i in 0..n, collected in order: on rayon's threads where `parallel` (each
/// job's `state` from `init`), else on the caller's.
pub fn map_indices<T, S, I, F>(n: usize, parallel: bool, init: I, f: F) -> Vec<T>
where
    T: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, usize) -> T + Sync + Send,
{
    use rayon::prelude::*;
    if parallel {
        (0..n).into_par_iter().map_init(init, f).collect()
    } else {
        let mut s = init();
        (0..n).map(|i| f(&mut s, i)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both loops give the same result on rayon's threads as on the caller's: every chunk and
    /// index once, in order, with its own state.
    #[test]
    fn both_paths_agree() {
        for parallel in [false, true] {
            let mut data: Vec<usize> = vec![0; 1000];
            for_chunks_mut(
                &mut data,
                7,
                parallel,
                || 1,
                |s, k, c| {
                    c.iter_mut().for_each(|x| *x = k * *s);
                },
            );
            assert!(data.iter().enumerate().all(|(i, x)| *x == i / 7));
            let v = map_indices(1000, parallel, || 3, |s, i| i * *s);
            assert!(v.iter().enumerate().all(|(i, x)| *x == 3 * i));
        }
    }
}
