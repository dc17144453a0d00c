"""Analytic derivatives of the PUMA 560 dynamics against Pinocchio, measured in the same run.

robodyn: ``model.inverse_dynamics_derivatives`` (d tau/dq, d tau/dqd) and
``model.forward_dynamics_derivatives`` (d qdd/dq, d qdd/dqd, d qdd/dtau) on a batch of states,
one C call each, one thread. Pinocchio: ``computeRNEADerivatives`` / ``computeABADerivatives``
called once per state from a Python loop (Pinocchio has no batched ``*InParallel`` variant of
its derivatives; the installed version's names are checked and printed). The Python loop's own
cost per call is measured around a no-op and printed: it is part of the "loop" ratio, and the
"minus loop" ratio removes it.

Not identical work, said in the output: robodyn's tau includes the PUMA description's joint
friction (viscous in d tau/dqd; the Coulomb step's derivative is 0 away from qd = 0, but its
value enters qdd = FD(q, qd, tau) where the forward derivatives are evaluated); Pinocchio has
none. Both include the reflected rotor inertia (Pinocchio's armature). robodyn also returns all
three forward derivatives as one array (views), Pinocchio as three matrices.

Target (issue 15): forward-dynamics derivatives at least 5x faster than computeABADerivatives.
Run: ``.venv/bin/python benchmarks/bench_derivatives.py [--quick]``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_simulation import pinocchio_puma  # noqa: E402 - sibling benchmark module
from peers import pinocchio_loop  # noqa: E402
from timing import best_of  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10,000 states instead of 100,000")
    args = parser.parse_args()
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    n_states = 10_000 if args.quick else 100_000
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, n_states, 6))
    t0 = time.perf_counter()
    model.inverse_dynamics_derivatives(q[:1], qd[:1], qdd[:1])  # generates/compiles on first use
    print(f"derivative kernels ready in {time.perf_counter() - t0:.1f} s (generated and compiled "
          "on first use, then cached)")
    tau = model.inverse_dynamics(q, qd, qdd)
    ours = {
        "RNEA derivatives": best_of(lambda: model.inverse_dynamics_derivatives(q, qd, qdd)),
        "ABA derivatives": best_of(lambda: model.forward_dynamics_derivatives(q, qd, tau)),
        "(inverse dynamics)": best_of(lambda: model.inverse_dynamics(q, qd, qdd)),
        "(forward dynamics)": best_of(lambda: model.forward_dynamics(q, qd, tau)),
    }

    pmodel, source = pinocchio_puma(robot)
    pdata = pmodel.createData()
    # same model? d tau/dq equal; d tau/dqd differs by robodyn's viscous friction on the diagonal
    fv = np.diag(model.inverse_dynamics_derivatives(q[0], np.full(6, 1e-3), qdd[0])[1]
                 + model.inverse_dynamics_derivatives(q[0], np.full(6, -1e-3), qdd[0])[1]) / 2
    dq_err = dqd_err = 0.0
    for k in range(20):
        rq, rv, _ = pin.computeRNEADerivatives(pmodel, pdata, q[k], qd[k], qdd[k])
        dq, dqd = model.inverse_dynamics_derivatives(q[k], qd[k], qdd[k])
        dq_err = max(dq_err, np.max(np.abs(dq - rq)))
        dqd_err = max(dqd_err, np.max(np.abs(dqd - np.diag(fv) - rv)))
    print(f"Pinocchio {pin.__version__} model: {source}; max |dtau/dq - pin| = {dq_err:.1e}, "
          f"max |dtau/dqd - diag(Fv) - pin| = {dqd_err:.1e} (Fv = robodyn's viscous friction)")
    loops = min(n_states, 20_000)

    def loop(fn, *arrays):
        return pinocchio_loop(fn, pmodel, pdata, loops, *arrays)

    def nothing(_model, _data, *_states):
        return None

    theirs = {
        "RNEA derivatives": best_of(loop(pin.computeRNEADerivatives, q, qd, qdd), 3),
        "ABA derivatives": best_of(loop(pin.computeABADerivatives, q, qd, tau), 3),
        "(inverse dynamics)": best_of(loop(pin.rnea, q, qd, qdd), 3),
        "(forward dynamics)": best_of(loop(pin.aba, q, qd, tau), 3),
    }
    overhead = best_of(loop(nothing, q, qd, qdd), 3) / loops
    parallel = [n for n in dir(pin) if n.endswith("InParallel")]
    print(f"Pinocchio batched functions available: {', '.join(parallel) or 'none'} "
          "(no derivatives among them: the derivatives are looped from Python)")
    print(f"robodyn: {n_states} states per call, one thread, C -O3 -march=native, friction "
          "included; Pinocchio: installed wheel, looped over "
          f"{loops} states, rigid body + armature, no friction")
    print(f"Python loop alone: {overhead * 1e9:.0f} ns per call (measured around a no-op)")
    print(f"{'kernel':22s}{'robodyn ns':>11s}{'pin loop ns':>13s}{'loop ratio':>12s}"
          f"{'minus loop':>12s}")
    for name, t in ours.items():
        ns = t / n_states * 1e9
        pl = theirs[name] / loops * 1e9
        bare = pl - overhead * 1e9
        print(f"{name:22s}{ns:11.0f}{pl:13.0f}{pl / ns:11.1f}x{bare / ns:11.1f}x")
    ratio = (theirs["ABA derivatives"] / loops - overhead) / (ours["ABA derivatives"] / n_states)
    print(f"forward-dynamics derivatives vs computeABADerivatives without the Python loop: "
          f"{ratio:.1f}x (target >= 5x): {'met' if ratio >= 5 else 'NOT met'}")


if __name__ == "__main__":
    main()
