#!/usr/bin/env python3
"""pkm's platform stiffness (`pkm stiffness`, K = Jᵀ K_p J from the wrench
analysis and the file's `limbs` block) against the frame of beams of
frame_stiffness.py (PyNite), for the 3-RPS and the 3-SPR of seed 004 at
docs/seed004.md's three poses: issue 14's independent structural check.

For each mechanism and pose it runs `pkm stiffness FILE --pose … --json`
($PKM, else target/release/pkm; `cargo build --release -p pkm-cli` first;
CI passes the debug binary `cargo test` built), takes the
assembly the seed draws (the legs on the platform's own side: the shortest
legs), writes the joints' centres and axes, the legs' E, A, I and pkm's K as
a frame_stiffness.py configuration (schema pkm-frame-stiffness/1) with K
under `expect.K`, and runs frame_stiffness.py on it, which exits non-zero
when pkm's K and the frame's differ by more than 1e-6 (relative, in energy).
Exit status 1 on any failure.
"""

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PKM = Path(os.environ.get("PKM") or ROOT / "target" / "release" / "pkm")
FRAME = ROOT / "tests" / "frame" / "frame_stiffness.py"
# docs/seed004.md's poses: (name, Z_A mm, α°, β°).
POSES = [("I", 75.0, 0.0, 0.0), ("II", 75.0, 10.0, 0.0), ("III", 80.0, 5.0, 10.0)]
MECHANISMS = [("3-RPS", "rps_3"), ("3-SPR", "spr_3")]
# The legs as the files declare them (E in N/mm², A in mm², I in mm⁴).
E, AREA, INERTIA = 2.11e5, math.pi * 20.0**2, 1.256e5
# Seed 004 §3's load on the platform centre: N, and N·m read as N·mm × 1000.
WRENCH = [10.0, -15.0, 20.0, -20000.0, 10000.0, 15000.0]


def pkm(file, za, alpha, beta):
    pose = f"ZA={za},alpha={alpha},beta={beta}"
    wrench = ",".join(str(w) for w in WRENCH)
    out = subprocess.run(
        [str(PKM), "--json", "stiffness", str(file), "--degrees", "--pose", pose, "--wrench", wrench],
        capture_output=True,
        text=True,
    )
    if out.returncode != 0:
        raise SystemExit(f"pkm stiffness {file.name} {pose} failed ({out.returncode}): {out.stdout}{out.stderr}")
    return json.loads(out.stdout)


def drawn(result):
    """The assembly the seed draws: the shortest legs (the other branches
    put the platform half a turn about z, or repeat it with a leg's slide
    read the other way)."""
    ok = [b for b in result["branches"] if b["ok"]]
    return min(ok, key=lambda b: sum(l["length"] for l in b["limbs"]))


def frame_config(name, branch):
    legs = []
    for limb in branch["limbs"]:
        joints = limb["joints"]
        ends = []
        for j in (joints[0], joints[-1]):
            kind = j["kind"]
            if kind not in ("R", "S"):
                raise SystemExit(f"{name}: limb {limb['name']} ends in a {kind} joint; the frame takes R and S")
            end = {"joint": kind, "centre": j["point"]}
            if kind == "R":
                end["axis"] = j["axis"]
            ends.append(end)
        legs.append(
            {
                "base": ends[0],
                "platform": ends[1],
                "length": limb["length"],
                "E": E,
                "A": AREA,
                "I": INERTIA,
            }
        )
    return {
        "schema": "pkm-frame-stiffness/1",
        "name": name,
        "units": {"length": "mm", "force": "N", "modulus": "N/mm^2", "area": "mm^2", "second_moment": "mm^4"},
        "reference": branch["reference"],
        "legs": legs,
        "expect": {"K": branch["K"], "tolerance": 1e-6},
    }


def main():
    if not PKM.exists():
        raise SystemExit(f"{PKM} is missing: run `cargo build --release -p pkm-cli` first, or set PKM")
    failures = 0
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, stem in MECHANISMS:
            file = ROOT / "examples" / "mechanisms" / f"{stem}.pkm"
            for pose, za, alpha, beta in POSES:
                name = f"{label} pose {pose}"
                branch = drawn(pkm(file, za, alpha, beta))
                path = Path(tmp) / f"{stem}_{pose}.json"
                path.write_text(json.dumps(frame_config(name, branch)))
                out = subprocess.run([sys.executable, str(FRAME), str(path), "--json"], capture_output=True, text=True)
                try:
                    res = json.loads(out.stdout)
                    rel = res.get("expect_rel_frame")
                except json.JSONDecodeError:
                    res, rel = None, None
                ok = out.returncode == 0 and rel is not None and rel <= 1e-6
                failures += not ok
                rel_text = "—" if rel is None else f"{rel:.2e}"
                print(f"{'ok ' if ok else 'BAD'} {name}: pkm's K against the frame's (rigid platform), rel {rel_text}")
                if not ok:
                    print(out.stdout[-2000:], out.stderr[-2000:])
                rows.append((name, branch))
    print()
    print("pkm's figures (K at the platform centre; the seed's wrench there, moments in N·mm):")
    print(f"{'':16}{'Kxx':>10}{'Kyy':>10}{'Kzz':>10}{'kx':>10}{'ky':>10}{'kz':>10}{'δx':>11}{'δy':>11}{'δz':>11}")
    print(f"{'':16}{'N/mm':>10}{'N/mm':>10}{'N/mm':>10}{'N/mm':>10}{'N/mm':>10}{'N/mm':>10}{'mm':>11}{'mm':>11}{'mm':>11}")
    for name, b in rows:
        k, d, t = b["K"], b["directional"], b["deflection"]["translation"]
        print(
            f"{name:16}{k[0][0]:10.4g}{k[1][1]:10.4g}{k[2][2]:10.4g}{d['x']:10.4g}{d['y']:10.4g}{d['z']:10.4g}"
            f"{t[0]:11.3e}{t[1]:11.3e}{t[2]:11.3e}"
        )
    if failures:
        print(f"{failures} configuration(s) disagree")
        return 1
    print("pkm's stiffness agrees with the frame at every pose of both mechanisms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
