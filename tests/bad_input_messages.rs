//! Output that cannot be written and Rhai's own messages: a command whose standard output is
//! closed or full ends cleanly (no Rust panic), and every message a user can reach about
//! properties and shared values is in swimlab's words.

use crate::common::cli::{self, case, case_dir};
use std::process::{Command, Stdio};

/// `swimlab reference` into a full disk: an error that says what was lost and what to do,
/// exit 1, never a panic.
#[test]
fn a_full_disk_is_the_commands_error() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full (Linux)");
    let out = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .arg("reference")
        .stdout(full)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    cli::check(
        "swimlab reference > /dev/full",
        &out,
        &["cannot write standard output", "redirect it to a file"],
        1,
    );
}

/// `swimlab reference | true`: the reader went away, so the process ends at once and quietly,
/// with the status a shell gives a process that SIGPIPE ended (141), as `swimlab run` does.
#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    // The pipe's reading end is closed before the command starts: its output (~55 kB) would
    // fit in the pipe's buffer, so a reader closed only after the spawn could come too late.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .arg("reference")
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{err}");
    assert!(err.is_empty(), "{err}");
}

/// No command writes through Rust's `print!` family, which panics when standard output cannot
/// be written: the CLI's text goes through the console (`emit`, `to_stdout`, `to_stderr`).
#[test]
fn no_print_macros_in_src() {
    let mut found = Vec::new();
    let mut stack = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src")];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                for (k, line) in text.lines().enumerate() {
                    let code = line.split("//").next().unwrap_or("");
                    if ["print!(", "println!(", "eprint!(", "eprintln!("]
                        .iter()
                        .any(|m| code.contains(m))
                    {
                        found.push(format!("{}:{}: {}", p.display(), k + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// A read-only property set, a property of a value that has none, and a property of another
/// type: each named in script words with the fix, never Rhai's "a setter is not registered".
#[test]
fn properties_are_named_in_script_words() {
    let b = "let b = scene();\nb.box = [120e-6, 120e-6, 120e-6];\nb.add(dumbbell(#{ center: [-30e-6, 0, 0] }));\nb.add(dumbbell(#{ phase: 1.0 }));\nlet c = continuum(b, #{ grid: 4, orientations: 2 });\n";
    case(
        &format!("{b}c.time = 1.0;"),
        &["Continuum.time can be read but not set"],
        1,
    );
    case(
        "let x = 3;\nx.wall = #{ z: 0 };",
        &["int has no property .wall", ".wall is a property of Scene"],
        1,
    );
    case(
        "let x = 3.5;\nprint(x.count);",
        &["float has no property .count", ".count is a property of"],
        1,
    );
    let shell = cli::swimlab(&[], "3\nans.wall = #{ z: 0 }\n", &case_dir());
    cli::check(
        "ans.wall after a number",
        &shell,
        &["int has no property .wall", "is a property of Scene"],
        1,
    );
    for out in [
        cli::run_in(&format!("{b}c.time = 1.0;"), &case_dir()),
        shell,
    ] {
        let text = cli::text(&out);
        assert!(!text.contains("is not registered"), "{text}");
    }
}

/// A closure that changes a variable it captured while a method of that variable runs: Rhai's
/// bare "Data race detected" becomes what happened and the fix.
#[test]
fn a_data_race_is_explained() {
    let text = case(
        "let a = [1, 2];\nlet f = |x| { a.push(x); x };\nprint(a.map(f));",
        &["was in use by one call while another needed it", "a copy"],
        1,
    );
    assert!(!text.contains("Data race detected"), "{text}");
}

/// Refusals name extreme numbers compactly: 1e308 as "1e308", not as 309 digits, whether the
/// message comes from the engine or the script layer, caught or not; numbers of ordinary size,
/// and digits inside words, are written as before.
#[test]
fn extreme_numbers_in_refusals_are_written_compactly() {
    let t = case(
        "let s = scene();\ns.add(dumbbell());\ntry { s.temperature = 1e308; } catch (e) { print(e); }\ntry { s.mu = -1e308; } catch (e) { print(e); }\ntry { s.run_periods(-1e308); } catch (e) { print(e); }\ntry { s.view(#{ every: 1e308 }); } catch (e) { print(e); }\ntry { s.view(#{ every: 0 }); } catch (e) { print(e); }\ntry { s.view(#{ pace: -1e308 }); } catch (e) { print(e); }\ntry { s.view(#{ every: -1e-320 }); } catch (e) { print(e); }\ns.ewald_tol = 1e308;",
        &[
            "temperature must lie between 0 and 1e6 K, got 1e308",
            "mu must be a finite positive number (Pa s), got -1e308",
            "the number of periods must be >= 0, got -1e308",
            "above 0 and at most 3600 s (default 0.0333 s: 30 frames a second), got 1e308",
            "above 0 and at most 3600 s (default 0.0333 s: 30 frames a second), got 0\n",
            "got -1e308\n",
            "got -1e-320\n",
            ":10:3: the Ewald tolerance must lie between 1e-15 and 1e-2, got 1e308",
        ],
        1,
    );
    assert!(!t.contains("00000000000000000000"), "{t}");
    assert!(!t.contains("from 0 to 3600"), "{t}");
}

/// A call of one of Rhai's own functions (`split`, `trim`) with arguments none of its forms
/// takes names that function and its forms, caught or not: not Rhai's error map with Rust's
/// spelling of the types, and not "there is no function split; did you mean plot?".
#[test]
fn a_wrong_call_of_a_core_function_names_its_forms() {
    let t = case(
        "let x = ();\ntry { x.split(\",\"); } catch (e) { print(e); }\nprint(\"a,b\".split(\",\"));\nlet a = [1];\na.push(2);\nprint(a);\nprint(timestamp().elapsed >= 0.0);\nx.split(\",\");",
        &[
            "split cannot be called as split((), string); its forms: split(string), ",
            "split(string, string)",
            "[\"a\", \"b\"]",
            "[1, 2]",
            "true",
            ":8:3: split cannot be called as split((), string); its forms:",
        ],
        1,
    );
    assert!(
        !t.contains("ImmutableString")
            && !t.contains("ErrorFunctionNotFound")
            && !t.contains("did you mean plot"),
        "{t}"
    );
}
