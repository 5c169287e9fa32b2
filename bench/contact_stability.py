"""Benchmark: stability on contacts at many heights (snakehead.dynamics.contact_set, equilibrium_region,
wrench_balance) for 4, 10, 20 and 40 contacts. Prints tables (best of repeated runs, wall-clock). Not a test.

* The contact wrench cone's face form: pycddlib's double description (the library's ``contact_wrench_cone``), pypoman's
  ``compute_cone_face_matrix`` (the same cddlib, through pypoman) and Qhull (scipy's ConvexHull of the edges and the
  apex, the facets through the apex): time, faces, the largest A S (> 0: an edge outside the face form) and the
  verdicts that differ from the span form's LP on random wrenches; and the collinear (lower-dimensional) case.
* The static-equilibrium region: the library's Bretl-Lall (HiGHS LPs) against pypoman's Bretl-Lall (cvxopt's GLPK
  LPs) and pypoman's cdd projection (double description of the lifted polytope; 4 contacts only): time, vertices, LPs
  and the largest distance of one's vertices to the other's polygon.
* One balance test: the face form's margin (A precomputed) against the span form's LP.

pypoman (and cvxopt) are optional here (``pip install pypoman``): their columns are left out without them.

    python3 bench/contact_stability.py [--repeat 3]
"""
from __future__ import annotations

import argparse
import os
import platform
import time
from typing import Any, Callable

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

import snakehead.dynamics.equilibrium_region as er
from snakehead.dynamics.contact_set import ContactSet, contact_wrench_cone, contact_wrench_span, flat_contacts
from snakehead.dynamics.wrench_balance import cwc_margin, gravito_inertial_wrench, is_balanced_lp

try:
    import pypoman
except ImportError:  # optional: the comparison columns
    pypoman = None

SIZES = (4, 10, 20, 40)
#: Most contacts of a region by pypoman's cdd projection (the lifted polytope's vertices: 22,260 with 4 contacts, 6 s).
CDD_PROJECTION_MAX = 4


def uneven(k: int, seed: int = 0) -> ContactSet:
    """k contacts over 1 m x 1 m, up to 0.2 m high, normals tilted up to ~30 degrees, mu 0.8."""
    rng = np.random.default_rng(seed + k)
    p = rng.uniform(-0.5, 0.5, (k, 3)) * [1, 1, 0.4]
    n = np.column_stack([rng.normal(0, 0.3, (k, 2)), np.ones(k)])
    return ContactSet(p, n, 0.8)


def flat(k: int, seed: int = 0) -> ContactSet:
    return flat_contacts(np.random.default_rng(seed + 100 + k).uniform(-0.5, 0.5, (k, 2)), 0.8)


