"""Benchmark the attitude stage for one day at 1 s (86,400 epochs).

Run: ``.venv/bin/python bench/bench_attitude.py [--ivp]``

Prints the best of several wall-clock timings per model, and, for the torque-free
cases, the relative drift of energy and inertial angular momentum over the day as a
sanity figure. ``--ivp`` also times the numerical reference path (tens of seconds).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

from speclight.attitude import (
    body_directions,
    fixed_attitude,
    quat_to_matrix,
    spin_attitude,
    torque_free_attitude,
)

N_EPOCHS = 86_400
T_S = np.arange(N_EPOCHS, dtype=np.float64)
INERTIA = np.array([1.0, 2.0, 3.0])
Q0 = np.array([0.8, 0.2, -0.4, 0.4]) / np.linalg.norm([0.8, 0.2, -0.4, 0.4])
TORQUE_FREE_CASES = {
    "slow 0.05 rad/s": np.array([0.03, 0.02, 0.035]),
    "fast 0.5 rad/s, L2>2EI2": np.array([0.05, 0.2, 0.45]),
    "fast 0.5 rad/s, L2<2EI2": np.array([0.45, 0.2, 0.05]),
    "near intermediate axis": np.array([0.005, 0.5, 0.005]),
}


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def drift(q: np.ndarray, omega: np.ndarray) -> tuple[float, float]:
    energy = np.sum(INERTIA * omega**2, axis=1)
    momentum = np.einsum("nij,nj->ni", quat_to_matrix(q), INERTIA * omega)
    e_drift = float(np.max(np.abs(energy / energy[0] - 1.0)))
    l_drift = float(np.max(np.linalg.norm(momentum - momentum[0], axis=1)))
    return e_drift, l_drift / float(np.linalg.norm(momentum[0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--ivp", action="store_true", help="also time method='ivp'")
    args = parser.parse_args()
    print(f"attitude benchmark, {N_EPOCHS} epochs (one day at 1 s)")
    print(f"fixed_attitude:            {best_of(lambda: fixed_attitude(N_EPOCHS, Q0)):8.4f} s")
    spin_time = best_of(lambda: spin_attitude(T_S, 30.0, 45.0, 12.0))
    print(f"spin_attitude:             {spin_time:8.4f} s")
    q_spin = spin_attitude(T_S, 30.0, 45.0, 12.0)
    rng = np.random.default_rng(0)
    sun, obs = rng.normal(size=(N_EPOCHS, 3)), rng.normal(size=(N_EPOCHS, 3))
    print(f"body_directions:           {best_of(lambda: body_directions(q_spin, sun, obs)):8.4f} s")
    methods = ["analytic", "ivp"] if args.ivp else ["analytic"]
    results: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for method in methods:
        for name, omega0 in TORQUE_FREE_CASES.items():
            repeat = 3 if method == "analytic" else 1

            def run(omega0: np.ndarray = omega0, method: str = method) -> object:
                return torque_free_attitude(T_S, INERTIA, Q0, omega0, method=method)  # type: ignore[arg-type]

            elapsed = best_of(run, repeat)
            q, omega = torque_free_attitude(T_S, INERTIA, Q0, omega0, method=method)  # type: ignore[arg-type]
            e_drift, l_drift = drift(q, omega)
            line = (
                f"torque_free[{method}] {name:26s} {elapsed:8.4f} s   "
                f"max |dE/E| {e_drift:.1e}  max |dL|/|L| {l_drift:.1e}"
            )
            if method == "ivp":
                q_a, omega_a = results[name]
                d_omega = np.max(np.abs(omega - omega_a))
                d_att = np.max(np.abs(quat_to_matrix(q) - quat_to_matrix(q_a)))
                line += f"  vs analytic: |dω| {d_omega:.1e} rad/s, |dR| {d_att:.1e}"
            results[name] = (q, omega)
            print(line)


if __name__ == "__main__":
    main()
