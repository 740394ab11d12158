//! `s.view()` and `s.view(#{ ... })`: a scene's live view in the browser ([`crate::view`]), its
//! address printed on a line of its own and returned (nothing is opened); `s.close_view()`.
//! A view stops with the last handle on its scene, unless views are kept (`swimlab run --view`,
//! [`keep_views`]). A front end that shows pages itself (the notebook kernel) sets a [`ViewSink`].

use super::console::{self, Hook};
use super::convert::{describe, number, script_error, suggest, ScriptResult};
use super::doc::{doc_entry, Doc};
use super::interrupt;
use super::scene_api::SceneHandle;
use crate::view::{Pace, Parts, Publisher, Server, ServerOptions, Slot};
use rhai::{Dynamic, Engine, ImmutableString, Map};
use std::net::IpAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::Duration;

/// The options `s.view(#{ ... })` takes.
const KEYS: &[&str] = &["port", "every", "pace", "fields", "address", "expose"];

/// The least time between two frames by default: 30 frames a second.
const DEFAULT_EVERY: f64 = 1.0 / 30.0;

/// The slowest pace a view holds runs to (periods per wall-clock second): slower, a period
/// would take days, and far slower the pace's arithmetic underflows to none at all.
const MIN_PACE: f64 = 1e-4;

/// A front end's own way to show a view's page (the kernel's inline frame): called with its
/// address when a view starts.
pub type ViewSink = Arc<dyn Fn(&str) + Send + Sync>;

static SINK: Hook<ViewSink> = Hook::new();

/// Show new views' pages through `sink` (`None`: only print their addresses).
pub fn set_sink(sink: Option<ViewSink>) {
    SINK.set(sink);
}

/// Every view started in this process, while it serves.
static STARTED: Mutex<Vec<Weak<Server>>> = Mutex::new(Vec::new());

/// Whether this process ever started a view (to tell "none started" from "all stopped").
static ANY_STARTED: AtomicBool = AtomicBool::new(false);

/// The views kept past their scenes (`Some` once [`keep_views`] was called).
static KEPT: Mutex<Option<Vec<Arc<Server>>>> = Mutex::new(None);

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// From now on, views serve until the process ends (or `s.close_view()`), not only while their
/// scene lives: `swimlab run --view` keeps the pages up after the script.
pub fn keep_views() {
    lock(&KEPT).get_or_insert_with(Vec::new);
}

/// After a script run with `--view`: keep serving the views it started until Ctrl-C (nothing to
/// wait for when it started none).
pub fn serve_until_interrupted() {
    let urls = live_views();
    if urls.is_empty() {
        console::note(if !ANY_STARTED.load(Ordering::SeqCst) {
            "--view: the script started no view (s.view()), so there is none to keep up"
        } else {
            "--view: every view the script started was stopped before it ended (s.close_view()), so there is none to keep up; leave out s.close_view() to keep a page up after the script"
        });
        return;
    }
    console::note(&format!(
        "--view: the page stays up until Ctrl-C: {}",
        urls.join(" ")
    ));
    while !interrupt::requested() {
        std::thread::sleep(Duration::from_millis(100));
    }
    lock(&KEPT).take();
}

/// The addresses of the views that serve now, oldest first.
pub fn live_views() -> Vec<String> {
    let mut started = lock(&STARTED);
    started.retain(|w| w.strong_count() > 0);
    started
        .iter()
        .filter_map(|w| w.upgrade().map(|s| s.url().to_string()))
        .collect()
}

/// What `s.view(#{ ... })` asked for.
struct Options {
    server: ServerOptions,
    every: Duration,
    pace: Option<f64>,
    parts: Parts,
    expose: bool,
}

fn port(v: &Dynamic) -> ScriptResult<u16> {
    let p = v.as_int().map_err(|_| {
        script_error(format!(
            "view: port must be an integer from 0 to 65535 (0: any free port), got {}",
            describe(v)
        ))
    })?;
    u16::try_from(p).map_err(|_| {
        script_error(format!(
            "view: port {p} is out of range; give a port from 1024 to 65535, or 0 for any free port"
        ))
    })
}

fn address(v: &Dynamic) -> ScriptResult<IpAddr> {
    let text = v.clone().into_immutable_string().map_err(|_| {
        script_error(format!(
            "view: address must be a string such as \"127.0.0.1\", got {}",
            describe(v)
        ))
    })?;
    match text.as_str() {
        "localhost" => Ok(IpAddr::from([127, 0, 0, 1])),
        t => t.parse().map_err(|_| {
            script_error(format!(
                "view: address \"{t}\" is not an IP address; give one such as \"127.0.0.1\" (the default), or leave address out"
            ))
        }),
    }
}

