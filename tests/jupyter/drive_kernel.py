"""Drive `swimlab kernel` with jupyter_client, as Jupyter does, and check what comes back.

Run by tests/kernel.rs: python drive_kernel.py SWIMLAB_EXE. Prints "ok NAME" per check and exits
non-zero at the first failure (the message says what differed).
"""
import json
import os
import queue
import sys
import tempfile
import time

import zmq
from jupyter_client import KernelManager
from jupyter_client.session import Session

EXE = sys.argv[1]
TIMEOUT = 120


PREFIX = tempfile.mkdtemp(prefix="swimlab-kernelspec-")


def install():
    """`swimlab kernel install --prefix` into a fresh folder that Jupyter is pointed at."""
    import subprocess

    subprocess.run([EXE, "kernel", "install", "--prefix", PREFIX], check=True)
    os.environ["JUPYTER_PATH"] = os.path.join(PREFIX, "share", "jupyter")
    spec = json.load(open(os.path.join(PREFIX, "share", "jupyter", "kernels", "swimlab", "kernel.json")))
    assert spec["argv"][1:] == ["kernel", "-f", "{connection_file}"], spec


def start():
    km = KernelManager(kernel_name="swimlab")
    km.start_kernel()
    kc = km.client()
    kc.start_channels()
    kc.wait_for_ready(timeout=TIMEOUT)
    return km, kc


def run(kc, code, timeout=TIMEOUT):
    """Execute code; return (reply content, iopub messages of this request)."""
    msg_id = kc.execute(code)
    outputs = []
    while True:
        m = kc.get_iopub_msg(timeout=timeout)
        if m["parent_header"].get("msg_id") != msg_id:
            continue
        if m["msg_type"] == "status" and m["content"]["execution_state"] == "idle":
            break
        outputs.append(m)
    reply = kc.get_shell_msg(timeout=timeout)
    assert reply["parent_header"]["msg_id"] == msg_id
    return reply["content"], outputs


def of_type(outputs, t):
    return [m["content"] for m in outputs if m["msg_type"] == t]


def check(name, cond, detail=""):
    if not cond:
        print(f"FAIL {name}: {detail}", flush=True)
        sys.exit(1)
    print(f"ok {name}", flush=True)


