#!/usr/bin/env python3
"""pkm's inverse dynamics against MuJoCo, on models `pkm export --mjcf` writes.

Four mechanisms: the four-bar, the slider-crank, seed 003's punch (its own
Table-1 masses) and seed 000's mechanism A (masses of this test's own), the
first, second and last given the masses below by adding them to the example
file's text, as the Rust tests' `common::example_with` does.

(a) Exact. At random states (q, q̇, q̈ all nonzero) on every branch pkm
    solves, MuJoCo's open-chain dynamics of the exported tree (the loops cut:
    mass matrix `mj_fullM`, bias forces `qfrc_bias`) and the Jacobian of the
    loop-closure equality constraints (`efc_J`'s equality rows) give the
    actuators' forces τ and the loop forces λ by one least-squares solve of
    [Sᵀ Jᵀ] [τ; λ] = M q̈ + b (minimum norm: a planar loop is redundant in
    3-D). `mj_inverse` is not used: it gives passive joints torque. pkm must
    agree to 1e-9 of the largest actuator force at that state.

(b) In time. pkm's forces along a trajectory are MuJoCo's motor inputs in a
    forward simulation (timestep 1e-4 s, implicitfast, stiff loop
    constraints), with a weak servo holding the trajectory; the servo's
    largest force must stay a small share of the largest motor force.

Run: python3 tests/mujoco/test_mujoco.py (from anywhere). Without `mujoco`
importable, it makes a venv under target/ and installs it there with pip.
The pkm binary is $PKM, else target/release/pkm (built if missing).
"""

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MUJOCO = "mujoco==4.0.0"


def bootstrap():
    """Re-runs this script in a venv holding MuJoCo unless it imports here."""
    try:
        import mujoco  # noqa: F401
        import numpy  # noqa: F401

        return
    except ImportError:
        pass
    venv = ROOT / "target" / "mujoco-venv"
    python = venv / "bin" / "python"
    if os.environ.get("PKM_MUJOCO_VENV_TRIED"):
        sys.exit("mujoco does not import even in the venv " + str(venv))
    if not python.exists():
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", MUJOCO, "numpy"], check=True)
    os.environ["PKM_MUJOCO_VENV_TRIED"] = "1"
    os.execv(str(python), [str(python), __file__, *sys.argv[1:]])


bootstrap()

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

EXACT_TOL = 1e-9
# The servo's share of the force in (b). Semi-implicit Euler is first order:
# its velocities lag the motion's, and the forces they need differ from the
# exact ones by O(dt) (measured: 1.4e-4 for the four-bar at dt = 1e-4 s,
# 3.5e-5 at dt = 2.5e-5 s). The two fast full crank turns show that; the
# slower punch and seed 000 stay near 1e-6.
SERVO_TOL = {"four_bar": 1e-3, "slider_crank": 1e-3, "seed003_punch": 1e-5, "seed000_a": 1e-5}

# Masses of this test's own, added to the examples that have none. The
# slider-crank's crank is massless (the export's stand-in mass), and so is
# seed 000's cross (the link between R3 and R4).
EXTRA = {
    "four_bar": """
    units { length = mm; mass = kg; }
    masses {
        crank   { mass = 0.12; centroid = (l1 / 2, 0); inertia = 0.12 * l1^2 / 12; }
        coupler { mass = 0.25; centroid = (l2 / 2, 15); inertia = 0.25 * l2^2 / 12; }
        rocker  { mass = 0.2; centroid = (l3 / 2, -5); inertia = 0.2 * l3^2 / 12; }
    }
""",
    "slider_crank": """
    units { length = mm; mass = kg; }
    masses {
        massless crank;
        rod    { mass = 0.15; centroid = (l / 3, 4); inertia = 0.15 * l^2 / 12; }
        slider { mass = 0.3; centroid = (0, 0); }
    }
    gravity (0, -9.81);
""",
    "seed000_a": """
    units { length = mm; mass = kg; }
    masses {
        s1 { mass = 0.057; centroid = (0, 0, 40); inertia = (10, 12, 5); }
        c1 { mass = 0.072; centroid = (90, 3, 1); inertia = (117, 291, 181); }
        c2 { mass = 0.070; centroid = (100, -2, 0); inertia = (113, 276, 173, 4, -2, 1); }
        s2 { mass = 0.057; centroid = (0, 0, 50); inertia = (10, 12, 5); }
        massless cross;
        platform { mass = 0.494; centroid = (0, l3 / 2, 4); inertia = (7162, 1188, 7106); }
        pc { mass = 0.106; centroid = (0, 0, 5); inertia = (913, 706, 358); }
        r5 { mass = 0.03; centroid = (0, 0, 10); inertia = (2, 2, 1); }
        s3 { mass = 0.067; centroid = (0, 0, 30); inertia = (10, 12, 5); }
    }
""",
    "seed003_punch": "",
}