fn fields(v: &Dynamic) -> ScriptResult<Parts> {
    let wrong = || {
        script_error(format!(
            "view: fields must be an array of names from {:?}, got {}",
            Parts::NAMES,
            describe(v)
        ))
    };
    let list = v.clone().into_array().map_err(|_| wrong())?;
    let names: Vec<String> = list
        .iter()
        .map(|x| x.clone().into_string().map_err(|_| wrong()))
        .collect::<ScriptResult<_>>()?;
    Parts::from_names(names.iter().map(String::as_str)).map_err(|name| {
        let hint = suggest(&name, &Parts::NAMES)
            .map(|s| format!(" did you mean \"{s}\"?"))
            .unwrap_or_default();
        script_error(format!(
            "view: unknown field \"{name}\";{hint} the fields are {}",
            Parts::NAMES.join(", ")
        ))
    })
}

impl Options {
    fn parse(opts: &Map) -> ScriptResult<Options> {
        if let Some(k) = opts.keys().find(|k| !KEYS.contains(&k.as_str())) {
            let hint = suggest(k, KEYS)
                .map(|s| format!(" did you mean \"{s}\"?"))
                .unwrap_or_default();
            return Err(script_error(format!(
                "view: unknown option \"{k}\";{hint} the options are {}",
                KEYS.join(", ")
            )));
        }
        let mut o = Options {
            server: ServerOptions::default(),
            every: Duration::from_secs_f64(DEFAULT_EVERY),
            pace: None,
            parts: Parts::default(),
            expose: false,
        };
        if let Some(v) = opts.get("port") {
            o.server.port = port(v)?;
        }
        if let Some(v) = opts.get("every") {
            let every = number("view: every", v)?;
            if !(every > 0.0 && every <= 3600.0) {
                return Err(script_error(format!(
                    "view: every is the least wall-clock time between frames, above 0 and at most 3600 s (default {DEFAULT_EVERY:.4} s: 30 frames a second), got {every}"
                )));
            }
            o.every = Duration::from_secs_f64(every);
        }
        if let Some(v) = opts.get("pace") {
            let pace = number("view: pace", v)?;
            if !(pace >= MIN_PACE && pace.is_finite()) {
                return Err(script_error(format!(
                    "view: pace is the most stroke periods a run goes per second of wall-clock time, a number from {MIN_PACE:e} (a period in under three hours) up (leave it out to run at full speed), got {pace}"
                )));
            }
            o.pace = Some(pace);
        }
        if let Some(v) = opts.get("fields") {
            o.parts = fields(v)?;
        }
        if let Some(v) = opts.get("address") {
            o.server.address = address(v)?;
        }
        if let Some(v) = opts.get("expose") {
            o.expose = v.as_bool().map_err(|_| {
                script_error(format!(
                    "view: expose must be true or false, got {}",
                    describe(v)
                ))
            })?;
        }
        if !o.server.address.is_loopback() && !o.expose {
            return Err(script_error(format!(
                "view: address {} is not this machine's loopback (127.0.0.1): other machines could reach the view, and its token travels in plain HTTP; leave address out to serve on 127.0.0.1, or add expose: true to serve there anyway",
                o.server.address
            )));
        }
        Ok(o)
    }
}

/// The socket's refusal in script words.
fn bind_error(e: &std::io::Error, o: &ServerOptions) -> Box<rhai::EvalAltResult> {
    let (a, p) = (o.address, o.port);
    script_error(match e.kind() {
        std::io::ErrorKind::AddrInUse => format!(
            "view: port {p} is in use on {a} (another program, or another view); give another port, or port: 0 for any free one"
        ),
        std::io::ErrorKind::PermissionDenied => format!(
            "view: port {p} on {a} needs privileges this process lacks (ports below 1024); give a port from 1024 to 65535, or port: 0 for any free one"
        ),
        std::io::ErrorKind::AddrNotAvailable => format!(
            "view: address {a} is not one of this machine's; leave address out to serve on 127.0.0.1"
        ),
        _ => format!("view: cannot serve on {a}:{p} ({e}); leave address and port out to serve on any free port of 127.0.0.1"),
    })
}