def best(f: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """Best wall-clock time (s) of ``repeat`` calls, and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def qhull_faces(S: np.ndarray) -> np.ndarray:
    """Face form by Qhull: the hull of the apex and the unit edges, its facets through the apex."""
    pts = np.vstack([np.zeros(6), (S / np.linalg.norm(S, axis=0)).T])
    eq = ConvexHull(pts, qhull_options="Qt").equations
    A = eq[np.abs(eq[:, 6]) < 1e-9, :6]
    return np.unique(np.round(A / np.linalg.norm(A, axis=1)[:, None], 9), axis=0)


def pypoman_faces(S: np.ndarray) -> np.ndarray:
    A = pypoman.compute_cone_face_matrix(S)
    return A / np.linalg.norm(A, axis=1)[:, None]


def lp_disagreements(A: np.ndarray, S: np.ndarray, rng: np.random.Generator, n: int = 100) -> int:
    """Random wrenches (half near the cone) whose face-form verdict differs from the span form's LP."""
    bad = 0
    for i in range(n):
        lam = rng.exponential(1.0, S.shape[1]) * (rng.random(S.shape[1]) < 0.05)
        w = (S @ lam if i % 2 == 0 else rng.normal(0, 1, 6)) + rng.normal(0, 0.1, 6)
        res = linprog(np.zeros(S.shape[1]), A_eq=S, b_eq=w, bounds=(0, None), method="highs")
        slack = np.max(A @ w, initial=-np.inf)
        if abs(slack) > 1e-7 and (res.status == 0) != (slack < 0):
            bad += 1
    return bad


def cwc_table(repeat: int) -> None:
    methods: dict[str, Callable[[np.ndarray, ContactSet], np.ndarray]] = {
        "pycddlib (contact_wrench_cone)": lambda S, c: contact_wrench_cone(c), "Qhull (scipy)": lambda S, c: qhull_faces(S)}
    if pypoman is not None:
        methods["pypoman.compute_cone_face_matrix"] = lambda S, c: pypoman_faces(S)
    print("\n### Contact wrench cone, face form (8-edge cones)\n")
    print("| ground | contacts | method | time (ms) | faces | max A S | LP disagreements /100 |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for ground, make in (("uneven", uneven), ("flat", flat)):
        for k in SIZES:
            c = make(k)
            S = contact_wrench_span(c)
            for name, f in methods.items():
                try:
                    dt, A = best(lambda: f(S, c), repeat)
                except Exception as exc:  # a method that fails is a row of the table
                    print(f"| {ground} | {k} | {name} | fails: {type(exc).__name__} | | | |")
                    continue
                viol = float(np.max(A @ S))
                bad = lp_disagreements(A, S, np.random.default_rng(k))
                print(f"| {ground} | {k} | {name} | {dt * 1e3:.1f} | {len(A)} | {viol:.1e} | {bad} |")
    collinear_row(methods)


def collinear_row(methods: dict[str, Callable[[np.ndarray, ContactSet], np.ndarray]]) -> None:
    """Collinear contacts on flat ground: a 5-dimensional cone; tau_x = 0.1 N m about their line is not exertable."""
    c = flat_contacts([[0, 0], [1, 0], [2, 0]], 0.5)
    S = contact_wrench_span(c)
    w = np.array([0.0, 0.0, 1.0, 0.1, -1.0, 0.0])
    print("\nCollinear contacts (3 on a line, flat): is w = (0, 0, 1, 0.1, -1, 0) -- a moment about the line -- "
          "outside the face form (it is outside the cone)?\n")
    for name, f in methods.items():
        try:
            A = f(S, c)
            print(f"- {name}: {len(A)} faces, outside: {bool(np.max(A @ w) > 1e-9)}")
        except Exception as exc:
            print(f"- {name}: fails ({type(exc).__name__}: {str(exc).splitlines()[0][:80]})")


def pypoman_region(c: ContactSet, method: str) -> np.ndarray:
    """The region by pypoman's projection of {(lambda, x, y)} (the library's LP, written as pypoman's input)."""
    lp = er._SupportLP(c, er.REGION_RADIUS)
    n = lp.A_eq.shape[1]
    box = np.zeros((4, n))
    box[0, -2], box[1, -2], box[2, -1], box[3, -1] = 1.0, -1.0, 1.0, -1.0  # the CoM in the square, as ours
    ineq = (np.vstack([np.hstack([-np.eye(n - 2), np.zeros((n - 2, 2))]), box]),
            np.r_[np.zeros(n - 2), np.full(4, er.REGION_RADIUS)])
    E = np.zeros((2, n))
    E[0, -2] = E[1, -1] = 1.0
    verts = pypoman.project_polytope((E, lp.centre[:2].copy()), ineq, (lp.A_eq, lp.b_eq), method=method)
    return np.array(verts)


def gap(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance (m) of a vertex of one polygon to the other polygon (0 when they are equal)."""
    return float(max(np.abs(er.region_margin(b, a)).max(), np.abs(er.region_margin(a, b)).max()))


def region_table(repeat: int) -> None:
    print("\n### Static-equilibrium region (uneven contacts, mu 0.8)\n")
    print("| contacts | method | time (ms) | vertices | LPs | max vertex distance to ours (m) |")
    print("|---:|---|---:|---:|---:|---:|")
    for k in SIZES:
        c = uneven(k)
        dt, region = best(lambda: er.static_equilibrium_region(c), repeat)
        print(f"| {k} | ours (Bretl-Lall, HiGHS) | {dt * 1e3:.1f} | {len(region.vertices)} | {region.lps} | 0 |")
        if pypoman is None:
            continue
        for method in ("bretl", "cdd") if k <= CDD_PROJECTION_MAX else ("bretl",):
            try:
                dt, verts = best(lambda: pypoman_region(c, method), 1 if method == "cdd" else repeat)
            except Exception as exc:  # a method that fails is a row of the table
                print(f"| {k} | pypoman {method} | fails: {type(exc).__name__} | | | |")
                continue
            poly = verts[ConvexHull(verts).vertices]  # counter-clockwise
            print(f"| {k} | pypoman {method} | {dt * 1e3:.1f} | {len(poly)} | | {gap(poly, region.vertices):.1e} |")


def balance_table(repeat: int) -> None:
    print("\n### One balance test (uneven contacts): face-form margin (A precomputed) vs span-form LP\n")
    print("| contacts | cwc_margin (us) | is_balanced_lp (ms) |")
    print("|---:|---:|---:|")
    w = gravito_inertial_wrench(3.2, [0.0, 0.0, 0.2], [0.3, -0.2, 0.1], [0.0, 0.1, 0.0])
    for k in SIZES:
        c = uneven(k)
        A = contact_wrench_cone(c)
        dt_m, _ = best(lambda: cwc_margin(A, w), max(repeat, 20))
        dt_lp, _ = best(lambda: is_balanced_lp(c, w), repeat)
        print(f"| {k} | {dt_m * 1e6:.1f} | {dt_lp * 1e3:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, python {platform.python_version()}")
    cwc_table(args.repeat)
    region_table(args.repeat)
    balance_table(args.repeat)


if __name__ == "__main__":
    main()
