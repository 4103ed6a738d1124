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
    forward simulation (MuJoCo's forward dynamics integrated by RK4, each
    stage's input pkm's force at that stage's time; the loop constraints'
    time constant 2 ms), with a weak servo holding the trajectory. A control run
    feeds MuJoCo's own forces of (a) at the same states instead: the
    servo's force with pkm's must equal the control's to 1e-9 of the
    largest motor force, and the control's largest servo force (the
    integration's share) must stay below 5e-7 of it. `--euler` runs mj_step
    (semi-implicit Euler) instead, whose first-order error is larger.

Run: python3 tests/mujoco/test_mujoco.py (from anywhere). Without `mujoco`
importable, it makes a venv under target/ and installs it there with pip.
The pkm binary is $PKM, else target/release/pkm (built if missing).
"""

import json
import math
import re
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


def fixture(stem, simulated=False):
    """The example with the test's masses, as a file (the example itself if it has its own).

    simulated: its massless links given a light body (20 g, 20 kg·mm² in a
    file in mm), as (b) needs. MuJoCo's forward dynamics of a body with the
    export's 1e-11 stand-in mass is so stiff that explicit steps diverge
    (seed 000 A, whose cross link and parallelogram sides are massless, leaves
    twice the motors' force to the servo, with MuJoCo's own forces too);
    pkm reads the same file, so both sides have the light bodies.
    """
    text = (ROOT / "examples" / "mechanisms" / f"{stem}.pkm").read_text()
    extra = EXTRA[stem]
    if extra and "units" not in text:
        end = text.rindex("}")
        text = text[:end] + extra + "}\n"
    if simulated:
        light = "centroid = (0, 0); inertia = 20;" if "planar;" in text else "centroid = (0, 0, 0); inertia = (20, 20, 20);"
        text = re.sub(
            r"massless ([^;]*);",
            lambda g: " ".join(f"{name.strip()} {{ mass = 0.02; {light} }}" for name in g.group(1).split(",")),
            text,
        )
    path = WORK / (f"{stem}.simulated.pkm" if simulated else f"{stem}.pkm")
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
        self.scratch = {}
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
        # The file's loads, which MJCF cannot hold: (body, point in its frame, force, moment), SI.
        self.loads = [
            (mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, p["body"]), *(np.array(p[k]) for k in ("point", "force", "moment")))
            for p in info["loads"]
        ]

    def load_forces(self, m, d):
        """The loads' generalized forces at d's positions (its kinematics computed)."""
        out = np.zeros(m.nv)
        for body, point, force, moment in self.loads:
            at = d.xpos[body] + d.xmat[body].reshape(3, 3) @ point
            mujoco.mj_applyFT(m, d, force, moment, at, body, out)
        return out

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
        # One scratch MjData per model: making one per state is most of the time.
        if id(m) not in self.scratch:
            self.scratch[id(m)] = (m, mujoco.MjData(m))
        d = self.scratch[id(m)][1]
        d.qpos[:], d.qvel[:] = q, v
        mujoco.mj_forward(m, d)
        M = full_mass_matrix(m, d)
        rhs = M @ a + d.qfrc_bias - self.load_forces(m, d)
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

# (b) integrates MuJoCo's forward dynamics (mj_forward's qacc) by classical
# RK4, each stage's motor input pkm's force at that stage's time, so that the
# forces are exact where the integrator uses them. Its step: 0.1 ms for the
# fast crank turns (0.2 ms leaves 1.8e-6 of the force to the servo), 0.2 ms
# for the punch (0.4 ms: 2.2e-7), 0.4 ms for seed 000 A, whose share (5e-8)
# is the same at 0.2 ms and whose many branches make pkm's states costly.
STEP = {"four_bar": 1e-4, "slider_crank": 1e-4, "seed003_punch": 2e-4, "seed000_a": 4e-4}
# The exported timestep only sets the loops' time constant (2 timesteps): at
# 1 ms the constraint's own motion is slow enough for RK4 at these steps
# (at 0.1 ms it is as fast as the step, and the four-bar's share is 7.6e-5).
MODEL_TIMESTEP = 1e-3
# With --euler: mj_step's semi-implicit Euler (implicitfast) at this step.
EULER_STEP = 1e-4
# The control run's share (MuJoCo's own inverse dynamics as the motors'
# input) is the integration's; pkm's must match it, and it must stay small.
# Seed 000 A with the paper's masses, its parallelogram bar and the 50 N
# payload leaves 7.0e-7 to the servo at 0.4 and at 0.2 ms alike: not the
# steps' error but the loops' and the bar's soft equality constraints
# stretching under the load (its light stand-in bodies of `fixture` at 5 g
# left 2.9e-6). pkm's forces and MuJoCo's leave the same share to 1e-12.
CONTROL_TOL = {"four_bar": 5e-7, "slider_crank": 5e-7, "seed003_punch": 1e-7, "seed000_a": 1e-6}
# The largest difference of pkm's servo force from the control's, over the
# motion, relative to the largest motor force (the exact part's tolerance).
SAME_TOL = 1e-9


def simulate(ex, plan, taus, held, step, euler):
    """The servo's force at each step of the motion, under the motor inputs taus.

    plan[j] is (q, v, a) at the j-th time of the inputs' grid: every step for
    --euler, every half step for RK4 (its stages' times).
    """
    m, d = ex.model, ex.data
    dofs = [a[1] for a in ex.actuators]
    mujoco.mj_resetData(m, d)
    q, v = plan[0][0].copy(), plan[0][1].copy()
    d.qpos[:], d.qvel[:] = q, v
    mujoco.mj_forward(m, d)
    # A weak servo: natural frequency 5 Hz, critically damped, on the dof's own inertia.
    M = full_mass_matrix(m, d)
    inertia = np.array([M[k, k] for k in dofs])
    kp, kd = inertia * (2 * math.pi * 5) ** 2, inertia * 2 * (2 * math.pi * 5)

    def servo(q, v, j):
        # The inputs' references are pkm's inputs as given, not wrapped.
        q_ref, v_ref, _ = plan[j]
        return kp * (q_ref[dofs] - q[dofs]) + kd * (v_ref[dofs] - v[dofs])

    def loaded(q, v):
        # The file's loads at these positions, as applied forces.
        d.qpos[:], d.qvel[:] = q, v
        if ex.loads:
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            d.qfrc_applied[:] = ex.load_forces(m, d)

    def qacc(q, v, j):
        loaded(q, v)
        d.ctrl[:] = taus[j] + servo(q, v, j)
        mujoco.mj_forward(m, d)
        return d.qacc.copy()

    out, stray = [], 0.0
    for k in range(len(taus) // (1 if euler else 2)):
        j = k if euler else 2 * k
        if k >= held:
            out.append(servo(q, v, j))
            stray = max(stray, np.abs(plan[j][0][dofs] - q[dofs]).max())
        if euler:
            loaded(q, v)
            d.ctrl[:] = taus[j] + servo(q, v, j)
            mujoco.mj_step(m, d)
            q, v = d.qpos.copy(), d.qvel.copy()
            continue
        # Hinges and slides only: qpos adds like qvel.
        a1 = qacc(q, v, j)
        v2 = v + step / 2 * a1
        a2 = qacc(q + step / 2 * v, v2, j + 1)
        v3 = v + step / 2 * a2
        a3 = qacc(q + step / 2 * v2, v3, j + 1)
        v4 = v + step * a3
        a4 = qacc(q + step * v3, v4, j + 2)
        q = q + step / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + step / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    return np.array(out), stray


def in_time(stem, euler=False, duration=1.0, settle=0.1):
    path = fixture(stem, simulated=True)
    start = START.get(stem) or list(Exported(path).info["inputs"].values())
    start, travel = np.array(start, dtype=float), np.array(TRAVEL[stem], dtype=float)
    w = 2 * math.pi / duration

    def inputs(t):
        t = min(max(t, 0.0), duration)
        return (
            start + travel * (t / duration - math.sin(w * t) / (2 * math.pi)),
            travel / duration * (1 - math.cos(w * t)),
            travel / duration * w * math.sin(w * t),
        )

    step = EULER_STEP if euler else STEP[stem]
    ex = Exported(path, "--q=" + ",".join(repr(float(x)) for x in start), f"--timestep={step if euler else MODEL_TIMESTEP}")
    m = ex.model
    # Semi-implicit Euler (mj_step's implicitfast is the same here: nothing
    # depends on the velocity but the bias forces, which it keeps explicit).
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    held, steps = int(round(settle / step)), int(round(duration / step))
    # First held still at the start (the loop constraints' small stretch
    # under the static load settles in), then moved: its times from −settle.
    if euler:
        times = [(k - held) * step for k in range(held + steps)]
    else:
        times = [(k - 2 * held) * step / 2 for k in range(2 * (held + steps) + 1)]

    def state(t):
        q, qd, qdd = inputs(t)
        if euler:
            # Semi-implicit Euler's velocity at step k is (q_k − q_{k−1})/dt:
            # the velocity half a step earlier, to second order.
            qd = inputs(t - step / 2)[1]
        return np.concatenate([q, qd, qdd])

    lines = [",".join(repr(float(x)) for x in state(t)) for t in times]
    states_file = WORK / f"{stem}.trajectory"
    states_file.write_text("\n".join(lines) + "\n")
    answer = pkm("dynamics", path, "--states", str(states_file))
    # Follow the exported branch by continuity of the joint values.
    names = [a[0] for a in ex.actuators]
    to_si = np.array([1 / a[2] for a in ex.actuators])
    previous = None
    plan, ours, control, closure = [], [], [], 0.0
    for k, state in enumerate(answer["states"]):
        ok = [b for b in state.get("branches", []) if b["ok"]]
        assert ok, f"{stem}: no dynamics at t = {times[k]}: {state}"
        if previous is None:
            signs = ["-" if ex.info["branch"] >> i & 1 else "+" for i in range(len(ok[0]["signs"]))]
            pick = next(b for b in ok if b["signs"] == signs)
        else:
            pick = min(ok, key=lambda b: ex.distance(ex.state(b["motion"])[0], previous))
        qva = ex.state(pick["motion"])
        previous = qva[0]
        plan.append(qva)
        ours.append(np.array([pick["actuators"][n] for n in names]) * to_si)
        # The control: MuJoCo's inverse dynamics of (a) at the same state.
        tau, _, gap = ex.forces(*qva)
        control.append(tau * to_si)
        closure = max(closure, gap)
    assert closure < 1e-9, f"{stem}: the trajectory does not close MuJoCo's loops ({closure:e})"
    peak = np.abs(np.array(ours)).max()
    servo, stray = simulate(ex, plan, ours, held, step, euler)
    servo_control, stray_control = simulate(ex, plan, control, held, step, euler)
    share, share_control = np.abs(servo).max() / peak, np.abs(servo_control).max() / peak
    same = np.abs(servo - servo_control).max() / peak
    how = f"{'semi-implicit Euler' if euler else 'RK4'}, {steps} steps of {step} s after {held} held"
    print(
        f"(b) {stem}: {how}; the servo's largest force is {share:.3e} of the motors' largest with pkm's "
        f"forces, {share_control:.3e} with MuJoCo's (they differ by {same:.1e}); the inputs stray at most "
        f"{stray:.1e} and {stray_control:.1e} (rad or m)"
    )
    assert same < SAME_TOL, f"{stem}: pkm's servo force differs from the control's by {same:e}"
    # mj_step's first-order error: 1.4e-4 and 2.1e-4 for the crank turns.
    bound = 1e-3 if euler else CONTROL_TOL[stem]
    assert share_control < bound, f"{stem}: even MuJoCo's own forces leave {share_control:e}"
    assert share < bound, f"{stem}: the servo carries {share:e} of the force"
    return share, share_control


def main():
    rng = np.random.default_rng(12)
    # Arguments: mechanisms to check (all by default), `--exact` or `--in-time`
    # for one part, `--euler` for (b) by mj_step's semi-implicit Euler.
    args = sys.argv[1:]
    stems = [a for a in args if not a.startswith("--")] or ["four_bar", "slider_crank", "seed003_punch", "seed000_a"]
    for stem in stems if "--in-time" not in args else []:
        exact(stem, rng)
    for stem in stems if "--exact" not in args else []:
        in_time(stem, euler="--euler" in args)
    print("pkm agrees with MuJoCo")


if __name__ == "__main__":
    main()
