"""Execute the teaching notebooks (examples/notebooks) against the real swimlab kernel with nbclient,
as Jupyter does, and check their outputs. Run by tests/kernel.rs: python run_notebooks.py SWIMLAB_EXE
NOTEBOOK_DIR. Prints "ok NAME" per notebook; exits non-zero at the first failure, saying what differed.
"""
import os
import re
import subprocess
import sys
import tempfile

import nbformat
from nbclient import NotebookClient

EXE, DIR = sys.argv[1], sys.argv[2]
prefix = tempfile.mkdtemp(prefix="swimlab-notebooks-")
subprocess.run([EXE, "kernel", "install", "--prefix", prefix], check=True, stdout=subprocess.DEVNULL)
os.environ["JUPYTER_PATH"] = os.path.join(prefix, "share", "jupyter")

# Per notebook: pictures expected (PNG display_data), and patterns its printed text must match.
EXPECT = {
    "scallop.ipynb": (2, [r"the scallop theorem holds: no net motion"]),
    "two_swimmers.ipynb": (2, [r"largest departure from the sine: \d\.\d+e-[3-9]\b", r"in phase: -?\d\.\d+e-1\d, antiphase: -?\d\.\d+e-1\d"]),
    "averaged_vs_micro.ipynb": (1, [r"the averaged model improves with distance", r"microscopic [\d.]+ ms, averaged [\d.]+ ms"]),
    "watch_a_pair.ipynb": (1, [r"http://127\.0\.0\.1:\d+/[0-9a-f]{32}/", r"collective drift per period: -?\d\.\d+e-\d+ ell"]),
}


def text_of(nb):
    out = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o.get("output_type") == "stream":
                out.append(o["text"])
            elif "data" in o and "text/plain" in o["data"]:
                out.append(o["data"]["text/plain"] + "\n")
    return "".join(out)


for name, (pictures, patterns) in EXPECT.items():
    nb = nbformat.read(os.path.join(DIR, name), as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), f"{name} is committed with outputs"
    NotebookClient(nb, timeout=300, kernel_name="swimlab", allow_errors=False).execute()
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    pngs = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "display_data" and "image/png" in o.get("data", {})]
    text = text_of(nb)
    missing = [p for p in patterns if not re.search(p, text)]
    if errors or len(pngs) < pictures or missing:
        print(f"FAIL {name}: errors {errors}, {len(pngs)} pictures (want {pictures}), unmatched {missing}\n{text}", flush=True)
        sys.exit(1)
    print(f"ok {name}", flush=True)
    sys.stdout.write(text)
print("all notebooks passed", flush=True)