fn view(s: &mut SceneHandle, opts: &Map) -> ScriptResult<ImmutableString> {
    let o = Options::parse(opts)?;
    let mut current = s.view();
    if let Some(v) = current.as_ref() {
        return Err(script_error(format!(
            "view: this scene is already viewed at {}; open that address, or stop it first with s.close_view()",
            v.url()
        )));
    }
    let mut sim = s.borrow_mut()?;
    let pace = match o.pace {
        None => None,
        Some(periods) => {
            let period = sim.period().map_err(|e| {
                script_error(format!(
                    "view: pace counts stroke periods, and {}; leave pace out",
                    super::engine_message(&e)
                ))
            })?;
            let seconds_per_second = periods * period;
            if seconds_per_second <= 0.0 {
                return Err(script_error(format!(
                    "view: pace {periods} periods a second of a stroke period of {period} s is no time at all in f64; give a larger pace, or leave pace out to run at full speed"
                )));
            }
            let stop = interrupt::current();
            Some(Pace {
                seconds_per_second,
                stop: Arc::new(move || stop.requested()),
            })
        }
    };
    let slot = Arc::new(Slot::default());
    let server = Server::start(slot.clone(), &o.server).map_err(|e| bind_error(&e, &o.server))?;
    let publisher = Publisher::new(slot, o.parts, o.every, pace).with_refresh(s.redraw());
    sim.set_watcher(Some(Arc::new(publisher)));
    drop(sim);
    let server = Arc::new(server);
    let url = server.url().to_string();
    if o.expose && !o.server.address.is_loopback() {
        console::note(&format!(
            "WARNING: this view is served on {} and other machines may reach it: anyone who learns its address (sent in plain HTTP) can watch the scene",
            server.local_addr()
        ));
    }
    lock(&STARTED).push(Arc::downgrade(&server));
    ANY_STARTED.store(true, Ordering::SeqCst);
    if let Some(kept) = lock(&KEPT).as_mut() {
        kept.push(server.clone());
    }
    *current = Some(server);
    drop(current);
    console::write(&format!("{url}\n"));
    if let Some(sink) = SINK.get() {
        sink(&url);
    }
    Ok(url.into())
}

fn close_view(s: &mut SceneHandle) -> ScriptResult<()> {
    let mut current = s.view();
    if current.is_none() {
        return Ok(());
    }
    // Refused (the view kept whole) while a sweep shares the scene.
    s.borrow_mut()?.set_watcher(None);
    let Some(server) = current.take() else {
        return Ok(());
    };
    if let Some(kept) = lock(&KEPT).as_mut() {
        kept.retain(|k| !Arc::ptr_eq(k, &server));
    }
    drop(current);
    drop(server);
    Ok(())
}

/// Register `view` and `close_view`.
pub fn register(engine: &mut Engine) {
    engine
        .register_fn("view", |s: &mut SceneHandle| view(s, &Map::new()))
        .register_fn("view", |s: &mut SceneHandle, opts: Map| view(s, &opts))
        .register_fn("close_view", close_view);
}

#[rustfmt::skip]
pub(super) const DOCS: &[Doc] = &[
    doc_entry!("view", "pictures", "s.view() -> string\ns.view(#{ port, every, pace, fields, address, expose }) -> string", "Serve a live 3D view of the scene in the browser while it runs, on 127.0.0.1 under a random token; prints the page's address (http://127.0.0.1:PORT/TOKEN/) on a line of its own and returns it. Opens nothing: paste the address into a browser (the shell's :view opens it). Spheres coloured by kind (a1, a2) and sized by radius, N as arrows, the box or wall, a clock, live plots of the recorders' columns; drag to turn, wheel to zoom. Frames are taken at most once per `every` seconds of wall-clock time (default 1/30) and dropped, never queued, for slow browsers; `pace: p` holds runs to p stroke periods per second, to watch them; `fields` picks the frame's parts (\"spheres\", \"n\", \"rows\"); `port` (default 0: any free port). The stream: ADDRESS/frames (Server-Sent Events), ADDRESS/frame (the latest frame as JSON). It stops when the scene is dropped or with s.close_view(); `address` other than 127.0.0.1 only with expose: true.", "let s = scene(); s.add(dumbbell()); let url = s.view(#{ every: 0.1 }); s.run_periods(1); s.close_view(); print(url.ends_with(\"/\"));"),
    doc_entry!("close_view", "pictures", "s.close_view()", "Stop serving the scene's live view (s.view()); nothing is left listening. Nothing happens if the scene has no view.", "let s = scene(); s.view(); s.close_view(); s.close_view();"),
];
