# Draws docs/figures/wear_history.svg from two `geardiag wear` runs (see docs/wear.md):
#   geardiag wear --gearbox testdata/gearbox/three_shaft.json --mesh z1_z2 --cycles 1e7 --steps 100 -o wa.h5
#   geardiag wear ... --law seed004 -o ws.h5
#   /usr/bin/python3 docs/figures/wear_history.py wa.h5 ws.h5 docs/figures/wear_history.svg
import sys
import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

matplotlib.rcParams["svg.hashsalt"] = "geardiag"  # reproducible ids
fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
for path, law, ls in [(sys.argv[1], "Archard", "-"), (sys.argv[2], "seed 004", "--")]:
    f = h5py.File(path, "r")
    cyc = f["wear/cycles"][:]
    for k, col in zip([len(cyc) // 4, len(cyc) // 2, len(cyc) - 1], ["#9ac", "#58a", "#135"]):
        ax[0].plot(f["wear/z1/radius_mm"][:], f["wear/z1/depth_um"][k], ls=ls, color=col,
                   label=f"{law}, {cyc[k]:.2g} cycles")
        ax[1].plot(f["wear/z2/radius_mm"][:], f["wear/z2/depth_um"][k], ls=ls, color=col)
    ax[2].semilogy(cyc, f["wear/te_peak_to_peak_rad"][:], ls=ls, color="k", label=law + ": peak-to-peak")
    ax[2].semilogy(cyc, f["wear/te_harmonics_rad"][:, 0], ls=ls, color="#c60", label=law + ": 1st mesh harmonic")
ax[0].set(xlabel="pinion z1 radius [mm]", ylabel="wear depth [um]", title="driver (18 teeth)")
ax[1].set(xlabel="wheel z2 radius [mm]", title="driven (36 teeth)")
ax[2].set(xlabel="driver revolutions", ylabel="unloaded TE [rad of z2]", title="transmission error")
ax[0].legend(fontsize=6)
ax[2].legend(fontsize=6)
fig.tight_layout()
fig.savefig(sys.argv[3], metadata={"Date": None})
