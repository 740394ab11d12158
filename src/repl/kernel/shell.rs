//! The shell channel: the loop on the main thread, and each request's answer (execution,
//! completion, inspection, completeness, history, shutdown).

use super::control::kernel_info;
use super::output::mime_bundle;
use super::shared::Shared;
use super::wire::Message;
use crate::repl::session::{Reply, Session};
use crate::script::console;
use serde_json::json;
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// The shell loop: each request marks the kernel busy, is handled, and marks it idle, until a
/// shutdown.
pub(super) fn serve(session: &mut Session, shell: &zmq::Socket, shared: &Arc<Shared>) {
    let mut count = 0u64;
    shared.publish(None, "status", json!({"execution_state": "starting"}));
    while !shared.shutdown.load(Ordering::SeqCst) {
        let Ok(Some(msg)) = shared.receive(shell, "shell", 100) else {
            continue;
        };
        if let Ok(mut c) = shared.current.lock() {
            *c = Some(msg.clone());
        }
        shared.publish(Some(&msg), "status", json!({"execution_state": "busy"}));
        handle_shell(session, shell, shared, &msg, &mut count);
        shared.publish(Some(&msg), "status", json!({"execution_state": "idle"}));
    }
}

/// The word around byte `pos` of `code` (for inspection).
fn word_at(code: &str, pos: usize) -> &str {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let pos = (0..=pos.min(code.len()))
        .rev()
        .find(|&p| code.is_char_boundary(p))
        .unwrap_or(0);
    let start = code[..pos]
        .char_indices()
        .rev()
        .find(|(_, c)| !is_word(*c))
        .map_or(0, |(i, c)| i + c.len_utf8());
    let end = code[pos..]
        .char_indices()
        .find(|(_, c)| !is_word(*c))
        .map_or(code.len(), |(i, _)| pos + i);
    &code[start..end]
}

/// Byte offset of code point `cursor` (the protocol counts code points).
fn byte_of(code: &str, cursor: usize) -> usize {
    code.char_indices()
        .nth(cursor)
        .map_or(code.len(), |(i, _)| i)
}

fn handle_shell(
    session: &mut Session,
    shell: &zmq::Socket,
    shared: &Shared,
    msg: &Message,
    count: &mut u64,
) {
    match msg.msg_type() {
        "kernel_info_request" => shared.reply(shell, msg, "kernel_info_reply", kernel_info()),
        "execute_request" => execute(session, shell, shared, msg, count),
        "complete_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let cursor = msg.content["cursor_pos"].as_u64().unwrap_or(0) as usize;
            let pos = byte_of(code, cursor);
            let (start, matches) = session.complete(code, pos);
            shared.reply(
                shell,
                msg,
                "complete_reply",
                json!({
                    "status": "ok",
                    "matches": matches,
                    "cursor_start": code[..start].chars().count(),
                    "cursor_end": code[..pos].chars().count(),
                    "metadata": {},
                }),
            );
        }
        "inspect_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let cursor = msg.content["cursor_pos"].as_u64().unwrap_or(0) as usize;
            let name = word_at(code, byte_of(code, cursor));
            let help = Session::help(name);
            shared.reply(
                shell,
                msg,
                "inspect_reply",
                json!({
                    "status": "ok",
                    "found": help.is_some(),
                    "data": help.map_or(json!({}), |h| json!({"text/plain": h})),
                    "metadata": {},
                }),
            );
        }
        "is_complete_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let status = if session.is_complete(code) {
                json!({"status": "complete"})
            } else {
                json!({"status": "incomplete", "indent": "  "})
            };
            shared.reply(shell, msg, "is_complete_reply", status);
        }
        "history_request" => shared.reply(
            shell,
            msg,
            "history_reply",
            json!({"status": "ok", "history": []}),
        ),
        "comm_info_request" => shared.reply(
            shell,
            msg,
            "comm_info_reply",
            json!({"status": "ok", "comms": {}}),
        ),
        "shutdown_request" => shared.shut_down(shell, msg),
        other => console::to_stderr(&format!(
            "swimlab kernel: no handler for \"{other}\" on the shell channel\n"
        )),
    }
}

fn execute(
    session: &mut Session,
    shell: &zmq::Socket,
    shared: &Shared,
    msg: &Message,
    count: &mut u64,
) {
    let code = msg.content["code"].as_str().unwrap_or("").to_string();
    let silent = msg.content["silent"].as_bool().unwrap_or(false);
    if !silent {
        *count += 1;
        shared.publish(
            Some(msg),
            "execute_input",
            json!({"code": code, "execution_count": *count}),
        );
    }
    let outcome = if code.trim_start().starts_with(':') {
        match session.handle(&code) {
            Reply::Output(s) => {
                if !s.is_empty() {
                    shared.publish(
                        Some(msg),
                        "stream",
                        json!({"name": "stdout", "text": format!("{s}\n")}),
                    );
                }
                Ok(None)
            }
            Reply::Error(e) => Err(e),
            Reply::Quit => Err(":quit ends the shell; in a notebook, shut the kernel down from Jupyter (Kernel > Shut Down)".into()),
        }
    } else {
        session.execute(&code)
    };
    match outcome {
        Ok(value) => {
            if let Some(v) = value.filter(|_| !silent) {
                let (data, picture) = mime_bundle(&v);
                if picture {
                    shared.publish(
                        Some(msg),
                        "display_data",
                        json!({"data": data, "metadata": {}}),
                    );
                } else {
                    shared.publish(
                        Some(msg),
                        "execute_result",
                        json!({"data": data, "metadata": {}, "execution_count": *count}),
                    );
                }
            }
            shared.reply(
                shell,
                msg,
                "execute_reply",
                json!({"status": "ok", "execution_count": *count, "user_expressions": {}, "payload": []}),
            );
        }
        Err(rendered) => {
            let rendered = rendered.trim_end().to_string();
            let evalue = rendered.lines().next().unwrap_or("").to_string();
            let error = json!({
                "ename": "Error",
                "evalue": evalue,
                "traceback": rendered.lines().collect::<Vec<_>>(),
            });
            if !silent {
                shared.publish(Some(msg), "error", error.clone());
            }
            let mut reply = error;
            reply["status"] = json!("error");
            reply["execution_count"] = json!(*count);
            shared.reply(shell, msg, "execute_reply", reply);
        }
    }
}
