#!/usr/bin/python3
"""Peer figure for bench/dynamics_bench.cpp: the seed-000 6-DOF spur pair (Drozdov friction,
back flank, speed-controlled motor) integrated with scipy.integrate.solve_ivp over the span the
C++ RK4 integrated, on one core.

The model is the one exported by `bench_dynamics --export FILE` (parameters, the pair-stiffness
table on MeshStiffness's grid, the friction table, the equilibrium state, right-hand-side samples
and the RK4 mesh-force trajectory). The right-hand side below is gearbox_model.cpp's
GearboxModel::derivatives for one healthy mesh (no pitch errors, no runout) in plain Python
floats (the state has 12 entries and at most 3 tooth pairs are in contact, too small for numpy
vectors to pay: one numpy call costs more than the whole scalar arithmetic).

Checks and figures printed:
  1. the right-hand side against the C++ one at the exported states (max relative difference);
  2. the same fixed-step RK4 as sim::Rk4 in Python (identical step): its mesh force against the
     C++ trajectory (round-off only) and its CPU time;
  3. solve_ivp RK45 (rtol, atol stated) over the span: mesh force against the C++ RK4 at the
     C++ step times (max difference, in N and relative to the static mesh force), accepted steps,
     right-hand-side evaluations, CPU time; both against a reference (RK45 at rtol 1e-12), so the
     ratio is quoted at stated accuracies (the default rtol 1e-10 makes scipy at least as accurate
     as the C++ RK4 at its production step);
  4. CPU time ratios C++ RK4 / scipy for the same simulated span.

Usage: /usr/bin/python3 bench/peer_dynamics.py MODEL.json [--rtol R] [--atol A] [--repeat N]
Run it under `taskset -c 0` with OMP_NUM_THREADS=1 etc. (as bench/run.sh does).
"""
import argparse
import json
import math
import os
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402


class PairModel:
    """GearboxModel::derivatives for one mesh, two gears, two shafts (6 DOFs)."""

    def __init__(self, m):
        self.n = m["dofs"]
        self.inv_mass = [1.0 / v for v in m["mass"]]
        self.a, self.b, self.xa, self.xb = m["driver"], m["driven"], m["xa"], m["xb"]
        self.rba, self.rbb, self.ra = m["rba"], m["rbb"], m["ra"]
        self.nx, self.ny, self.tx, self.ty = m["nx"], m["ny"], m["tx"], m["ty"]
        self.pitch_a = 2 * math.pi / m["za"]
        self.inv_pitch_a = 1.0 / self.pitch_a
        self.s_start, self.s_end, self.s_pitch = m["s_start"], m["s_end"], m["s_pitch"]
        self.pb, self.loa = m["base_pitch"], m["loa"]
        self.k_table = list(m["k_table"])
        self.k_last = len(self.k_table) - 1
        self.k_inv_ds = self.k_last / (self.s_end - self.s_start)
        self.mu = list(m["mu_table"])
        self.mu_last = len(self.mu) - 1
        self.mu_inv_ds = self.mu_last / (self.s_end - self.s_start)
        self.friction = m["friction_law"] != "none" and any(v > 0 for v in self.mu)
        self.c_z, self.inv_k_mean = m["c_z"], 1.0 / m["k_mean"]
        self.backlash, self.back_flank = m["backlash"], m["back_flank"]
        self.supports = [(x, m["bearing_kx"][x], m["bearing_ky"][x], m["bearing_cx"][x],
                          m["bearing_cy"][x]) for x in sorted({self.xa, self.xb})]
        self.in_gear, self.out_gear = m["input_gear"], m["output_gear"]
        self.k_c, self.c_c = m["coupling_k"], m["coupling_c"]
        self.t_load = m["load_torque"]
        self.omega = m["omega_in"]

    def pair_stiffness(self, s):
        x = (s - self.s_start) * self.k_inv_ds
        if not (-1e-3 <= x <= self.k_last + 1e-3):  # MeshStiffness::kEdgeCells
            return 0.0
        i = min(max(int(x), 0), self.k_last - 1)
        f = x - i
        return self.k_table[i] + f * (self.k_table[i + 1] - self.k_table[i])

    def mu_at(self, s):
        x = min(max((s - self.s_start) * self.mu_inv_ds, 0.0), self.mu_last - 1e-9)
        i = int(x)
        return self.mu[i] + (x - i) * (self.mu[i + 1] - self.mu[i])

    def mesh(self, t, q, v):
        """(force, friction, moment_a, moment_b) of the mesh."""
        a, b, xa, xb = self.a, self.b, self.xa, self.xb
        theta_a = self.ra * (self.omega * t) + q[a]
        delta = (self.rba * q[a] - self.rbb * q[b] + self.nx * (q[xa] - q[xb]) +
                 self.ny * (q[xa + 1] - q[xb + 1]))
        ddot = (self.rba * v[a] - self.rbb * v[b] + self.nx * (v[xa] - v[xb]) +
                self.ny * (v[xa + 1] - v[xb + 1]))
        cycles = math.floor(theta_a * self.inv_pitch_a)
        phase = theta_a - cycles * self.pitch_a
        force = fric = moment_a = moment_b = ksum = 0.0
        for k in range(3):
            s = self.s_start + self.rba * phase + k * self.pb
            if s > self.s_end:
                break
            kp = self.pair_stiffness(s)
            ksum += kp
            if not delta > 0.0:  # healthy teeth: no gap
                continue
            fi = kp * delta + self.c_z * kp * self.inv_k_mean * ddot
            if fi <= 0.0:
                continue
            force += fi
            if self.friction:
                sigma = -1.0 if s < self.s_pitch else (1.0 if s > self.s_pitch else 0.0)
                ff = sigma * self.mu_at(s) * fi
                fric += ff
                moment_a -= ff * s
                moment_b += ff * (self.loa - s)
        if self.back_flank and delta < -self.backlash:
            fb = ksum * (delta + self.backlash) + self.c_z * ddot
            if fb < 0.0:
                force += fb
        return force, fric, moment_a, moment_b

    def rhs_list(self, t, y):
        n = self.n
        q, v = y[:n], y[n:]
        f = [0.0] * n
        g = self.in_gear
        f[g] += -self.k_c * q[g] - self.c_c * v[g]
        f[self.out_gear] -= self.t_load
        for x, kx, ky, cx, cy in self.supports:
            f[x] -= kx * q[x] + cx * v[x]
            f[x + 1] -= ky * q[x + 1] + cy * v[x + 1]
        force, fric, moment_a, moment_b = self.mesh(t, q, v)
        a, b, xa, xb = self.a, self.b, self.xa, self.xb
        f[a] += -self.rba * force + moment_a
        f[b] += self.rbb * force + moment_b
        f[xa] += -force * self.nx - fric * self.tx
        f[xa + 1] += -force * self.ny - fric * self.ty
        f[xb] += force * self.nx + fric * self.tx
        f[xb + 1] += force * self.ny + fric * self.ty
        return list(v) + [fi * im for fi, im in zip(f, self.inv_mass)]

    def rhs(self, t, y):  # solve_ivp's interface: ndarray in, ndarray out
        return np.array(self.rhs_list(t, y.tolist()))

    def force(self, t, y):
        return self.mesh(t, y[:self.n], y[self.n:])[0]


