//! The live view: a scene's frames as the stream serves them while it runs, and the page
//! as a real browser draws it.
//!
//! The stream (no browser): every frame shows the scene as it was at the frame's time, to the
//! last bit (positions against recorder rows taken at every step), in time order, with the box
//! or wall as set; a reader that never reads, or that goes away, neither stalls nor breaks the
//! run, and the server stops promptly; a GPU run streams the device's state between its
//! submissions; a wrong token is a 404, anything but GET a 405. Bad input
//! to `s.view` is a clear message, and a view stops with its scene, leaving nothing listening.
//!
//! The page: headless Chromium (Debian's `chromium`; skipped without it unless
//! `SWIMLAB_REQUIRE_BROWSER=1`, as in CI) loads the page of a script's scene while `swimlab run`
//! runs it: two screenshots taken at different moments each show both sphere kinds' colours and
//! differ, and the page's own error box stays empty.

use nalgebra::Vector3;
use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};
use swimlab::engine::wall::Wall;
use swimlab::engine::{Dumbbell, IntegratorSpec, Observable, Scene, Simulation, Trigger};
use swimlab::view::{Pace, Parts, Publisher, Server, ServerOptions, Slot};

/// The fixed step of the stream tests (s): a tenth of a period's 1/25 at ω = 500/s.
const DT: f64 = 2e-5;

/// A pair with both sphere kinds (a1 = 2 a2), fixed steps.
fn pair(shift: Vector3<f64>) -> Scene {
    let mut s = Scene::new();
    let d = Dumbbell {
        a1: 1.0e-6,
        a2: 0.5e-6,
        ..Dumbbell::default()
    };
    s.add(d, shift + Vector3::new(-5e-6, 0.0, 0.0), Vector3::x())
        .unwrap();
    let d2 = Dumbbell { phase: 1.0, ..d };
    s.add(d2, shift + Vector3::new(5e-6, 2e-6, 0.0), Vector3::y())
        .unwrap();
    s.set_integrator(Some(IntegratorSpec::Rk4 { dt: DT }));
    s
}

/// A view of `sim` on any free port: its server and the publisher the simulation watches.
fn serve(sim: &mut Simulation, pace: Option<f64>) -> Server {
    let slot = Arc::new(Slot::default());
    let server = Server::start(slot.clone(), &ServerOptions::default()).unwrap();
    let pace = pace.map(|periods| Pace {
        seconds_per_second: periods * sim.period().unwrap(),
        stop: Arc::new(|| false),
    });
    let publisher = Publisher::new(slot, Parts::default(), Duration::from_millis(10), pace);
    sim.set_watcher(Some(Arc::new(publisher)));
    server
}

/// The path part of a view's address (`/TOKEN/`).
fn path_of(url: &str) -> String {
    let rest = url.strip_prefix("http://").unwrap();
    rest[rest.find('/').unwrap()..].to_string()
}

