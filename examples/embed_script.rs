//! Embed the script engine in a Rust program: register an extra function, run an experiment written
//! in Rhai, and read its result back as Rust values.
//!
//! cargo run --release --example embed_script

use rhai::{Dynamic, Map, Scope};

fn main() {
    let mut engine = swimlab::script::engine();
    // Anything a host application wants to offer scripts, next to swimlab's vocabulary.
    engine.register_fn("microns", |x: f64| x * 1e-6);

    let script = r#"
        import "paper" as paper;
        import "measure" as measure;
        let results = [];
        for D in [6.0, 10.0, 14.0] {
            let r = measure::settled_per_period(paper::mirror(D, true, true), 1);
            results.push(#{ D: D, drift: r.drift, speed_um_per_s: r.drift * 5.0 / (2.0 * pi() / 500.0) });
        }
        results
    "#;
    let mut scope = Scope::new();
    let results: Vec<Dynamic> = match engine.eval_with_scope::<rhai::Array>(&mut scope, script) {
        Ok(r) => r,
        Err(e) => {
            eprint!("{}", swimlab::script::render_error("embedded", script, &e));
            std::process::exit(1);
        }
    };
    println!("mirror pair, small spheres inwards (a2 = a1/2, Λ = 0.15ℓ):");
    for r in results {
        let m = r.cast::<Map>();
        println!(
            "  D = {:>4} ell: drift {:.4e} ell per period = {:.4e} um/s",
            m["D"].as_float().unwrap_or(f64::NAN),
            m["drift"].as_float().unwrap_or(f64::NAN),
            m["speed_um_per_s"].as_float().unwrap_or(f64::NAN)
        );
    }
    let check: f64 = engine.eval("microns(5.0)").unwrap_or(f64::NAN);
    println!("host function microns(5.0) = {check:e} m");
}
