//! The live view's cost to a run (`swimlab bench view`): a suspension of the averaged model run
//! for a fixed number of RK4 steps without a view, with a view no one reads, and with a view whose
//! one reader never reads and another reads every frame, side by side in alternating rounds.
//! What a view may cost is the encoding of its frames (at most 30 a second, and no more than a
//! tenth of the run's time): a reader never slows the run, since frames wait in a one-frame slot
//! and each client has a thread of its own.

use super::suspension::bulk_scene;
use super::table::Table;
use crate::engine::error::Result;
use crate::engine::{Dumbbell, IntegratorSpec, Simulation};
use crate::view::{Parts, Publisher, Server, ServerOptions, Slot};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The ways a run is watched.
const SETUPS: [&str; 3] = [
    "no view",
    "view, no reader",
    "view, a stuck and a reading reader",
];

/// One run's measurement: seconds and frames published.
struct Timing {
    seconds: f64,
    frames: u64,
}

/// A connection that asks for the stream of `server` and, if `read`, reads it to the end on a
/// thread of its own.
fn reader(
    server: &Server,
    read: bool,
) -> std::io::Result<(TcpStream, Option<std::thread::JoinHandle<()>>)> {
    let mut c = TcpStream::connect(server.local_addr())?;
    let path = server.url().splitn(4, '/').nth(3).unwrap_or("");
    write!(c, "GET /{path}frames HTTP/1.1\r\n\r\n")?;
    let thread = if read {
        let mut r = c.try_clone()?;
        Some(std::thread::spawn(move || {
            let mut buf = vec![0u8; 1 << 16];
            while matches!(r.read(&mut buf), Ok(n) if n > 0) {}
        }))
    } else {
        None
    };
    Ok((c, thread))
}

/// `steps` RK4 steps of a suspension of `n` swimmers watched as `setup` (an index of [`SETUPS`]).
fn run_once(n: usize, steps: u64, setup: usize) -> Result<Timing> {
    let d = Dumbbell::default();
    let mut s = bulk_scene(n, d, 1e-3, 2026)?;
    let dt = d.period() / 20.0;
    s.set_integrator(Some(IntegratorSpec::Rk4 { dt }));
    let mut sim = Simulation::new(s);
    let slot = Arc::new(Slot::default());
    let mut server = None;
    let mut readers = Vec::new();
    if setup > 0 {
        let started = Server::start(slot.clone(), &ServerOptions::default())
            .map_err(|e| crate::engine::error::invalid!("cannot serve the view: {e}"))?;
        let publisher = Publisher::new(
            slot.clone(),
            Parts::default(),
            Duration::from_secs_f64(1.0 / 30.0),
            None,
        );
        sim.set_watcher(Some(Arc::new(publisher)));
        if setup == 2 {
            for read in [false, true] {
                readers
                    .push(reader(&started, read).map_err(|e| {
                        crate::engine::error::invalid!("cannot read the view: {e}")
                    })?);
            }
        }
        server = Some(started);
    }
    let begun = Instant::now();
    sim.run(steps as f64 * dt)?;
    let seconds = begun.elapsed().as_secs_f64();
    drop(server);
    for (c, thread) in readers {
        drop(c);
        if let Some(t) = thread {
            let _ = t.join();
        }
    }
    Ok(Timing {
        seconds,
        frames: slot.published(),
    })
}

/// The cost of encoding one frame of the suspension of `n` swimmers: (median seconds of a few
/// encodings, the frame's bytes).
pub fn encoding(n: usize) -> Result<(f64, usize)> {
    let s = bulk_scene(n, Dumbbell::default(), 1e-3, 2026)?;
    let mut times = Vec::new();
    let mut bytes = 0;
    for _ in 0..5 {
        let begun = Instant::now();
        bytes = crate::view::frame::encode(&s, &[], Parts::default()).len();
        times.push(begun.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], bytes))
}

/// The side-by-side table: per setup, the median seconds of `rounds` runs of `steps` steps of
/// `n` swimmers, the frames published, and the time against the unwatched run.
pub fn run(n: usize, steps: u64, rounds: usize) -> Result<Table> {
    let mut seconds = vec![Vec::new(); SETUPS.len()];
    let mut frames = vec![0; SETUPS.len()];
    for _ in 0..rounds {
        for (k, (secs, fr)) in seconds.iter_mut().zip(frames.iter_mut()).enumerate() {
            let t = run_once(n, steps, k)?;
            secs.push(t.seconds);
            *fr = t.frames;
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let base = median(&mut seconds[0].clone());
    let mut t = Table::new(&["setup", "seconds", "frames", "against no view"]);
    for (k, name) in SETUPS.iter().enumerate() {
        let m = median(&mut seconds[k]);
        t.rows.push(vec![
            name.to_string(),
            format!("{m:.3}"),
            frames[k].to_string(),
            format!("{:.3}", m / base),
        ]);
    }
    Ok(t)
}