/// Send `method path` and read the whole response: (status code, body).
fn request(addr: SocketAddr, method: &str, path: &str) -> (u16, String) {
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(c, "{method} {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut text = String::new();
    c.read_to_string(&mut text).unwrap();
    let code = text.split_whitespace().nth(1).unwrap().parse().unwrap();
    let body = text
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    (code, body)
}

/// Read the frames of `frames` until one at `t_end` or later (or `limit` passes).
fn read_frames(addr: SocketAddr, path: &str, t_end: f64, limit: Duration) -> Vec<Value> {
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(c, "GET {path}frames HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let reader = BufReader::new(c);
    let started = Instant::now();
    let mut frames = Vec::new();
    for line in reader.lines() {
        let line = line.unwrap();
        if let Some(json) = line.strip_prefix("data: ") {
            let f: Value = serde_json::from_str(json).unwrap();
            let t = f["t"].as_f64().unwrap();
            frames.push(f);
            if t >= t_end {
                break;
            }
        }
        assert!(
            started.elapsed() < limit,
            "no frame at t_end within {limit:?}"
        );
    }
    frames
}

fn vec3(v: &Value) -> Vector3<f64> {
    Vector3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

/// Frames streamed during a paced run of `scene`: each at a recorder row's time (one every step)
/// holds the spheres that row's R_G, N and length place, to 1e-12 of ℓ; times increase; the
/// last frame is the scene at the run's end, exactly; box and wall as `check` wants.
fn frames_follow_the_run(scene: Scene, check: impl Fn(&Value)) {
    let ell = Dumbbell::default().ell;
    let mut sim = Simulation::new(scene);
    let obs = (0..2)
        .flat_map(|i| {
            [
                Observable::CenterG(i),
                Observable::Dir(i),
                Observable::Length(i),
            ]
        })
        .collect();
    let id = sim.record(obs, Trigger::EverySeconds(DT)).unwrap();
    // Two periods in about a second.
    let server = serve(&mut sim, Some(2.0));
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    let t_end = 2.0 * sim.period().unwrap();
    let runner = std::thread::spawn(move || {
        sim.run(t_end).unwrap();
        sim
    });
    let frames = read_frames(addr, &path, t_end, Duration::from_secs(120));
    let sim = runner.join().unwrap();
    assert!(
        frames.len() >= 5,
        "only {} frames during a run of a second",
        frames.len()
    );
    let rows = &sim.recorder(id).unwrap().rows;
    let mut last_t = f64::NEG_INFINITY;
    for f in &frames {
        check(f);
        let t = f["t"].as_f64().unwrap();
        assert!(t >= last_t, "frame times go back: {t} after {last_t}");
        last_t = t;
        let Some(row) = rows.iter().find(|r| r[0] == t) else {
            // The run's last, shorter step ends between rows: that frame is checked below.
            assert_eq!(t, sim.time(), "no row at the frame's time {t}");
            continue;
        };
        let spheres = f["spheres"].as_array().unwrap();
        assert_eq!(spheres.len(), 4);
        for i in 0..2 {
            let c = 7 * i + 1;
            let rg = Vector3::new(row[c], row[c + 1], row[c + 2]);
            let n = Vector3::new(row[c + 3], row[c + 4], row[c + 5]);
            let half = 0.5 * row[c + 6] * n;
            for (k, expected) in [rg - half, rg + half].into_iter().enumerate() {
                let s = &spheres[2 * i + k];
                let got = vec3(s);
                assert!(
                    (got - expected).norm() <= 1e-12 * ell,
                    "sphere {k} of swimmer {i} at t = {t}: {got:?}, the scene had {expected:?}"
                );
                assert_eq!(s[4].as_u64(), Some(k as u64 + 1), "kind of sphere {k}");
                let radius = if k == 0 { 1.0e-6 } else { 0.5e-6 };
                assert_eq!(s[3].as_f64(), Some(radius));
            }
            assert!((vec3(&f["n"][i]) - n).norm() <= 1e-12, "N of {i} at {t}");
        }
        assert_eq!(f["rows"][0]["columns"].as_object().unwrap().len(), 14);
    }
    // The last frame is the scene at the end, bit for bit.
    let last = frames.last().unwrap();
    assert_eq!(last["t"].as_f64(), Some(sim.time()));
    for i in 0..2 {
        let (x1, x2) = sim.shown_spheres(i);
        assert_eq!(vec3(&last["spheres"][2 * i]), x1);
        assert_eq!(vec3(&last["spheres"][2 * i + 1]), x2);
    }
    assert_eq!(last["steps"].as_u64(), Some(sim.stats().steps));
    let periods = last["periods"].as_f64().unwrap();
    assert!((periods - 2.0).abs() < 1e-9, "periods {periods}");
    // The frame endpoint serves the scene as the run left it: the last streamed frame's state,
    // and the recorder's last row. (The streamed frame at the run's end may be the one of its
    // last step, published before the run settled and its rows were copied once more: the same
    // state, rows up to the view's interval older.)
    let (code, body) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200);
    let served: Value = serde_json::from_str(&body).unwrap();
    for part in ["t", "periods", "steps", "box", "wall", "spheres", "n"] {
        assert_eq!(served[part], last[part], "{part}");
    }
    let last_row = rows.last().unwrap();
    assert_eq!(served["rows"][0]["t"].as_f64(), Some(last_row[0]));
    drop(server);
    assert!(
        TcpStream::connect(addr).is_err(),
        "the view's port still listens"
    );
}

#[test]
fn frames_are_the_scene_at_their_time_in_a_box() {
    let mut s = pair(Vector3::zeros());
    s.set_box(Some([40e-6, 30e-6, 20e-6])).unwrap();
    frames_follow_the_run(s, |f| {
        assert_eq!(f["box"], serde_json::json!([40e-6, 30e-6, 20e-6]));
        assert!(f["wall"].is_null());
    });
}

#[test]
fn frames_are_the_scene_at_their_time_above_a_wall() {
    let mut s = pair(Vector3::new(0.0, 0.0, 6e-6));
    s.set_wall(Some(Wall::at(-1e-6).unwrap())).unwrap();
    frames_follow_the_run(s, |f| {
        assert_eq!(f["wall"].as_f64(), Some(-1e-6));
        assert!(f["box"].is_null());
    });
}

/// A stroke-averaged suspension big enough that its frames fill a socket's buffers in a few.
fn suspension(n: usize) -> Scene {
    let mut s = Scene::new();
    s.set_model(swimlab::engine::Model::Averaged);
    swimlab::engine::build::random_suspension(
        &mut s,
        n,
        Dumbbell::default(),
        [200e-6; 3],
        swimlab::engine::build::Orientations::Random,
        swimlab::engine::build::Phases::Random,
        3,
    )
    .unwrap();
    s
}

/// A GPU run (uniform steps on the device) streams frames between its submissions, each the
/// state the device held at the frame's time: a fresh GPU run of a copy to that time agrees to
/// rounding. Skipped without an f64-capable adapter unless `SWIMLAB_REQUIRE_GPU=1` (CI's lavapipe).
#[test]
fn a_gpu_run_streams_the_device_state_between_submissions() {
    if let Err(e) = swimlab::engine::gpu::device() {
        assert!(
            std::env::var_os("SWIMLAB_REQUIRE_GPU").is_none_or(|v| v == "0"),
            "SWIMLAB_REQUIRE_GPU is set but {e}"
        );
        eprintln!("skipped: {e}");
        return;
    }
    let mut s = suspension(64);
    s.set_backend(swimlab::engine::Backend::Gpu);
    let period = s.period().unwrap();
    s.set_integrator(Some(IntegratorSpec::Rk4 { dt: period / 50.0 }));
    let start = s.clone();
    let mut sim = Simulation::new(s);
    // Ten periods in about two seconds.
    let server = serve(&mut sim, Some(5.0));
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    let t_end = 10.0 * period;
    let runner = std::thread::spawn(move || {
        sim.run(t_end).unwrap();
        sim
    });
    let frames = read_frames(addr, &path, t_end, Duration::from_secs(120));
    let sim = runner.join().unwrap();
    let inside: Vec<&Value> = frames
        .iter()
        .filter(|f| (0.0..t_end).contains(&f["t"].as_f64().unwrap()) && f["t"] != 0.0)
        .collect();
    assert!(inside.len() >= 3, "{} frames inside the run", inside.len());
    let ell = Dumbbell::default().ell;
    for f in inside.iter().step_by((inside.len() / 4).max(1)) {
        let t = f["t"].as_f64().unwrap();
        let mut copy = Simulation::new(start.clone());
        copy.run(t).unwrap();
        for i in 0..copy.count() {
            let (x1, _) = copy.shown_spheres(i);
            let got = vec3(&f["spheres"][2 * i]);
            assert!(
                (got - x1).norm() <= 1e-9 * ell,
                "swimmer {i} at t = {t}: {got:?} streamed, {x1:?} by a run to t"
            );
        }
    }
    let last = frames.last().unwrap();
    assert_eq!(last["t"].as_f64(), Some(sim.time()));
    assert_eq!(vec3(&last["spheres"][0]), sim.shown_spheres(0).0);
}

#[test]
fn readers_that_never_read_or_vanish_neither_stall_nor_break_the_run() {
    let mut sim = Simulation::new(suspension(2000));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    // One reader asks for the stream and never reads; others ask and go away at once, or send
    // half a request; one reads a frame and goes.
    let mut stuck = TcpStream::connect(addr).unwrap();
    write!(stuck, "GET {path}frames HTTP/1.1\r\n\r\n").unwrap();
    for _ in 0..5 {
        let mut gone = TcpStream::connect(addr).unwrap();
        write!(gone, "GET {path}frames HTTP/1.1\r\n\r\n").unwrap();
        drop(gone);
        let mut half = TcpStream::connect(addr).unwrap();
        write!(half, "GET {path}fra").unwrap();
        drop(half);
    }
    let (code, _) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200);
    let started = Instant::now();
    sim.run_periods(1.0).unwrap();
    let ran = started.elapsed();
    // The run went on and the stream kept its last frame.
    let (code, body) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200);
    let last: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(last["t"].as_f64(), Some(sim.time()));
    assert_eq!(last["spheres"].as_array().unwrap().len(), 4000);
    // Dropping the server ends every thread, the stuck reader's too, promptly.
    let stopping = Instant::now();
    drop(server);
    assert!(
        stopping.elapsed() < Duration::from_secs(5),
        "the server took {:?} to stop (the run took {ran:?})",
        stopping.elapsed()
    );
    assert!(TcpStream::connect(addr).is_err());
    drop(stuck);
}

