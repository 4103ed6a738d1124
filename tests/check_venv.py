"""The Python checks' one way into their own venv (mpmath, MuJoCo, PyNite).

A check calls `enter(name, requirements)` before its imports: where every
requirement is installed here (`installed`: each distribution's metadata
found, at its pinned version where it pins one), it goes on in this
interpreter; otherwise it makes `target/NAME` with `python3 -m venv` (once),
pip-installs the requirements there and re-runs itself in that venv. A venv
that still fails stops the check with a message, not a loop.

By the installed distributions, not by `import`: a folder of the same name
on the path (`tests/mujoco` beside `tests/check_venv.py`) imports as an
empty namespace package and would pass an import probe.
"""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def installed(requirements):
    """Whether every requirement (`dist` or `dist==version`) is installed
    here, at its pinned version where it pins one."""
    from importlib.metadata import PackageNotFoundError, version

    for requirement in requirements:
        dist, _, want = requirement.partition("==")
        try:
            have = version(dist)
        except PackageNotFoundError:
            return False
        if want and have != want:
            return False
    return True


def enter(name, requirements):
    if installed(requirements):
        return
    venv = ROOT / "target" / name
    python = venv / "bin" / "python"
    tried = "PKM_VENV_TRIED_" + name.upper().replace("-", "_")
    if os.environ.get(tried):
        sys.exit(f"{' '.join(requirements)} are not installed even in the venv {venv}")
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    # No byte-code at install (the modules a check imports compile on first
    # import), no version check: about half the install time.
    pip = [str(python), "-m", "pip", "install", "-q", "--no-compile", "--disable-pip-version-check"]
    subprocess.run([*pip, *requirements], check=True)
    os.environ[tried] = "1"
    script = str(Path(sys.argv[0]).resolve())
    os.execv(str(python), [str(python), script, *sys.argv[1:]])