PUNCH_CHANGE_POINTS = (154.5189, 234.6346)  # degrees of crank angle (docs/dynamics.md)


def pkm_binary():
    given = os.environ.get("PKM")
    if given:
        return given
    binary = ROOT / "target" / "release" / "pkm"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "pkm-cli"], cwd=ROOT, check=True)
    return str(binary)


PKM = pkm_binary()
WORK = Path(tempfile.mkdtemp(prefix="pkm-mujoco-"))


def pkm(*args):
    out = subprocess.run([PKM, *args, "--json"], capture_output=True, text=True)
    answer = json.loads(out.stdout)
    assert out.returncode == 0, f"pkm {' '.join(args)}: {answer}"
    return answer


def fixture(stem):
    """The example with the test's masses, as a file (the example itself if it has its own)."""
    text = (ROOT / "examples" / "mechanisms" / f"{stem}.pkm").read_text()
    extra = EXTRA[stem]
    if extra and "units" not in text:
        end = text.rindex("}")
        text = text[:end] + extra + "}\n"
    path = WORK / f"{stem}.pkm"
    path.write_text(text)
    return str(path)


def full_mass_matrix(m, d):
    """The dense mass matrix (MuJoCo 3 takes the sparse one, 4 the data)."""
    M = np.zeros((m.nv, m.nv))
    if hasattr(d, "qM"):
        mujoco.mj_fullM(m, M, d.qM)
    else:
        mujoco.mj_fullM(m, d, M)
    return M


class Exported:
    """A mechanism's MJCF loaded in MuJoCo, and how its joints map to pkm's."""

    def __init__(self, path, *args):
        info = pkm("export", path, "--mjcf", *args)
        self.info = info
        self.model = mujoco.MjModel.from_xml_string(info["mjcf"])
        self.model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.map = []  # (qpos address, dof address, pkm joint, scale)
        for name, j in info["joints"].items():
            assert j["type"] in ("hinge", "slide"), f"{name}: a ball joint is not exercised here"
            k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
            self.map.append((m.jnt_qposadr[k], m.jnt_dofadr[k], j["pkm"], j["scale"]))
        assert len(self.map) == m.nq == m.nv
        self.hinge = np.array([m.jnt_type[m.dof_jntid[k]] == mujoco.mjtJoint.mjJNT_HINGE for k in range(m.nv)])
        # The motors: each drives one joint's dof with gear 1.
        self.actuators = []  # (pkm name, dof address, MuJoCo force -> pkm unit)
        for name, a in info["actuators"].items():
            k = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
            assert m.actuator_gear[k][0] == 1.0
            self.actuators.append((name, m.jnt_dofadr[m.actuator_trnid[k][0]], a["to_pkm"]))
        self.stand_ins = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, b) for b in info["stand_in"]["bodies"]]

    def state(self, motion):
        """qpos, qvel, qacc of pkm's values, rates and accelerations (by joint name)."""
        q, v, a = (np.zeros(self.model.nv) for _ in range(3))
        for qadr, dadr, name, scale in self.map:
            q[qadr] = scale * motion["values"][name]
            v[dadr] = scale * motion["rates"][name]
            a[dadr] = scale * motion["accelerations"][name]
        return q, v, a

    def forces(self, q, v, a, model=None):
        """τ (pkm's units) by [Sᵀ Jᵀ][τ; λ] = M q̈ + b, and how well the state closes the loops."""
        m = model or self.model
        d = mujoco.MjData(m)
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_forward(m, d)
        M = full_mass_matrix(m, d)
        rhs = M @ a + d.qfrc_bias
        eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        J = d.efc_J.reshape(d.nefc, m.nv)[eq]
        S = np.zeros((m.nv, len(self.actuators)))
        for i, (_, dof, _) in enumerate(self.actuators):
            S[dof, i] = 1.0
        A = np.hstack([S, J.T])
        x, *_ = np.linalg.lstsq(A, rhs, rcond=None)
        residual = np.abs(A @ x - rhs).max() / max(np.abs(rhs).max(), 1e-300)
        tau = np.array([x[i] * to_pkm for i, (_, _, to_pkm) in enumerate(self.actuators)])
        # The loops' gaps (m) and their rates (m/s, rad/s) at pkm's state.
        closure = max(np.abs(d.efc_pos[eq]).max(), np.abs(J @ v).max())
        return tau, residual, closure

    def distance(self, q1, q2):
        """The largest difference of two configurations, angles modulo 2π (pkm wraps them)."""
        e = q1 - q2
        e[self.hinge] = (e[self.hinge] + math.pi) % (2 * math.pi) - math.pi
        return np.abs(e).max()

    def without_stand_ins(self):
        """The same model with the stand-in masses and inertias at zero."""
        m = mujoco.MjModel.from_xml_string(self.info["mjcf"])
        m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        for b in self.stand_ins:
            m.body_mass[b] = 0.0
            m.body_inertia[b] = 0.0
        return m