#[test]
fn a_wrong_token_is_404_and_anything_but_get_is_405() {
    let mut sim = Simulation::new(pair(Vector3::zeros()));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    assert_eq!(path.len(), 34, "a token of 32 hex digits: {path}");
    assert_eq!(request(addr, "GET", &path).0, 200);
    assert_eq!(request(addr, "GET", &format!("{path}frame")).0, 200);
    assert_eq!(
        request(addr, "GET", &format!("{path}vendor/three.core.js")).0,
        200
    );
    assert_eq!(request(addr, "GET", &format!("{path}nothing")).0, 404);
    assert_eq!(request(addr, "GET", "/").0, 404);
    assert_eq!(
        request(addr, "GET", "/0123456789abcdef0123456789abcdef/frame").0,
        404
    );
    let (code, _) = request(addr, "GET", &path[..path.len() - 1]);
    assert_eq!(code, 301, "the address without its slash is sent to it");
    for method in ["POST", "PUT", "DELETE", "HEAD", "OPTIONS"] {
        assert_eq!(
            request(addr, method, &format!("{path}frame")).0,
            405,
            "{method}"
        );
    }
    // Another server has another token.
    let mut other = Simulation::new(pair(Vector3::zeros()));
    let second = serve(&mut other, None);
    assert_ne!(path_of(second.url()), path);
}

/// Send `bytes` as they are and read the answer until the server closes: its status code (0 for
/// none).
fn raw(addr: SocketAddr, bytes: &[u8]) -> u16 {
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    c.write_all(bytes).unwrap();
    let mut text = Vec::new();
    let _ = c.read_to_end(&mut text);
    String::from_utf8_lossy(&text)
        .split_whitespace()
        .nth(1)
        .and_then(|w| w.parse().ok())
        .unwrap_or(0)
}

