//! Every ```rhai block in README.md runs: examples that are run cannot rot.

use rhai::Scope;
use swimlab::script::run_source;

#[test]
fn readme_rhai_blocks_run() {
    let text = std::fs::read_to_string("README.md").unwrap();
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```rhai") => current = Some(String::new()),
            (Some(b), l) if l.starts_with("```") => {
                blocks.push(std::mem::take(b));
                current = None;
            }
            (Some(b), _) => {
                b.push_str(line);
                b.push('\n');
            }
            _ => {}
        }
    }
    assert!(!blocks.is_empty(), "README has no rhai examples");
    for (k, b) in blocks.iter().enumerate() {
        run_source(&format!("README.md block {k}"), b, &mut Scope::new())
            .unwrap_or_else(|e| panic!("{e}"));
    }
}