def random_inputs(stem, rng, start):
    """One random state of the inputs: values, rates, accelerations (file units)."""
    n = len(start)
    if stem == "seed000_a":
        q = np.array(start) + rng.uniform(-30, 30, n)
        return q, rng.uniform(-300, 300, n), rng.uniform(-3000, 3000, n)
    while True:
        q = rng.uniform(-math.pi, math.pi, n)
        degrees = math.degrees(q[0]) % 360
        # The punch's change points: a few degrees away.
        if stem != "seed003_punch" or all(abs(degrees - c) > 3 for c in PUNCH_CHANGE_POINTS):
            break
    return q, rng.uniform(-3, 3, n), rng.uniform(-20, 20, n)


def exact(stem, rng, count=40):
    path = fixture(stem)
    ex = Exported(path)
    start = list(ex.info["inputs"].values())
    names = [a[0] for a in ex.actuators]
    worst, stand_in, overall, states, pairs = 0.0, 0.0, 0.0, 0, 0
    # The mechanism as declared: its massless links without mass (MuJoCo's
    # M q̈ + b is fine with them; only its forward dynamics needs the stand-ins).
    bare = ex.without_stand_ins()
    lines = []
    for _ in range(count):
        q, qd, qdd = random_inputs(stem, rng, start)
        lines.append(",".join(repr(float(x)) for x in [*q, *qd, *qdd]))
    states_file = WORK / f"{stem}.states"
    states_file.write_text("\n".join(lines) + "\n")
    answer = pkm("dynamics", path, "--states", str(states_file))
    for state in answer["states"]:
        ok = [b for b in state.get("branches", []) if b["ok"]]
        if not ok:
            continue
        states += 1
        for b in ok:
            pairs += 1
            q, v, a = ex.state(b["motion"])
            tau, residual, closure = ex.forces(q, v, a, bare)
            assert residual < 1e-12, f"{stem}: the least-squares system is not consistent ({residual:e})"
            assert closure < 1e-9, f"{stem}: pkm's state does not close MuJoCo's loops ({closure:e})"
            ours = np.array([b["actuators"][n] for n in names])
            peak = np.abs(tau).max()
            worst = max(worst, np.abs(ours - tau).max() / peak)
            # The exported model's stand-ins, against the largest force of all states.
            tau_exported, _, _ = ex.forces(q, v, a)
            stand_in = max(stand_in, np.abs(tau_exported - tau).max())
            overall = max(overall, peak)
    stand_in /= overall
    print(
        f"(a) {stem}: {states} input states, {pairs} (state, branch) pairs; worst |τ_pkm − τ_MuJoCo| / max|τ_MuJoCo| "
        f"= {worst:.2e}; the exported stand-in masses change τ by {stand_in:.2e} of the largest τ"
    )
    assert states >= 36, f"{stem}: only {states} states solved"
    assert worst < EXACT_TOL, f"{stem}: pkm and MuJoCo differ by {worst:e}"
    assert stand_in < EXACT_TOL
    return worst, states, pairs


# The trajectories of (b): from rest to rest, q(t) = start + travel·(t/T −
# sin(2πt/T)/2π), whose speed and acceleration both start and end at zero.
TRAVEL = {
    # A full crank turn in a second.
    "four_bar": [2 * math.pi],
    "slider_crank": [2 * math.pi],
    # 165° to 225°: at least 9.6° from either change point.
    "seed003_punch": [math.radians(60)],
    # Along the study's sine amplitudes, from its start (mm).
    "seed000_a": [20, -10, 20],
}
START = {"four_bar": [0.3], "slider_crank": [0.3], "seed003_punch": [math.radians(165)]}