/// The tests that hold hundreds of sockets run one at a time, so that two of them together stay
/// within a soft limit of 1,024 open files.
static FEW_SOCKETS: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A broken request line is answered 400 (TLS bytes at once, not after a timeout), a head over
/// 16 KiB 431, an HTTP version other than 1.0 and 1.1 505, each then closed.
#[test]
fn broken_requests_are_answered_400_431_or_505() {
    let mut sim = Simulation::new(pair(Vector3::zeros()));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    assert_eq!(raw(addr, b"hello there\r\n\r\n"), 400);
    assert_eq!(raw(addr, b"GET\r\n\r\n"), 400);
    assert_eq!(
        raw(addr, format!("GET {path}frame\r\n\r\n").as_bytes()),
        400
    );
    assert_eq!(
        raw(addr, format!("GET {path}frame HTTP/x\r\n\r\n").as_bytes()),
        400
    );
    let started = Instant::now();
    assert_eq!(
        raw(addr, &[0x16, 0x03, 0x01, 0x02, 0x00, 0x01, 0x00, 0x01]),
        400
    );
    assert!(
        started.elapsed() < Duration::from_secs(4),
        "TLS bytes waited for the head's deadline"
    );
    for version in ["HTTP/2.0", "HTTP/0.9", "HTTP/3"] {
        let head = format!("GET {path}frame {version}\r\nHost: x\r\n\r\n");
        assert_eq!(raw(addr, head.as_bytes()), 505, "{version}");
    }
    assert_eq!(raw(addr, b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"), 505);
    // A refused client that goes on trickling bytes is closed within the linger's bound (well
    // under a second), not read for as long as it sends.
    let mut c = TcpStream::connect(addr).unwrap();
    c.write_all(b"hello there\r\n\r\n").unwrap();
    let started = Instant::now();
    let mut closed = false;
    while !closed && started.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(100));
        closed = c.write_all(b"x").is_err();
    }
    assert!(
        closed && started.elapsed() < Duration::from_secs(5),
        "a refused client trickling bytes was still read after {:?}",
        started.elapsed()
    );
    let long = format!(
        "GET {path}frame HTTP/1.1\r\nX-Long: {}\r\n",
        "a".repeat(17 * 1024)
    );
    assert_eq!(raw(addr, long.as_bytes()), 431);
    let head = format!("GET {path}frame HTTP/1.0\r\n\r\n");
    assert_eq!(raw(addr, head.as_bytes()), 200);
}

/// Slow clients cannot lock an honest one out: with 70 connections that trickle their head a
/// byte at a time and 70 that send nothing, an honest `GET TOKEN/frame` is answered 200, and
/// the trickling ones are cut off at the head's deadline (5 s for the whole head, however often
/// they send), well within the loop's bound.
#[test]
fn slow_clients_do_not_lock_out_an_honest_one() {
    let _few = FEW_SOCKETS.lock().unwrap_or_else(|e| e.into_inner());
    let mut sim = Simulation::new(pair(Vector3::zeros()));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    let mut slow: Vec<TcpStream> = (0..70)
        .map(|_| {
            let mut c = TcpStream::connect(addr).unwrap();
            c.write_all(b"G").unwrap();
            c
        })
        .collect();
    let idle: Vec<TcpStream> = (0..70).map(|_| TcpStream::connect(addr).unwrap()).collect();
    let (code, _) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200, "an honest client locked out by slow ones");
    // The slow clients go on sending a byte every 100 ms; by 15 s every one is cut off.
    let started = Instant::now();
    let mut open = slow.len();
    while open > 0 && started.elapsed() < Duration::from_secs(15) {
        open = 0;
        for c in &mut slow {
            if c.write_all(b"E").is_ok() {
                open += 1;
            }
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    assert!(
        started.elapsed() < Duration::from_secs(15),
        "trickling clients were not cut off at the head's deadline"
    );
    drop(idle);
}

/// Past the bound on connections reading their head (256), a new one cuts off the one that has
/// waited longest: 260 idle connections do not keep an honest client out either.
#[test]
fn idle_connections_past_the_bound_do_not_lock_out_an_honest_one() {
    let _few = FEW_SOCKETS.lock().unwrap_or_else(|e| e.into_inner());
    let mut sim = Simulation::new(pair(Vector3::zeros()));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    let idle: Vec<TcpStream> = (0..260)
        .map(|_| TcpStream::connect(addr).unwrap())
        .collect();
    let (code, _) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200, "an honest client locked out by idle ones");
    drop(idle);
}

/// Many views stop without each stop waiting out a poll of its accepting thread: stopping 300
/// takes at most three times what starting them took, and a second (a poll of 20 ms a view
/// would take 6 s), a bound that scales with the machine's load.
#[test]
fn many_views_stop_promptly() {
    let _few = FEW_SOCKETS.lock().unwrap_or_else(|e| e.into_inner());
    let started = Instant::now();
    let servers: Vec<Server> = (0..300)
        .map(|_| Server::start(Arc::new(Slot::default()), &ServerOptions::default()).unwrap())
        .collect();
    let start = started.elapsed();
    let addrs: Vec<SocketAddr> = servers.iter().map(Server::local_addr).collect();
    let started = Instant::now();
    drop(servers);
    let took = started.elapsed();
    assert!(
        took < 3 * start + Duration::from_secs(1),
        "300 views took {took:?} to stop, {start:?} to start"
    );
    assert!(addrs.iter().all(|a| TcpStream::connect(a).is_err()));
}

/// Run `source` in-process; the script's variables are returned in its scope, the error as text.
fn script(source: &str) -> (rhai::Scope<'static>, Result<(), String>) {
    let mut scope = rhai::Scope::new();
    let r = swimlab::script::run_source("view.rhai", source, &mut scope);
    (scope, r)
}

/// The port of a view address.
fn addr_of(url: &str) -> SocketAddr {
    let rest = url.strip_prefix("http://").unwrap();
    rest[..rest.find('/').unwrap()].parse().unwrap()
}

