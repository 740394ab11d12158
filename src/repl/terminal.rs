//! The front ends: an interactive terminal (rustyline) and piped standard input.

use super::helper::ReplHelper;
use super::session::{Reply, Session};
use crate::script::{console, interrupt};
use rustyline::error::ReadlineError;
use rustyline::history::DefaultHistory;
use rustyline::{CompletionType, Config, Editor};
use std::cell::RefCell;
use std::io::{BufRead, IsTerminal, Write};
use std::path::PathBuf;
use std::rc::Rc;

/// The prompt (also what pty tests wait for).
pub const PROMPT: &str = "swimlab> ";

/// Where history is kept: $SWIMLAB_HISTORY, else $XDG_DATA_HOME/swimlab/history, else
/// ~/.local/share/swimlab/history (empty variables count as unset, a relative XDG_DATA_HOME as
/// invalid: the XDG rules).
pub fn history_path() -> Option<PathBuf> {
    if let Some(p) = super::env_path("SWIMLAB_HISTORY", false) {
        return Some(p);
    }
    let data = super::env_path("XDG_DATA_HOME", true)
        .or_else(|| super::env_path("HOME", false).map(|h| h.join(".local/share")))?;
    Some(data.join("swimlab").join("history"))
}

/// Run the REPL on the terminal, or on piped input when stdin is not a terminal. Returns whether
/// every input succeeded (piped mode's exit status).
pub fn run() -> bool {
    // Ctrl-C while a simulation runs: stop it at the next step boundary, keep the scene.
    let _ = ctrlc::set_handler(interrupt::request);
    if std::io::stdin().is_terminal() {
        interactive()
    } else {
        piped(
            std::io::stdin().lock(),
            &mut std::io::stdout(),
            &mut std::io::stderr(),
        )
    }
}

/// Append the entries added since the last call to the history file (created with its folder),
/// so that a closed terminal or a killed process loses no command already entered.
fn append_history(rl: &mut Editor<ReplHelper, DefaultHistory>, path: &std::path::Path) {
    if let Some(dir) = path.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    let _ = rl.append_history(path);
}

fn interactive() -> bool {
    let session = Rc::new(RefCell::new(Session::new()));
    // A first Tab completes what the candidates share, a second lists them (as bash and
    // IPython do).
    let config = Config::builder()
        .auto_add_history(false)
        .completion_type(CompletionType::List)
        .build();
    let mut rl: Editor<ReplHelper, DefaultHistory> = match Editor::with_config(config) {
        Ok(rl) => rl,
        Err(e) => {
            console::to_stderr(&format!("error: cannot start the line editor: {e}\n"));
            return false;
        }
    };
    rl.set_helper(Some(ReplHelper::new(session.clone())));
    let history = history_path();
    if let Some(h) = &history {
        let _ = rl.load_history(h);
    }
    console::to_stdout(&format!(
        "swimlab {} — dumbbell swimmers at low Reynolds number. :help lists everything, Ctrl-D leaves.\n",
        env!("CARGO_PKG_VERSION")
    ));
    loop {
        match rl.readline(PROMPT) {
            Ok(line) => {
                if !line.trim().is_empty() {
                    let _ = rl.add_history_entry(line.as_str());
                    if let Some(h) = &history {
                        append_history(&mut rl, h);
                    }
                }
                let reply = session.borrow_mut().handle(&line);
                match reply {
                    Reply::Quit => break,
                    Reply::Output(s) if s.is_empty() => {}
                    Reply::Output(s) => console::to_stdout(&format!("{s}\n")),
                    Reply::Error(s) => console::to_stderr(&format!(
                        "{s}{}",
                        if s.ends_with('\n') { "" } else { "\n" }
                    )),
                }
            }
            Err(ReadlineError::Interrupted) => console::to_stdout("(Ctrl-D or :quit leaves)\n"),
            Err(ReadlineError::Eof) => break,
            Err(e) => {
                console::to_stderr(&format!("error: {e}\n"));
                break;
            }
        }
    }
    true
}

/// Read inputs from `input` (multi-line statements joined until they parse), write values to
/// `out` and errors to `err`. Returns false if any input failed.
pub fn piped(input: impl BufRead, out: &mut dyn Write, err: &mut dyn Write) -> bool {
    let mut session = Session::new();
    let mut buffer = String::new();
    let mut ok = true;
    let mut lines = input.lines();
    loop {
        let line = match lines.next() {
            Some(Ok(l)) => l,
            Some(Err(e)) => {
                let _ = writeln!(err, "error: cannot read input: {e}");
                return false;
            }
            None => break,
        };
        buffer.push_str(&line);
        buffer.push('\n');
        if !session.is_complete(&buffer) {
            continue;
        }
        let reply = session.handle(&buffer);
        buffer.clear();
        match reply {
            Reply::Quit => return ok,
            Reply::Output(s) if s.is_empty() => {}
            Reply::Output(s) => {
                // A reader that has gone reads no more values: end quietly, as `print` does.
                if let Err(e) = writeln!(out, "{s}") {
                    if e.kind() == std::io::ErrorKind::BrokenPipe {
                        std::process::exit(crate::script::console::CLOSED_STDOUT_STATUS);
                    }
                }
            }
            Reply::Error(s) => {
                ok = false;
                let _ = out.flush();
                let _ = write!(err, "{s}{}", if s.ends_with('\n') { "" } else { "\n" });
            }
        }
    }
    if !buffer.trim().is_empty() {
        let _ = writeln!(
            err,
            "error: the input ended inside an unfinished statement:\n{buffer}"
        );
        ok = false;
    }
    ok
}
