"""Closed check of a `geardiag wear` history from its output file alone.

At every step, the loaded contact ratio and the mesh stiffness are recomputed from the worn
profiles the file holds (/wear/<gear>/roll_mm, depth_um), the pair stiffness k(s) and the normal
force F it states: at the history's sample angles (te_points_per_mesh per mesh period) the pairs in
contact sit at s + j p_b, each separated by g = h1(s) + h2(T1T2 - s); the compression d with
sum k (d - g)^+ = F is found by bisection; a pair is loaded when k (d - g) > 0. The loaded contact
ratio is the mean number of loaded pairs, the mesh stiffness the mean of their k. Both must agree
with /wear/loaded_contact_ratio and /wear/mesh_stiffness_n_per_m: the ratio within one sample
angle (1/nt: a pair at the very edge of contact, load within round-off of zero, may fall either
side), the stiffness within 1 %.

usage: wear_contact_check.py OUT.h5   (prints one line per law state; exit 1 on disagreement)
"""
import json
import sys

import h5py
import numpy as np


def check(path):
    f = h5py.File(path, "r")

    def attr(name):
        v = f.attrs[name]
        return v.decode() if isinstance(v, bytes) else str(v)

    gb = json.loads(attr("gearbox"))
    driver, driven = next((m["driver"], m["driven"]) for m in gb["meshes"]
                          if m["driver"] + "_" + m["driven"] == attr("mesh"))
    z1 = next(g["teeth"] for g in gb["gears"] if g["name"] == driver)
    nt = int(attr("te_points_per_mesh"))
    s = f[f"wear/{driver}/roll_mm"][:] * 1e-3
    r = f[f"wear/{driver}/radius_mm"][:] * 1e-3
    s2 = f[f"wear/{driven}/roll_mm"][:] * 1e-3
    d1 = f[f"wear/{driver}/depth_um"][:] * 1e-6
    d2 = f[f"wear/{driven}/depth_um"][:] * 1e-6
    k = f[f"wear/{driver}/pair_stiffness_n_per_m"][:]
    force = float(f["wear/normal_force_n"][0])
    s0, s1 = s[0], s[-1]
    rb1 = float(np.median(np.sqrt(r * r - s * s)))
    pb = 2 * np.pi * rb1 / z1
    length = s0 + s2[-1]  # T1T2: the driven roll at the start of contact is T1T2 - s0
    eps_file = f["wear/loaded_contact_ratio"][:]
    k_file = f["wear/mesh_stiffness_n_per_m"][:]
    worst_eps = worst_k = 0.0
    for step in range(len(eps_file)):
        eps = kmesh = 0.0
        for i in range(nt):
            q = s0 + pb * (i + 0.5) / nt + pb * np.arange(0, 4)
            q = q[q <= s1 + 1e-12]
            kq = np.interp(q, s, k)
            g = np.interp(q, s, d1[step]) + np.interp(length - q, s2, d2[step])
            lo, hi = 0.0, 1e-3
            for _ in range(64):  # 1 mm / 2^64: far below round-off of d
                mid = 0.5 * (lo + hi)
                if np.sum(kq * np.maximum(mid - g, 0.0)) < force:
                    lo = mid
                else:
                    hi = mid
            loaded = kq * (hi - g) > 0
            eps += np.count_nonzero(loaded) / nt
            kmesh += np.sum(kq[loaded]) / nt
        worst_eps = max(worst_eps, abs(eps - eps_file[step]))
        worst_k = max(worst_k, abs(kmesh - k_file[step]) / kmesh)
    law = attr("law")
    ok = worst_eps <= 1.0 / nt + 1e-9 and worst_k <= 0.01
    print(f"{law}: {len(eps_file)} steps, loaded contact ratio {eps_file[0]:.4f} -> "
          f"{eps_file[-1]:.4f}, largest difference {worst_eps:.4f} (bound {1.0 / nt:.4f}); "
          f"mesh stiffness {k_file[0]:.4g} -> {k_file[-1]:.4g} N/m, largest difference "
          f"{100 * worst_k:.3f} % (bound 1 %): {'ok' if ok else 'DISAGREE'}")
    return ok


if __name__ == "__main__":
    sys.exit(0 if all(check(p) for p in sys.argv[1:]) else 1)