install()
km, kc = start()
try:
    info = kc.kernel_info(reply=True, timeout=TIMEOUT)["content"]
    check("kernel_info", info["protocol_version"] == "5.3" and info["language_info"]["name"] == "swimlab", info)

    reply, out = run(kc, "1 + 2")
    res = of_type(out, "execute_result")
    check("a value is the execute_result", reply["status"] == "ok" and res and res[0]["data"]["text/plain"] == "3", out)

    run(kc, 'let s = scene(); s.add(dumbbell(#{ a1: 1.125e-6, a2: 0.5625e-6 })); fn twice(x) { x * 2 }')
    reply, out = run(kc, "print(s.count); twice(21)")
    streams = "".join(c["text"] for c in of_type(out, "stream") if c["name"] == "stdout")
    res = of_type(out, "execute_result")
    check("variables and functions persist; print is the stdout stream", streams == "1\n" and res[0]["data"]["text/plain"] == "42", out)

    run(kc, 'import "phases" as ph;')
    reply, out = run(kc, "ph::alternating(4, 1.0).len()")
    res = of_type(out, "execute_result")
    check("imports persist", reply["status"] == "ok" and res and res[0]["data"]["text/plain"] == "4", (reply, out))

    reply, out = run(kc, "plot(#{ x: [1, 2, 3], y: [1, 4, 9] })")
    shown = of_type(out, "display_data")
    check("a picture is display_data, PNG and SVG",
          shown and shown[0]["data"]["image/png"].startswith("iVBORw0KGgo") and "<svg" in shown[0]["data"]["image/svg+xml"], [m["msg_type"] for m in out])
    reply, out = run(kc, "tplot(#{ x: [0, 1, 2], y: [0, 1, 4] }, #{ cols: 30, rows: 6 })")
    text = "".join(c["text"] for c in of_type(out, "stream"))
    check("a text plot goes to the stdout stream", reply["status"] == "ok" and text.count("\n") >= 6, (reply, text))
    reply, out = run(kc, "for k in 0..2 { display(s.snapshot()); } display(1.5); 7")
    shown = of_type(out, "display_data")
    check("display(value) shows pictures and values mid-cell", len(shown) == 3 and "image/png" in shown[1]["data"] and shown[2]["data"]["text/plain"] == "1.5" and of_type(out, "execute_result"), [m["msg_type"] for m in out])
    reply, out = run(kc, "s.snapshot()")
    check("a snapshot is shown", of_type(out, "display_data"), [m["msg_type"] for m in out])
    reply, out = run(kc, "let w = scene(); w.add(dumbbell()); let url = w.view(); w.run_periods(0.2); w.close_view(); url")
    html = [d["data"].get("text/html", "") for d in of_type(out, "display_data")]
    check("a view shows its page inline", reply["status"] == "ok" and any("<iframe" in h and "http://127.0.0.1:" in h for h in html), [m["msg_type"] for m in out])

    reply, out = run(kc, "let x = 1;\nx.nope()")
    err = of_type(out, "error")
    check("an error replies status error with the caret rendering",
          reply["status"] == "error" and err and any(line.strip() == "^" or line.rstrip().endswith("^") for line in err[0]["traceback"]) and ":2:" in err[0]["evalue"], (reply, err))

    # Interrupts: a long run stopped at a step boundary, the scene kept, the kernel alive.
    # Rows every 0.02 periods: a few hundred in the second before the interrupt.
    run(kc, "let rec = s.record([R_H(0)], every_periods(0.02));")
    for how in ["message", "signal"]:
        t0 = run(kc, "s.time")[1]
        before = of_type(t0, "execute_result")[0]["data"]["text/plain"]
        rows_before = int(of_type(run(kc, "rec.rows.len()")[1], "execute_result")[0]["data"]["text/plain"])
        msg_id = kc.execute("s.integrator = rk4(1e-7); s.run_periods(1e4)")
        time.sleep(1.0)
        if how == "message":
            m = kc.session.msg("interrupt_request", {})
            kc.control_channel.send(m)
            rep = kc.control_channel.get_msg(timeout=TIMEOUT)
            check("interrupt_reply", rep["msg_type"] == "interrupt_reply", rep)
        else:
            km.interrupt_kernel()
        reply = kc.get_shell_msg(timeout=TIMEOUT)
        check(f"an interrupt ({how}) stops the running cell", reply["parent_header"]["msg_id"] == msg_id and reply["content"]["status"] == "error" and "interrupt" in reply["content"]["evalue"].lower(), reply["content"])
        reply, out = run(kc, "s.time")
        after = of_type(out, "execute_result")[0]["data"]["text/plain"]
        check(f"the scene is kept and moved on ({how})", float(after) > float(before), (before, after))
        rows_after = int(of_type(run(kc, "rec.rows.len()")[1], "execute_result")[0]["data"]["text/plain"])
        check(f"the rows recorded before the interrupt are kept ({how})", rows_after > rows_before, (rows_before, rows_after))
        reply, out = run(kc, "s.integrator = \"default\"; s.run_periods(1.0); s.count")
        check(f"the session continues after the interrupt ({how})", reply["status"] == "ok" and of_type(out, "execute_result")[0]["data"]["text/plain"] == "1", reply)

    # A long run shows an updating progress line.
    reply, out = run(kc, "s.integrator = rk4(2e-7); s.run_periods(100.0)")
    kinds = [m["msg_type"] for m in out]
    check("a long run shows progress updating in place", "display_data" in kinds and "update_display_data" in kinds, kinds)

    # A continuum runs as a scene does: its long run shows the progress line and an interrupt
    # stops it at a step boundary, the continuum kept and moved on (a step of this one takes
    # about a second, so the line is shown after the first and the run is far from its end).
    run(kc, 'let cs = scene(); cs.model = "averaged"; cs.box = [400e-6, 400e-6, 400e-6]; '
            'cs.add_random(dumbbell(), 40, 1, #{ phase: 0.0 }); '
            'cs.add_random(dumbbell(), 40, 2, #{ phase: pi() / 2.0 }); '
            'let c = continuum(cs, #{ grid: 16, orientations: 4 }); c.perturb(#{ amplitude: 0.5 });')
    before = of_type(run(kc, "c.time")[1], "execute_result")[0]["data"]["text/plain"]
    msg_id = kc.execute("c.run_periods(1e6)")
    time.sleep(3.0)
    m = kc.session.msg("interrupt_request", {})
    kc.control_channel.send(m)
    kc.control_channel.get_msg(timeout=TIMEOUT)
    reply = kc.get_shell_msg(timeout=TIMEOUT)
    check("an interrupt stops a continuum's run", reply["parent_header"]["msg_id"] == msg_id and reply["content"]["status"] == "error" and "interrupt" in reply["content"]["evalue"].lower(), reply["content"])
    kinds = []
    while True:
        m = kc.get_iopub_msg(timeout=TIMEOUT)
        if m["parent_header"].get("msg_id") != msg_id:
            continue
        if m["msg_type"] == "status" and m["content"]["execution_state"] == "idle":
            break
        kinds.append(m["msg_type"])
    check("a continuum's long run shows progress updating in place", "display_data" in kinds and "update_display_data" in kinds, kinds)
    after = of_type(run(kc, "c.time")[1], "execute_result")[0]["data"]["text/plain"]
    check("the continuum is kept and moved on", float(after) > float(before), (before, after))

    c = kc.complete("s.run_per", 9, reply=True, timeout=TIMEOUT)["content"]
    check("completion", "run_periods" in c["matches"] and c["cursor_start"] == 2 and c["cursor_end"] == 9, c)
    c = kc.complete("twi", 3, reply=True, timeout=TIMEOUT)["content"]
    check("completion of user functions", "twice" in c["matches"], c)
    i = kc.inspect("s.run_periods(2.0)", 6, reply=True, timeout=TIMEOUT)["content"]
    check("inspection shows :help", i["found"] and "run_periods" in i["data"]["text/plain"], i)
    kc.is_complete("fn f(x) {")
    ic = kc.get_shell_msg(timeout=TIMEOUT)["content"]
    check("is_complete", ic["status"] == "incomplete", ic)

    # A client with the wrong key: its code never runs, and the kernel lives on.
    marker = os.path.join(PREFIX, "forged")
    bad = kc.session.clone()
    bad.key = b"not-the-key"
    ctx = zmq.Context.instance()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(kc.shell_channel.socket.getsockopt_string(zmq.LAST_ENDPOINT))
    bad.send(sock, "execute_request", {"code": f'write_csv("{marker}", [#{{ a: 1 }}]);', "silent": False, "store_history": True, "user_expressions": {}, "allow_stdin": False, "stop_on_error": True})
    unsigned = kc.session.msg("execute_request", {"code": f'write_csv("{marker}", [#{{ a: 2 }}]);', "silent": False, "store_history": True, "user_expressions": {}, "allow_stdin": False, "stop_on_error": True})
    sock.send_multipart([b"<IDS|MSG>", b"", *[kc.session.pack(unsigned[k]) for k in ["header", "parent_header", "metadata", "content"]]])
    got = sock.poll(1000)
    time.sleep(1.0)
    reply, out = run(kc, "7 * 6")
    check("a message with a wrong or missing signature is dropped, never run", not got and not os.path.exists(marker) and of_type(out, "execute_result")[0]["data"]["text/plain"] == "42", (got, os.path.exists(marker)))
    sock.close(0)

    # Restart: a fresh session.
    km.restart_kernel(now=False)
    kc.wait_for_ready(timeout=TIMEOUT)
    reply, out = run(kc, "s")
    check("a restart gives a fresh session", reply["status"] == "error", reply)
finally:
    try:
        kc.stop_channels()
        km.shutdown_kernel(now=False)
        check("shutdown ends the kernel process", not km.is_alive())
    except SystemExit:
        raise
print("all passed", flush=True)