#[test]
fn a_view_stops_with_its_scene_or_close_view() {
    let (scope, r) =
        script("let s = scene(); s.add(dumbbell()); let url = s.view(); s.run_periods(0.5);");
    r.unwrap();
    let url = scope.get_value::<rhai::ImmutableString>("url").unwrap();
    assert!(
        url.starts_with("http://127.0.0.1:") && url.ends_with('/'),
        "{url}"
    );
    let addr = addr_of(&url);
    assert_eq!(
        request(addr, "GET", &format!("{}frame", path_of(&url))).0,
        200
    );
    drop(scope);
    assert!(
        TcpStream::connect(addr).is_err(),
        "still listening after the scene went"
    );

    let (scope, r) = script(
        "let s = scene(); s.add(dumbbell()); let url = s.view(); let t = s; t.close_view(); s.close_view();",
    );
    r.unwrap();
    let url = scope.get_value::<rhai::ImmutableString>("url").unwrap();
    assert!(
        TcpStream::connect(addr_of(&url)).is_err(),
        "still listening after close_view"
    );
    // A closed view may be opened again.
    let (_, r) = script("let s = scene(); s.add(dumbbell()); s.view(); s.close_view(); s.view(); s.run_periods(0.1);");
    r.unwrap();
}

/// A recorder keeps its scene, not the scene's view: replacing or dropping the script's scene
/// while a recorder of it is held stops the view, as the book says ("nothing is left listening").
#[test]
fn a_view_stops_with_its_scene_while_a_recorder_holds_it() {
    let (scope, r) = script(
        "let s = scene(); s.add(dumbbell()); let url = s.view(); let rec = s.record([msd()], 1); s.run_periods(1); s = scene(); let rows = rec.len;",
    );
    r.unwrap();
    let url = scope.get_value::<rhai::ImmutableString>("url").unwrap();
    assert!(
        TcpStream::connect(addr_of(&url)).is_err(),
        "the replaced scene's view still listens while its recorder is held"
    );
    assert_eq!(scope.get_value::<rhai::INT>("rows"), Some(2));
    // While the scene lives, the recorder changes nothing: its view serves.
    let (scope, r) = script(
        "let s = scene(); s.add(dumbbell()); let url = s.view(); let rec = s.record([msd()], 1); s.run_periods(1);",
    );
    r.unwrap();
    let url = scope.get_value::<rhai::ImmutableString>("url").unwrap();
    assert_eq!(
        request(addr_of(&url), "GET", &format!("{}frame", path_of(&url))).0,
        200
    );
}

/// `swimlab run --view` after the script closed its only view says so, not that it started none.
#[test]
fn run_with_view_after_close_view_says_the_views_were_stopped() {
    let dir = cli_dir("close");
    std::fs::write(
        dir.join("closed.rhai"),
        "let s = scene(); s.add(dumbbell()); s.view(); s.close_view();\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", "closed.rhai", "--view"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("every view the script started was stopped before it ended (s.close_view())"),
        "{err}"
    );
    assert!(!err.contains("started no view"), "{err}");
}

