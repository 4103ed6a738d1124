"""The Python checks' one way into their own venv (mpmath, MuJoCo, PyNite).

A check calls `enter(name, requirements, probe)` before its imports: if
`probe()` is true (the pinned packages import here), it goes on in this
interpreter; otherwise it makes `target/NAME` with `python3 -m venv` (once),
pip-installs the requirements there and re-runs itself in that venv. A venv
that still fails the probe stops the check with a message, not a loop.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def enter(name, requirements, probe):
    if probe():
        return
    venv = ROOT / "target" / name
    python = venv / "bin" / "python"
    tried = "PKM_VENV_TRIED_" + name.upper().replace("-", "_")
    if os.environ.get(tried):
        sys.exit(f"{' '.join(requirements)} do not import even in the venv {venv}")
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    # No byte-code at install (the modules a check imports compile on first
    # import), no version check: about half the install time.
    pip = [str(python), "-m", "pip", "install", "-q", "--no-compile", "--disable-pip-version-check"]
    subprocess.run([*pip, *requirements], check=True)
    os.environ[tried] = "1"
    script = str(Path(sys.argv[0]).resolve())
    os.execv(str(python), [str(python), script, *sys.argv[1:]])