def in_time(stem, dt=1e-4, duration=1.0, settle=0.1):
    path = fixture(stem)
    start = START.get(stem) or list(Exported(path).info["inputs"].values())
    start, travel = np.array(start, dtype=float), np.array(TRAVEL[stem], dtype=float)
    w = 2 * math.pi / duration

    def inputs(t):
        t = max(t, 0.0)
        return (
            start + travel * (t / duration - math.sin(w * t) / (2 * math.pi)),
            travel / duration * (1 - math.cos(w * t)),
            travel / duration * w * math.sin(w * t),
        )

    ex = Exported(path, "--q=" + ",".join(repr(float(x)) for x in start), f"--timestep={dt}")
    m, d = ex.model, ex.data
    # Semi-implicit Euler (RK4's held motor input lags within its stages).
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    held, steps = int(round(settle / dt)), int(round(duration / dt))
    # First held still at the start (the loop constraints' small stretch
    # under the static load settles in), then moved: its times from −settle.
    times = [(k - held) * dt for k in range(held + steps)]
    # Semi-implicit Euler's velocity at step k is (q_k − q_{k−1})/dt: the
    # velocity half a step earlier, to second order. pkm is given that.
    def state(t):
        q, _, qdd = inputs(t)
        return np.concatenate([q, inputs(t - dt / 2)[1], qdd])

    lines = [",".join(repr(float(x)) for x in state(t)) for t in times]
    states_file = WORK / f"{stem}.trajectory"
    states_file.write_text("\n".join(lines) + "\n")
    answer = pkm("dynamics", path, "--states", str(states_file))
    # Follow the exported branch by continuity of the joint values.
    names = [a[0] for a in ex.actuators]
    to_si = np.array([1 / a[2] for a in ex.actuators])
    dofs = [a[1] for a in ex.actuators]
    previous = None
    plan = []
    for k, state in enumerate(answer["states"]):
        ok = [b for b in state.get("branches", []) if b["ok"]]
        assert ok, f"{stem}: no dynamics at t = {times[k]}: {state}"
        if previous is None:
            signs = ["-" if ex.info["branch"] >> i & 1 else "+" for i in range(len(ok[0]["signs"]))]
            pick = next(b for b in ok if b["signs"] == signs)
        else:
            pick = min(ok, key=lambda b: ex.distance(ex.state(b["motion"])[0], previous))
        previous = ex.state(pick["motion"])[0]
        plan.append((np.array([pick["actuators"][n] for n in names]) * to_si, ex.state(pick["motion"])))
    q0, v0, _ = plan[0][1]
    d.qpos[:], d.qvel[:] = q0, v0
    mujoco.mj_forward(m, d)
    # A weak servo: natural frequency 5 Hz, critically damped, on the dof's own inertia.
    M = full_mass_matrix(m, d)
    inertia = np.array([M[k, k] for k in dofs])
    kp, kd = inertia * (2 * math.pi * 5) ** 2, inertia * 2 * (2 * math.pi * 5)
    peak, servo_peak, drift = 0.0, 0.0, 0.0
    for k in range(held + steps):
        if k == held:
            # Settled: the motion starts from rest.
            d.qvel[:] = 0.0
        tau, (q_ref, v_ref, _) = plan[k]
        # The inputs' references are pkm's inputs as given, not wrapped.
        e, ed = q_ref[dofs] - d.qpos[dofs], v_ref[dofs] - d.qvel[dofs]
        servo = kp * e + kd * ed
        d.ctrl[:] = tau + servo
        if k >= held:
            peak = max(peak, np.abs(tau).max())
            servo_peak = max(servo_peak, np.abs(servo).max())
            drift = max(drift, np.abs(e).max())
        mujoco.mj_step(m, d)
    share = servo_peak / peak
    print(
        f"(b) {stem}: {steps} steps of {dt} s after {held} held; the servo's largest force is {share:.2e} of the "
        f"motors' largest; the inputs stray at most {drift:.2e} (rad or m) from the trajectory"
    )
    assert share < SERVO_TOL[stem], f"{stem}: the servo carries {share:e} of the force"
    return share


def main():
    rng = np.random.default_rng(12)
    # Arguments: mechanisms to check (all by default), `--exact` or `--in-time` for one part.
    args = sys.argv[1:]
    stems = [a for a in args if not a.startswith("--")] or ["four_bar", "slider_crank", "seed003_punch", "seed000_a"]
    for stem in stems if "--in-time" not in args else []:
        exact(stem, rng)
    for stem in stems if "--exact" not in args else []:
        in_time(stem)
    print("pkm agrees with MuJoCo")


if __name__ == "__main__":
    main()