/// A fresh folder for a test that runs the binary.
fn cli_dir(what: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("swimlab-view-{what}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn changes_between_runs_show_without_a_run() {
    let (scope, r) = script(
        "let s = scene(); let url = s.view(); s.add(dumbbell()); s.box = [40e-6, 40e-6, 40e-6];",
    );
    r.unwrap();
    let url = scope.get_value::<rhai::ImmutableString>("url").unwrap();
    // The changes came within a frame's interval of the view's start: the last is drawn when
    // the next frame is due (1/30 s later), without a run.
    let started = Instant::now();
    let f = loop {
        let (code, body) = request(addr_of(&url), "GET", &format!("{}frame", path_of(&url)));
        assert_eq!(code, 200);
        let f: Value = serde_json::from_str(&body).unwrap();
        if !f["box"].is_null() || started.elapsed() > Duration::from_secs(10) {
            break f;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(f["spheres"].as_array().unwrap().len(), 2, "{f}");
    assert_eq!(f["box"], serde_json::json!([40e-6, 40e-6, 40e-6]));
    assert_eq!(f["t"].as_f64(), Some(0.0));
}

/// Changes between runs are drawn at the view's rate, not each as it is made: 2,000 swimmers
/// added one by one with a view open take a few frames (one per 50 ms interval at most, and
/// fewer as the frames grow), not 2,000; the last change is still drawn, soon after.
#[test]
fn changes_between_runs_are_drawn_at_the_views_rate() {
    let sim = Arc::new(std::sync::RwLock::new(Simulation::new(Scene::new())));
    let slot = Arc::new(Slot::default());
    let weak = Arc::downgrade(&sim);
    let refresh: swimlab::view::Refresh = Arc::new(move || {
        if let Some(sim) = weak.upgrade() {
            sim.read().unwrap().show_change();
        }
    });
    let every = Duration::from_millis(50);
    let publisher =
        Publisher::new(slot.clone(), Parts::default(), every, None).with_refresh(refresh);
    sim.write().unwrap().set_watcher(Some(Arc::new(publisher)));
    let started = Instant::now();
    for k in 0..2000 {
        let mut s = sim.write().unwrap();
        let c = Vector3::new(k as f64 * 20e-6, 0.0, 0.0);
        s.scene_mut()
            .add(Dumbbell::default(), c, Vector3::x())
            .unwrap();
        s.show_change();
    }
    let took = started.elapsed();
    let frames = slot.published();
    let most = 2 + (took.as_secs_f64() / every.as_secs_f64()) as u64;
    assert!(
        frames <= most,
        "{frames} frames for 2000 changes in {took:?}"
    );
    // The last change is drawn when the next frame is due.
    let waited = Instant::now();
    loop {
        let f: Value = serde_json::from_str(&slot.latest().unwrap()).unwrap();
        if f["spheres"].as_array().unwrap().len() == 4000 {
            break;
        }
        assert!(
            waited.elapsed() < Duration::from_secs(10),
            "the last change was not drawn"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[track_caller]
fn refused(source: &str, fragments: &[&str]) -> String {
    let (scope, r) = script(source);
    let e = r.expect_err(source);
    for f in fragments {
        assert!(e.contains(f), "{f:?} not in:\n{e}");
    }
    assert!(
        !e.contains("panicked") && !e.contains("internal error"),
        "{e}"
    );
    drop(scope);
    e
}

#[test]
fn bad_views_are_clear_messages_and_leave_nothing_listening() {
    let s = "let s = scene(); s.add(dumbbell());\n";
    // A port in use: ours.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port();
    refused(
        &format!("{s}s.view(#{{ port: {port} }});"),
        &[&format!("port {port} is in use"), "port: 0", "view.rhai:2:"],
    );
    refused(
        &format!("{s}s.view(#{{ port: 70000 }});"),
        &["port 70000 is out of range"],
    );
    refused(&format!("{s}s.view(#{{ port: -1 }});"), &["out of range"]);
    refused(
        &format!("{s}s.view(#{{ port: 1.5 }});"),
        &["port must be an integer"],
    );
    refused(
        &format!("{s}s.view(#{{ address: \"0.0.0.0\" }});"),
        &["not this machine's loopback", "expose: true"],
    );
    refused(
        &format!("{s}s.view(#{{ address: \"here\" }});"),
        &["not an IP address"],
    );
    refused(
        &format!("{s}s.view(#{{ prot: 8080 }});"),
        &["unknown option \"prot\"", "did you mean \"port\""],
    );
    refused(
        &format!("{s}s.view(#{{ every: 0 }});"),
        &["every is the least wall-clock time"],
    );
    refused(
        &format!("{s}s.view(#{{ pace: -1 }});"),
        &["pace is the most stroke periods"],
    );
    // A pace whose period underflows to no time between frames, or one that would hold a run
    // for ever: refused with the least pace taken.
    for (pace, shown) in [
        ("5e-324", "5e-324"),
        ("1e-300", "1e-300"),
        ("2e-5", "0.00002"),
    ] {
        refused(
            &format!("{s}s.view(#{{ pace: {pace} }});"),
            &[
                "a number from 1e-4 (a period in under three hours) up",
                &format!("got {shown}"),
            ],
        );
    }
    refused(
        &format!("{s}s.view(#{{ every: 0 }});"),
        &["above 0 and at most 3600 s"],
    );
    refused(
        &format!("{s}s.view(#{{ fields: [\"sphere\"] }});"),
        &["unknown field \"sphere\"", "did you mean \"spheres\""],
    );
    refused(
        "let s = scene(); s.add(dumbbell()); s.add(dumbbell(#{ omega: 300, center: [0, 20e-6, 0] })); s.view(#{ pace: 1 });",
        &["pace counts stroke periods", "different omega"],
    );
    // A second view of one scene names the first and the fix; the first stops with the scene.
    let e = refused(
        &format!("{s}s.view();\nlet t = s;\nt.view();"),
        &[
            "already viewed at http://127.0.0.1:",
            "s.close_view()",
            "view.rhai:4:",
        ],
    );
    let url = e
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap()
        .trim_end_matches(';');
    assert!(
        TcpStream::connect(addr_of(url)).is_err(),
        "the first view still listens"
    );
    drop(taken);
}

// ----- the page in a real browser ---------------------------------------------------------------

/// Debian's Chromium, or `None` (the test skips) unless `SWIMLAB_REQUIRE_BROWSER=1`.
fn chromium() -> Option<PathBuf> {
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        if let Ok(out) = Command::new("sh")
            .arg("-c")
            .arg(format!("command -v {name}"))
            .output()
        {
            let path = String::from_utf8_lossy(&out.stdout).trim().to_string();
            if out.status.success() && !path.is_empty() {
                return Some(PathBuf::from(path));
            }
        }
    }
    assert!(
        std::env::var("SWIMLAB_REQUIRE_BROWSER").as_deref() != Ok("1"),
        "SWIMLAB_REQUIRE_BROWSER=1 but no chromium found (apt-get install chromium)"
    );
    eprintln!("skipped: no chromium (apt-get install chromium; CI sets SWIMLAB_REQUIRE_BROWSER=1)");
    None
}

/// Run headless Chromium on `url` with `what` (`--screenshot=FILE`, `--dump-dom`); its stdout.
fn headless(browser: &Path, dir: &Path, what: &str, url: &str) -> String {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let profile = dir.join(format!("profile-{}", N.fetch_add(1, Ordering::SeqCst)));
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            // Containers often give /dev/shm 64 MB, which Chromium outgrows.
            "--disable-dev-shm-usage",
            "--window-size=800,600",
            "--virtual-time-budget=3000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(what)
        // Two frames, then the stream is closed: a still picture of this moment.
        .arg(format!("{url}?frames=2"))
        .stderr(Stdio::null())
        .output()
        .expect("run chromium");
    assert!(out.status.success(), "chromium {what} failed");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// An RGBA picture from a PNG file: (width, height, pixels).
fn read_png(path: &Path) -> (usize, usize, Vec<[u8; 4]>) {
    let decoder = png::Decoder::new(BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(
        info.bit_depth == png::BitDepth::Eight && channels >= 3,
        "{info:?}"
    );
    let pixels = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|p| [p[0], p[1], p[2], if channels == 4 { p[3] } else { 255 }])
        .collect();
    (info.width as usize, info.height as usize, pixels)
}

/// The scene's part of a screenshot: left of the plots, below the clock, above the help line.
fn scene_part((w, h, px): &(usize, usize, Vec<[u8; 4]>)) -> Vec<[u8; 4]> {
    (70..h - 30)
        .flat_map(|y| (0..w - 280).map(move |x| (x, y)))
        .map(|(x, y)| px[y * w + x])
        .collect()
}

/// Pixels of the a1 spheres' orange-red and of the a2 spheres' blue, however lit.
fn kind_pixels(px: &[[u8; 4]]) -> (usize, usize) {
    let red = px
        .iter()
        .filter(|[r, g, b, _]| {
            let (r, g, b) = (*r as f64, *g as f64, *b as f64);
            r > 90.0 && r > 1.6 * g && r > 3.0 * b
        })
        .count();
    let blue = px
        .iter()
        .filter(|[r, g, b, _]| {
            let (r, g, b) = (*r as f64, *g as f64, *b as f64);
            b > 90.0 && b > 1.8 * r && b > 1.3 * g
        })
        .count();
    (red, blue)
}

#[test]
fn the_page_draws_both_kinds_and_moves_in_headless_chromium() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("swimlab-view-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // A pair of both kinds, beating at 0.7 periods a second for up to two minutes.
    let source = "let s = scene();\n\
        s.add(dumbbell(#{ center: [-5e-6, 0, 0], a1: 1.2e-6, a2: 0.6e-6 }));\n\
        s.add(dumbbell(#{ center: [5e-6, 3e-6, 0], a1: 1.2e-6, a2: 0.6e-6, phase: 1.5, dir: [0, 1, 0] }));\n\
        s.integrator = rk4(2e-5);\n\
        s.record([length(0), R_H(1)], every_periods(0.05));\n\
        s.view(#{ pace: 0.7 });\n\
        s.run_periods(84);\n";
    std::fs::write(dir.join("view.rhai"), source).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", "view.rhai"])
        .current_dir(&dir)
        .env("SWIMLAB_PROGRESS", "0")
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let url = first.trim().to_string();
    assert!(
        url.starts_with("http://127.0.0.1:") && url.ends_with('/'),
        "{url:?}"
    );

    let dom = headless(&browser, &dir, "--dump-dom", &url);
    let errors = dom
        .split("<pre id=\"errors\">")
        .nth(1)
        .and_then(|rest| rest.split("</pre>").next())
        .unwrap_or_else(|| panic!("no error box in the page:\n{dom}"));
    assert_eq!(errors.trim(), "", "the page reported errors");
    assert!(dom.contains(" periods · "), "no clock in the page:\n{dom}");
    assert!(
        dom.contains("title=\"length[0]\""),
        "no plot of length[0]:\n{dom}"
    );

    let shot = |k: usize| {
        let file = dir.join(format!("shot{k}.png"));
        headless(
            &browser,
            &dir,
            &format!("--screenshot={}", file.display()),
            &url,
        );
        read_png(&file)
    };
    let one = shot(1);
    let (red, blue) = kind_pixels(&scene_part(&one));
    assert!(
        red > 400 && blue > 100,
        "kinds' colours: {red} a1 pixels, {blue} a2 pixels"
    );
    // A later moment, at a phase that differs (a second try lands elsewhere in the period).
    let mut moved = 0;
    for k in 2..4 {
        std::thread::sleep(Duration::from_millis(if k == 2 { 900 } else { 370 }));
        let two = shot(k);
        let (red, blue) = kind_pixels(&scene_part(&two));
        assert!(
            red > 400 && blue > 100,
            "shot {k}: {red} a1 pixels, {blue} a2 pixels"
        );
        moved = scene_part(&one)
            .iter()
            .zip(scene_part(&two))
            .filter(|(a, b)| **a != *b)
            .count();
        if moved > 50 {
            break;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(moved > 50, "the two pictures differ in {moved} pixels only");
}

#[test]
fn the_shell_view_command_names_the_latest_view() {
    use swimlab::repl::{Reply, Session};
    let mut s = Session::new();
    // Other tests' views may serve in this process at once: `:view` names the latest of all.
    s.handle("let s = scene(); s.add(dumbbell());");
    let url = match s.handle("s.view()") {
        Reply::Output(o) => o[o.find("http://").unwrap()..]
            .split(['"', '\n'])
            .next()
            .unwrap()
            .to_string(),
        other => panic!("{other:?}"),
    };
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    match s.handle(":view") {
        Reply::Output(o) => assert!(o.contains("http://127.0.0.1:"), "{o}"),
        other => panic!("{other:?}"),
    }
    s.handle("s.close_view();");
    assert!(TcpStream::connect(addr_of(&url)).is_err());
}

#[test]
fn run_with_view_keeps_the_page_up_after_the_script_until_ctrl_c() {
    let dir = std::env::temp_dir().join(format!("swimlab-view-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("short.rhai"),
        "let s = scene(); s.add(dumbbell()); s.view(); s.run_periods(0.5); print(\"ran\");\n",
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(["run", "short.rhai", "--view"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let (mut url, mut ran) = (String::new(), String::new());
    out.read_line(&mut url).unwrap();
    out.read_line(&mut ran).unwrap();
    assert_eq!(ran.trim(), "ran");
    let mut note = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut note)
        .unwrap();
    assert!(note.contains("until Ctrl-C"), "{note}");
    // The script has ended; its page and last frame are still served.
    let (url, addr) = (url.trim(), addr_of(url.trim()));
    let (code, body) = request(addr, "GET", &format!("{}frame", path_of(url)));
    assert_eq!(code, 200);
    let f: Value = serde_json::from_str(&body).unwrap();
    assert!((f["periods"].as_f64().unwrap() - 0.5).abs() < 1e-9, "{f}");
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "--view did not stop on Ctrl-C"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(child.wait().unwrap().success());
    assert!(TcpStream::connect(addr).is_err());
}

/// A seeded fuzz of the view's server: 400 requests made from honest ones (a byte changed, the
/// head cut short, a method, version, path or header drawn from hostile values, bytes that are
/// not text), eight connections at a time, each sent whole and the sending side then closed. Every
/// one gets a status line the server gives (or none, where it closed at once), within the head's
/// deadline (a stream of frames is read to its head); after all of them, honest requests still
/// get their answers: no lock-out, no panic.
#[test]
fn a_fuzz_of_requests_gets_answers_and_leaves_the_server_serving() {
    let _few = FEW_SOCKETS.lock().unwrap_or_else(|e| e.into_inner());
    let mut sim = Simulation::new(pair(Vector3::zeros()));
    let server = serve(&mut sim, None);
    let (addr, path) = (server.local_addr(), path_of(server.url()));
    let methods = [
        "GET", "HEAD", "POST", "get", "", "G\0T", "OPTIONS", "GET GET",
    ];
    let targets = [
        format!("{path}frame"),
        format!("{path}frames"),
        path.clone(),
        format!("{path}../frame"),
        "/".into(),
        "*".into(),
        format!("{path}frame?x=1"),
        format!("{path}%00"),
        "http://example.com/".into(),
        "/".repeat(5000),
    ];
    let versions = [
        "HTTP/1.1",
        "HTTP/1.0",
        "HTTP/2.0",
        "HTTP/1.1 extra",
        "http/1.1",
        "",
        "HTTP/1.12",
    ];
    let headers = [
        "Host: x",
        "",
        "Host:",
        ": value",
        "Connection: keep-alive",
        "Transfer-Encoding: chunked",
        "Content-Length: 100",
        "Content-Length: -1",
        "X: \u{00e9}\u{4e2d}",
    ];
    let mut rng = crate::common::Rng::new(67_2026);
    let requests: Vec<Vec<u8>> = (0..400)
        .map(|k| {
            let pick = |rng: &mut crate::common::Rng, n: usize| (rng.next() % n as u64) as usize;
            let head = format!(
                "{} {} {}\r\n{}\r\n{}\r\n\r\n",
                methods[pick(&mut rng, methods.len())],
                targets[pick(&mut rng, targets.len())],
                versions[pick(&mut rng, versions.len())],
                headers[pick(&mut rng, headers.len())],
                headers[pick(&mut rng, headers.len())],
            );
            let mut bytes = head.into_bytes();
            let at = pick(&mut rng, bytes.len());
            match k % 4 {
                0 => bytes.truncate(at),
                1 => bytes[at] = (rng.next() & 0xff) as u8,
                2 => bytes
                    .splice(
                        at..at,
                        (0..pick(&mut rng, 64)).map(|_| (rng.next() & 0xff) as u8),
                    )
                    .for_each(drop),
                _ => {}
            }
            bytes
        })
        .collect();
    let next = std::sync::Mutex::new(requests.iter().enumerate());
    let answered = [0, 200, 400, 404, 405, 431, 505];
    std::thread::scope(|scope| {
        for _ in 0..8 {
            scope.spawn(|| loop {
                let Some((k, bytes)) = next.lock().unwrap().next() else {
                    break;
                };
                let mut c = TcpStream::connect(addr).unwrap();
                c.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
                let started = Instant::now();
                // A client the server already closed on may fail to send the rest: fine.
                let _ = c.write_all(bytes);
                let _ = c.shutdown(std::net::Shutdown::Write);
                // The answer's head (a stream of frames goes on after it): read to its end.
                let mut text = Vec::new();
                let mut chunk = [0u8; 4096];
                while !text.windows(4).any(|w| w == b"\r\n\r\n") {
                    match c.read(&mut chunk) {
                        Ok(n) if n > 0 => text.extend_from_slice(&chunk[..n]),
                        _ => break,
                    }
                }
                let text = String::from_utf8_lossy(&text);
                let code: u16 = text
                    .split_whitespace()
                    .nth(1)
                    .and_then(|w| w.parse().ok())
                    .unwrap_or(0);
                assert!(
                    answered.contains(&code) && (code == 0 || text.starts_with("HTTP/1.1 ")),
                    "request {k} {:?} got {:?}",
                    String::from_utf8_lossy(bytes),
                    &text[..text.len().min(200)]
                );
                assert!(
                    started.elapsed() < Duration::from_secs(7),
                    "request {k} {:?} took {:?}",
                    String::from_utf8_lossy(bytes),
                    started.elapsed()
                );
            });
        }
    });
    let (code, body) = request(addr, "GET", &format!("{path}frame"));
    assert_eq!(code, 200);
    assert!(body.contains("\"t\""), "{body}");
    sim.run(10.0 * DT).unwrap();
    let frames = read_frames(addr, &path, 0.0, Duration::from_secs(10));
    assert!(!frames.is_empty());
}