def rk4(model, y0, h, steps):
    """sim::Rk4 in Python: the same stages and the same operation order."""
    y = list(y0)
    n2 = len(y)
    forces = [model.force(0.0, y)]
    f = model.rhs_list
    for i in range(steps):
        t = i * h
        k1 = f(t, y)
        k2 = f(t + 0.5 * h, [y[j] + 0.5 * h * k1[j] for j in range(n2)])
        k3 = f(t + 0.5 * h, [y[j] + 0.5 * h * k2[j] for j in range(n2)])
        k4 = f(t + h, [y[j] + h * k3[j] for j in range(n2)])
        h6 = h / 6.0
        y = [y[j] + h6 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]) for j in range(n2)]
        forces.append(model.force((i + 1) * h, y))
    return y, forces


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model", help="JSON written by bench_dynamics --export")
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--atol", type=float, default=1e-8,
                    help="times the static deflection scale (and x w_mesh for speeds)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="write the figures to this JSON file too")
    args = ap.parse_args()
    with open(args.model) as fh:
        m = json.load(fh)
    model = PairModel(m)
    n = model.n
    y0 = np.array(m["y0"])
    h, steps, span = m["step_s"], m["rk4_steps"], m["span_s"]
    cpp_t = np.array(m["trajectory"]["t"])
    cpp_force = np.array(m["trajectory"]["force"])
    f_static = m["input_torque"] / m["ra"] / m["rba"]
    out = {"scipy": scipy.__version__, "numpy": np.__version__, "span_s": span, "step_s": h,
           "cpp_rk4_steps": steps, "cpp_rk4_cpu_s": m["rk4_cpu_s"]}
    print(f"scipy {scipy.__version__} numpy {np.__version__}; seed-000 pair, span {span * 1e3:.3f}"
          f" ms, static mesh force {f_static:.1f} N")

    # 1. Right-hand side against C++.
    worst = 0.0
    for smp in m["rhs_samples"]:
        d = np.array(model.rhs_list(smp["t"], smp["y"]))
        ref = np.array(smp["dydt"])
        scale = np.maximum(np.abs(ref), 1e-300)
        worst = max(worst, float(np.max(np.abs(d - ref) / scale)))
    out["rhs_max_rel_diff"] = worst
    print(f"1. right-hand side vs C++ at {len(m['rhs_samples'])} states: max relative difference"
          f" {worst:.2e}")

    # 2. Fixed-step RK4 in Python with the C++ step.
    best = math.inf
    for _ in range(args.repeat):
        c0 = time.process_time()
        y_end, forces = rk4(model, m["y0"], h, steps)
        best = min(best, time.process_time() - c0)
    dmax = float(np.max(np.abs(np.array(forces) - cpp_force)))
    out.update(py_rk4_cpu_s=best, py_rk4_force_max_diff_n=dmax)
    print(f"2. Python RK4, {steps} steps of {h * 1e6:.3f} us: mesh force vs C++ RK4 max |diff|"
          f" {dmax:.3e} N ({dmax / f_static:.1e} of static); CPU {best * 1e3:.1f} ms,"
          f" {steps / best:.3g} steps/s")

    # 3. solve_ivp RK45. atol per component: --atol times the static deflection scale of the
    # positions, and that times the mesh angular frequency for the speeds.
    pos_scale = float(np.max(np.abs(y0[:n])))
    w_mesh = m["omega_in"] * m["za"]

    def tolerances(factor):
        return np.concatenate([np.full(n, factor * pos_scale), np.full(n, factor * pos_scale * w_mesh)])

    def ivp_force(rtol, atol_factor):
        sol = solve_ivp(model.rhs, (0.0, span), y0, method="RK45", rtol=rtol,
                        atol=tolerances(atol_factor), t_eval=cpp_t)
        return np.array([model.force(t, sol.y[:, i].tolist()) for i, t in enumerate(sol.t)])

    atol = tolerances(args.atol)
    best = math.inf
    for _ in range(args.repeat):
        c0 = time.process_time()
        sol = solve_ivp(model.rhs, (0.0, span), y0, method="RK45", rtol=args.rtol, atol=atol)
        best = min(best, time.process_time() - c0)
    if not sol.success:
        print("   solve_ivp failed:", sol.message)
    accepted = len(sol.t) - 1
    f_ivp = ivp_force(args.rtol, args.atol)
    diff = np.abs(f_ivp - cpp_force)
    # Reference: RK45 at rtol 1e-12 (the mesh stiffness jumps when a pair enters or leaves, so
    # fixed-step RK4 converges only about linearly there and cannot serve as its own reference).
    f_ref = ivp_force(1e-12, 1e-10)
    err_cpp = float(np.max(np.abs(cpp_force - f_ref)))
    err_ivp = float(np.max(np.abs(f_ivp - f_ref)))
    out.update(ivp_rtol=args.rtol, ivp_atol_factor=args.atol, ivp_cpu_s=best, ivp_steps=accepted,
               ivp_nfev=int(sol.nfev), ivp_force_max_diff_n=float(diff.max()),
               ivp_force_rms_diff_n=float(np.sqrt(np.mean(diff ** 2))),
               cpp_rk4_force_err_vs_ref_n=err_cpp, ivp_force_err_vs_ref_n=err_ivp)
    print(f"3. solve_ivp RK45 rtol {args.rtol:g}, atol {args.atol:g} x (static deflection,"
          f" x w_mesh for speeds): {accepted} steps, {sol.nfev} RHS evaluations, CPU"
          f" {best * 1e3:.1f} ms, {accepted / best:.3g} steps/s")
    print(f"   mesh force vs C++ RK4 at the {len(cpp_t)} step times: max |diff| {diff.max():.3e} N"
          f" ({diff.max() / f_static:.1e} of static), rms {out['ivp_force_rms_diff_n']:.3e} N")
    print(f"   max error against RK45 at rtol 1e-12: C++ RK4 {err_cpp:.3e} N"
          f" ({err_cpp / f_static:.1e} of static), this solve_ivp {err_ivp:.3e} N")

    # 4. Ratios.
    cpp = m["rk4_cpu_s"]
    out.update(ratio_ivp_over_cpp=best / cpp, ratio_pyrk4_over_cpp=out["py_rk4_cpu_s"] / cpp)
    print(f"4. C++ RK4 {steps} steps in {cpp * 1e3:.3f} ms CPU ({steps / cpp:.3g} steps/s):"
          f" solve_ivp takes {best / cpp:.0f}x as long for the same span, the Python RK4 with the"
          f" same steps {out['py_rk4_cpu_s'] / cpp:.0f}x")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
